//! Polygon meshes: the in-memory form of every point or mesh file, and the control meshes that
//! subdivision and fitting work on; their repair on intake and their QEM simplification.

mod error;
mod features;
mod halfedge;
mod poly;
mod repair;
mod simplify;
mod validate;

pub use error::MeshError;
pub use features::{detect_features, FeatureLine, FeatureOptions, Features};
pub use halfedge::{ControlMesh, ControlMeshError, NONE};
pub use poly::PolyMesh;
pub use repair::{repair, repair_with, Components, Found, RepairOptions, RepairReport, Repaired};
pub use simplify::{
    deviation, foldovers, simplify, simplify_with, simplify_with_creases, simplify_with_report,
    CreaseCount, Deviation, Foldovers, Relaxation, Simplified, SimplifyError, SimplifyOptions,
    SimplifyReport,
};
pub use validate::{check_oriented_edges, TopologyError};
