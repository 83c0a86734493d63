//! Binary glTF 2.0 (GLB) writer for a triangle mesh: what three.js, model-viewer, Blender and
//! most viewers open directly.
//!
//! The file holds one scene with one node and one mesh primitive: `POSITION` (f32, with the
//! `min`/`max` the spec requires), `NORMAL` (unit f32 vectors), and, when a per-vertex
//! deviation is given, `COLOR_0` (the deviation through a colour map) and the custom attribute
//! `_DEVIATION` (the signed value as f32), indexed by u32 triangles. The caller's `extras` (the
//! fit's figures) are the scene's `extras` (three.js: `gltf.scene.userData`). glTF units are
//! metres: a mesh in other units gets a uniform scale on its node, so the stored coordinates
//! stay the ones the fit produced. A mesh without faces is written as a point primitive.

use super::write::{checked_f32, WriteError};
use crate::geom::{Point3, Vec3};
use crate::mesh::PolyMesh;
use serde_json::{json, Value};
use std::io::Write;

/// The built-in diverging map's colour for a deviation of 0 (sRGB, components in [0, 1]):
/// near-white grey.
pub const DIVERGING_ZERO: [f32; 3] = [0.94, 0.94, 0.94];
/// The built-in map's colour for deviations at or beyond −3 × tolerance (the data lies behind
/// the surface): blue.
pub const DIVERGING_NEGATIVE: [f32; 3] = [0.13, 0.38, 0.85];
/// The built-in map's colour for deviations at or beyond +3 × tolerance (the data lies in
/// front of the surface): red.
pub const DIVERGING_POSITIVE: [f32; 3] = [0.84, 0.15, 0.12];

/// How far toward [`DIVERGING_ZERO`] the colours at the tolerance are, inside and just outside
/// the band: the band stays pale, and its edge shows as a step in saturation.
const PALE_INSIDE: f32 = 0.65;
const PALE_OUTSIDE: f32 = 0.3;

/// A caller's colour map: the signed deviation of a vertex to an sRGB colour with components
/// in [0, 1] (as CSS colours are given). The writer converts it to the linear values glTF's
/// `COLOR_0` holds; components outside [0, 1] are clamped.
pub type ColourMap<'a> = &'a dyn Fn(f64) -> [f32; 3];

fn lerp(a: [f32; 3], b: [f32; 3], t: f32) -> [f32; 3] {
    [0, 1, 2].map(|k| a[k] + (b[k] - a[k]) * t)
}

/// The built-in diverging colour of `deviation` with tolerance band `tolerance` (> 0), sRGB:
/// inside ±tolerance from [`DIVERGING_ZERO`] to a pale blue or red at the band's edge; outside,
/// a step to a stronger tint that saturates to [`DIVERGING_NEGATIVE`] / [`DIVERGING_POSITIVE`]
/// at three times the tolerance. A non-positive or non-finite tolerance gives the zero colour
/// for 0 and the saturated colours for anything else.
///
/// ```
/// use geofit::io::{diverging_colour, DIVERGING_POSITIVE, DIVERGING_ZERO};
/// assert_eq!(diverging_colour(0.0, 0.1), DIVERGING_ZERO);
/// assert_eq!(diverging_colour(0.5, 0.1), DIVERGING_POSITIVE);
/// let inside = diverging_colour(0.09, 0.1);
/// let outside = diverging_colour(0.11, 0.1);
/// assert!(inside[1] > outside[1]); // paler (more green and blue) inside the band
/// ```
pub fn diverging_colour(deviation: f64, tolerance: f64) -> [f32; 3] {
    let full = if deviation < 0.0 {
        DIVERGING_NEGATIVE
    } else {
        DIVERGING_POSITIVE
    };
    if deviation == 0.0 || deviation.is_nan() {
        return DIVERGING_ZERO;
    }
    if !(tolerance > 0.0 && tolerance.is_finite()) {
        return full;
    }
    let t = deviation.abs() / tolerance;
    if t >= 3.0 {
        return full;
    }
    if t <= 1.0 {
        lerp(
            DIVERGING_ZERO,
            lerp(full, DIVERGING_ZERO, PALE_INSIDE),
            t as f32,
        )
    } else {
        let s = ((t - 1.0) / 2.0) as f32;
        lerp(lerp(full, DIVERGING_ZERO, PALE_OUTSIDE), full, s)
    }
}

