//! `geofit info FILE [--json]`.

use crate::output::{print_json, read_input};
use std::path::PathBuf;

/// Arguments of `geofit info`.
#[derive(clap::Args)]
pub struct Args {
    /// Point or mesh file (PLY, OBJ, STL, XYZ/CSV/PTS, E57, LAS/LAZ, PCD, PTX, glTF/GLB).
    file: PathBuf,
    /// Print one JSON object on one line instead of indented JSON.
    #[arg(long)]
    json: bool,
}

/// Reads the file and prints its format, counts and bounding box. `triangles` counts the mesh
/// after triangulating polygons and strips; a range scan's grid is reported as
/// `range_grid: [cols, rows]` and not counted as triangles. The scanner formats with scans
/// (E57, LAS/LAZ, PTX) add `scans` and `grid_kept` (a file of several scans keeps no grid);
/// formats that define their unit (E57, glTF/GLB: metres) add `unit_to_metres`. A mesh adds
/// `repairs`: what the repair every fit starts with would change ([`geofit::mesh::RepairReport`]:
/// counts per kind, the first few indices of each, and a one-line `summary`). Points a fit would
/// leave out as strays ([`geofit::geom::find_strays`]) add `strays` (`count`, `first`). A mesh
/// also adds `features`: the sharp creases [`geofit::mesh::detect_features`] finds on the
/// repaired mesh with its default angle (counts, total length, and the first few corners).
pub fn run(args: Args) -> Result<(), String> {
    let loaded = read_input(&args.file)?;
    let mesh = &loaded.mesh;
    let bbox = mesh.bbox();
    let mut report = serde_json::json!({
        "format": loaded.format,
        "points": mesh.num_vertices(),
        "triangles": mesh.num_triangles(),
        "bbox_min": bbox.map(|b| b.min.to_array()),
        "bbox_max": bbox.map(|b| b.max.to_array()),
    });
    if let Some(grid) = &loaded.range_grid {
        report["range_grid"] = serde_json::json!([grid.cols(), grid.rows()]);
    }
    if let Some(scans) = loaded.scans {
        report["scans"] = scans.into();
        report["grid_kept"] = loaded.range_grid.is_some().into();
    }
    if let Some(unit) = loaded.unit_to_metres {
        report["unit_to_metres"] = unit.into();
    }
    if !mesh.is_point_cloud() {
        let repaired =
            geofit::mesh::repair(mesh).map_err(|e| format!("{}: {e}", args.file.display()))?;
        report["repairs"] = serde_json::to_value(&repaired.report).map_err(|e| e.to_string())?;
        report["features"] = features_json(&repaired.mesh)?;
    }
    let strays = geofit::geom::find_strays(mesh.positions());
    if !strays.is_empty() {
        report["strays"] = serde_json::json!({
            "count": strays.len(),
            "first": &strays[..strays.len().min(5)],
        });
    }
    if !loaded.polylines.is_empty() {
        report["polylines"] = loaded.polylines.len().into();
    }
    if loaded.dimension == 2 {
        report["dimension"] = 2.into();
    }
    print_json(&report, args.json)
}

/// The `features` object of `geofit info`: crease edges, lines, their length (model units and %
/// of the bounding-box diagonal), corners and dart ends, at the default crease angle.
fn features_json(mesh: &geofit::mesh::PolyMesh) -> Result<serde_json::Value, String> {
    let options = geofit::mesh::FeatureOptions::default();
    let found = geofit::mesh::detect_features(mesh, &options).map_err(|e| e.to_string())?;
    let diagonal = mesh.bbox().map_or(0.0, |b| b.diagonal());
    let pct = if diagonal > 0.0 {
        100.0 * found.total_length / diagonal
    } else {
        0.0
    };
    Ok(serde_json::json!({
        "angle_deg": options.angle_deg,
        "crease_edges": found.edges.len(),
        "lines": found.lines.len(),
        "length": found.total_length,
        "length_diagonals": pct / 100.0,
        "corners": found.corners.len(),
        "darts": found.darts.len(),
        "first_corners": &found.corners[..found.corners.len().min(5)],
        "summary": found.summary(),
    }))
}
