//! `geofit simplify FILE --target N [-o OUT.obj] [--json]`: QEM simplification, timed, with the
//! distance of the input's points to the result.

use crate::output::{print_json, read_input};
use geofit::mesh::simplify::deviation;
use geofit::mesh::{simplify_with, SimplifyOptions};
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `geofit simplify`.
#[derive(clap::Args)]
pub struct Args {
    /// Mesh file (PLY, OBJ, STL) with faces.
    file: PathBuf,
    /// Number of vertices of the result (vertices in no face are not counted or kept).
    #[arg(long)]
    target: usize,
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
    /// Print one JSON object on one line instead of indented JSON.
    #[arg(long)]
    json: bool,
}

/// Simplifies the file's mesh and prints counts, the time of the simplification alone
/// (`simplify_s`) and the distance of every input point to the result (`deviation_*_pct`, in %
/// of the input's bounding-box diagonal).
pub fn run(args: Args) -> Result<(), String> {
    let loaded = read_input(&args.file)?;
    let mesh = &loaded.mesh;
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
    let start = Instant::now();
    let coarse = simplify_with(mesh, args.target, &options).map_err(|e| e.to_string())?;
    let seconds = start.elapsed().as_secs_f64();
    let diagonal = mesh.bbox().map_or(0.0, |b| b.diagonal());
    let dev = deviation(mesh.positions(), &coarse).map(|d| d.percent_of(diagonal));
    if let Some(path) = &args.output {
        write(&coarse, path)?;
    }
    let report = serde_json::json!({
        "input_points": mesh.num_vertices(),
        "input_triangles": mesh.num_triangles(),
        "vertices": coarse.num_vertices(),
        "triangles": coarse.num_triangles(),
        "simplify_s": seconds,
        "deviation_max_pct": dev.map(|d| d.max),
        "deviation_rms_pct": dev.map(|d| d.rms),
        "deviation_mean_pct": dev.map(|d| d.mean),
    });
    print_json(&report, args.json)
}

fn write(mesh: &geofit::mesh::PolyMesh, path: &std::path::Path) -> Result<(), String> {
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
