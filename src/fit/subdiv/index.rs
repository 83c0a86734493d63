//! Where Newton starts each foot-point search: a spatial index over samples of the limit
//! surface, so every data point starts near its global closest point.

use crate::geom::Point3;
use crate::subdiv::{LimitSurface, PatchDomain, SurfaceParam};
use kiddo::immutable::float::kdtree::ImmutableKdTree;
use kiddo::SquaredEuclidean;

/// A k-d tree over points of the limit surface (a few per patch), giving each data point a
/// starting parameter for Newton that is near the global closest point.
pub(crate) struct SurfaceIndex {
    tree: ImmutableKdTree<f64, u64, 3, 32>,
    params: Vec<SurfaceParam>,
}

impl SurfaceIndex {
    /// Samples every patch at `resolution`² interior points (centres of the cells of a
    /// `resolution` grid: no sample is shared by two patches, so the tree never holds
    /// duplicates) and indexes them. Non-finite samples are skipped.
    pub(crate) fn build<S: LimitSurface + ?Sized>(surface: &S, resolution: usize) -> SurfaceIndex {
        let cells = patch_cell_centres(surface.domain(), resolution.max(1));
        let mut points = Vec::with_capacity(surface.num_patches() * cells.len());
        let mut params = Vec::with_capacity(points.capacity());
        for patch in 0..surface.num_patches() as u32 {
            for &(u, v) in &cells {
                let at = SurfaceParam { patch, u, v };
                let s = surface.eval(at).point;
                if s.is_finite() {
                    points.push(s.to_array());
                    params.push(at);
                }
            }
        }
        SurfaceIndex {
            tree: ImmutableKdTree::new_from_slice(&points),
            params,
        }
    }

    /// The indexed sample nearest to `p`, or `None` when the index is empty.
    pub(crate) fn nearest(&self, p: Point3) -> Option<SurfaceParam> {
        if self.params.is_empty() || !p.is_finite() {
            return None;
        }
        let hit = self.tree.nearest_one::<SquaredEuclidean>(&p.to_array());
        self.params.get(hit.item as usize).copied()
    }
}

/// Parameters of the centres of the cells of a `r`-grid over one patch domain.
pub(crate) fn patch_cell_centres(domain: PatchDomain, r: usize) -> Vec<(f64, f64)> {
    let h = 1.0 / r as f64;
    let mut out = Vec::new();
    match domain {
        PatchDomain::Square => {
            for i in 0..r {
                for j in 0..r {
                    out.push(((i as f64 + 0.5) * h, (j as f64 + 0.5) * h));
                }
            }
        }
        PatchDomain::Triangle => {
            for i in 0..r {
                for j in 0..r - i {
                    let (u, v) = (i as f64, j as f64);
                    out.push(((u + 1.0 / 3.0) * h, (v + 1.0 / 3.0) * h));
                    if i + j + 1 < r {
                        out.push(((u + 2.0 / 3.0) * h, (v + 2.0 / 3.0) * h));
                    }
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cell_centres_lie_inside_and_count_r_squared() {
        for r in 1..6 {
            let tri = patch_cell_centres(PatchDomain::Triangle, r);
            assert_eq!(tri.len(), r * r);
            assert!(tri.iter().all(|&(u, v)| u > 0.0 && v > 0.0 && u + v < 1.0));
            let sq = patch_cell_centres(PatchDomain::Square, r);
            assert_eq!(sq.len(), r * r);
        }
    }
}
