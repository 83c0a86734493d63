//! The surface as a linear map of the control points at frozen foot parameters:
//! S(t_i) = Σ_j B_j(t_i) P_j with the limit stencils cached, and conjugate gradients on the
//! least-squares problem min Σ_i ‖p_i − S(t_i)‖² over control-point moves, with a fairness term
//! on the control net that holds the control points few data points pull on.

use crate::geom::{median, Point3, Vec3};
use crate::mesh::PolyMesh;
use crate::subdiv::{LimitSurface, SurfaceParam};

/// The umbrella fairness of a control net, E = w Σ_j ‖P_j − mean of P_j's neighbours‖²: zero on
/// an evenly spaced flat net, small on a smooth one, large at a spike. Added to the fit's
/// least-squares problem with a weight `w` that is a small fraction of a typical control
/// point's data support, it barely moves a control point that many data points hold, and holds
/// one that few or none do — without it such points take the huge steps of an ill-conditioned
/// problem and the surface grows sheets and spikes away from the data.
pub(crate) struct Fairness {
    starts: Vec<usize>,
    neighbours: Vec<u32>,
}

impl Fairness {
    /// The neighbours (edge-connected vertices) of every control point of `control`, with its
    /// crease edges `creases` (vertex pairs) taken as the subdivision rules take them: a
    /// vertex on a crease line (two crease edges) is smoothed along the line only, and a
    /// corner (three or more) not at all.
    ///
    /// Why: the umbrella of a vertex on a crease averages the two faces that meet there, so
    /// its mean lies off the surface, inside the fold; on fandisk (Catmull–Clark with
    /// creases, E_max 0.05 %) that pull dragged the crease vertices of a thin wall's rim
    /// down, and the control points of the flat top beside them rose to make up for it: a
    /// bump 1 % of the diagonal above the top face after one move.
    pub(crate) fn of(control: &PolyMesh, creases: &[[u32; 2]]) -> Fairness {
        let n = control.num_vertices();
        let mut pairs: Vec<(u32, u32)> = Vec::new();
        for f in control.faces() {
            for k in 0..f.len() {
                let (a, b) = (f[k], f[(k + 1) % f.len()]);
                pairs.push((a, b));
                pairs.push((b, a));
            }
        }
        let mut along: Vec<(u32, u32)> = creases
            .iter()
            .filter(|[a, b]| (*a as usize) < n && (*b as usize) < n && a != b)
            .flat_map(|&[a, b]| [(a, b), (b, a)])
            .collect();
        along.sort_unstable();
        along.dedup();
        let mut crease_degree = vec![0usize; n];
        for &(a, _) in &along {
            crease_degree[a as usize] += 1;
        }
        pairs.retain(|&(a, _)| crease_degree[a as usize] < 2);
        pairs.extend(
            along
                .into_iter()
                .filter(|&(a, _)| crease_degree[a as usize] == 2),
        );
        pairs.sort_unstable();
        pairs.dedup();
        let mut starts = vec![0usize; n + 1];
        for &(a, _) in &pairs {
            starts[a as usize + 1] += 1;
        }
        for j in 0..n {
            starts[j + 1] += starts[j];
        }
        Fairness {
            starts,
            neighbours: pairs.into_iter().map(|(_, b)| b).collect(),
        }
    }

    fn ring(&self, j: usize) -> &[u32] {
        self.starts
            .get(j..j + 2)
            .map_or(&[][..], |s| &self.neighbours[s[0]..s[1]])
    }

    /// (U x)_j = x_j − mean of x over j's neighbours (0 for a point without neighbours).
    fn umbrella(&self, x: &[Vec3]) -> Vec<Vec3> {
        (0..x.len())
            .map(|j| {
                let ring = self.ring(j);
                if ring.is_empty() {
                    return Vec3::ZERO;
                }
                let mean: Vec3 =
                    ring.iter().map(|&k| x[k as usize]).sum::<Vec3>() / ring.len() as f64;
                x[j] - mean
            })
            .collect()
    }

    /// out += Uᵀ W U x, W the diagonal of per-point weights `w` times `scale`.
    fn add_normal(&self, x: &[Vec3], w: &[f64], scale: f64, out: &mut [Vec3]) {
        let u = self.umbrella(x);
        for (j, uj) in u.iter().enumerate() {
            let ring = self.ring(j);
            let wj = w.get(j).copied().unwrap_or(0.0) * scale;
            if ring.is_empty() || wj == 0.0 {
                continue;
            }
            out[j] += *uj * wj;
            let share = *uj * (wj / ring.len() as f64);
            for &k in ring {
                out[k as usize] -= share;
            }
        }
    }
}

