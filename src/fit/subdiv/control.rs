//! The fitter's view of the subdivision library: [`SubdivSurface`] as a [`ControlSurface`],
//! refined and remeshed by the library's own local rules (`subdiv::adaptive`).

use super::{ControlSurface, SubdivFitOptions, SubdivFitter};
use crate::fit::FitError;
use crate::geom::Point3;
use crate::mesh::{ControlMesh, PolyMesh};
use crate::subdiv::{adaptive, quadrangulate, LimitSurface, Scheme, SubdivSurface};

/// The limit surface of `control` under `scheme` with the edges `creases` tagged sharp; quad
/// schemes accept any polygon mesh and turn it into quads first (one Catmull–Clark step, which
/// keeps the creases) when it is not all quads.
pub fn surface_of(
    scheme: Scheme,
    control: &PolyMesh,
    creases: &[[u32; 2]],
) -> Result<SubdivSurface, FitError> {
    Ok(SubdivSurface::try_new(
        scheme,
        control_mesh_of(scheme, control, creases)?,
    )?)
}

/// The control mesh of `control` with `creases` tagged, for `scheme` (quads for the quad
/// schemes).
fn control_mesh_of(
    scheme: Scheme,
    control: &PolyMesh,
    creases: &[[u32; 2]],
) -> Result<ControlMesh, FitError> {
    let mut mesh = ControlMesh::try_new(control)?;
    adaptive::tag_creases(&mut mesh, creases);
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
    fn scheme(&self) -> Scheme {
        SubdivSurface::scheme(self)
    }

    fn control_polygons(&self) -> PolyMesh {
        self.control_mesh().to_poly_mesh().unwrap_or_default()
    }

    fn as_subdiv(&self) -> Option<&SubdivSurface> {
        Some(self)
    }

    /// The creases carry over: the refinements keep old vertex numbers, so
    /// [`adaptive::carried_creases`] finds them in the new mesh.
    fn rebuild(&self, control: &PolyMesh) -> Result<Self, FitError> {
        let creases = adaptive::carried_creases(self.control_mesh(), control);
        Ok(self.with_mesh(control_mesh_of(
            SubdivSurface::scheme(self),
            control,
            &creases,
        )?)?)
    }

    /// Loop and Catmull–Clark patches are the control faces. Doo–Sabin patches sit at
    /// (face, vertex) sites and belong to that face.
    fn patch_face(&self, patch: u32) -> usize {
        match SubdivSurface::scheme(self) {
            Scheme::DooSabin => self
                .patch_site(patch)
                .map_or(usize::MAX, |(f, _)| f as usize),
            _ => patch as usize,
        }
    }

    fn refine_control(&self, control: &PolyMesh, marked: &[bool]) -> Result<PolyMesh, FitError> {
        Ok(adaptive::refine_marked(
            SubdivSurface::scheme(self),
            control,
            marked,
            &self.control_mesh().creases(),
        )?)
    }

    fn kept_patch(&self, patch: u32) -> Option<u32> {
        SubdivSurface::kept_patch(self, patch)
    }

    fn remesh_control(&self, control: &mut PolyMesh) -> Result<usize, FitError> {
        let first_new = self.control_points().len() as u32;
        let creases = adaptive::carried_creases(self.control_mesh(), control);
        Ok(adaptive::remesh(
            SubdivSurface::scheme(self),
            control,
            first_new,
            &creases,
        )?)
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
        Self::with_creases(data_points, initial_control, &[], scheme, options)
    }

    /// [`SubdivFitter::try_new`] with the edges `creases` of `initial_control` tagged sharp:
    /// the limit surface keeps them as crease curves, and refinements carry them on.
    pub fn with_creases(
        data_points: &[Point3],
        initial_control: PolyMesh,
        creases: &[[u32; 2]],
        scheme: Scheme,
        options: SubdivFitOptions,
    ) -> Result<Self, FitError> {
        let surface = surface_of(scheme, &initial_control, creases)?;
        SubdivFitter::with_surface(data_points, surface, options)
    }
}
