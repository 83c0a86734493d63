//! `geofit subdiv FILE --scheme loop|catmull-clark|doo-sabin --levels L -o OUT.obj [--limit]`.

use crate::output::read_input;
use geofit::mesh::ControlMesh;
use geofit::subdiv::{limit_positions, refine_levels, Scheme};
use std::path::PathBuf;

/// Scheme names on the command line.
#[derive(Clone, Copy, clap::ValueEnum)]
enum SchemeArg {
    Loop,
    CatmullClark,
    DooSabin,
}

/// Arguments of `geofit subdiv`.
#[derive(clap::Args)]
pub struct Args {
    /// Control mesh (OBJ, PLY, STL with faces).
    file: PathBuf,
    /// Subdivision scheme.
    #[arg(long, value_enum, default_value = "loop")]
    scheme: SchemeArg,
    /// Number of refinement steps.
    #[arg(long, default_value_t = 1)]
    levels: usize,
    /// Output OBJ file.
    #[arg(short, long)]
    output: PathBuf,
    /// Move the output vertices to their exact limit positions (for Doo–Sabin: the limit
    /// points of interior vertices).
    #[arg(long)]
    limit: bool,
}

/// Most refinement steps accepted (each multiplies the face count by about 4).
const MAX_LEVELS: usize = 8;

pub fn run(args: Args) -> Result<(), String> {
    let scheme = match args.scheme {
        SchemeArg::Loop => Scheme::Loop,
        SchemeArg::CatmullClark => Scheme::CatmullClark,
        SchemeArg::DooSabin => Scheme::DooSabin,
    };
    if args.levels > MAX_LEVELS {
        return Err(format!(
            "--levels {} is more than {MAX_LEVELS}",
            args.levels
        ));
    }
    let name = args.file.display();
    let loaded = read_input(&args.file)?;
    let control = ControlMesh::try_new(&loaded.mesh).map_err(|e| format!("{name}: {e}"))?;
    let refined =
        refine_levels(scheme, &control, args.levels).map_err(|e| format!("{name}: {e}"))?;
    let mut mesh = refined.to_poly_mesh().map_err(|e| e.to_string())?;
    if args.limit {
        let limits =
            limit_positions(scheme, &refined).map_err(|e| format!("{name}: --limit: {e}"))?;
        mesh = geofit::mesh::PolyMesh::try_new(limits, mesh.faces()).map_err(|e| e.to_string())?;
    }
    let file = std::fs::File::create(&args.output)
        .map_err(|e| format!("{}: {e}", args.output.display()))?;
    let mut out = std::io::BufWriter::new(file);
    geofit::io::write_obj(&mesh, &mut out)
        .map_err(|e| format!("{}: {e}", args.output.display()))?;
    outln!(
        "{}: {} vertices, {} faces after {} {:?} step(s){}",
        args.output.display(),
        mesh.num_vertices(),
        mesh.num_faces(),
        args.levels,
        scheme,
        if args.limit {
            ", at limit positions"
        } else {
            ""
        }
    );
    Ok(())
}
