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
        let mut starts = vec![0];
        let mut entries = Vec::new();
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

    /// out_i = Σ_j B_ij x_j.
    fn apply(&self, x: &[Vec3], out: &mut [Vec3]) {
        for (i, o) in out.iter_mut().enumerate().take(self.rows()) {
            *o = self.row(i).iter().map(|&(j, w)| x[j as usize] * w).sum();
        }
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

    /// `steps` steps of Jacobi-preconditioned CG on BᵀB Δ = Bᵀ e (three right-hand sides, one
    /// per coordinate): the control-point moves that best reduce the error vectors `e` with the
    /// parameters frozen. Control points no data point depends on do not move.
    pub(crate) fn cg(&self, e: &[Vec3], steps: usize) -> Vec<Vec3> {
        let n = self.columns;
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
        let dot = |a: &[Vec3], b: &[Vec3]| -> Vec3 { a.iter().zip(b).map(|(x, y)| *x * *y).sum() };
        let mut x = vec![Vec3::ZERO; n];
        let mut r = vec![Vec3::ZERO; n];
        self.apply_transposed(e, &mut r);
        let mut z = precondition(&r);
        let mut p = z.clone();
        let mut rz = dot(&r, &z);
        let (mut bp, mut ap) = (vec![Vec3::ZERO; self.rows()], vec![Vec3::ZERO; n]);
        for _ in 0..steps {
            self.apply(&p, &mut bp);
            self.apply_transposed(&bp, &mut ap);
            let pap = dot(&p, &ap);
            let alpha = safe_div(rz, pap);
            if alpha == Vec3::ZERO {
                break;
            }
            for k in 0..n {
                x[k] += alpha * p[k];
                r[k] -= alpha * ap[k];
            }
            z = precondition(&r);
            let rz_next = dot(&r, &z);
            let beta = safe_div(rz_next, rz);
            rz = rz_next;
            for k in 0..n {
                p[k] = z[k] + beta * p[k];
            }
        }
        x
    }
}

/// Componentwise a / b, with 0 where b is 0 or the quotient is not finite.
fn safe_div(a: Vec3, b: Vec3) -> Vec3 {
    let f = |a: f64, b: f64| {
        let q = a / b;
        if b != 0.0 && q.is_finite() {
            q
        } else {
            0.0
        }
    };
    Vec3::new(f(a.x, b.x), f(a.y, b.y), f(a.z, b.z))
}
