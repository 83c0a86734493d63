//! geofit: fit smooth surfaces and curves to 3D scans by geometric iteration.
//!
//! A point file (a scan) goes in; a Loop, Catmull–Clark or Doo–Sabin subdivision surface, or a
//! B-spline/NURBS surface or curve, is fitted to it by moving control points along weighted error
//! vectors (no linear system per iteration), and the result is exported for CAD.
//!
//! Architecture (dependencies point one way):
//!
//! | module | what it is |
//! |---|---|
//! | [`geom`] | f64 points, vectors, boxes, tolerances |
//! | [`mesh`] | polygon meshes, adjacency, validation, simplification |
//! | [`subdiv`] | subdivision schemes and exact limit-surface evaluation |
//! | [`spline`] | B-spline / NURBS curves and surfaces |
//! | [`fit`] | the fitting engines (geometric iteration, least squares) |
//! | [`io`] | readers and writers for point and mesh files |
//! | [`cloud`] | bare point clouds to meshes (range grid, Delaunay, implicit surface) |
//! | [`export`] | IGES and STEP export of B-spline / NURBS curves and surfaces |
//! | [`render`] | the wgpu viewer (GPU part on `wasm32` only) and its f32 draw buffers |
//! | `wasm` | JavaScript bindings (`wasm32` only) |
//!
//! The core is plain Rust with f64 maths and is tested natively with `cargo test`; the renderer
//! and the wasm bindings sit behind the `wasm32` target.

#[macro_use]
mod macros;

pub mod cloud;
pub mod export;
pub mod fit;
pub mod geom;
pub mod io;
pub mod mesh;
pub mod render;
pub mod spline;
pub mod subdiv;
#[cfg(target_arch = "wasm32")]
pub mod wasm;
