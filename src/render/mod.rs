//! The viewer's renderer (wgpu): point clouds as sprites, lit triangle meshes with an optional
//! wireframe, and line sets, seen through an orbit camera.
//!
//! Geometry arrives as flat f32 arrays and may be replaced every frame (the fitted surface
//! animates). [`buffers`] turns core f64 geometry into such arrays. The camera and the buffer
//! helpers are plain maths and build everywhere; the GPU part builds only for `wasm32`.

pub mod buffers;
mod camera;

pub use camera::{OrbitCamera, PickSpot};

#[cfg(target_arch = "wasm32")]
mod context;
#[cfg(target_arch = "wasm32")]
mod error;
#[cfg(target_arch = "wasm32")]
mod pipeline;
#[cfg(target_arch = "wasm32")]
mod scene;

#[cfg(target_arch = "wasm32")]
pub use error::RenderError;
#[cfg(target_arch = "wasm32")]
pub use scene::Renderer;
