//! The surface as a linear map of the control points at frozen foot parameters:
//! S(t_i) = Σ_j B_j(t_i) P_j with the limit stencils cached, and conjugate gradients on the
//! least-squares problem min Σ_i ‖p_i − S(t_i)‖² over control-point moves.

use crate::geom::Vec3;
use crate::subdiv::{LimitSurface, SurfaceParam};

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
    /// min Σ_i r_iᵀ M_i r_i, r_i = e_i − Σ_j B_ij Δ_j, with M_i = n_i n_iᵀ + w (I − n_i n_iᵀ):
    /// full weight on the distance along the normal n_i, weight `w` = `tangent_weight` on the
    /// tangential slip that frozen parameters create as the surface moves (w = 1 is the plain
    /// point-to-point problem; smaller w converges faster, as in squared-distance minimisation).
    /// Returns the control-point moves Δ; control points no data point depends on stay put.
    pub(crate) fn cg(
        &self,
        e: &[Vec3],
        normals: &[Vec3],
        tangent_weight: f64,
        steps: usize,
    ) -> Vec<Vec3> {
        let n = self.columns;
        let metric = |i: usize, v: Vec3| {
            let nrm = normals.get(i).copied().unwrap_or_default();
            let along = nrm * nrm.dot(v);
            along + (v - along) * tangent_weight
        };
        let mut diag = vec![0.0; n];
        for &(j, w) in &self.entries {
            diag[j as usize] += w * w;
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
        let mut z = precondition(&r);
        let mut p = z.clone();
        let mut rz = dot(&r, &z);
        let mut ap = vec![Vec3::ZERO; n];
        for _ in 0..steps {
            self.apply_normal(&p, metric, &mut ap);
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
