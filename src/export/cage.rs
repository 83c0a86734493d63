//! The control cage of a subdivision fit with its creases, in the forms other tools read:
//! USD (`.usda`), whose `Mesh` prim OpenSubdiv-based tools (Blender, Maya, Houdini, usdview)
//! evaluate with the same scheme, and a JSON sidecar for the OBJ cage (OBJ has no creases).
//!
//! geofit's creases are infinitely sharp, which OpenSubdiv writes as sharpness 10
//! (`Sdc::Crease::SHARPNESS_INFINITE`); a vertex with three or more crease edges is a corner
//! and one with a single crease edge a dart in both. Open boundaries are interpolated as
//! OpenSubdiv's `edgeOnly` does (the boundary curve is the boundary polygon's B-spline).

use super::ExportError;
use crate::fit::{Fitter, Scheme};
use crate::mesh::PolyMesh;
use serde::Serialize;
use std::fmt::Write;

/// OpenSubdiv's (and USD's) sharpness of an infinitely sharp crease.
pub const INFINITE_SHARPNESS: f64 = 10.0;

/// The cage of a subdivision fit and its crease edges (vertex pairs of the cage, smaller
/// first), or the error for fits that have no cage of a subdivision surface.
fn cage_and_creases(fit: &dyn Fitter) -> Result<(PolyMesh, Vec<[u32; 2]>), ExportError> {
    let surface = fit
        .subdiv_surface()
        .ok_or_else(|| ExportError::Unsupported {
            what: format!(
                "scheme {}: only subdivision fits have a cage with creases; export the control \
             net as OBJ",
                fit.scheme()
            ),
        })?;
    let control = surface.control_mesh();
    let mesh = control
        .to_poly_mesh()
        .map_err(|e| ExportError::Unsupported {
            what: e.to_string(),
        })?;
    let creases = control.creases();
    Ok((mesh, creases))
}

/// The crease sidecar of the OBJ cage ([`super::cage_obj`]): what OBJ cannot say.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CageCreases {
    /// The subdivision scheme the cage is evaluated with.
    pub scheme: Scheme,
    /// Vertices of the cage (as in the OBJ, whose `v` lines are numbered from 1; these from 0).
    pub vertices: usize,
    /// The crease edges, pairs of 0-based vertex indices, smaller first.
    pub creases: Vec<[u32; 2]>,
    /// Their sharpness in OpenSubdiv's terms: all infinitely sharp.
    pub sharpness: f64,
}

/// The crease sidecar of the cage of a subdivision fit, as JSON text.
pub fn cage_creases_json(fit: &dyn Fitter) -> Result<String, ExportError> {
    let (mesh, creases) = cage_and_creases(fit)?;
    let sidecar = CageCreases {
        scheme: fit.scheme(),
        vertices: mesh.num_vertices(),
        creases,
        sharpness: INFINITE_SHARPNESS,
    };
    serde_json::to_string_pretty(&sidecar).map_err(|e| ExportError::Unsupported {
        what: e.to_string(),
    })
}

/// The cage of a Loop or Catmull–Clark fit as a USD layer (`.usda` text): one `Mesh` prim with
/// the scheme, the faces, the points and the creases (`creaseIndices`, `creaseLengths`,
/// `creaseSharpnesses`). USD has no Doo–Sabin scheme, so such fits are refused.
pub fn cage_usda(fit: &dyn Fitter) -> Result<String, ExportError> {
    let scheme = match fit.scheme() {
        Scheme::Loop => "loop",
        Scheme::CatmullClark => "catmullClark",
        other => {
            return Err(ExportError::Unsupported {
                what: format!(
                    "scheme {other}: USD evaluates Loop and Catmull–Clark cages only; export \
                     the cage as OBJ with its crease sidecar"
                ),
            })
        }
    };
    let (mesh, creases) = cage_and_creases(fit)?;
    Ok(usda_text(&mesh, &creases, scheme))
}

/// The USDA layer of `mesh` with the crease edges `creases`, for `scheme` (USD's token).
fn usda_text(mesh: &PolyMesh, creases: &[[u32; 2]], scheme: &str) -> String {
    let mut t = String::new();
    t.push_str(
        "#usda 1.0\n(\n    defaultPrim = \"cage\"\n    doc = \"geofit control cage\"\n)\n\n",
    );
    t.push_str("def Mesh \"cage\"\n{\n");
    let _ = writeln!(t, "    uniform token subdivisionScheme = \"{scheme}\"");
    t.push_str("    uniform token interpolateBoundary = \"edgeOnly\"\n");
    t.push_str("    uniform token orientation = \"rightHanded\"\n");
    let counts = mesh.faces().map(|f| f.len().to_string());
    list(&mut t, "int[] faceVertexCounts", counts);
    let indices = mesh.faces().flat_map(|f| f.iter().map(u32::to_string));
    list(&mut t, "int[] faceVertexIndices", indices);
    // USD's points are single precision (point3f): the layer stores, it does not compute.
    let points = mesh
        .positions()
        .iter()
        .map(|p| format!("({}, {}, {})", p.x as f32, p.y as f32, p.z as f32));
    list(&mut t, "point3f[] points", points);
    if !creases.is_empty() {
        let ends = creases.iter().flat_map(|e| e.map(|v| v.to_string()));
        list(&mut t, "int[] creaseIndices", ends);
        list(
            &mut t,
            "int[] creaseLengths",
            creases.iter().map(|_| "2".into()),
        );
        let sharp = creases.iter().map(|_| format!("{INFINITE_SHARPNESS}"));
        list(&mut t, "float[] creaseSharpnesses", sharp);
    }
    t.push_str("}\n");
    t
}

/// Appends the attribute `declaration = [a, b, ...]` to `t`.
fn list(t: &mut String, declaration: &str, items: impl Iterator<Item = String>) {
    let items: Vec<String> = items.collect();
    let _ = writeln!(t, "    {declaration} = [{}]", items.join(", "));
}
