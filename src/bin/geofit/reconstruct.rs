//! `geofit reconstruct FILE [-o OUT.obj] [--kind open|closed] [--no-grid] [--json]`: a mesh from
//! bare points, timed, with the distance of the points to it.

use crate::output::{print_json, read_input};
use geofit::cloud::{reconstruct, ReconstructOptions, SurfaceKind};
use geofit::mesh::deviation;
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `geofit reconstruct`.
#[derive(clap::Args)]
pub struct Args {
    /// Point file (PLY, XYZ/CSV/PTS; faces in the file are ignored).
    file: PathBuf,
    /// Where to write the mesh; the format follows the extension (obj, ply, stl).
    #[arg(short = 'o', long = "output")]
    output: Option<PathBuf>,
    /// Force the kind of surface instead of detecting it.
    #[arg(long, value_parser = ["open", "closed"])]
    kind: Option<String>,
    /// Ignore the file's range grid (triangulate open scans by Delaunay instead).
    #[arg(long)]
    no_grid: bool,
    /// Statistical outlier removal: drop points this many standard deviations sparser than
    /// the mean.
    #[arg(long)]
    outliers: Option<f64>,
    /// Print one JSON object on one line instead of indented JSON.
    #[arg(long)]
    json: bool,
}

/// Builds the mesh and prints its kind, counts, the time of the reconstruction alone
/// (`reconstruct_s`) and the distance of every point to it (in % of the bounding-box diagonal).
pub fn run(args: Args) -> Result<(), String> {
    let loaded = read_input(&args.file)?;
    let points = loaded.mesh.positions();
    let kind = match args.kind.as_deref() {
        Some("open") => Some(SurfaceKind::Open),
        Some("closed") => Some(SurfaceKind::Closed),
        _ => None,
    };
    let options = ReconstructOptions::default()
        .with_kind(kind)
        .with_outlier_std_ratio(args.outliers);
    let grid = loaded.range_grid.as_ref().filter(|_| !args.no_grid);
    let start = Instant::now();
    let result = reconstruct(points, grid, &options).map_err(|e| e.to_string())?;
    let seconds = start.elapsed().as_secs_f64();
    let diagonal = loaded.mesh.bbox().map_or(0.0, |b| b.diagonal());
    let dev = deviation(points, &result.mesh).map(|d| d.percent_of(diagonal));
    if let Some(path) = &args.output {
        let bytes = match path.extension().and_then(|e| e.to_str()) {
            Some("ply") => geofit::io::to_ply_bytes(&result.mesh),
            Some("stl") => geofit::io::to_stl_bytes(&result.mesh),
            _ => geofit::io::to_obj_bytes(&result.mesh),
        }
        .map_err(|e| e.to_string())?;
        std::fs::write(path, bytes).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    let report = serde_json::json!({
        "points": points.len(),
        "kind": format!("{:?}", result.kind).to_lowercase(),
        "outliers": result.outliers,
        "vertices": result.mesh.num_vertices(),
        "triangles": result.mesh.num_triangles(),
        "stray_triangles": result.stray_triangles,
        "open_uncovered": result.open_uncovered,
        "reconstruct_s": seconds,
        "deviation_max_pct": dev.map(|d| d.max),
        "deviation_rms_pct": dev.map(|d| d.rms),
    });
    print_json(&report, args.json)
}
