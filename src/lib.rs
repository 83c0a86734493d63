//! geofit: fit smooth surfaces and curves to 3D scans by geometric iteration.
//!
//! A point file (a scan) goes in; a Loop, Catmull–Clark or Doo–Sabin subdivision surface, or a
//! B-spline/NURBS surface or curve, is fitted to it by moving control points along weighted error
//! vectors (no linear system per iteration), and the result is exported for CAD.
//!
//! ```
//! use geofit::fit::{FitData, FitSpec, FitStatus, Scheme};
//! use geofit::io::read_bytes;
//!
//! // An octahedron as OBJ text; any PLY, OBJ, STL or point file reads the same way.
//! let obj = b"v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\n\
//!             f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n";
//! let file = read_bytes(obj, Some("octahedron.obj"))?;
//! // Loop subdivision from the mesh itself, to loose tolerances (% of the diagonal).
//! let spec = FitSpec::new(Scheme::Loop)
//!     .with_initial(Some(6))
//!     .with_tol_avg(Some(2.0))
//!     .with_tol_max(Some(6.0));
//! let mut fit = spec.build(&FitData::from(&file))?;
//! let status = fit.run()?;
//! assert_eq!(status, FitStatus::Converged);
//! println!("{} control points, E_max {:.3} %", fit.num_control_points(), fit.stats().e_max_pct);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! Architecture (dependencies point one way):
//!
//! | module | what it is |
//! |---|---|
//! | [`geom`] | f64 points, vectors, boxes; the one closest-point query ([`geom::ClosestPoint`]) |
//! | [`mesh`] | polygon meshes, adjacency, validation, simplification |
//! | [`subdiv`] | subdivision schemes, exact limit-surface evaluation, local (adaptive) refinement |
//! | [`spline`] | B-spline / NURBS curves and surfaces |
//! | [`fit`] | [`fit::FitSpec`] (what to fit, every option and default) and the engines behind [`fit::Fitter`]: subdivision surfaces, B-spline surfaces, curves |
//! | [`io`] | readers and writers for point and mesh files |
//! | [`cloud`] | bare point clouds to meshes (range grid, Delaunay, implicit surface) |
//! | [`export`] | IGES and STEP export of B-spline / NURBS curves and surfaces; what any fit exports |
//! | [`fem`] | quadrilateral FEM meshes of fitted B-spline and Catmull–Clark surfaces, graded by curvature, with element quality |
//! | [`progress`] | progress reports of the long calls (reading, repair, reconstruction, QEM, set-up, iterations) to a scoped sink |
//! | [`render`] | the wgpu viewer (GPU part on `wasm32` only) and its f32 draw buffers |
//! | `wasm` | JavaScript bindings (`wasm32` only) |
//!
//! The core is plain Rust with f64 maths and is tested natively with `cargo test`; the renderer
//! and the wasm bindings sit behind the `wasm32` target.

#[macro_use]
mod macros;

pub mod cloud;
pub mod export;
pub mod fem;
pub mod fit;
pub mod geom;
pub mod io;
pub mod mesh;
pub mod progress;
pub mod render;
pub mod spline;
pub mod subdiv;
#[cfg(target_arch = "wasm32")]
pub mod wasm;
