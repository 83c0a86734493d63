//! The fitter's view of the subdivision library: [`SubdivSurface`] as a [`ControlSurface`],
//! with each scheme's refinement and remeshing.

use super::refine::{improve_by_flips, split_triangles, SplitRule};
use super::refine_ds::split_polygons;
use super::refine_quad::split_quads;
use super::subdiv::{ControlSurface, SubdivFitter};
use super::{FitError, SubdivFitOptions};
use crate::geom::Point3;
use crate::mesh::{ControlMesh, PolyMesh};
use crate::subdiv::{quadrangulate, LimitSurface, Scheme, SubdivSurface};

/// The limit surface of `control` under `scheme`; quad schemes accept any polygon mesh and turn
/// it into quads first (one Catmull–Clark step) when it is not all quads.
pub fn surface_of(scheme: Scheme, control: &PolyMesh) -> Result<SubdivSurface, FitError> {
    Ok(SubdivSurface::try_new(
        scheme,
        control_mesh_of(scheme, control)?,
    )?)
}

/// The control mesh of `control` for `scheme` (quads for the quad schemes).
fn control_mesh_of(scheme: Scheme, control: &PolyMesh) -> Result<ControlMesh, FitError> {
    let mesh = ControlMesh::try_new(control).map_err(|e| FitError::ControlMesh {
        reason: e.to_string(),
    })?;
    Ok(match scheme {
        Scheme::Loop => mesh,
        _ if mesh.is_quad_mesh() => mesh,
        // Doo–Sabin takes any polygons; only an all-triangle start is turned into quads (its
        // local refinements add quads and (n + 1)-gons, which must stay as they are).
        Scheme::DooSabin if !mesh.is_triangle_mesh() => mesh,
        _ => quadrangulate(&mesh)?,
    })
}

impl ControlSurface for SubdivSurface {
    fn scheme_name(&self) -> &'static str {
        match self.scheme() {
            Scheme::Loop => "loop",
            Scheme::CatmullClark => "catmull-clark",
            Scheme::DooSabin => "doo-sabin",
        }
    }

    fn control_polygons(&self) -> PolyMesh {
        self.control_mesh().to_poly_mesh().unwrap_or_default()
    }

    fn rebuild(&self, control: &PolyMesh) -> Result<Self, FitError> {
        Ok(self.with_mesh(control_mesh_of(self.scheme(), control)?)?)
    }

    /// Loop and Catmull–Clark patches are the control faces. Doo–Sabin patches sit at
    /// (face, vertex) sites and belong to that face.
    fn patch_face(&self, patch: u32) -> usize {
        match self.scheme() {
            Scheme::DooSabin => self
                .patch_site(patch)
                .map_or(usize::MAX, |(f, _)| f as usize),
            _ => patch as usize,
        }
    }

    /// Loop: red–green splitting with Loop's masks. Catmull–Clark: local conforming quad
    /// splitting with transition templates and Catmull–Clark's masks. Doo–Sabin: marked
    /// faces split into quads around their centroids, neighbours gain the edge midpoints.
    fn refine_control(&self, control: &PolyMesh, marked: &[bool]) -> Result<PolyMesh, FitError> {
        match self.scheme() {
            Scheme::Loop => split_triangles(control, marked, SplitRule::Loop),
            Scheme::CatmullClark => split_quads(control, marked),
            Scheme::DooSabin => split_polygons(control, marked),
        }
    }

    fn kept_patch(&self, patch: u32) -> Option<u32> {
        SubdivSurface::kept_patch(self, patch)
    }

    fn remesh_control(&self, control: &mut PolyMesh) -> Result<usize, FitError> {
        match self.scheme() {
            Scheme::Loop => improve_by_flips(control, 3, self.control_points().len() as u32),
            _ => Ok(0),
        }
    }
}

impl SubdivFitter<SubdivSurface> {
    /// A fitter of `data_points` (connectivity not needed) by the limit surface of `scheme`,
    /// starting from `initial_control` (triangles for Loop; any polygons for the quad schemes,
    /// which are turned into quads when needed).
    pub fn try_new(
        data_points: &[Point3],
        initial_control: PolyMesh,
        scheme: Scheme,
        options: SubdivFitOptions,
    ) -> Result<Self, FitError> {
        let surface = surface_of(scheme, &initial_control)?;
        SubdivFitter::with_surface(data_points, surface, options)
    }
}
