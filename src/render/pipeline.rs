//! The render pipelines (points, mesh, wireframe, lines) and the uniform block they share.

use bytemuck::{Pod, Zeroable};
use glam::Mat4;

/// Depth buffer format: 24-bit depth exists on every backend, WebGL2 included.
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth24Plus;

/// The uniform block of `shaders/scene.wgsl`, field for field.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub struct Uniforms {
    /// Projection × view.
    pub view_proj: [f32; 16],
    /// Camera position (w unused).
    pub eye: [f32; 4],
    /// Viewport width and height in pixels, point diameter in pixels, 1 to encode sRGB by hand.
    pub viewport: [f32; 4],
    /// Wireframe colour, sRGB (a unused).
    pub wire_color: [f32; 4],
    /// x: 1 to shade the mesh with zebra stripes (reflection lines) instead of its colours
    /// (y, z, w unused).
    pub shading: [f32; 4],
}

impl Uniforms {
    /// Packs a matrix column by column, as WGSL reads it.
    pub fn matrix(m: Mat4) -> [f32; 16] {
        m.to_cols_array()
    }
}

/// One pipeline per kind of primitive, all sharing one bind group layout.
pub struct Pipelines {
    /// Layout of group 0: the uniform buffer.
    pub bind_group_layout: wgpu::BindGroupLayout,
    /// Instanced point sprites.
    pub points: wgpu::RenderPipeline,
    /// Lit triangles.
    pub mesh: wgpu::RenderPipeline,
    /// Triangle edges over the mesh.
    pub wire: wgpu::RenderPipeline,
    /// Coloured line segments.
    pub lines: wgpu::RenderPipeline,
}

const XYZ: [wgpu::VertexAttribute; 1] = wgpu::vertex_attr_array![0 => Float32x3];
const RGB: [wgpu::VertexAttribute; 1] = wgpu::vertex_attr_array![1 => Float32x3];
const MESH_RGB: [wgpu::VertexAttribute; 1] = wgpu::vertex_attr_array![2 => Float32x3];

/// A tightly packed buffer of vec3<f32>, one per vertex or per instance.
fn vec3_buffer(
    attributes: &'static [wgpu::VertexAttribute],
    step_mode: wgpu::VertexStepMode,
) -> wgpu::VertexBufferLayout<'static> {
    wgpu::VertexBufferLayout {
        array_stride: 12,
        step_mode,
        attributes,
    }
}

struct Stage<'a> {
    label: &'a str,
    vertex: &'a str,
    fragment: &'a str,
    buffers: &'a [Option<wgpu::VertexBufferLayout<'a>>],
    topology: wgpu::PrimitiveTopology,
}

impl Pipelines {
    /// Compiles the shaders and builds the pipelines for colour target `format`.
    pub fn new(device: &wgpu::Device, format: wgpu::TextureFormat) -> Pipelines {
        let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("scene.wgsl"),
            source: wgpu::ShaderSource::Wgsl(include_str!("shaders/scene.wgsl").into()),
        });
        let bind_group_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("uniforms"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            }],
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("scene"),
            bind_group_layouts: &[Some(&bind_group_layout)],
            immediate_size: 0,
        });
        let build = |s: Stage| build_pipeline(device, &layout, &shader, format, s);
        let per_vertex = wgpu::VertexStepMode::Vertex;
        let per_instance = wgpu::VertexStepMode::Instance;
        Pipelines {
            points: build(Stage {
                label: "points",
                vertex: "vs_points",
                fragment: "fs_points",
                buffers: &[
                    Some(vec3_buffer(&XYZ, per_instance)),
                    Some(vec3_buffer(&RGB, per_instance)),
                ],
                topology: wgpu::PrimitiveTopology::TriangleList,
            }),
            mesh: build(Stage {
                label: "mesh",
                vertex: "vs_mesh",
                fragment: "fs_mesh",
                buffers: &[
                    Some(vec3_buffer(&XYZ, per_vertex)),
                    Some(vec3_buffer(&RGB, per_vertex)),
                    Some(vec3_buffer(&MESH_RGB, per_vertex)),
                ],
                topology: wgpu::PrimitiveTopology::TriangleList,
            }),
            wire: build(Stage {
                label: "wireframe",
                vertex: "vs_wire",
                fragment: "fs_lines",
                buffers: &[Some(vec3_buffer(&XYZ, per_vertex))],
                topology: wgpu::PrimitiveTopology::LineList,
            }),
            lines: build(Stage {
                label: "lines",
                vertex: "vs_lines",
                fragment: "fs_lines",
                buffers: &[
                    Some(vec3_buffer(&XYZ, per_vertex)),
                    Some(vec3_buffer(&RGB, per_vertex)),
                ],
                topology: wgpu::PrimitiveTopology::LineList,
            }),
            bind_group_layout,
        }
    }
}

fn build_pipeline(
    device: &wgpu::Device,
    layout: &wgpu::PipelineLayout,
    shader: &wgpu::ShaderModule,
    format: wgpu::TextureFormat,
    stage: Stage,
) -> wgpu::RenderPipeline {
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(stage.label),
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module: shader,
            entry_point: Some(stage.vertex),
            compilation_options: Default::default(),
            buffers: stage.buffers,
        },
        primitive: wgpu::PrimitiveState {
            topology: stage.topology,
            cull_mode: None,
            ..Default::default()
        },
        depth_stencil: Some(wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::LessEqual),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: shader,
            entry_point: Some(stage.fragment),
            compilation_options: Default::default(),
            targets: &[Some(wgpu::ColorTargetState {
                format,
                blend: None,
                write_mask: wgpu::ColorWrites::ALL,
            })],
        }),
        multiview_mask: None,
        cache: None,
    })
}
