//! glTF 2.0 meshes: binary `.glb` (JSON chunk + BIN chunk) and `.gltf` JSON whose buffers are
//! embedded as base64 `data:` URIs.
//!
//! Every primitive of every mesh that the default scene (else the first scene, else every root
//! node, else every mesh) reaches is read, with the node transforms of the scene graph applied
//! (matrix or translation · rotation · scale, in f64). Triangle lists, strips and fans become
//! triangles (strips and fans with glTF's winding; the degenerate triangles strips use as
//! restarts are dropped); point and line primitives give points only. A mesh used by several
//! nodes is read once per node. Positions may be float or (`KHR_mesh_quantization`) integer,
//! normalised or not; sparse accessors are applied. Morph targets and skins are not applied
//! (the rest pose is read). A buffer in an external file cannot be opened from these bytes and
//! is an [`ReadError::ExternalData`]; the compression extensions (Draco, meshopt) are
//! [`ReadError::Unsupported`]. glTF units are metres.

use super::{Format, LoadedFile, Location, ReadError};
use crate::geom::Point3;
use crate::mesh::PolyMesh;
use serde_json::Value;

/// At most this many output points per input byte: bounds what instancing (one mesh under many
/// nodes) can make a small file expand to.
const MAX_POINTS_PER_BYTE: usize = 4;

/// Extensions that change how vertex data is stored; a file that requires one cannot be read
/// without decoding it.
const UNSUPPORTED: [&str; 3] = [
    "KHR_draco_mesh_compression",
    "EXT_meshopt_compression",
    "KHR_meshopt_compression",
];

/// Whether the bytes start with the GLB magic.
pub fn is_glb(bytes: &[u8]) -> bool {
    bytes.starts_with(b"glTF")
}

/// Whether the start of a text file looks like glTF JSON: an object with an `"asset"` key
/// near the start (exporters put it first or after a few top-level arrays).
pub fn looks_like_json(head: &[u8]) -> bool {
    let t = head.trim_ascii_start();
    let t = t.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(t);
    t.starts_with(b"{") && t.windows(7).any(|w| w == b"\"asset\"")
}

/// A 4 × 4 column-major matrix, as glTF stores them: `m[col][row]`.
type Mat4 = [[f64; 4]; 4];

const IDENTITY: Mat4 = [
    [1.0, 0.0, 0.0, 0.0],
    [0.0, 1.0, 0.0, 0.0],
    [0.0, 0.0, 1.0, 0.0],
    [0.0, 0.0, 0.0, 1.0],
];

fn mul(a: &Mat4, b: &Mat4) -> Mat4 {
    let mut m = [[0.0; 4]; 4];
    for (c, col) in m.iter_mut().enumerate() {
        for (r, v) in col.iter_mut().enumerate() {
            *v = (0..4).map(|k| a[k][r] * b[c][k]).sum();
        }
    }
    m
}

fn apply(m: &Mat4, p: [f64; 3]) -> Point3 {
    let c = |r: usize| m[0][r] * p[0] + m[1][r] * p[1] + m[2][r] * p[2] + m[3][r];
    Point3::new(c(0), c(1), c(2))
}

/// The parts of a glTF file the reader needs while it walks the scene.
struct Doc<'a> {
    format: Format,
    json: Value,
    buffers: Vec<Result<Vec<u8>, String>>,
    bin: Option<&'a [u8]>,
    max_points: usize,
    positions: Vec<Point3>,
    triangles: Vec<[u32; 3]>,
}

fn syntax(format: Format, at: Location, message: impl Into<String>) -> ReadError {
    ReadError::Syntax {
        format,
        at,
        message: message.into(),
    }
}

