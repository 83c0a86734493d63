//! Polygon meshes: the in-memory form of every point or mesh file, and the control meshes that
//! subdivision and fitting work on.

mod error;
mod poly;

pub use error::MeshError;
pub use poly::PolyMesh;