/// How each data point's residual counts in [`Stencils::cg`]: the foot point's normal, the
/// weight of the tangential part, and the point's own weight (1 where `weights` has none).
#[derive(Clone, Copy)]
pub(crate) struct PointFrame<'a> {
    pub(crate) normals: &'a [Vec3],
    pub(crate) tangent_weight: f64,
    pub(crate) weights: &'a [f64],
}

impl PointFrame<'_> {
    fn weight(&self, i: usize) -> f64 {
        self.weights.get(i).copied().unwrap_or(1.0)
    }
}

/// Limit stencils of a set of parameters, in compressed rows (one row per data point).
pub(crate) struct Stencils {
    starts: Vec<usize>,
    entries: Vec<(u32, f64)>,
    columns: usize,
}

impl Stencils {
    /// Stencils of `params` on `surface`; entries whose control index is out of range are
    /// dropped (a broken stencil must not panic the fit).
    pub(crate) fn build<S: LimitSurface + ?Sized>(
        surface: &S,
        params: impl Iterator<Item = SurfaceParam>,
    ) -> Stencils {
        let columns = surface.control_points().len();
        let rows = params.size_hint().0;
        let mut starts = Vec::with_capacity(rows + 1);
        starts.push(0);
        // A regular patch has 12 (Loop) or 16 (Catmull–Clark) weights: reserving for that
        // avoids copying megabytes while the rows grow.
        let mut entries = Vec::with_capacity(rows * 16);
        let mut row = Vec::new();
        for at in params {
            row.clear();
            surface.stencil(at, &mut row);
            entries.extend(
                row.iter()
                    .filter(|&&(j, w)| (j as usize) < columns && w.is_finite()),
            );
            starts.push(entries.len());
        }
        Stencils {
            starts,
            entries,
            columns,
        }
    }

    /// Which control points the rows reach weakly: support Σ_i B_ij² below `share` of the
    /// median support.
    pub(crate) fn weakly_supported(&self, share: f64) -> Vec<bool> {
        let mut support = vec![0.0; self.columns];
        for &(j, w) in &self.entries {
            support[j as usize] += w * w;
        }
        let typical = median(&support);
        support.iter().map(|&s| s < share * typical).collect()
    }

    fn row(&self, i: usize) -> &[(u32, f64)] {
        &self.entries[self.starts[i]..self.starts[i + 1]]
    }

    fn rows(&self) -> usize {
        self.starts.len() - 1
    }

    /// out_j = Σ_i B_ij r_i.
    fn apply_transposed(&self, r: &[Vec3], out: &mut [Vec3]) {
        out.fill(Vec3::ZERO);
        for (i, ri) in r.iter().enumerate().take(self.rows()) {
            for &(j, w) in self.row(i) {
                out[j as usize] += *ri * w;
            }
        }
    }

    /// out = Bᵀ M B x in one pass over the rows (each row's value is used right away, which
    /// halves the memory traffic of applying B and Bᵀ in turn); `metric(i, v)` is M_i v.
    fn apply_normal(&self, x: &[Vec3], metric: impl Fn(usize, Vec3) -> Vec3, out: &mut [Vec3]) {
        out.fill(Vec3::ZERO);
        for i in 0..self.rows() {
            let row = self.row(i);
            let t = metric(i, row.iter().map(|&(j, w)| x[j as usize] * w).sum());
            for &(j, w) in row {
                out[j as usize] += t * w;
            }
        }
    }

