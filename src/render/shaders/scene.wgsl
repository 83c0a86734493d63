// Shaders of the viewer: point sprites, lit triangle meshes, the wireframe overlay and line sets.
// Colours arrive in sRGB (as people write them) and are lit in linear space; when the surface
// format is not sRGB the fragment shaders encode the output themselves.

struct Uniforms {
    view_proj: mat4x4<f32>,
    // xyz: the camera position.
    eye: vec4<f32>,
    // xy: viewport size in pixels; z: point diameter in pixels; w: 1 to encode sRGB by hand.
    viewport: vec4<f32>,
    // rgb: the wireframe colour (sRGB).
    wire_color: vec4<f32>,
    // x: 1 for zebra stripes on the mesh.
    shading: vec4<f32>,
};

@group(0) @binding(0) var<uniform> u: Uniforms;

fn srgb_to_linear(c: vec3<f32>) -> vec3<f32> {
    let lo = c / 12.92;
    let hi = pow((c + vec3(0.055)) / 1.055, vec3(2.4));
    return select(hi, lo, c <= vec3(0.04045));
}

fn linear_to_srgb(c: vec3<f32>) -> vec3<f32> {
    let lo = c * 12.92;
    let hi = 1.055 * pow(c, vec3(1.0 / 2.4)) - vec3(0.055);
    return select(hi, lo, c <= vec3(0.0031308));
}

fn output(linear: vec3<f32>) -> vec4<f32> {
    let c = clamp(linear, vec3(0.0), vec3(1.0));
    if u.viewport.w > 0.5 {
        return vec4(linear_to_srgb(c), 1.0);
    }
    return vec4(c, 1.0);
}

// Lines drawn over surfaces are pulled this far towards the camera (in clip depth per w).
const LINE_DEPTH_PULL: f32 = 0.0005;

struct PointOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) corner: vec2<f32>,
    @location(1) color: vec3<f32>,
};

// One instance per point; six vertices make a screen-aligned square around it.
@vertex
fn vs_points(
    @builtin(vertex_index) vertex: u32,
    @location(0) position: vec3<f32>,
    @location(1) color: vec3<f32>,
) -> PointOut {
    var corners = array<vec2<f32>, 6>(
        vec2(-1.0, -1.0), vec2(1.0, -1.0), vec2(1.0, 1.0),
        vec2(-1.0, -1.0), vec2(1.0, 1.0), vec2(-1.0, 1.0),
    );
    let corner = corners[vertex % 6u];
    let center = u.view_proj * vec4(position, 1.0);
    let offset = corner * u.viewport.z / u.viewport.xy * center.w;
    var out: PointOut;
    out.clip = vec4(center.xy + offset, center.zw);
    out.corner = corner;
    out.color = srgb_to_linear(color);
    return out;
}

@fragment
fn fs_points(in: PointOut) -> @location(0) vec4<f32> {
    let r2 = dot(in.corner, in.corner);
    if r2 > 1.0 {
        discard;
    }
    // Darker towards the rim, so that dense clouds keep some depth.
    return output(in.color * (1.0 - 0.3 * r2));
}

struct MeshOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) color: vec3<f32>,
};

@vertex
fn vs_mesh(
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) color: vec3<f32>,
) -> MeshOut {
    var out: MeshOut;
    out.clip = u.view_proj * vec4(position, 1.0);
    out.world = position;
    out.normal = normal;
    out.color = srgb_to_linear(color);
    return out;
}

// Stripes per half turn of the reflected view direction's elevation.
const ZEBRA_STRIPES: f32 = 9.0;

// Zebra stripes: the view direction reflected in the surface, black and white by its elevation
// (reflection lines of a striped sky). Kinks and wobbles in the stripes show where the surface
// is not smooth or not fair.
fn zebra(n: vec3<f32>, l: vec3<f32>, d: f32) -> vec3<f32> {
    let facing = select(-n, n, dot(n, l) >= 0.0);
    let r = reflect(-l, facing);
    let t = asin(clamp(r.y, -1.0, 1.0)) / 3.14159265 * ZEBRA_STRIPES;
    let stripe = select(0.04, 0.85, fract(t) < 0.5);
    return vec3(stripe * (0.35 + 0.65 * d));
}

// A headlight: diffuse plus a little specular, two-sided because scans are open surfaces.
@fragment
fn fs_mesh(in: MeshOut) -> @location(0) vec4<f32> {
    let n = normalize(in.normal);
    let l = normalize(u.eye.xyz - in.world);
    let d = abs(dot(n, l));
    if u.shading.x > 0.5 {
        return output(zebra(n, l, d));
    }
    let lit = in.color * (0.15 + 0.85 * d) + vec3(0.25 * pow(d, 40.0));
    return output(lit);
}

struct LineOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) color: vec3<f32>,
};

fn line_clip(position: vec3<f32>) -> vec4<f32> {
    let clip = u.view_proj * vec4(position, 1.0);
    return vec4(clip.xy, clip.z - LINE_DEPTH_PULL * clip.w, clip.w);
}

@vertex
fn vs_wire(@location(0) position: vec3<f32>) -> LineOut {
    var out: LineOut;
    out.clip = line_clip(position);
    out.color = srgb_to_linear(u.wire_color.rgb);
    return out;
}

@vertex
fn vs_lines(@location(0) position: vec3<f32>, @location(1) color: vec3<f32>) -> LineOut {
    var out: LineOut;
    out.clip = line_clip(position);
    out.color = srgb_to_linear(color);
    return out;
}

@fragment
fn fs_lines(in: LineOut) -> @location(0) vec4<f32> {
    return output(in.color);
}
