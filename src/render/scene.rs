//! The renderer: what is on screen (points, mesh, lines), the camera, and one frame's drawing.

use super::context::Gpu;
use super::pipeline::{Pipelines, Uniforms, DEPTH_FORMAT};
use super::{OrbitCamera, RenderError};
use glam::Vec3;

/// Background colour, sRGB (a dark slate), as the page shows it on every backend.
const BACKGROUND: [f64; 3] = [0.11, 0.13, 0.17];
/// Mesh colour, sRGB: a light clay, for a mesh given without colours.
const MESH_COLOR: [f32; 3] = [0.80, 0.76, 0.70];
/// Wireframe colour, sRGB: dark grey.
const WIRE_COLOR: [f32; 4] = [0.10, 0.10, 0.12, 1.0];
/// Point diameter in CSS pixels unless the page sets another.
const DEFAULT_POINT_SIZE: f32 = 3.0;
/// Smallest buffer allocated, so that empty data never asks for a zero-sized buffer.
const MIN_BUFFER_BYTES: u64 = 256;

/// A GPU buffer that grows (to the next power of two) when new data no longer fits.
struct DynBuffer {
    buffer: wgpu::Buffer,
    usage: wgpu::BufferUsages,
}

impl DynBuffer {
    fn new(device: &wgpu::Device, usage: wgpu::BufferUsages) -> DynBuffer {
        let usage = usage | wgpu::BufferUsages::COPY_DST;
        DynBuffer {
            buffer: allocate(device, usage, MIN_BUFFER_BYTES),
            usage,
        }
    }

    fn write(&mut self, gpu: &Gpu, bytes: &[u8]) {
        let len = bytes.len() as u64;
        if len > self.buffer.size() {
            let size = len.next_power_of_two().max(MIN_BUFFER_BYTES);
            self.buffer = allocate(&gpu.device, self.usage, size);
        }
        if len > 0 {
            gpu.queue.write_buffer(&self.buffer, 0, bytes);
        }
    }

    fn slice(&self, bytes: u64) -> wgpu::BufferSlice<'_> {
        self.buffer.slice(..bytes.max(4))
    }
}

fn allocate(device: &wgpu::Device, usage: wgpu::BufferUsages, size: u64) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size,
        usage,
        mapped_at_creation: false,
    })
}

/// Two vec3 streams (positions and colours or normals) and how many vertices they hold.
struct Vec3Pair {
    first: DynBuffer,
    second: DynBuffer,
    count: u32,
}

impl Vec3Pair {
    fn new(device: &wgpu::Device) -> Vec3Pair {
        Vec3Pair {
            first: DynBuffer::new(device, wgpu::BufferUsages::VERTEX),
            second: DynBuffer::new(device, wgpu::BufferUsages::VERTEX),
            count: 0,
        }
    }

    fn write(&mut self, gpu: &Gpu, first: &[f32], second: &[f32]) {
        self.first.write(gpu, bytemuck::cast_slice(first));
        self.second.write(gpu, bytemuck::cast_slice(second));
        self.count = (first.len() / 3) as u32;
    }

    fn bind<'a>(&'a self, pass: &mut wgpu::RenderPass<'a>) {
        let bytes = u64::from(self.count) * 12;
        pass.set_vertex_buffer(0, self.first.slice(bytes));
        pass.set_vertex_buffer(1, self.second.slice(bytes));
    }
}

/// An index buffer and its length.
struct Indices {
    buffer: DynBuffer,
    count: u32,
}

impl Indices {
    fn write(&mut self, gpu: &Gpu, indices: &[u32]) {
        self.buffer.write(gpu, bytemuck::cast_slice(indices));
        self.count = indices.len() as u32;
    }
}

/// Which layers are drawn.
#[derive(Clone, Copy, Debug)]
struct Layers {
    points: bool,
    mesh: bool,
    wireframe: bool,
    lines: bool,
}