pub fn read(bytes: &[u8]) -> Result<LoadedFile, ReadError> {
    let (format, json_bytes, bin) = if is_glb(bytes) {
        let (json, bin) = glb_chunks(bytes)?;
        (Format::Glb, json, bin)
    } else {
        (Format::Gltf, bytes, None)
    };
    let json: Value = serde_json::from_slice(json_bytes).map_err(|e| {
        let at = if format == Format::Glb {
            Location::Byte(20 + e.column().saturating_sub(1))
        } else {
            Location::Line(e.line())
        };
        syntax(format, at, format!("invalid JSON: {e}"))
    })?;
    let mut doc = Doc {
        format,
        json,
        buffers: Vec::new(),
        bin,
        max_points: bytes.len().saturating_mul(MAX_POINTS_PER_BYTE),
        positions: Vec::new(),
        triangles: Vec::new(),
    };
    doc.check_asset()?;
    doc.load_buffers()?;
    doc.walk()?;
    let mesh = PolyMesh::try_new(doc.positions, doc.triangles.iter())?;
    Ok(LoadedFile {
        unit_to_metres: Some(1.0),
        ..LoadedFile::from_mesh(format, mesh)
    })
}

/// The JSON chunk and the BIN chunk (if any) of a GLB container.
fn glb_chunks(bytes: &[u8]) -> Result<(&[u8], Option<&[u8]>), ReadError> {
    let word = |at: usize| {
        bytes
            .get(at..at + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize)
    };
    let (Some(version), Some(length)) = (word(4), word(8)) else {
        return Err(ReadError::Truncated {
            format: Format::Glb,
            at: Location::Byte(bytes.len()),
            message: "the GLB header takes 12 bytes".into(),
        });
    };
    if version != 2 {
        return Err(syntax(
            Format::Glb,
            Location::Byte(4),
            format!("GLB version {version}; only glTF 2.0 is supported"),
        ));
    }
    if length > bytes.len() {
        return Err(ReadError::Truncated {
            format: Format::Glb,
            at: Location::Byte(8),
            message: format!(
                "the header gives {length} bytes, the file has {}",
                bytes.len()
            ),
        });
    }
    let bytes = &bytes[..length];
    let mut at = 12;
    let mut json = None;
    let mut bin = None;
    while at < bytes.len() {
        let (Some(len), Some(kind)) = (word(at), bytes.get(at + 4..at + 8)) else {
            return Err(ReadError::Truncated {
                format: Format::Glb,
                at: Location::Byte(at),
                message: "a chunk header takes 8 bytes".into(),
            });
        };
        let Some(data) = bytes.get(at + 8..).and_then(|d| d.get(..len)) else {
            return Err(ReadError::Truncated {
                format: Format::Glb,
                at: Location::Byte(at),
                message: format!("the chunk of {len} bytes runs past the end of the file"),
            });
        };
        match kind {
            b"JSON" if json.is_none() => json = Some(data),
            b"BIN\0" if json.is_some() && bin.is_none() => bin = Some(data),
            b"JSON" | b"BIN\0" => {
                return Err(syntax(
                    Format::Glb,
                    Location::Byte(at + 4),
                    "the chunks must be one JSON chunk, then at most one BIN chunk",
                ))
            }
            _ => {} // unknown chunk types are skipped, as the spec says
        }
        at += 8 + len;
    }
    let json = json.ok_or_else(|| syntax(Format::Glb, Location::Byte(12), "no JSON chunk"))?;
    Ok((json, bin))
}

/// Decodes standard base64 (with or without padding); `None` on any other character.
fn base64(text: &[u8]) -> Option<Vec<u8>> {
    let value = |c: u8| -> Option<u32> {
        Some(match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' | b'-' => 62,
            b'/' | b'_' => 63,
            _ => return None,
        } as u32)
    };
    let text = text
        .strip_suffix(b"==")
        .or_else(|| text.strip_suffix(b"="))
        .unwrap_or(text);
    let mut out = Vec::with_capacity(text.len() / 4 * 3 + 3);
    for chunk in text.chunks(4) {
        let mut n = 0u32;
        for (k, &c) in chunk.iter().enumerate() {
            n |= value(c)? << (18 - 6 * k);
        }
        let bytes = n.to_be_bytes();
        match chunk.len() {
            4 => out.extend_from_slice(&bytes[1..4]),
            3 => out.extend_from_slice(&bytes[1..3]),
            2 => out.push(bytes[1]),
            _ => return None,
        }
    }
    Some(out)
}

