//! `geofit simplify FILE --target N [--creases] [-o OUT.obj] [--json]`: QEM simplification (with the repair
//! it starts with), timed, with the distance of the input's points to the result; and
//! `geofit simplify FILE --measure OTHER`: the same measures for a mesh made elsewhere, so that
//! other simplifiers are judged exactly as geofit is.

use crate::output::{print_json, read_input};
use geofit::mesh::{
    detect_features, simplify_with_creases, FeatureOptions, PolyMesh, SimplifyOptions,
};
use geofit::mesh::{deviation, foldovers};
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `geofit simplify`.
#[derive(clap::Args)]
pub struct Args {
    /// Mesh file (PLY, OBJ, STL) with faces.
    file: PathBuf,
    /// Number of vertices of the result (vertices in no face are not counted or kept).
    #[arg(long, required_unless_present = "measure")]
    target: Option<usize>,
    /// Instead of simplifying, measure this mesh (e.g. another simplifier's output) against
    /// FILE: deviation of FILE's points from it and its fold-overs.
    #[arg(long, conflicts_with = "target")]
    measure: Option<PathBuf>,
    /// Where to write the result; the format follows the extension (obj, ply, stl).
    #[arg(short = 'o', long = "output")]
    output: Option<PathBuf>,
    /// Stiffness of open boundaries (default 10; 0 lets them move).
    #[arg(long)]
    boundary_weight: Option<f64>,
    /// Largest rotation of a face normal per collapse, in degrees (default 60).
    #[arg(long)]
    max_normal_change: Option<f64>,
    /// Smallest triangle quality a collapse may create, 0..1 (default 0.1).
    #[arg(long)]
    min_quality: Option<f64>,
    /// Largest valence a collapse may create (default 16).
    #[arg(long)]
    max_valence: Option<usize>,
    /// Find the mesh's sharp creases first and keep them as edge chains (the result's crease
    /// edges are counted in `creases`).
    #[arg(long)]
    creases: bool,
    /// With --creases: dihedral angle above which an edge is a crease, degrees (default 40).
    #[arg(long)]
    crease_angle: Option<f64>,
    /// Print one JSON object on one line instead of indented JSON.
    #[arg(long)]
    json: bool,
}

/// Simplifies the file's mesh and prints counts, the time of the simplification alone (wall
/// `simplify_s`, and `simplify_cpu_s`, the thread's CPU time, which a loaded machine inflates
/// less), what repair and relaxation did, and the distance of every input point to the result
/// (`deviation_*_pct`, in % of the input's bounding-box diagonal) with its fold-overs.
pub fn run(args: Args) -> Result<(), String> {
    let loaded = read_input(&args.file)?;
    let mesh = &loaded.mesh;
    if let Some(other) = &args.measure {
        let other = read_input(other)?.mesh;
        return print_json(&measures(mesh, &other), args.json);
    }
    let target = args.target.unwrap_or_default();
    let options = options(&args);
    let features = FeatureOptions {
        angle_deg: args
            .crease_angle
            .unwrap_or(FeatureOptions::DEFAULT_ANGLE_DEG),
        ..FeatureOptions::default()
    };
    let creases = match args.creases {
        true => {
            detect_features(mesh, &features)
                .map_err(|e| e.to_string())?
                .edges
        }
        false => Vec::new(),
    };
    let (cpu, start) = (thread_cpu_seconds(), Instant::now());
    let done =
        simplify_with_creases(mesh, target, &options, &creases).map_err(|e| e.to_string())?;
    let seconds = start.elapsed().as_secs_f64();
    let cpu_seconds = thread_cpu_seconds().zip(cpu).map(|(b, a)| b - a);
    if let Some(path) = &args.output {
        write(&done.mesh, path)?;
    }
    let mut report = measures(mesh, &done.mesh);
    let r = &done.report;
    let extra = serde_json::json!({
        "target": target,
        "simplify_s": seconds,
        "simplify_cpu_s": cpu_seconds,
        "passes": r.passes,
        "relaxations": r.relaxations,
        "floor_note": r.floor_note,
        "max_valence": r.max_valence,
        "repairs": r.repair,
        "creases": r.creases,
    });
    if let (Some(map), serde_json::Value::Object(more)) = (report.as_object_mut(), extra) {
        map.extend(more);
    }
    print_json(&report, args.json)
}

/// The options from the command line.
fn options(args: &Args) -> SimplifyOptions {
    let mut options = SimplifyOptions::default();
    if let Some(w) = args.boundary_weight {
        options = options.with_boundary_weight(w);
    }
    if let Some(a) = args.max_normal_change {
        options = options.with_max_normal_change_deg(a);
    }
    if let Some(q) = args.min_quality {
        options = options.with_min_triangle_quality(q);
    }
    if let Some(v) = args.max_valence {
        options = options.with_max_valence(v);
    }
    options
}

/// Counts of `input` and `coarse`, the deviation of `input`'s points from `coarse` (in % of
/// `input`'s bounding-box diagonal) and `coarse`'s fold-overs against `input`.
fn measures(input: &PolyMesh, coarse: &PolyMesh) -> serde_json::Value {
    let diagonal = input.bbox().map_or(0.0, |b| b.diagonal());
    let dev = deviation(input.positions(), coarse).map(|d| d.percent_of(diagonal));
    let used = {
        let mut used = vec![false; coarse.num_vertices()];
        coarse
            .faces()
            .flatten()
            .for_each(|&v| used[v as usize] = true);
        used.iter().filter(|&&u| u).count()
    };
    serde_json::json!({
        "input_points": input.num_vertices(),
        "input_triangles": input.num_triangles(),
        "vertices": used,
        "triangles": coarse.num_triangles(),
        "deviation_max_pct": dev.map(|d| d.max),
        "deviation_rms_pct": dev.map(|d| d.rms),
        "deviation_mean_pct": dev.map(|d| d.mean),
        "foldovers": foldovers(input, coarse),
    })
}

/// CPU time of the calling thread in seconds (Linux: `/proc/thread-self/schedstat`, whose first
/// field is nanoseconds on the CPU), or `None` where that is not available.
fn thread_cpu_seconds() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    let ns: f64 = text.split_whitespace().next()?.parse().ok()?;
    Some(ns * 1e-9)
}

fn write(mesh: &PolyMesh, path: &std::path::Path) -> Result<(), String> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let bytes = match ext.as_deref() {
        Some("ply") => geofit::io::to_ply_bytes(mesh),
        Some("stl") => geofit::io::to_stl_bytes(mesh),
        _ => geofit::io::to_obj_bytes(mesh),
    }
    .map_err(|e| e.to_string())?;
    std::fs::write(path, bytes).map_err(|e| format!("{}: {e}", path.display()))
}
