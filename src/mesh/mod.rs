//! Polygon meshes: the in-memory form of every point or mesh file, and the control meshes that
//! subdivision and fitting work on.

mod error;
mod halfedge;
mod poly;
pub mod repair;
pub mod simplify;
mod validate;

pub use error::MeshError;
pub use halfedge::{ControlMesh, ControlMeshError, NONE};
pub use poly::PolyMesh;
pub use repair::{repair, repair_with, RepairOptions, RepairReport, Repaired};
pub use simplify::{
    simplify, simplify_with, simplify_with_report, Simplified, SimplifyError, SimplifyOptions,
    SimplifyReport,
};
pub use validate::TopologyError;