/// The component size in bytes of a glTF `componentType`.
fn component_size(ctype: u64) -> Option<usize> {
    match ctype {
        5120 | 5121 => Some(1),
        5122 | 5123 => Some(2),
        5125 | 5126 => Some(4),
        _ => None,
    }
}

fn components(kind: &str) -> Option<usize> {
    match kind {
        "SCALAR" => Some(1),
        "VEC2" => Some(2),
        "VEC3" => Some(3),
        "VEC4" | "MAT2" => Some(4),
        "MAT3" => Some(9),
        "MAT4" => Some(16),
        _ => None,
    }
}

/// One component as f64 (normalised integers mapped to [0, 1] or [-1, 1]).
fn component(b: &[u8], ctype: u64, normalized: bool) -> f64 {
    let (v, max) = match ctype {
        5120 => (f64::from(b[0] as i8), 127.0),
        5121 => (f64::from(b[0]), 255.0),
        5122 => (f64::from(i16::from_le_bytes([b[0], b[1]])), 32767.0),
        5123 => (f64::from(u16::from_le_bytes([b[0], b[1]])), 65535.0),
        5125 => (
            f64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            4294967295.0,
        ),
        _ => (f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])), 1.0),
    };
    if normalized && ctype != 5126 {
        (v / max).max(-1.0)
    } else {
        v
    }
}

