//! Building a subdivision fitter from a loaded data file: the one path the command line and the
//! wasm API share (initial control mesh by QEM simplification, scheme set-up, fitter).

use super::{FitError, SubdivFitOptions, SubdivFitter};
use crate::mesh::PolyMesh;
use crate::subdiv::{Scheme, SubdivSurface};

/// The initial control-mesh size for `n` data points when the user gives none: n/60 (at least
/// 50, at most 20,000, never more than the `used` vertices of the data mesh), a density at which
/// QEM keeps the shape of scans like the Stanford bunny (35,947 points -> 599).
pub fn default_initial_count(n: usize, used: usize) -> usize {
    (n / 60).clamp(50, 20_000).min(used)
}

/// The data mesh simplified by QEM to `target` vertices (or [`default_initial_count`]).
/// A point cloud has no faces to simplify: the caller must supply a control mesh.
pub fn initial_control(data: &PolyMesh, target: Option<usize>) -> Result<PolyMesh, FitError> {
    if data.is_point_cloud() {
        return Err(FitError::ControlMesh {
            reason: "the data has no faces; give a control mesh".into(),
        });
    }
    let used = used_vertices(data);
    let target = target.unwrap_or_else(|| default_initial_count(data.num_vertices(), used));
    crate::mesh::simplify::simplify(data, target).map_err(|e| FitError::ControlMesh {
        reason: format!("simplification: {e}"),
    })
}

/// A fitter of every vertex of `data` by the limit surface of `scheme`, starting from `control`
/// when given, else from the data simplified to `initial` vertices.
pub fn build_subdiv_fitter(
    data: &PolyMesh,
    scheme: Scheme,
    control: Option<PolyMesh>,
    initial: Option<usize>,
    options: SubdivFitOptions,
) -> Result<SubdivFitter<SubdivSurface>, FitError> {
    options.validate()?;
    let control = match control {
        Some(mesh) => mesh,
        None => initial_control(data, initial)?,
    };
    SubdivFitter::try_new(data.positions(), control, scheme, options)
}

/// How many vertices of `mesh` some face uses.
fn used_vertices(mesh: &PolyMesh) -> usize {
    let mut used = vec![false; mesh.num_vertices()];
    for f in mesh.faces() {
        for &v in f {
            used[v as usize] = true;
        }
    }
    used.iter().filter(|&&u| u).count()
}
