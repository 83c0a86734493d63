//! A piecewise-linear "limit surface": the control triangle mesh itself. Patch i is triangle i
//! with S(u, v) = (1 − u − v) P0 + u P1 + v P2; walking across an edge uses the lattice
//! unfolding that the Loop patches use, so the fitter's patch walking is exercised for real.

use geofit::fit::{ControlSurface, FitError};
use geofit::geom::{ClosestPoint, Nearest, NewtonOptions, Point3};
use geofit::mesh::PolyMesh;
use geofit::subdiv::adaptive::{split_triangles, SplitRule};
use geofit::subdiv::{newton_foot, LimitEval, LimitSurface, PatchDomain, Scheme, SurfaceParam};
use std::collections::HashMap;

/// The piecewise-linear surface of a triangle mesh.
pub struct Linear {
    points: Vec<Point3>,
    tris: Vec<[u32; 3]>,
    /// `across[t][k]`: the triangle across edge k (from corner k to corner k + 1) of t.
    across: Vec<[Option<u32>; 3]>,
}

impl LimitSurface for Linear {
    fn domain(&self) -> PatchDomain {
        PatchDomain::Triangle
    }
    fn num_patches(&self) -> usize {
        self.tris.len()
    }
    fn control_points(&self) -> &[Point3] {
        &self.points
    }
    fn set_control_points(&mut self, points: &[Point3]) {
        self.points.copy_from_slice(points);
    }
    fn eval(&self, at: SurfaceParam) -> LimitEval {
        let [a, b, c] = self.tris[at.patch as usize].map(|i| self.points[i as usize]);
        LimitEval {
            point: a + (b - a) * at.u + (c - a) * at.v,
            du: b - a,
            dv: c - a,
            ..LimitEval::default()
        }
    }
    fn stencil(&self, at: SurfaceParam, out: &mut Vec<(u32, f64)>) {
        self.corner_weights(at, out);
    }
    fn corner_weights(&self, at: SurfaceParam, out: &mut Vec<(u32, f64)>) {
        let t = self.tris[at.patch as usize];
        out.extend([(t[0], 1.0 - at.u - at.v), (t[1], at.u), (t[2], at.v)]);
    }
    fn relocate(&self, patch: u32, u: f64, v: f64) -> SurfaceParam {
        let (mut patch, mut w) = (patch, [1.0 - u - v, u, v]);
        for _ in 0..1000 {
            let (k, &wk) = w
                .iter()
                .enumerate()
                .min_by(|a, b| a.1.total_cmp(b.1))
                .expect("three weights");
            if wk >= 0.0 {
                break;
            }
            // Vertex k is beyond edge (k + 1, k + 2).
            let t = self.tris[patch as usize];
            let (b, c) = (t[(k + 1) % 3], t[(k + 2) % 3]);
            let Some(next) = self.across[patch as usize][(k + 1) % 3] else {
                let clamped = w.map(|x| x.max(0.0));
                let s: f64 = clamped.iter().sum();
                w = clamped.map(|x| x / s);
                break;
            };
            let g = self.tris[next as usize];
            let mut nw = [0.0; 3];
            for j in 0..3 {
                nw[j] = if g[j] == b {
                    w[(k + 1) % 3] + wk
                } else if g[j] == c {
                    w[(k + 2) % 3] + wk
                } else {
                    -wk
                };
            }
            (patch, w) = (next, nw);
        }
        SurfaceParam {
            patch,
            u: w[1],
            v: w[2],
        }
    }
}

/// Newton on the piecewise-linear surface, as on any limit surface.
impl ClosestPoint for Linear {
    type Param = SurfaceParam;
    fn closest_point_from(
        &self,
        p: Point3,
        start: SurfaceParam,
        options: &NewtonOptions,
    ) -> Nearest<SurfaceParam> {
        newton_foot(self, p, start, options)
    }
}

/// Reported as Loop: like Loop's, its patches are the control triangles.
impl ControlSurface for Linear {
    fn scheme(&self) -> Scheme {
        Scheme::Loop
    }
    fn control_polygons(&self) -> PolyMesh {
        PolyMesh::try_new(self.points.clone(), &self.tris).expect("valid by construction")
    }
    fn rebuild(&self, control: &PolyMesh) -> Result<Self, FitError> {
        Linear::try_new(control)
    }
    fn patch_face(&self, patch: u32) -> usize {
        patch as usize
    }
    fn refine_control(&self, control: &PolyMesh, marked: &[bool]) -> Result<PolyMesh, FitError> {
        Ok(split_triangles(control, marked, SplitRule::Midpoint, &[])?)
    }
}

impl Linear {
    /// The surface of a triangle mesh.
    pub fn try_new(control: &PolyMesh) -> Result<Self, FitError> {
        let tris = geofit::subdiv::adaptive::triangles_of(control)?;
        let mut owner: HashMap<(u32, u32), (u32, usize)> = HashMap::new();
        for (f, t) in tris.iter().enumerate() {
            for k in 0..3 {
                owner.insert((t[k], t[(k + 1) % 3]), (f as u32, k));
            }
        }
        let across = tris
            .iter()
            .map(|t| {
                let mut a = [None; 3];
                for k in 0..3 {
                    a[k] = owner.get(&(t[(k + 1) % 3], t[k])).map(|&(g, _)| g);
                }
                a
            })
            .collect();
        Ok(Linear {
            points: control.positions().to_vec(),
            tris,
            across,
        })
    }
}

/// Points of `surface` at `per_patch` random parameters in each patch (deterministic).
pub fn sample<S: LimitSurface>(surface: &S, per_patch: usize, rng: &mut super::Rng) -> Vec<Point3> {
    let mut out = Vec::new();
    for patch in 0..surface.num_patches() as u32 {
        for _ in 0..per_patch {
            let (mut u, mut v) = (rng.next_f64(), rng.next_f64());
            if surface.domain() == PatchDomain::Triangle && u + v > 1.0 {
                (u, v) = (1.0 - u, 1.0 - v);
            }
            out.push(surface.eval(SurfaceParam { patch, u, v }).point);
        }
    }
    out
}