impl Doc<'_> {
    fn err(&self, at: Location, message: impl Into<String>) -> ReadError {
        syntax(self.format, at, message)
    }

    fn array(&self, key: &str) -> &[Value] {
        self.json
            .get(key)
            .and_then(Value::as_array)
            .map_or(&[][..], Vec::as_slice)
    }

    /// Item `index` of the top-level array `key`, or an error naming it and `from`.
    fn item(&self, key: &'static str, index: usize, from: Location) -> Result<&Value, ReadError> {
        self.array(key).get(index).ok_or_else(|| {
            self.err(
                from,
                format!(
                    "refers to {key}[{index}], but the file has {}",
                    self.array(key).len()
                ),
            )
        })
    }

    fn check_asset(&self) -> Result<(), ReadError> {
        let version = self
            .json
            .get("asset")
            .and_then(|a| a.get("version"))
            .and_then(Value::as_str)
            .ok_or_else(|| self.err(Location::Item("asset", 0), "no asset.version"))?;
        if !version.starts_with("2.") {
            return Err(self.err(
                Location::Item("asset", 0),
                format!("glTF version {version}; only 2.x is supported"),
            ));
        }
        for ext in self.array("extensionsRequired") {
            if let Some(name) = ext.as_str().filter(|n| UNSUPPORTED.contains(n)) {
                return Err(ReadError::Unsupported {
                    format: self.format,
                    at: Location::Item("extensionsRequired", 0),
                    message: format!("the mesh data is compressed with {name}"),
                });
            }
        }
        Ok(())
    }

    fn load_buffers(&mut self) -> Result<(), ReadError> {
        let mut out = Vec::new();
        for (k, b) in self.array("buffers").iter().enumerate() {
            let at = Location::Item("buffer", k);
            let length = b.get("byteLength").and_then(Value::as_u64).unwrap_or(0);
            let data = match b.get("uri").and_then(Value::as_str) {
                None => match self.bin {
                    Some(bin) if k == 0 => Ok(bin.to_vec()),
                    _ => {
                        return Err(self.err(at, "has no uri and the file has no BIN chunk for it"))
                    }
                },
                Some(uri) if uri.starts_with("data:") => {
                    let (_, payload) = uri
                        .split_once(";base64,")
                        .ok_or_else(|| self.err(at, "a data: URI must be base64 (';base64,')"))?;
                    Ok(base64(payload.as_bytes())
                        .ok_or_else(|| self.err(at, "the data: URI is not valid base64"))?)
                }
                Some(uri) => Err(uri.to_string()),
            };
            if let Ok(d) = &data {
                if (d.len() as u64) < length {
                    return Err(ReadError::Truncated {
                        format: self.format,
                        at,
                        message: format!("byteLength is {length}, the data has {} bytes", d.len()),
                    });
                }
            }
            out.push(data);
        }
        self.buffers = out;
        Ok(())
    }

    /// The scene's root nodes, or `None` to read every mesh without a transform.
    fn roots(&self) -> Result<Option<Vec<usize>>, ReadError> {
        let scenes = self.array("scenes");
        let scene = match self.json.get("scene").and_then(Value::as_u64) {
            Some(s) => Some(self.item("scenes", s as usize, Location::Item("scene", 0))?),
            None => scenes.first(),
        };
        if let Some(scene) = scene {
            return Ok(Some(index_list(scene.get("nodes"))));
        }
        let nodes = self.array("nodes");
        if nodes.is_empty() {
            return Ok(None);
        }
        let mut is_child = vec![false; nodes.len()];
        for n in nodes {
            for c in index_list(n.get("children")) {
                if let Some(flag) = is_child.get_mut(c) {
                    *flag = true;
                }
            }
        }
        Ok(Some((0..nodes.len()).filter(|&i| !is_child[i]).collect()))
    }

    fn walk(&mut self) -> Result<(), ReadError> {
        let Some(roots) = self.roots()? else {
            for m in 0..self.array("meshes").len() {
                self.emit_mesh(m, &IDENTITY, Location::Item("mesh", m))?;
            }
            return Ok(());
        };
        let mut seen = vec![false; self.array("nodes").len()];
        // Depth-first with an explicit stack; each node may be visited once (glTF nodes have at
        // most one parent), which also rules out cycles.
        let mut stack: Vec<(usize, Mat4)> =
            roots.into_iter().rev().map(|r| (r, IDENTITY)).collect();
        while let Some((n, parent)) = stack.pop() {
            let at = Location::Item("node", n);
            let node = self.item("nodes", n, at)?.clone();
            if std::mem::replace(&mut seen[n], true) {
                return Err(self.err(
                    at,
                    "is reached twice in the scene graph (a node has one parent at most)",
                ));
            }
            let world = mul(&parent, &self.local(&node, at)?);
            if let Some(m) = node.get("mesh").and_then(Value::as_u64) {
                self.emit_mesh(m as usize, &world, at)?;
            }
            for c in index_list(node.get("children")).into_iter().rev() {
                stack.push((c, world));
            }
        }
        Ok(())
    }

    /// A node's local transform: its matrix, else T · R · S.
    fn local(&self, node: &Value, at: Location) -> Result<Mat4, ReadError> {
        let nums = |key: &str, n: usize| -> Result<Option<Vec<f64>>, ReadError> {
            let Some(v) = node.get(key) else {
                return Ok(None);
            };
            let list: Option<Vec<f64>> = v
                .as_array()
                .and_then(|a| a.iter().map(Value::as_f64).collect());
            match list {
                Some(l) if l.len() == n && l.iter().all(|x| x.is_finite()) => Ok(Some(l)),
                _ => Err(self.err(at, format!("'{key}' must be {n} finite numbers"))),
            }
        };
        if let Some(m) = nums("matrix", 16)? {
            let mut out = [[0.0; 4]; 4];
            for (k, v) in m.into_iter().enumerate() {
                out[k / 4][k % 4] = v;
            }
            return Ok(out);
        }
        let t = nums("translation", 3)?.unwrap_or_else(|| vec![0.0; 3]);
        let q = nums("rotation", 4)?.unwrap_or_else(|| vec![0.0, 0.0, 0.0, 1.0]);
        let s = nums("scale", 3)?.unwrap_or_else(|| vec![1.0; 3]);
        let norm = q.iter().map(|v| v * v).sum::<f64>().sqrt();
        let (x, y, z, w) = if norm > 0.0 {
            (q[0] / norm, q[1] / norm, q[2] / norm, q[3] / norm)
        } else {
            (0.0, 0.0, 0.0, 1.0)
        };
        let r = [
            [
                1.0 - 2.0 * (y * y + z * z),
                2.0 * (x * y + w * z),
                2.0 * (x * z - w * y),
            ],
            [
                2.0 * (x * y - w * z),
                1.0 - 2.0 * (x * x + z * z),
                2.0 * (y * z + w * x),
            ],
            [
                2.0 * (x * z + w * y),
                2.0 * (y * z - w * x),
                1.0 - 2.0 * (x * x + y * y),
            ],
        ];
        let mut m = IDENTITY;
        for c in 0..3 {
            for row in 0..3 {
                m[c][row] = r[c][row] * s[c];
            }
        }
        m[3] = [t[0], t[1], t[2], 1.0];
        Ok(m)
    }

    fn emit_mesh(&mut self, m: usize, world: &Mat4, from: Location) -> Result<(), ReadError> {
        let mesh = self.item("meshes", m, from)?.clone();
        let prims = mesh
            .get("primitives")
            .and_then(Value::as_array)
            .cloned()
            .unwrap_or_default();
        for (p, prim) in prims.iter().enumerate() {
            let at = Location::Item("mesh", m);
            if prim
                .get("extensions")
                .is_some_and(|e| UNSUPPORTED.iter().any(|u| e.get(u).is_some()))
            {
                return Err(ReadError::Unsupported {
                    format: self.format,
                    at,
                    message: format!("primitive {p} is compressed (Draco or meshopt)"),
                });
            }
            let Some(pos) = prim
                .get("attributes")
                .and_then(|a| a.get("POSITION"))
                .and_then(Value::as_u64)
            else {
                continue; // a primitive without positions draws nothing
            };
            let local = self.accessor(pos as usize, at, Some(3))?;
            let base = self.positions.len();
            let count = local.len() / 3;
            if count > self.max_points.saturating_sub(base) {
                return Err(self.err(
                    at,
                    "the scene instances more points than the file size allows",
                ));
            }
            let base_u32 = u32::try_from(base + count)
                .map_err(|_| self.err(at, "more than 2³² points"))?
                - count as u32;
            for v in local.chunks_exact(3) {
                let q = apply(world, [v[0], v[1], v[2]]);
                if !q.is_finite() {
                    return Err(ReadError::NonFinite {
                        format: self.format,
                        at,
                    });
                }
                self.positions.push(q);
            }
            let mode = prim.get("mode").and_then(Value::as_u64).unwrap_or(4);
            if !matches!(mode, 4..=6) {
                continue; // points and lines: the vertices are data points
            }
            let indices: Vec<u32> = match prim.get("indices").and_then(Value::as_u64) {
                Some(a) => {
                    let acc = a as usize;
                    let values = self.accessor(acc, Location::Item("accessor", acc), Some(1))?;
                    let mut out = Vec::with_capacity(values.len());
                    for v in values {
                        if v >= count as f64 {
                            return Err(ReadError::IndexOutOfRange {
                                format: self.format,
                                at: Location::Item("accessor", acc),
                                index: v as i64,
                                count,
                            });
                        }
                        out.push(v as u32);
                    }
                    out
                }
                None => (0..count as u32).collect(),
            };
            let tri = |a: u32, b: u32, c: u32| [base_u32 + a, base_u32 + b, base_u32 + c];
            match mode {
                4 => self
                    .triangles
                    .extend(indices.chunks_exact(3).map(|t| tri(t[0], t[1], t[2]))),
                5 => {
                    for (i, w) in indices.windows(3).enumerate() {
                        let t = if i % 2 == 0 {
                            tri(w[0], w[1], w[2])
                        } else {
                            tri(w[1], w[0], w[2])
                        };
                        if t[0] != t[1] && t[1] != t[2] && t[0] != t[2] {
                            self.triangles.push(t);
                        }
                    }
                }
                _ => {
                    if let Some((&first, rest)) = indices.split_first() {
                        self.triangles
                            .extend(rest.windows(2).map(|w| tri(w[0], w[1], first)));
                    }
                }
            }
        }
        Ok(())
    }

    /// An accessor's values, `components` per element (checked when given), as f64.
    fn accessor(
        &self,
        index: usize,
        from: Location,
        want: Option<usize>,
    ) -> Result<Vec<f64>, ReadError> {
        let at = Location::Item("accessor", index);
        let acc = self.item("accessors", index, from)?;
        let ctype = acc
            .get("componentType")
            .and_then(Value::as_u64)
            .unwrap_or(0);
        let csize = component_size(ctype)
            .ok_or_else(|| self.err(at, format!("unknown componentType {ctype}")))?;
        let kind = acc.get("type").and_then(Value::as_str).unwrap_or("");
        let n = components(kind).ok_or_else(|| self.err(at, format!("unknown type '{kind}'")))?;
        if want.is_some_and(|w| w != n) {
            return Err(self.err(
                at,
                format!(
                    "expected {} components, the accessor has type {kind}",
                    want.unwrap_or(0)
                ),
            ));
        }
        if want == Some(1) && !matches!(ctype, 5121 | 5123 | 5125) {
            return Err(self.err(at, "indices must be unsigned bytes, shorts or ints"));
        }
        let normalized = acc
            .get("normalized")
            .and_then(Value::as_bool)
            .unwrap_or(false);
        let count = acc.get("count").and_then(Value::as_u64).unwrap_or(0) as usize;
        let offset = acc.get("byteOffset").and_then(Value::as_u64).unwrap_or(0) as usize;
        let elem = n * csize;
        let mut out = match acc.get("bufferView").and_then(Value::as_u64) {
            Some(v) => self.read_view(v as usize, at, offset, count, elem, None, |b, out| {
                for k in 0..n {
                    out.push(component(&b[k * csize..], ctype, normalized));
                }
            })?,
            None => {
                if count > self.max_points {
                    return Err(self.err(
                        at,
                        format!("{count} elements without a bufferView exceed the file size"),
                    ));
                }
                vec![0.0; count * n]
            }
        };
        if let Some(sparse) = acc.get("sparse") {
            self.apply_sparse(sparse, at, &mut out, n, count, ctype, normalized)?;
        }
        Ok(out)
    }

    /// Reads `count` elements of `elem` bytes from a buffer view, every bound checked.
    #[allow(clippy::too_many_arguments)]
    fn read_view(
        &self,
        view: usize,
        at: Location,
        offset: usize,
        count: usize,
        elem: usize,
        stride: Option<usize>,
        mut push: impl FnMut(&[u8], &mut Vec<f64>),
    ) -> Result<Vec<f64>, ReadError> {
        let v = self.item("bufferViews", view, at)?;
        let buffer = v.get("buffer").and_then(Value::as_u64).unwrap_or(u64::MAX) as usize;
        let data = match self.buffers.get(buffer) {
            Some(Ok(d)) => d.as_slice(),
            Some(Err(uri)) => {
                return Err(ReadError::ExternalData {
                    format: self.format,
                    at: Location::Item("buffer", buffer),
                    uri: uri.clone(),
                })
            }
            None => {
                return Err(self.err(
                    Location::Item("bufferView", view),
                    format!("refers to buffer {buffer}, which does not exist"),
                ))
            }
        };
        let v_off = v.get("byteOffset").and_then(Value::as_u64).unwrap_or(0) as usize;
        let v_len = v.get("byteLength").and_then(Value::as_u64).unwrap_or(0) as usize;
        let stride = stride
            .or_else(|| {
                v.get("byteStride")
                    .and_then(Value::as_u64)
                    .map(|s| s as usize)
            })
            .unwrap_or(elem)
            .max(1);
        let view_bytes = data
            .get(v_off..v_off.saturating_add(v_len))
            .ok_or_else(|| ReadError::Truncated {
                format: self.format,
                at: Location::Item("bufferView", view),
                message: format!(
                    "{v_len} bytes at {v_off} run past the end of buffer {buffer} ({} bytes)",
                    data.len()
                ),
            })?;
        let needed = match count {
            0 => 0,
            _ => stride
                .saturating_mul(count - 1)
                .saturating_add(elem)
                .saturating_add(offset),
        };
        if needed > view_bytes.len() {
            return Err(ReadError::Truncated {
                format: self.format,
                at,
                message: format!(
                    "{count} elements need {needed} bytes of bufferView {view}, which has {}",
                    view_bytes.len()
                ),
            });
        }
        let mut out = Vec::with_capacity(count * elem);
        for i in 0..count {
            let s = offset + i * stride;
            push(&view_bytes[s..s + elem], &mut out);
        }
        Ok(out)
    }

    #[allow(clippy::too_many_arguments)]
    fn apply_sparse(
        &self,
        sparse: &Value,
        at: Location,
        out: &mut [f64],
        n: usize,
        count: usize,
        ctype: u64,
        normalized: bool,
    ) -> Result<(), ReadError> {
        let k = sparse.get("count").and_then(Value::as_u64).unwrap_or(0) as usize;
        let idx = sparse
            .get("indices")
            .ok_or_else(|| self.err(at, "sparse without indices"))?;
        let val = sparse
            .get("values")
            .ok_or_else(|| self.err(at, "sparse without values"))?;
        let ictype = idx
            .get("componentType")
            .and_then(Value::as_u64)
            .unwrap_or(0);
        let isize = component_size(ictype)
            .filter(|_| matches!(ictype, 5121 | 5123 | 5125))
            .ok_or_else(|| self.err(at, "sparse indices must be unsigned"))?;
        let view = |v: &Value| {
            v.get("bufferView")
                .and_then(Value::as_u64)
                .map(|x| x as usize)
                .ok_or_else(|| self.err(at, "sparse data without a bufferView"))
        };
        let offset = |v: &Value| v.get("byteOffset").and_then(Value::as_u64).unwrap_or(0) as usize;
        let indices = self.read_view(
            view(idx)?,
            at,
            offset(idx),
            k,
            isize,
            Some(isize),
            |b, o| o.push(component(b, ictype, false)),
        )?;
        let csize = component_size(ctype).unwrap_or(4);
        let values = self.read_view(
            view(val)?,
            at,
            offset(val),
            k,
            n * csize,
            Some(n * csize),
            |b, o| {
                for c in 0..n {
                    o.push(component(&b[c * csize..], ctype, normalized));
                }
            },
        )?;
        for (j, &i) in indices.iter().enumerate() {
            let i = i as usize;
            if i >= count {
                return Err(ReadError::IndexOutOfRange {
                    format: self.format,
                    at,
                    index: i as i64,
                    count,
                });
            }
            out[i * n..(i + 1) * n].copy_from_slice(&values[j * n..(j + 1) * n]);
        }
        Ok(())
    }
}

