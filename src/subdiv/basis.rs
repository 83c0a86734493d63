//! Closed-form bases of regular patches: the quartic three-direction box spline (Loop) and the
//! uniform bicubic B-spline (Catmull–Clark), with first and second derivatives.

/// Basis weights at one parameter: value, ∂u, ∂v, ∂uu, ∂uv, ∂vv for each control point.
pub(crate) type Weights<const N: usize> = [[f64; N]; 6];

/// Lattice positions of the 12 control points of a regular Loop patch whose corners are at
/// (0,0), (1,0), (0,1); lattice neighbours are ±(1,0), ±(0,1), ±(1,−1).
pub(crate) const LOOP_LATTICE: [(i32, i32); 12] = [
    (0, -1),
    (1, -1),
    (-1, 0),
    (0, 0),
    (1, 0),
    (2, -1),
    (-1, 1),
    (0, 1),
    (1, 1),
    (2, 0),
    (-1, 2),
    (0, 2),
];

/// Exponents (a, b) of the monomials u^a v^b used by [`LOOP_BOX`].
const MONOMIALS: [(i32, i32); 15] = [
    (0, 0),
    (0, 1),
    (0, 2),
    (0, 3),
    (0, 4),
    (1, 0),
    (1, 1),
    (1, 2),
    (1, 3),
    (2, 0),
    (2, 1),
    (2, 2),
    (3, 0),
    (3, 1),
    (4, 0),
];