/// sRGB component to linear (the IEC 61966-2-1 curve).
fn srgb_to_linear(c: f32) -> f32 {
    let c = c.clamp(0.0, 1.0);
    if c <= 0.04045 {
        c / 12.92
    } else {
        libm::powf((c + 0.055) / 1.055, 2.4)
    }
}

/// What [`write_glb`] writes besides positions and triangles.
///
/// ```
/// use geofit::io::{to_glb_bytes, GlbOptions};
/// use geofit::{geom::Point3, mesh::PolyMesh};
/// let mesh = PolyMesh::try_new(vec![Point3::ZERO, Point3::X, Point3::Y], [[0u32, 1, 2]])?;
/// let deviation = [0.0, 0.02, -0.2];
/// let figures = serde_json::json!({ "e_max_percent": 0.049 });
/// let options = GlbOptions::default()
///     .with_deviation(&deviation)
///     .with_tolerance(0.05)
///     .with_extras(&figures)
///     .with_unit_to_metres(0.001);
/// let glb = to_glb_bytes(&mesh, &options)?;
/// assert_eq!(&glb[..4], b"glTF");
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Copy, Default)]
#[non_exhaustive]
pub struct GlbOptions<'a> {
    /// Vertex normals, one per vertex (normalised when written). Default `None`: area-weighted
    /// normals of the triangles are computed.
    pub normals: Option<&'a [Vec3]>,
    /// The signed deviation of each vertex (data to surface), one per vertex. Default `None`:
    /// no `COLOR_0` and no `_DEVIATION`.
    pub deviation: Option<&'a [f64]>,
    /// The tolerance band of the built-in colour map, in the mesh's units. Default `None`: a
    /// third of the largest |deviation|.
    pub tolerance: Option<f64>,
    /// A colour map to use instead of [`diverging_colour`]. Default `None`.
    pub colour_map: Option<ColourMap<'a>>,
    /// JSON written as the scene's `extras` (an object, by glTF's recommendation). Default
    /// `None`.
    pub extras: Option<&'a Value>,
    /// Metres per unit of the mesh's coordinates (0.001 for millimetres), applied as the node's
    /// scale. Default `None`: the units are left as they are (glTF reads them as metres).
    pub unit_to_metres: Option<f64>,
}

impl std::fmt::Debug for GlbOptions<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GlbOptions")
            .field("normals", &self.normals.map(<[Vec3]>::len))
            .field("deviation", &self.deviation.map(<[f64]>::len))
            .field("tolerance", &self.tolerance)
            .field("colour_map", &self.colour_map.is_some())
            .field("extras", &self.extras)
            .field("unit_to_metres", &self.unit_to_metres)
            .finish()
    }
}

impl<'a> GlbOptions<'a> {
    /// Writes these normals instead of computed ones.
    pub fn with_normals(mut self, normals: &'a [Vec3]) -> Self {
        self.normals = Some(normals);
        self
    }

    /// Writes this per-vertex deviation as `COLOR_0` and `_DEVIATION`.
    pub fn with_deviation(mut self, deviation: &'a [f64]) -> Self {
        self.deviation = Some(deviation);
        self
    }

    /// The tolerance band of the built-in colour map.
    pub fn with_tolerance(mut self, tolerance: f64) -> Self {
        self.tolerance = Some(tolerance);
        self
    }

    /// Colours the deviation with `map` instead of the built-in diverging map.
    pub fn with_colour_map(mut self, map: ColourMap<'a>) -> Self {
        self.colour_map = Some(map);
        self
    }

    /// The scene's `extras`.
    pub fn with_extras(mut self, extras: &'a Value) -> Self {
        self.extras = Some(extras);
        self
    }

    /// Metres per unit of the coordinates.
    pub fn with_unit_to_metres(mut self, metres: f64) -> Self {
        self.unit_to_metres = Some(metres);
        self
    }
}

/// glTF's `componentType` and `target` codes.
const FLOAT: u32 = 5126;
const UNSIGNED_INT: u32 = 5125;
const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;

fn invalid(what: String) -> WriteError {
    WriteError::Invalid {
        format: "GLB",
        what,
    }
}

fn f32_of(x: f64) -> Result<f32, WriteError> {
    checked_f32(x, "GLB", "value")
}