/// A JSON array of indices; anything that is not a non-negative integer is dropped.
fn index_list(v: Option<&Value>) -> Vec<usize> {
    v.and_then(Value::as_array)
        .map(|a| {
            a.iter()
                .filter_map(Value::as_u64)
                .map(|i| i as usize)
                .collect()
        })
        .unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_decodes_with_and_without_padding() {
        assert_eq!(base64(b"TWFu").unwrap(), b"Man");
        assert_eq!(base64(b"TWE=").unwrap(), b"Ma");
        assert_eq!(base64(b"TQ==").unwrap(), b"M");
        assert_eq!(base64(b"TQ").unwrap(), b"M");
        assert!(base64(b"T").is_none());
        assert!(base64(b"T*==").is_none());
    }

    #[test]
    fn trs_is_translation_rotation_scale() {
        let node: Value = serde_json::json!({
            "translation": [1.0, 2.0, 3.0],
            "rotation": [0.0, 0.0, std::f64::consts::FRAC_1_SQRT_2, std::f64::consts::FRAC_1_SQRT_2],
            "scale": [2.0, 2.0, 2.0]
        });
        let doc = Doc {
            format: Format::Gltf,
            json: Value::Null,
            buffers: vec![],
            bin: None,
            max_points: 0,
            positions: vec![],
            triangles: vec![],
        };
        let m = doc.local(&node, Location::Item("node", 0)).unwrap();
        // x -> scaled 2, rotated 90° about z -> (0, 2, 0), translated -> (1, 4, 3).
        let p = apply(&m, [1.0, 0.0, 0.0]);
        assert!((p - Point3::new(1.0, 4.0, 3.0)).length() < 1e-12, "{p}");
    }
}
