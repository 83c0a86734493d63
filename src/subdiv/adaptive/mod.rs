//! Local (adaptive) refinement of control meshes, with each scheme's own rules: where a fit
//! misses its tolerance, the marked control faces are split and their neighbours adjusted so
//! the mesh stays one the scheme can evaluate, and new points are placed so the limit surface
//! changes as little as possible (SPEC §1.8).
//!
//! | scheme | split | module |
//! |---|---|---|
//! | Loop | red–green 1→4 / 1→2 with Loop's masks, then valence-lowering edge flips | `triangles` |
//! | Catmull–Clark | 1→4 quads closed by transition templates, Catmull–Clark's masks | `quads` |
//! | Doo–Sabin | marked n-gons into quads, neighbours gain the edge midpoints | `polygons` |

mod creases;
mod polygons;
mod quads;
mod triangles;

pub use creases::{carried_creases, tag_creases};
pub use polygons::split_polygons;
pub use quads::split_quads;
pub use triangles::{improve_by_flips, split_triangles, triangles_of, SplitRule};

use super::{Scheme, SubdivError};
use crate::mesh::PolyMesh;

/// Splits the `marked` faces of `control` (one flag per face) by `scheme`'s local refinement
/// and what conformity needs around them, with the crease rules on the edges `creases` (Loop
/// and Catmull–Clark; Doo–Sabin places midpoints everywhere). Quad schemes need the mesh they
/// evaluate (quads for Catmull–Clark; any polygons for Doo–Sabin). The crease edges of the
/// result are [`carried_creases`].
pub fn refine_marked(
    scheme: Scheme,
    control: &PolyMesh,
    marked: &[bool],
    creases: &[[u32; 2]],
) -> Result<PolyMesh, SubdivError> {
    match scheme {
        Scheme::Loop => split_triangles(control, marked, SplitRule::Loop, creases),
        Scheme::CatmullClark => split_quads(control, marked, creases),
        Scheme::DooSabin => split_polygons(control, marked),
    }
}

/// Local remeshing after [`refine_marked`]: valence-lowering and thin-triangle-removing edge
/// flips around the vertices numbered `first_new` and up (Loop; the quad schemes make none),
/// never of the crease edges `creases`. Returns the number of changes.
pub fn remesh(
    scheme: Scheme,
    control: &mut PolyMesh,
    first_new: u32,
    creases: &[[u32; 2]],
) -> Result<usize, SubdivError> {
    match scheme {
        Scheme::Loop => improve_by_flips(control, 3, first_new, creases),
        Scheme::CatmullClark | Scheme::DooSabin => Ok(0),
    }
}

/// One flag per face, or the error that says how many there were.
fn check_flags(marked: &[bool], faces: usize) -> Result<(), SubdivError> {
    if marked.len() == faces {
        return Ok(());
    }
    Err(SubdivError::FlagCount {
        flags: marked.len(),
        faces,
    })
}

/// A new vertex index, or the error for meshes beyond the u32 index range.
fn index_u32(n: usize) -> Result<u32, SubdivError> {
    u32::try_from(n).map_err(|_| SubdivError::TooManyPoints { count: n })
}