/// Twelve times the monomial coefficients of the box-spline basis function of each point of
/// [`LOOP_LATTICE`]. Derived by `tests/data/subdiv/derive_loop_basis.py` (fitting quartics to
/// exact limit points of a regular lattice, residual < 1e-14) and checked against refinement
/// in `tests/subdiv_loop.rs`.
#[rustfmt::skip]
const LOOP_BOX: [[f64; 15]; 12] = [
    [1.0, -4.0, 6.0, -4.0, 1.0, -2.0, 6.0, -6.0, 2.0, 0.0, 0.0, 0.0, 2.0, -2.0, -1.0],
    [1.0, -2.0, 0.0, 2.0, -1.0, 2.0, -6.0, 6.0, -2.0, 0.0, 0.0, 0.0, -4.0, 4.0, 2.0],
    [1.0, -2.0, 0.0, 2.0, -1.0, -4.0, 6.0, 0.0, -2.0, 6.0, -6.0, 0.0, -4.0, 2.0, 1.0],
    [6.0, 0.0, -12.0, 8.0, -1.0, 0.0, -12.0, 12.0, -2.0, -12.0, 12.0, 0.0, 8.0, -2.0, -1.0],
    [1.0, 2.0, 0.0, -4.0, 2.0, 4.0, 6.0, -12.0, 4.0, 6.0, -6.0, 0.0, -4.0, -2.0, -1.0],
    [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 2.0, -2.0, -1.0],
    [1.0, 2.0, 0.0, -4.0, 2.0, -2.0, -6.0, 0.0, 4.0, 0.0, 6.0, 0.0, 2.0, -2.0, -1.0],
    [1.0, 4.0, 6.0, -4.0, -1.0, 2.0, 6.0, -6.0, -2.0, 0.0, -12.0, 0.0, -4.0, 4.0, 2.0],
    [0.0, 0.0, 0.0, 2.0, -1.0, 0.0, 0.0, 6.0, -2.0, 0.0, 6.0, 0.0, 2.0, -2.0, -1.0],
    [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 2.0, 1.0],
    [0.0, 0.0, 0.0, 2.0, -1.0, 0.0, 0.0, 0.0, -2.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
];

/// x^k and its first two derivatives, for k = 0..=4.
fn powers(x: f64) -> [[f64; 5]; 3] {
    let p = [1.0, x, x * x, x * x * x, x * x * x * x];
    let mut d = [[0.0; 5]; 3];
    for k in 0..5 {
        d[0][k] = p[k];
        if k >= 1 {
            d[1][k] = k as f64 * p[k - 1];
        }
        if k >= 2 {
            d[2][k] = (k * (k - 1)) as f64 * p[k - 2];
        }
    }
    d
}

/// Box-spline weights of the 12 points of [`LOOP_LATTICE`] at (u, v).
pub(crate) fn loop_box(u: f64, v: f64) -> Weights<12> {
    let (pu, pv) = (powers(u), powers(v));
    // (du order, dv order) of value, ∂u, ∂v, ∂uu, ∂uv, ∂vv.
    const ORDERS: [(usize, usize); 6] = [(0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2)];
    let mut mono = [[0.0; 15]; 6];
    for (d, &(ou, ov)) in ORDERS.iter().enumerate() {
        for (m, &(a, b)) in MONOMIALS.iter().enumerate() {
            mono[d][m] = pu[ou][a as usize] * pv[ov][b as usize];
        }
    }
    let mut w = [[0.0; 12]; 6];
    for d in 0..6 {
        for (i, coeffs) in LOOP_BOX.iter().enumerate() {
            let s: f64 = coeffs.iter().zip(&mono[d]).map(|(c, m)| c * m).sum();
            w[d][i] = s / 12.0;
        }
    }
    w
}

/// Uniform cubic B-spline basis on [0, 1] (value, first, second derivative).
fn cubic(t: f64) -> [[f64; 4]; 3] {
    let s = 1.0 - t;
    [
        [
            s * s * s / 6.0,
            (3.0 * t * t * t - 6.0 * t * t + 4.0) / 6.0,
            (-3.0 * t * t * t + 3.0 * t * t + 3.0 * t + 1.0) / 6.0,
            t * t * t / 6.0,
        ],
        [
            -s * s / 2.0,
            (3.0 * t * t - 4.0 * t) / 2.0,
            (-3.0 * t * t + 2.0 * t + 1.0) / 2.0,
            t * t / 2.0,
        ],
        [s, 3.0 * t - 2.0, -3.0 * t + 1.0, t],
    ]
}

/// Lattice positions of the 16 control points of a regular Catmull–Clark patch whose corners
/// are at (0,0), (1,0), (1,1), (0,1): index `4 (j + 1) + (i + 1)` holds point (i, j).
pub(crate) fn bicubic_lattice() -> [(i32, i32); 16] {
    let mut out = [(0, 0); 16];
    for j in -1..3 {
        for i in -1..3 {
            out[(4 * (j + 1) + (i + 1)) as usize] = (i, j);
        }
    }
    out
}

/// Bicubic B-spline weights of the 16 points of [`bicubic_lattice`] at (u, v).
pub(crate) fn bicubic(u: f64, v: f64) -> Weights<16> {
    let (bu, bv) = (cubic(u), cubic(v));
    const ORDERS: [(usize, usize); 6] = [(0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2)];
    let mut w = [[0.0; 16]; 6];
    for (d, &(ou, ov)) in ORDERS.iter().enumerate() {
        for j in 0..4 {
            for i in 0..4 {
                w[d][4 * j + i] = bu[ou][i] * bv[ov][j];
            }
        }
    }
    w
}

/// Uniform quadratic B-spline basis on [0, 1] (value, first, second derivative).
fn quadratic(t: f64) -> [[f64; 3]; 3] {
    let s = 1.0 - t;
    [
        [
            s * s / 2.0,
            (-2.0 * t * t + 2.0 * t + 1.0) / 2.0,
            t * t / 2.0,
        ],
        [-s, 1.0 - 2.0 * t, t],
        [1.0, -2.0, 1.0],
    ]
}

/// Biquadratic B-spline weights of the 3 × 3 points (i, j) ∈ {-1, 0, 1}², index
/// `3 (j + 1) + (i + 1)`, at (u, v): the regular Doo–Sabin patch of the middle point, whose
/// corners are the centroids of its four faces.
pub(crate) fn biquadratic(u: f64, v: f64) -> Weights<9> {
    let (bu, bv) = (quadratic(u), quadratic(v));
    const ORDERS: [(usize, usize); 6] = [(0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2)];
    let mut w = [[0.0; 9]; 6];
    for (d, &(ou, ov)) in ORDERS.iter().enumerate() {
        for j in 0..3 {
            for i in 0..3 {
                w[d][3 * j + i] = bu[ou][i] * bv[ov][j];
            }
        }
    }
    w
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bases_partition_unity() {
        for &(u, v) in &[(0.0, 0.0), (0.2, 0.3), (0.5, 0.5), (1.0, 0.0)] {
            let w = loop_box(u, v);
            assert!((w[0].iter().sum::<f64>() - 1.0).abs() < 1e-14);
            for wd in w.iter().take(6).skip(1) {
                assert!(wd.iter().sum::<f64>().abs() < 1e-13);
            }
            let w = bicubic(u, v);
            assert!((w[0].iter().sum::<f64>() - 1.0).abs() < 1e-14);
        }
    }

    #[test]
    fn loop_box_reproduces_linear_functions() {
        let (u, v) = (0.31, 0.27);
        let w = loop_box(u, v);
        let x: f64 = LOOP_LATTICE
            .iter()
            .zip(&w[0])
            .map(|(p, w)| p.0 as f64 * w)
            .sum();
        let y: f64 = LOOP_LATTICE
            .iter()
            .zip(&w[0])
            .map(|(p, w)| p.1 as f64 * w)
            .sum();
        assert!((x - u).abs() < 1e-14 && (y - v).abs() < 1e-14);
    }
}