/// Draws the scene onto one canvas. Every `set_*` call replaces that layer's data.
pub struct Renderer {
    gpu: Gpu,
    pipelines: Pipelines,
    uniforms: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
    depth: wgpu::TextureView,
    points: Vec3Pair,
    mesh: Vec3Pair,
    /// The mesh's colours (sRGB per vertex; [`MESH_COLOR`] when the page gives none).
    mesh_colors: DynBuffer,
    triangles: Indices,
    edges: Indices,
    /// The triangle indices whose wireframe edges are not built yet: edges are made only when
    /// the wireframe is drawn, so that replacing the mesh every frame (a running fit) stays cheap.
    stale_edges: Option<Vec<u32>>,
    lines: Vec3Pair,
    layers: Layers,
    zebra: bool,
    /// Bounding boxes of the points, the mesh and the lines, for fitting the view.
    bounds: [Option<(Vec3, Vec3)>; 3],
    point_size: f32,
    pixel_ratio: f32,
    /// The camera; the page drives it from mouse and keyboard events.
    pub camera: OrbitCamera,
}

impl Renderer {
    /// Opens the GPU context on `canvas` and builds the pipelines.
    pub async fn new(canvas: web_sys::HtmlCanvasElement) -> Result<Renderer, RenderError> {
        let gpu = Gpu::new(canvas).await?;
        let device = &gpu.device;
        let pipelines = Pipelines::new(device, gpu.config.format);
        let uniforms = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("uniforms"),
            size: std::mem::size_of::<Uniforms>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("uniforms"),
            layout: &pipelines.bind_group_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: uniforms.as_entire_binding(),
            }],
        });
        let index_buffer = || Indices {
            buffer: DynBuffer::new(device, wgpu::BufferUsages::INDEX),
            count: 0,
        };
        Ok(Renderer {
            depth: depth_view(&gpu),
            points: Vec3Pair::new(device),
            mesh: Vec3Pair::new(device),
            mesh_colors: DynBuffer::new(device, wgpu::BufferUsages::VERTEX),
            triangles: index_buffer(),
            edges: index_buffer(),
            stale_edges: None,
            lines: Vec3Pair::new(device),
            layers: Layers {
                points: true,
                mesh: true,
                wireframe: false,
                lines: true,
            },
            zebra: false,
            bounds: [None; 3],
            point_size: DEFAULT_POINT_SIZE,
            pixel_ratio: 1.0,
            camera: OrbitCamera::default(),
            gpu,
            pipelines,
            uniforms,
            bind_group,
        })
    }

    /// "WebGPU" or "WebGL2".
    pub fn backend_name(&self) -> &'static str {
        self.gpu.backend_name()
    }

    /// Replaces the point cloud: `positions` and `colors` (sRGB, 0..1) hold three values per point.
    pub fn set_points(&mut self, positions: &[f32], colors: &[f32]) -> Result<(), RenderError> {
        check_xyz("point positions", positions)?;
        check_same_len("point colors", colors, positions.len())?;
        check_finite("point colors", colors)?;
        self.points.write(&self.gpu, positions, colors);
        self.bounds[0] = xyz_bounds(positions);
        Ok(())
    }

    /// Replaces the triangle mesh: three values per vertex in `positions` and `normals`, three
    /// vertex indices per triangle in `indices`, and `colors` (sRGB, 0..1, three per vertex),
    /// or none for the clay colour.
    pub fn set_mesh(
        &mut self,
        positions: &[f32],
        normals: &[f32],
        indices: &[u32],
        colors: Option<&[f32]>,
    ) -> Result<(), RenderError> {
        check_xyz("mesh positions", positions)?;
        check_same_len("mesh normals", normals, positions.len())?;
        check_finite("mesh normals", normals)?;
        check_indices("triangle indices", indices, 3, positions.len() / 3)?;
        let clay: Vec<f32>;
        let colors = match colors {
            Some(c) => {
                check_same_len("mesh colors", c, positions.len())?;
                check_finite("mesh colors", c)?;
                c
            }
            None => {
                clay = MESH_COLOR.repeat(positions.len() / 3);
                &clay
            }
        };
        self.mesh.write(&self.gpu, positions, normals);
        self.mesh_colors
            .write(&self.gpu, bytemuck::cast_slice(colors));
        self.triangles.write(&self.gpu, indices);
        self.stale_edges = Some(indices.to_vec());
        self.bounds[1] = xyz_bounds(positions);
        Ok(())
    }

    /// Replaces the line set: two vertices per segment, three values each in `positions` and
    /// `colors` (sRGB, 0..1).
    pub fn set_lines(&mut self, positions: &[f32], colors: &[f32]) -> Result<(), RenderError> {
        check_xyz("line positions", positions)?;
        if positions.len() % 6 != 0 {
            return Err(RenderError::BadLength {
                what: "line positions",
                len: positions.len(),
                expected: "a multiple of 6 (two points per segment)".into(),
            });
        }
        check_same_len("line colors", colors, positions.len())?;
        check_finite("line colors", colors)?;
        self.lines.write(&self.gpu, positions, colors);
        self.bounds[2] = xyz_bounds(positions);
        Ok(())
    }

    /// Chooses which layers are drawn.
    pub fn set_layers(&mut self, points: bool, mesh: bool, wireframe: bool, lines: bool) {
        self.layers = Layers {
            points,
            mesh,
            wireframe,
            lines,
        };
    }

    /// Shades the mesh with zebra stripes (reflection lines) instead of its colours.
    pub fn set_zebra(&mut self, on: bool) {
        self.zebra = on;
    }

    /// Point diameter in CSS pixels (scaled by the device pixel ratio when drawn).
    pub fn set_point_size(&mut self, css_pixels: f32) {
        if css_pixels.is_finite() && css_pixels > 0.0 {
            self.point_size = css_pixels;
        }
    }

    /// Resizes the drawing buffer to the canvas's CSS size times the device pixel ratio.
    pub fn resize(&mut self, css_width: f32, css_height: f32, pixel_ratio: f32) {
        let ratio = if pixel_ratio.is_finite() && pixel_ratio > 0.0 {
            pixel_ratio
        } else {
            1.0
        };
        self.pixel_ratio = ratio;
        let to_px = |css: f32| (css * ratio).round().clamp(1.0, u32::MAX as f32) as u32;
        let (w, h) = (to_px(css_width), to_px(css_height));
        if (w, h) != (self.gpu.config.width, self.gpu.config.height) {
            self.gpu.resize(w, h);
            self.depth = depth_view(&self.gpu);
        }
    }

    /// Frames everything that is shown.
    pub fn fit_view(&mut self) {
        let all = self.bounds.iter().flatten().copied();
        if let Some((min, max)) = all.reduce(|(a, b), (c, d)| (a.min(c), b.max(d))) {
            self.camera.fit(min, max);
        }
    }

    /// Width of the view in CSS pixels.
    pub fn css_width(&self) -> f32 {
        self.gpu.config.width as f32 / self.pixel_ratio
    }

    /// Height of the view in CSS pixels (for panning).
    pub fn css_height(&self) -> f32 {
        self.gpu.config.height as f32 / self.pixel_ratio
    }

    /// Draws one frame.
    pub fn render(&mut self) {
        let frame = match self.gpu.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t)
            | wgpu::CurrentSurfaceTexture::Suboptimal(t) => t,
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                // Reconfigure and draw on the next frame.
                self.gpu
                    .surface
                    .configure(&self.gpu.device, &self.gpu.config);
                return;
            }
            _ => return,
        };
        self.write_uniforms();
        if self.layers.wireframe {
            if let Some(indices) = self.stale_edges.take() {
                let edges = super::buffers::triangle_edges(&indices);
                self.edges.write(&self.gpu, &edges);
            }
        }
        let view = frame.texture.create_view(&Default::default());
        let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("scene"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(self.clear_color()),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &self.depth,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Discard,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_bind_group(0, &self.bind_group, &[]);
            self.draw(&mut pass);
        }
        self.gpu.queue.submit([encoder.finish()]);
        self.gpu.queue.present(frame);
    }

    fn draw<'a>(&'a self, pass: &mut wgpu::RenderPass<'a>) {
        if self.layers.mesh && self.triangles.count > 0 {
            pass.set_pipeline(&self.pipelines.mesh);
            self.mesh.bind(pass);
            pass.set_vertex_buffer(2, self.mesh_colors.slice(u64::from(self.mesh.count) * 12));
            pass.set_index_buffer(
                self.triangles
                    .buffer
                    .slice(u64::from(self.triangles.count) * 4),
                wgpu::IndexFormat::Uint32,
            );
            pass.draw_indexed(0..self.triangles.count, 0, 0..1);
        }
        if self.layers.wireframe && self.edges.count > 0 {
            pass.set_pipeline(&self.pipelines.wire);
            pass.set_vertex_buffer(0, self.mesh.first.slice(u64::from(self.mesh.count) * 12));
            pass.set_index_buffer(
                self.edges.buffer.slice(u64::from(self.edges.count) * 4),
                wgpu::IndexFormat::Uint32,
            );
            pass.draw_indexed(0..self.edges.count, 0, 0..1);
        }
        if self.layers.lines && self.lines.count > 0 {
            pass.set_pipeline(&self.pipelines.lines);
            self.lines.bind(pass);
            pass.draw(0..self.lines.count, 0..1);
        }
        if self.layers.points && self.points.count > 0 {
            pass.set_pipeline(&self.pipelines.points);
            self.points.bind(pass);
            pass.draw(0..6, 0..self.points.count);
        }
    }

    /// The background as the colour target stores it: sRGB values as they are when the shaders
    /// encode by hand, linear values when the target encodes.
    fn clear_color(&self) -> wgpu::Color {
        let [r, g, b] = if self.gpu.encodes_srgb_by_hand() {
            BACKGROUND
        } else {
            BACKGROUND.map(srgb_to_linear)
        };
        wgpu::Color { r, g, b, a: 1.0 }
    }

    fn write_uniforms(&self) {
        let (w, h) = (self.gpu.config.width as f32, self.gpu.config.height as f32);
        let eye = self.camera.eye();
        let u = Uniforms {
            view_proj: Uniforms::matrix(self.camera.view_proj(w / h)),
            eye: [eye.x, eye.y, eye.z, 1.0],
            viewport: [
                w,
                h,
                self.point_size * self.pixel_ratio,
                if self.gpu.encodes_srgb_by_hand() {
                    1.0
                } else {
                    0.0
                },
            ],
            wire_color: WIRE_COLOR,
            shading: [if self.zebra { 1.0 } else { 0.0 }, 0.0, 0.0, 0.0],
        };
        self.gpu
            .queue
            .write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&u));
    }
}

