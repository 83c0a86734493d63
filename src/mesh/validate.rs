//! Topology checks for control meshes: what makes a polygon soup unusable for subdivision.
//!
//! Subdivision rules and limit evaluation walk around vertices and across edges; a vertex whose
//! faces form two separate fans, an edge shared by three faces or two faces that disagree on
//! orientation make those walks ambiguous. Such meshes are rejected with a [`TopologyError`]
//! naming the offending element instead of producing garbage.

use thiserror::Error;

/// Why a polygon mesh cannot be a control mesh.
#[derive(Debug, Error, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum TopologyError {
    /// A face uses the same vertex twice.
    #[error("face {face} uses vertex {vertex} more than once")]
    DegenerateFace {
        /// The offending face.
        face: usize,
        /// The repeated vertex.
        vertex: u32,
    },
    /// An edge is shared by more than two faces.
    #[error("edge ({a}, {b}) is shared by {faces} faces; a manifold edge has at most 2")]
    NonManifoldEdge {
        /// One end of the edge.
        a: u32,
        /// The other end.
        b: u32,
        /// How many faces use it.
        faces: usize,
    },
    /// Two faces traverse their shared edge in the same direction.
    #[error("faces on edge ({a}, {b}) have inconsistent orientation")]
    InconsistentOrientation {
        /// One end of the edge.
        a: u32,
        /// The other end.
        b: u32,
    },
    /// The faces around a vertex form more than one fan (e.g. two cones touching at a tip).
    #[error("vertex {vertex} is non-manifold: its faces form {fans} separate fans")]
    NonManifoldVertex {
        /// The offending vertex.
        vertex: u32,
        /// Number of fans found (at least 2).
        fans: usize,
    },
    /// An operation needs a different face shape (e.g. an edge flip needs triangles).
    #[error("face {face} has {len} corners; this operation needs {needed}")]
    WrongFaceSize {
        /// The offending face.
        face: usize,
        /// Its number of corners.
        len: usize,
        /// The number needed.
        needed: usize,
    },
    /// An edge index or vertex pair does not name an edge of the mesh.
    #[error("no edge between vertices {a} and {b}")]
    NoSuchEdge {
        /// One end.
        a: u32,
        /// The other end.
        b: u32,
    },
    /// An edge flip was refused: the edge is on the boundary, or flipping would duplicate an edge.
    #[error("edge ({a}, {b}) cannot be flipped: {reason}")]
    CannotFlip {
        /// One end.
        a: u32,
        /// The other end.
        b: u32,
        /// Why not.
        reason: &'static str,
    },
    /// A face index is out of range.
    #[error("face {face} does not exist (the mesh has {count} faces)")]
    NoSuchFace {
        /// The requested face.
        face: usize,
        /// Number of faces.
        count: usize,
    },
}

/// Checks that `mesh` is a consistently oriented manifold with boundary as far as its edges
/// tell: no face repeats a vertex, and no directed edge is used twice (so every edge has one or
/// two faces, and two faces on an edge use it in opposite directions). Cheaper than building a
/// [`crate::mesh::ControlMesh`]; local refinement checks its output with it.
pub fn check_oriented_edges(mesh: &crate::mesh::PolyMesh) -> Result<(), TopologyError> {
    let mut directed = std::collections::HashSet::new();
    for (face, f) in mesh.faces().enumerate() {
        for k in 0..f.len() {
            let (a, b) = (f[k], f[(k + 1) % f.len()]);
            if a == b {
                return Err(TopologyError::DegenerateFace { face, vertex: a });
            }
            if !directed.insert((a, b)) {
                return Err(TopologyError::InconsistentOrientation { a, b });
            }
        }
    }
    Ok(())
}
