//! Sampling a limit surface on a regular grid per patch: the one tessellation behind display,
//! export and the two-sided error measures.

use super::{LimitSurface, PatchDomain, SurfaceParam};
use crate::geom::{Point3, Vec3};

/// A sampled limit surface. Patches are not welded to each other: samples on a shared patch
/// edge appear once per patch.
#[derive(Clone, Debug, Default)]
pub struct Tessellation {
    /// Sample positions (non-finite samples are replaced by the origin).
    pub positions: Vec<Point3>,
    /// Unit normals at the samples (zero where the surface is degenerate).
    pub normals: Vec<Vec3>,
    /// Triangles over the samples, counter-clockwise like the control faces.
    pub triangles: Vec<[u32; 3]>,
    /// Patch and parameters of each sample.
    pub params: Vec<SurfaceParam>,
}

/// Appends the parameters [`tessellate`] samples on `patch` with `segments` intervals per
/// patch edge (at least 1), in its order: (i / n, j / n) for rows i and, within a row, j, with
/// i + j ≤ n on triangles.
pub fn grid_params(domain: PatchDomain, patch: u32, segments: usize, out: &mut Vec<SurfaceParam>) {
    let r = segments.max(1);
    let h = 1.0 / r as f64;
    for i in 0..=r {
        let row = match domain {
            PatchDomain::Square => r,
            PatchDomain::Triangle => r - i,
        };
        for j in 0..=row {
            out.push(SurfaceParam {
                patch,
                u: i as f64 * h,
                v: j as f64 * h,
            });
        }
    }
}

/// Samples every patch of `surface` with `segments` intervals per patch edge (at least 1):
/// an (n + 1)² grid on square patches, the (n + 1)(n + 2)/2 lattice on triangles.
pub fn tessellate<S: LimitSurface + ?Sized>(surface: &S, segments: usize) -> Tessellation {
    let r = segments.max(1);
    let mut t = Tessellation::default();
    let mut params = Vec::new();
    for patch in 0..surface.num_patches() as u32 {
        let base = t.positions.len() as u32;
        params.clear();
        grid_params(surface.domain(), patch, r, &mut params);
        for &at in &params {
            t.push(surface, at);
        }
        match surface.domain() {
            PatchDomain::Square => {
                let id = |i: usize, j: usize| base + (i * (r + 1) + j) as u32;
                for i in 0..r {
                    for j in 0..r {
                        t.triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                        t.triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
                    }
                }
            }
            PatchDomain::Triangle => {
                // Row i (of r + 1 − i samples) starts after the rows before it.
                let mut row_start = Vec::with_capacity(r + 1);
                let mut k = 0;
                for i in 0..=r {
                    row_start.push(k);
                    k += (r + 1 - i) as u32;
                }
                let id = |i: usize, j: usize| base + row_start[i] + j as u32;
                for i in 0..r {
                    for j in 0..r - i {
                        t.triangles.push([id(i, j), id(i + 1, j), id(i, j + 1)]);
                        if j + 1 < r - i {
                            t.triangles
                                .push([id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
                        }
                    }
                }
            }
        }
    }
    t
}

impl Tessellation {
    /// Appends the sample at `at`.
    fn push<S: LimitSurface + ?Sized>(&mut self, s: &S, at: SurfaceParam) {
        let e = s.eval(at);
        let finite = e.point.is_finite();
        self.positions
            .push(if finite { e.point } else { Point3::ZERO });
        self.normals.push(if finite {
            e.du.cross(e.dv).normalize_or_zero()
        } else {
            Vec3::ZERO
        });
        self.params.push(at);
    }
}