    /// `steps` steps of Jacobi-preconditioned CG on the frozen-parameter least-squares problem
    /// min Σ_i ω_i r_iᵀ M_i r_i, r_i = e_i − Σ_j B_ij Δ_j, with M_i = n_i n_iᵀ + w (I − n_i n_iᵀ):
    /// full weight on the distance along the normal n_i, weight `w` = `tangent_weight` on the
    /// tangential slip that frozen parameters create as the surface moves (w = 1 is the plain
    /// point-to-point problem; smaller w converges faster, as in squared-distance minimisation),
    /// and ω_i the point's weight in `frame` (1 unless the fit pulls its worst points in).
    /// With `fair = Some((fairness, points, λ))` the problem gains the umbrella fairness of the
    /// control net at `points + Δ`, control point j's umbrella weighted λ_j times the median
    /// data support of a control point (Σ_i B_ij² over the data). Returns the control-point
    /// moves Δ.
    pub(crate) fn cg(
        &self,
        e: &[Vec3],
        frame: PointFrame,
        steps: usize,
        fair: Option<(&Fairness, &[Point3], &[f64])>,
    ) -> Vec<Vec3> {
        let n = self.columns;
        let metric = |i: usize, v: Vec3| {
            let nrm = frame.normals.get(i).copied().unwrap_or_default();
            let along = nrm * nrm.dot(v);
            (along + (v - along) * frame.tangent_weight) * frame.weight(i)
        };
        let mut support = vec![0.0; n];
        let mut diag = vec![0.0; n];
        for i in 0..self.rows() {
            let weight = frame.weight(i);
            for &(j, w) in self.row(i) {
                support[j as usize] += w * w;
                diag[j as usize] += w * w * weight;
            }
        }
        let typical = median(&support);
        // A control point that the data barely reaches (support below WEAK_SUPPORT of the
        // median) and no fairness holds is all but free in the least-squares problem, and one
        // CG solve can throw it anywhere; a ridge on its move keeps it where it is unless the
        // data pulls it. (Where fairness holds it, the ridge would only slow the fairness.)
        let held = |j: usize| fair.is_some_and(|(_, _, lambda)| lambda.get(j) > Some(&0.0));
        let ridge: Vec<f64> = diag
            .iter()
            .enumerate()
            .map(|(j, &d)| {
                if d < WEAK_SUPPORT * typical && !held(j) {
                    WEAK_SUPPORT * typical
                } else {
                    0.0
                }
            })
            .collect();
        for (d, r) in diag.iter_mut().zip(&ridge) {
            *d += r;
        }
        let fair = fair.map(|(f, points, lambda)| (f, points, lambda, typical));
        if let Some((_, _, lambda, scale)) = fair {
            for (d, l) in diag.iter_mut().zip(lambda) {
                *d += l * scale;
            }
        }
        let inv: Vec<f64> = diag
            .iter()
            .map(|&d| if d > 1e-300 { 1.0 / d } else { 0.0 })
            .collect();
        let precondition =
            |r: &[Vec3]| -> Vec<Vec3> { r.iter().zip(&inv).map(|(v, m)| *v * *m).collect() };
        let dot = |a: &[Vec3], b: &[Vec3]| -> f64 { a.iter().zip(b).map(|(x, y)| x.dot(*y)).sum() };
        let mut x = vec![Vec3::ZERO; n];
        let mut r = vec![Vec3::ZERO; n];
        let me: Vec<Vec3> = e.iter().enumerate().map(|(i, &v)| metric(i, v)).collect();
        self.apply_transposed(&me, &mut r);
        if let Some((f, points, lambda, scale)) = fair {
            // The right-hand side's fairness part: −Uᵀ W U P.
            let p: Vec<Vec3> = points.to_vec();
            let mut up = vec![Vec3::ZERO; n];
            f.add_normal(&p, lambda, scale, &mut up);
            for (rk, uk) in r.iter_mut().zip(&up) {
                *rk -= *uk;
            }
        }
        let mut z = precondition(&r);
        let mut p = z.clone();
        let mut rz = dot(&r, &z);
        let mut ap = vec![Vec3::ZERO; n];
        for _ in 0..steps {
            self.apply_normal(&p, metric, &mut ap);
            for ((a, q), r) in ap.iter_mut().zip(&p).zip(&ridge) {
                *a += *q * *r;
            }
            if let Some((f, _, lambda, scale)) = fair {
                f.add_normal(&p, lambda, scale, &mut ap);
            }
            let pap = dot(&p, &ap);
            let alpha = rz / pap;
            if !(pap > 0.0 && alpha.is_finite()) {
                break;
            }
            for k in 0..n {
                x[k] += p[k] * alpha;
                r[k] -= ap[k] * alpha;
            }
            z = precondition(&r);
            let rz_next = dot(&r, &z);
            let beta = rz_next / rz;
            if !beta.is_finite() {
                break;
            }
            rz = rz_next;
            for k in 0..n {
                p[k] = z[k] + p[k] * beta;
            }
        }
        x
    }
}

/// Support (Σ_i B_ij² over the data) below this share of the median is weak: see
/// [`Stencils::cg`].
const WEAK_SUPPORT: f64 = 0.01;
