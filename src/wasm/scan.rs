//! `loadFile` and the `LoadedScan` handle: a parsed point or mesh file, ready to draw.

use crate::geom::find_strays;
use crate::io::{self, LoadedFile};
use crate::mesh::PolyMesh;
use crate::render::buffers;
use wasm_bindgen::prelude::*;

/// A point or mesh file read by the core: its counts, bounding box and draw buffers. Points far
/// from the rest ([`crate::geom::find_strays`]), which a fit leaves out, are left out of the
/// bounding box and the draw buffers too, so that the view frames the object; `strays` lists
/// them.
///
/// Holds WebAssembly memory until `free()` is called, or the scope of a `using` declaration
/// ends (`[Symbol.dispose]()` is `free()`); the garbage collector does not free it in time.
#[wasm_bindgen]
pub struct LoadedScan {
    file: LoadedFile,
    strays: Vec<u32>,
    /// The file's mesh without its strays, when it has any.
    kept: Option<PolyMesh>,
}

/// Reads a point or mesh file (PLY, OBJ, STL, XYZ/CSV/PTS) from its bytes. `name` is the file
/// name, a hint for the format. Throws an `Error` saying what is wrong and where.
/// `onProgress(phase, done)`, when given, hears how far the reading is (phase `reading`).
#[wasm_bindgen(js_name = loadFile)]
pub fn load_file(
    bytes: &[u8],
    name: &str,
    #[wasm_bindgen(js_name = onProgress, unchecked_optional_param_type = "ProgressCallback | null")]
    on_progress: Option<js_sys::Function>,
) -> Result<LoadedScan, JsError> {
    let file = super::with_progress(on_progress, || io::read_bytes(bytes, Some(name)))?;
    let strays = find_strays(file.mesh.positions());
    let kept = (!strays.is_empty()).then(|| file.mesh.without_vertices(&strays).0);
    Ok(LoadedScan { file, strays, kept })
}

impl LoadedScan {
    /// What a fit of this file runs on.
    pub(crate) fn fit_data(&self) -> crate::fit::FitData<'_> {
        crate::fit::FitData::from(&self.file)
    }

    /// The points drawn and framed: the file's, strays left out.
    fn drawn(&self) -> &PolyMesh {
        self.kept.as_ref().unwrap_or(&self.file.mesh)
    }

    /// Metres per unit of the file's coordinates, when its format says (E57, glTF/GLB).
    pub(crate) fn unit_to_metres(&self) -> Option<f64> {
        self.file.unit_to_metres
    }
}

#[wasm_bindgen]
impl LoadedScan {
    /// The format the file was parsed as, in lower case ("ply", "obj", "e57", ...).
    #[wasm_bindgen(getter, unchecked_return_type = "FileFormat")]
    pub fn format(&self) -> Result<JsValue, JsError> {
        Ok(serde_wasm_bindgen::to_value(&self.file.format)?)
    }

    /// Number of points (vertices) in the file, strays included (see [`LoadedScan::strays`]).
    #[wasm_bindgen(getter, js_name = numPoints)]
    pub fn num_points(&self) -> usize {
        self.file.mesh.num_vertices()
    }

    /// Number of triangles after triangulating polygons.
    #[wasm_bindgen(getter, js_name = numTriangles)]
    pub fn num_triangles(&self) -> usize {
        self.file.mesh.num_triangles()
    }

    /// Point positions for drawing: `x, y, z` per point (f32).
    pub fn positions(&self) -> Vec<f32> {
        buffers::to_f32_xyz(self.drawn().positions())
    }

    /// Smooth vertex normals for drawing the triangles: `x, y, z` per point (f32).
    pub fn normals(&self) -> Vec<f32> {
        buffers::vertex_normals(self.drawn().positions(), &self.drawn().triangles())
    }

    /// Triangle vertex indices, three per triangle.
    pub fn indices(&self) -> Vec<u32> {
        self.drawn().triangles().into_iter().flatten().collect()
    }

    /// Indices of the points left out as strays (a fit leaves them out too), in order.
    pub fn strays(&self) -> Vec<u32> {
        self.strays.clone()
    }

    /// Smallest corner of the bounding box, `[x, y, z]` (f64), or empty when there are no points.
    #[wasm_bindgen(js_name = bboxMin)]
    pub fn bbox_min(&self) -> Vec<f64> {
        self.drawn()
            .bbox()
            .map_or(Vec::new(), |b| b.min.to_array().to_vec())
    }

    /// Largest corner of the bounding box, `[x, y, z]` (f64), or empty when there are no points.
    #[wasm_bindgen(js_name = bboxMax)]
    pub fn bbox_max(&self) -> Vec<f64> {
        self.drawn()
            .bbox()
            .map_or(Vec::new(), |b| b.max.to_array().to_vec())
    }
}
