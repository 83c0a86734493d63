//! `geofit info FILE [--json]`.

use std::path::PathBuf;

/// Arguments of `geofit info`.
#[derive(clap::Args)]
pub struct Args {
    /// Point or mesh file (PLY, OBJ, STL, XYZ/CSV/PTS).
    file: PathBuf,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
}

pub fn run(args: Args) -> Result<(), String> {
    let loaded =
        geofit::io::read_path(&args.file).map_err(|e| format!("{}: {e}", args.file.display()))?;
    let mesh = &loaded.mesh;
    let bbox = mesh.bbox();
    let report = serde_json::json!({
        "format": loaded.format,
        "points": mesh.num_vertices(),
        "triangles": mesh.num_triangles(),
        "bbox_min": bbox.map(|b| b.min.to_array()),
        "bbox_max": bbox.map(|b| b.max.to_array()),
    });
    if args.json {
        println!("{report}");
    } else {
        println!(
            "{}",
            serde_json::to_string_pretty(&report).map_err(|e| e.to_string())?
        );
    }
    Ok(())
}