/// The box around a flat xyz array, or `None` when it is empty.
fn xyz_bounds(xyz: &[f32]) -> Option<(Vec3, Vec3)> {
    let mut points = xyz.chunks_exact(3).map(Vec3::from_slice);
    let first = points.next()?;
    Some(points.fold((first, first), |(min, max), p| (min.min(p), max.max(p))))
}

/// Positions: three finite values per vertex.
fn check_xyz(what: &'static str, xyz: &[f32]) -> Result<(), RenderError> {
    if xyz.len() % 3 != 0 {
        return Err(RenderError::BadLength {
            what,
            len: xyz.len(),
            expected: "a multiple of 3 (x, y, z per vertex)".into(),
        });
    }
    check_finite(what, xyz)
}

fn check_same_len(what: &'static str, values: &[f32], expected: usize) -> Result<(), RenderError> {
    if values.len() != expected {
        return Err(RenderError::BadLength {
            what,
            len: values.len(),
            expected: format!("{expected}, one per position value"),
        });
    }
    Ok(())
}

fn check_finite(what: &'static str, values: &[f32]) -> Result<(), RenderError> {
    match values.iter().position(|v| !v.is_finite()) {
        Some(index) => Err(RenderError::NonFinite { what, index }),
        None => Ok(()),
    }
}

/// Indices: whole primitives of `arity` vertices, each index below `count`.
fn check_indices(
    what: &'static str,
    indices: &[u32],
    arity: usize,
    count: usize,
) -> Result<(), RenderError> {
    if indices.len() % arity != 0 {
        return Err(RenderError::BadLength {
            what,
            len: indices.len(),
            expected: format!("a multiple of {arity}"),
        });
    }
    match indices.iter().position(|&i| i as usize >= count) {
        Some(at) => Err(RenderError::IndexOutOfRange {
            what,
            index: indices[at],
            at,
            count,
        }),
        None => Ok(()),
    }
}

/// A depth buffer the size of the surface.
fn depth_view(gpu: &Gpu) -> wgpu::TextureView {
    gpu.device
        .create_texture(&wgpu::TextureDescriptor {
            label: Some("depth"),
            size: wgpu::Extent3d {
                width: gpu.config.width,
                height: gpu.config.height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: DEPTH_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            view_formats: &[],
        })
        .create_view(&Default::default())
}

/// The sRGB transfer function, inverted (as in `shaders/scene.wgsl`).
fn srgb_to_linear(c: f64) -> f64 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}
