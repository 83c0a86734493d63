//! Eigen-decomposition of symmetric 3×3 matrices (cyclic Jacobi), for principal directions of
//! point clouds and neighbourhoods.

use crate::geom::{Point3, Vec3};

/// The principal frame of a set of points: centroid, eigenvalues of the scatter matrix
/// (ascending) and their unit axes (the first is the normal of a best-fit plane).
pub struct Frame {
    /// The mean of the points.
    pub centroid: Point3,
    /// Eigenvalues of the scatter matrix Σ (p − c)(p − c)ᵀ, ascending.
    pub values: [f64; 3],
    /// Their unit eigenvectors (zero where the decomposition gave none).
    pub axes: [Vec3; 3],
}

/// Principal frame of `points` (the centroid is the origin for none).
pub fn principal_frame(points: impl Iterator<Item = Point3> + Clone) -> Frame {
    let (sum, n) = points
        .clone()
        .fold((Vec3::ZERO, 0usize), |(s, n), p| (s + p, n + 1));
    let centroid = sum / n.max(1) as f64;
    let mut m = [[0.0; 3]; 3];
    for p in points {
        let d = (p - centroid).to_array();
        for (i, row) in m.iter_mut().enumerate() {
            for (j, cell) in row.iter_mut().enumerate() {
                *cell += d[i] * d[j];
            }
        }
    }
    let (values, axes) = symmetric_eigen(m);
    Frame {
        centroid,
        values,
        axes,
    }
}

/// Eigenvalues (ascending) and unit eigenvectors of the symmetric matrix `m` (row-major).
pub fn symmetric_eigen(m: [[f64; 3]; 3]) -> ([f64; 3], [Vec3; 3]) {
    let mut a = m;
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for _ in 0..32 {
        let off = a[0][1].abs() + a[0][2].abs() + a[1][2].abs();
        let scale = a[0][0].abs() + a[1][1].abs() + a[2][2].abs();
        if off <= 1e-15 * scale || off == 0.0 {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            if a[p][q] == 0.0 {
                continue;
            }
            let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let t = if theta == 0.0 { 1.0 } else { t };
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            rotate(&mut a, &mut v, p, q, c, s);
        }
    }
    let mut order = [0usize, 1, 2];
    order.sort_by(|&i, &j| a[i][i].total_cmp(&a[j][j]));
    let values = order.map(|i| a[i][i]);
    let vectors = order.map(|i| Vec3::new(v[0][i], v[1][i], v[2][i]).normalize_or_zero());
    (values, vectors)
}

/// Applies the Jacobi rotation in the (p, q) plane: a ← Jᵀ a J, v ← v J.
fn rotate(a: &mut [[f64; 3]; 3], v: &mut [[f64; 3]; 3], p: usize, q: usize, c: f64, s: f64) {
    for row in a.iter_mut() {
        let (akp, akq) = (row[p], row[q]);
        row[p] = c * akp - s * akq;
        row[q] = s * akp + c * akq;
    }
    let (rp, rq) = (a[p], a[q]);
    a[p] = std::array::from_fn(|k| c * rp[k] - s * rq[k]);
    a[q] = std::array::from_fn(|k| s * rp[k] + c * rq[k]);
    for row in v.iter_mut() {
        let (vp, vq) = (row[p], row[q]);
        row[p] = c * vp - s * vq;
        row[q] = s * vp + c * vq;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn diagonalises_a_rotated_matrix() {
        // Eigenvalues 1, 2, 5 with known eigenvectors.
        let e = [
            Vec3::new(1.0, 1.0, 0.0).normalize(),
            Vec3::new(-1.0, 1.0, 1.0).normalize(),
            Vec3::new(1.0, -1.0, 2.0).normalize(),
        ];
        let l = [1.0, 2.0, 5.0];
        let mut m = [[0.0; 3]; 3];
        for k in 0..3 {
            for i in 0..3 {
                for j in 0..3 {
                    m[i][j] += l[k] * e[k][i] * e[k][j];
                }
            }
        }
        let (values, vectors) = symmetric_eigen(m);
        for k in 0..3 {
            assert!((values[k] - l[k]).abs() < 1e-12);
            assert!((vectors[k].dot(e[k]).abs() - 1.0).abs() < 1e-12);
        }
    }
}