/// The binary chunk under construction and the JSON describing its views and accessors.
#[derive(Default)]
struct Bin {
    data: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Bin {
    /// Appends a per-vertex float VEC3 attribute (one entry per vertex) and names it in
    /// `attributes`.
    fn push_vec3_attribute(
        &mut self,
        attributes: &mut serde_json::Map<String, Value>,
        name: &str,
        values: &[[f32; 3]],
    ) {
        let a = self.push(
            &vec3_bytes(values),
            ARRAY_BUFFER,
            json!({ "componentType": FLOAT, "count": values.len(), "type": "VEC3" }),
        );
        attributes.insert(name.into(), json!(a));
    }

    /// Appends a tightly packed view of `bytes`, 4-byte aligned, and an accessor over it.
    fn push(&mut self, bytes: &[u8], target: u32, accessor: Value) -> usize {
        while self.data.len() % 4 != 0 {
            self.data.push(0);
        }
        self.views.push(json!({
            "buffer": 0,
            "byteOffset": self.data.len(),
            "byteLength": bytes.len(),
            "target": target,
        }));
        self.data.extend_from_slice(bytes);
        let mut a = accessor;
        a["bufferView"] = json!(self.views.len() - 1);
        self.accessors.push(a);
        self.accessors.len() - 1
    }
}

fn vec3_bytes(v: &[[f32; 3]]) -> Vec<u8> {
    v.iter().flatten().flat_map(|c| c.to_le_bytes()).collect()
}

/// Area-weighted vertex normals (f64), unit length; a vertex in no non-degenerate triangle
/// gets +z, since glTF requires unit normals.
fn vertex_normals(p: &[Point3], tris: &[[u32; 3]]) -> Vec<Vec3> {
    crate::geom::area_weighted_normal_sums(p, tris)
        .into_iter()
        .map(unit_or_z)
        .collect()
}

fn unit_or_z(v: Vec3) -> Vec3 {
    let u = v.normalize_or_zero();
    if u == Vec3::ZERO || !u.is_finite() {
        Vec3::Z
    } else {
        u
    }
}

/// Writes `mesh` as GLB; see the module docs for what the file holds.
pub fn write_glb(
    mesh: &PolyMesh,
    options: &GlbOptions,
    out: &mut impl Write,
) -> Result<(), WriteError> {
    let bytes = to_glb_bytes(mesh, options)?;
    out.write_all(&bytes)?;
    Ok(())
}

/// [`write_glb`] into a new byte vector.
pub fn to_glb_bytes(mesh: &PolyMesh, options: &GlbOptions) -> Result<Vec<u8>, WriteError> {
    let positions = mesh.positions();
    let n = positions.len();
    if n == 0 {
        return Err(invalid("the mesh has no vertices".into()));
    }
    let triangles = mesh.triangles();
    let mut bin = Bin::default();
    let mut attributes = serde_json::Map::new();

    let pos: Vec<[f32; 3]> = positions
        .iter()
        .map(|p| Ok([f32_of(p.x)?, f32_of(p.y)?, f32_of(p.z)?]))
        .collect::<Result<_, WriteError>>()?;
    let mut min = [f32::INFINITY; 3];
    let mut max = [f32::NEG_INFINITY; 3];
    for p in &pos {
        for k in 0..3 {
            min[k] = min[k].min(p[k]);
            max[k] = max[k].max(p[k]);
        }
    }
    let a = bin.push(
        &vec3_bytes(&pos),
        ARRAY_BUFFER,
        json!({ "componentType": FLOAT, "count": n, "type": "VEC3", "min": min, "max": max }),
    );
    attributes.insert("POSITION".into(), json!(a));

    if !triangles.is_empty() {
        let normals = match options.normals {
            Some(given) if given.len() != n => {
                return Err(invalid(format!("{} normals for {n} vertices", given.len())))
            }
            Some(given) => given.iter().map(|&v| unit_or_z(v)).collect(),
            None => vertex_normals(positions, &triangles),
        };
        let normals: Vec<[f32; 3]> = normals
            .iter()
            .map(|v| [v.x as f32, v.y as f32, v.z as f32])
            .collect();
        bin.push_vec3_attribute(&mut attributes, "NORMAL", &normals);
    }

    if let Some(dev) = options.deviation {
        if dev.len() != n {
            return Err(invalid(format!(
                "{} deviations for {n} vertices",
                dev.len()
            )));
        }
        if let Some(i) = dev.iter().position(|d| !d.is_finite()) {
            return Err(invalid(format!(
                "the deviation of vertex {i} is not finite"
            )));
        }
        let largest = dev.iter().fold(0.0f64, |m, d| m.max(d.abs()));
        let tol = options
            .tolerance
            .unwrap_or(largest / 3.0)
            .max(f64::MIN_POSITIVE);
        let colours: Vec<[f32; 3]> = dev
            .iter()
            .map(|&d| {
                let c = match options.colour_map {
                    Some(map) => map(d),
                    None => diverging_colour(d, tol),
                };
                c.map(srgb_to_linear)
            })
            .collect();
        bin.push_vec3_attribute(&mut attributes, "COLOR_0", &colours);
        let values: Vec<u8> = dev
            .iter()
            .map(|&d| f32_of(d).map(f32::to_le_bytes))
            .collect::<Result<Vec<_>, _>>()?
            .concat();
        let a = bin.push(
            &values,
            ARRAY_BUFFER,
            json!({ "componentType": FLOAT, "count": n, "type": "SCALAR" }),
        );
        attributes.insert("_DEVIATION".into(), json!(a));
    }

    let mut primitive =
        json!({ "attributes": attributes, "mode": if triangles.is_empty() { 0 } else { 4 } });
    if !triangles.is_empty() {
        let idx: Vec<u8> = triangles
            .iter()
            .flatten()
            .flat_map(|i| i.to_le_bytes())
            .collect();
        let a = bin.push(
            &idx,
            ELEMENT_ARRAY_BUFFER,
            json!({ "componentType": UNSIGNED_INT, "count": triangles.len() * 3, "type": "SCALAR" }),
        );
        primitive["indices"] = json!(a);
    }

    let mut node = json!({ "mesh": 0, "name": "geofit surface" });
    if let Some(s) = options.unit_to_metres {
        if !(s > 0.0 && s.is_finite()) {
            return Err(invalid(format!(
                "unit_to_metres must be positive and finite, not {s}"
            )));
        }
        if s != 1.0 {
            node["scale"] = json!([s, s, s]);
        }
    }
    let mut scene = json!({ "nodes": [0] });
    if let Some(extras) = options.extras {
        scene["extras"] = extras.clone();
    }
    let doc = json!({
        "asset": { "version": "2.0", "generator": concat!("geofit ", env!("CARGO_PKG_VERSION")) },
        "scene": 0,
        "scenes": [scene],
        "nodes": [node],
        "meshes": [{ "primitives": [primitive] }],
        "accessors": bin.accessors,
        "bufferViews": bin.views,
        "buffers": [{ "byteLength": bin.data.len() }],
    });
    let mut json_chunk = serde_json::to_vec(&doc).map_err(|e| invalid(e.to_string()))?;
    while json_chunk.len() % 4 != 0 {
        json_chunk.push(b' ');
    }
    let mut bin_chunk = bin.data;
    while bin_chunk.len() % 4 != 0 {
        bin_chunk.push(0);
    }
    let total = 12 + 8 + json_chunk.len() + 8 + bin_chunk.len();
    let too_large = |what: &str| WriteError::TooLarge {
        format: "GLB",
        what: format!("{what} of {total} bytes exceeds 4 GiB"),
    };
    let total32 = u32::try_from(total).map_err(|_| too_large("a file"))?;
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend(2u32.to_le_bytes());
    out.extend(total32.to_le_bytes());
    out.extend((json_chunk.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json_chunk);
    out.extend((bin_chunk.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin_chunk);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_curve_ends() {
        assert_eq!(srgb_to_linear(0.0), 0.0);
        assert!((srgb_to_linear(1.0) - 1.0).abs() < 1e-6);
        assert!((srgb_to_linear(0.5) - 0.214).abs() < 1e-3);
        assert_eq!(srgb_to_linear(2.0), srgb_to_linear(1.0));
    }

    #[test]
    fn diverging_map_is_monotone_in_saturation() {
        let tol = 1.0;
        let mut last = f32::INFINITY;
        for k in 0..=40 {
            let c = diverging_colour(f64::from(k) * 0.1, tol);
            // Green falls as red saturates.
            assert!(c[1] <= last + 1e-6, "{k}");
            last = c[1];
        }
        assert_eq!(diverging_colour(-5.0, tol), DIVERGING_NEGATIVE);
        assert_eq!(diverging_colour(1.0, 0.0), DIVERGING_POSITIVE);
    }
}
