//! Least-squares B-spline curve fitting with fixed knots and parameters.
//!
//! The normal equations AᵀA P = AᵀQ of a curve are banded (bandwidth p); a closed curve adds
//! p wrapped rows. Both fit a skyline (envelope) matrix, factored by Cholesky in O(n·p²) for
//! open curves and O(p·n²) worst case for the p wrapped rows of closed ones. No dense n × n.

use super::FitError;
use crate::geom::{Point3, Vec3};
use crate::spline::BSplineCurve;

/// Relative weight of the pull towards the template's control points. It only decides control
/// points that no data point constrains; elsewhere its effect is ~1e-12 relative.
const RIDGE: f64 = 1e-12;

/// The control points of `template` (its degree, knots, closedness and weights kept) that
/// minimise Σ |C(uᵢ) − qᵢ|² over the data `points` at parameters `params`.
pub fn least_squares_curve(
    template: &BSplineCurve,
    points: &[Point3],
    params: &[f64],
) -> Result<BSplineCurve, FitError> {
    if points.len() != params.len() {
        return Err(FitError::InvalidOption {
            name: "params",
            reason: format!("{} parameters for {} points", params.len(), points.len()),
        });
    }
    let n = template.control_points().len();
    let p = template.degree();
    let rows: Vec<(Vec<usize>, Vec<f64>)> = params
        .iter()
        .map(|&u| {
            let b = template.basis(u);
            let idx = (0..=p).map(|j| template.ctrl_index(b.first + j)).collect();
            (idx, b.values[..=p].to_vec())
        })
        .collect();
    let mut first: Vec<usize> = (0..n).collect();
    for (idx, _) in &rows {
        for &a in idx {
            for &b in idx {
                first[a] = first[a].min(b);
            }
        }
    }
    let mut m = Skyline::new(first);
    let mut rhs = vec![Vec3::ZERO; n];
    for ((idx, val), &q) in rows.iter().zip(points) {
        for (a, &ia) in idx.iter().enumerate() {
            rhs[ia] += val[a] * q;
            for (b, &ib) in idx.iter().enumerate() {
                if ib <= ia {
                    *m.at_mut(ia, ib) += val[a] * val[b];
                }
            }
        }
    }
    let scale = (0..n)
        .map(|i| m.at(i, i))
        .fold(0.0, f64::max)
        .max(f64::MIN_POSITIVE);
    for (i, &c) in template.control_points().iter().enumerate() {
        *m.at_mut(i, i) += RIDGE * scale;
        rhs[i] += RIDGE * scale * c;
    }
    m.factor()?;
    let ctrl = m.solve(rhs);
    let mut curve = template.clone();
    if ctrl.iter().any(|c| !c.is_finite()) {
        return Err(FitError::Singular { index: 0 });
    }
    curve.control_points_mut().copy_from_slice(&ctrl);
    Ok(curve)
}

/// A symmetric matrix stored by rows from each row's first non-zero column to the diagonal.
struct Skyline {
    first: Vec<usize>,
    start: Vec<usize>,
    vals: Vec<f64>,
}

impl Skyline {
    fn new(first: Vec<usize>) -> Skyline {
        let mut start = Vec::with_capacity(first.len() + 1);
        let mut len = 0;
        for (i, &f) in first.iter().enumerate() {
            start.push(len);
            len += i + 1 - f;
        }
        Skyline {
            first,
            start,
            vals: vec![0.0; len],
        }
    }

    fn at(&self, i: usize, j: usize) -> f64 {
        if j < self.first[i] {
            0.0
        } else {
            self.vals[self.start[i] + j - self.first[i]]
        }
    }

    /// Entry (i, j), j ≤ i, inside the envelope.
    fn at_mut(&mut self, i: usize, j: usize) -> &mut f64 {
        &mut self.vals[self.start[i] + j - self.first[i]]
    }

    /// In-place Cholesky L·Lᵀ; the envelope holds no fill-in outside itself.
    fn factor(&mut self) -> Result<(), FitError> {
        let n = self.first.len();
        for i in 0..n {
            let fi = self.first[i];
            for j in fi..=i {
                let k0 = fi.max(self.first[j]);
                let mut s = self.at(i, j);
                for k in k0..j {
                    s -= self.at(i, k) * self.at(j, k);
                }
                if j < i {
                    *self.at_mut(i, j) = s / self.at(j, j);
                } else if s.is_nan() || s <= 0.0 {
                    return Err(FitError::Singular { index: i });
                } else {
                    *self.at_mut(i, i) = s.sqrt();
                }
            }
        }
        Ok(())
    }

    /// Solves L·Lᵀ x = b after [`Skyline::factor`].
    fn solve(&self, mut b: Vec<Vec3>) -> Vec<Vec3> {
        let n = b.len();
        for i in 0..n {
            let (row, fi) = (self.off_diagonal(i), self.first[i]);
            let s: Vec3 = row.iter().zip(&b[fi..i]).map(|(l, x)| *l * *x).sum();
            b[i] = (b[i] - s) / self.at(i, i);
        }
        for i in (0..n).rev() {
            b[i] /= self.at(i, i);
            let (bi, fi) = (b[i], self.first[i]);
            for (l, x) in self.off_diagonal(i).iter().zip(&mut b[fi..i]) {
                *x -= *l * bi;
            }
        }
        b
    }

    /// Row i of the envelope left of the diagonal.
    fn off_diagonal(&self, i: usize) -> &[f64] {
        &self.vals[self.start[i]..self.start[i] + i - self.first[i]]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn skyline_solves_a_wrapped_band() {
        // Tridiagonal plus corner entries (a periodic second-difference matrix + 4·I).
        let n = 7;
        let mut first: Vec<usize> = (0..n).map(|i: usize| i.saturating_sub(1)).collect();
        first[n - 1] = 0;
        let mut m = Skyline::new(first);
        let dense = |i: usize, j: usize| {
            if i == j {
                6.0
            } else if (i + 1) % n == j || (j + 1) % n == i {
                -1.0
            } else {
                0.0
            }
        };
        for i in 0..n {
            for j in m.first[i]..=i {
                *m.at_mut(i, j) = dense(i, j);
            }
        }
        let x: Vec<Vec3> = (0..n).map(|i| Vec3::splat(i as f64 + 1.0)).collect();
        let b: Vec<Vec3> = (0..n)
            .map(|i| (0..n).map(|j| dense(i, j) * x[j]).sum())
            .collect();
        m.factor().unwrap();
        let y = m.solve(b);
        for (a, b) in x.iter().zip(&y) {
            assert!((*a - *b).length() < 1e-12);
        }
    }
}
