//! Closed-form bases of regular patches: the quartic three-direction box spline (Loop) and the
//! uniform bicubic B-spline (Catmull–Clark), and their power forms used for evaluation. The
//! basis-function forms are kept for tests that check the power forms against them.

use super::LimitEval;
use crate::geom::Vec3;

/// Basis weights at one parameter: value, ∂u, ∂v, ∂uu, ∂uv, ∂vv for each control point.
#[cfg(test)]
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

/// The power form Σ c_ab u^a v^b over a ≤ N − 1 and b ≤ N − 1 (`TRIANGLE`: a + b ≤ N − 1),
/// coefficients grouped by `a` as in [`PowerBasis::exps`], with first and second derivatives.
/// Missing coefficients count as zero.
#[inline(always)]
fn eval_power<const N: usize, const TRIANGLE: bool>(c: &[Vec3], u: f64, v: f64) -> LimitEval {
    // x^k, k x^(k−1) and k (k − 1) x^(k−2) for k < N.
    let powers = |x: f64| {
        let mut p = [1.0; N];
        for k in 1..N {
            p[k] = p[k - 1] * x;
        }
        let mut d = [0.0; N];
        let mut dd = [0.0; N];
        for k in 1..N {
            d[k] = k as f64 * p[k - 1];
        }
        for k in 2..N {
            dd[k] = (k * (k - 1)) as f64 * p[k - 2];
        }
        (p, d, dd)
    };
    let (pu, du, ddu) = powers(u);
    let (pv, dv, ddv) = powers(v);
    let mut e = LimitEval::default();
    let mut start = 0;
    for a in 0..N {
        let len = if TRIANGLE { N - a } else { N };
        let Some(row) = c.get(start..start + len) else {
            break;
        };
        start += len;
        let mut s0 = row[0];
        let mut s1 = Vec3::ZERO;
        let mut s2 = Vec3::ZERO;
        for b in 1..len {
            s0 += row[b] * pv[b];
            s1 += row[b] * dv[b];
        }
        for b in 2..len {
            s2 += row[b] * ddv[b];
        }
        if a == 0 {
            e.point += s0;
            e.dv += s1;
            e.dvv += s2;
            continue;
        }
        e.point += s0 * pu[a];
        e.dv += s1 * pu[a];
        e.dvv += s2 * pu[a];
        e.du += s0 * du[a];
        e.duv += s1 * du[a];
        if a >= 2 {
            e.duu += s0 * ddu[a];
        }
    }
    e
}

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
#[cfg(test)]
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
#[cfg(test)]
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
#[cfg(test)]
pub(crate) fn bicubic(u: f64, v: f64) -> Weights<16> {
    tensor_product(&cubic(u), &cubic(v))
}

/// Weights of a K × K tensor-product lattice, index `K j + i`, from the univariate bases in u
/// and v (value, first, second derivative each); N = K².
#[cfg(test)]
fn tensor_product<const K: usize, const N: usize>(
    bu: &[[f64; K]; 3],
    bv: &[[f64; K]; 3],
) -> Weights<N> {
    assert_eq!(N, K * K);
    const ORDERS: [(usize, usize); 6] = [(0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2)];
    let mut w = [[0.0; N]; 6];
    for (d, &(ou, ov)) in ORDERS.iter().enumerate() {
        for j in 0..K {
            for i in 0..K {
                w[d][K * j + i] = bu[ou][i] * bv[ov][j];
            }
        }
    }
    w
}

/// Uniform quadratic B-spline basis on [0, 1] (value, first, second derivative).
#[cfg(test)]
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
#[cfg(test)]
pub(crate) fn biquadratic(u: f64, v: f64) -> Weights<9> {
    tensor_product(&quadratic(u), &quadratic(v))
}

/// A scheme's regular-patch basis rewritten in powers u^a v^b: patches are evaluated from
/// per-patch power coefficients (computed once per control-point update), so one evaluation
/// with first and second derivatives is a few multiply-adds per monomial instead of expanding
/// every basis function.
#[derive(Clone)]
pub(crate) struct PowerBasis {
    /// Exponents (a, b) of each monomial, grouped by `a` (evaluation sums each group in `v`
    /// first, then combines the groups in `u`).
    pub exps: Vec<(usize, usize)>,
    /// Number of spline control points (12 box-spline, 16 bicubic, 9 biquadratic).
    pub points: usize,
    /// `exps.len() × points`, row-major: power coefficients from spline control points.
    pub to_power: Vec<f64>,
    /// The monomial set, for the unrolled evaluation.
    layout: Layout,
}

/// The monomial sets of the three schemes, in the order of [`PowerBasis::exps`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Layout {
    /// u^a v^b with a + b ≤ 4 (Loop's box spline).
    Triangle4,
    /// u^a v^b with a, b ≤ 3 (bicubic).
    Square3,
    /// u^a v^b with a, b ≤ 2 (biquadratic).
    Square2,
}

/// Power coefficients of the uniform cubic B-spline basis on [0, 1] (rows: basis functions).
const CUBIC_POWER: [[f64; 4]; 4] = [
    [1.0 / 6.0, -0.5, 0.5, -1.0 / 6.0],
    [4.0 / 6.0, 0.0, -1.0, 0.5],
    [1.0 / 6.0, 0.5, 0.5, -0.5],
    [0.0, 0.0, 0.0, 1.0 / 6.0],
];

/// Power coefficients of the uniform quadratic B-spline basis on [0, 1].
const QUADRATIC_POWER: [[f64; 3]; 3] = [[0.5, -1.0, 0.5], [0.5, 1.0, -1.0], [0.0, 0.0, 0.5]];

impl PowerBasis {
    /// The power form of the box spline (`triangle`) or of a tensor-product B-spline of the
    /// given degree (3: Catmull–Clark, 2: Doo–Sabin).
    pub fn new(triangle: bool, degree: usize) -> PowerBasis {
        if triangle {
            let exps: Vec<(usize, usize)> = MONOMIALS
                .iter()
                .map(|&(a, b)| (a as usize, b as usize))
                .collect();
            let mut to_power = vec![0.0; exps.len() * 12];
            for (i, coeffs) in LOOP_BOX.iter().enumerate() {
                for (m, c) in coeffs.iter().enumerate() {
                    to_power[m * 12 + i] = c / 12.0;
                }
            }
            return PowerBasis {
                exps,
                points: 12,
                to_power,
                layout: Layout::Triangle4,
            };
        }
        let n = degree + 1;
        let coeff = |i: usize, a: usize| {
            if degree == 3 {
                CUBIC_POWER[i][a]
            } else {
                QUADRATIC_POWER[i][a]
            }
        };
        let mut exps = Vec::with_capacity(n * n);
        let mut to_power = vec![0.0; n * n * n * n];
        for a in 0..n {
            for b in 0..n {
                let m = exps.len();
                exps.push((a, b));
                for j in 0..n {
                    for i in 0..n {
                        to_power[m * n * n + n * j + i] = coeff(i, a) * coeff(j, b);
                    }
                }
            }
        }
        PowerBasis {
            exps,
            points: n * n,
            to_power,
            layout: if degree == 3 {
                Layout::Square3
            } else {
                Layout::Square2
            },
        }
    }

    /// Number of monomials.
    pub fn len(&self) -> usize {
        self.exps.len()
    }

    /// Power coefficients of the patch whose spline control points are `cp`, appended to `out`.
    pub fn coefficients(&self, cp: &[Vec3], out: &mut Vec<Vec3>) {
        match cp.get(..self.points) {
            Some(cp) if cp.len() == self.points => rows_times_points(&self.to_power, cp, out),
            _ => out.extend(std::iter::repeat_n(Vec3::ZERO, self.len())),
        }
    }

    /// Limit point and derivatives at (u, v) from power coefficients.
    ///
    /// Factored as Σ_a u^a (Σ_b c_ab v^b): the inner sums and their first two v-derivatives
    /// take three multiply-adds per monomial, and each power of u then combines them into the
    /// six outputs, instead of six products per monomial (this is the innermost loop of the
    /// foot-point search). Each scheme's monomial set has its own fully unrolled copy, which
    /// skips the terms that are zero (the derivatives of the low powers).
    #[inline]
    pub fn eval(&self, coeffs: &[Vec3], u: f64, v: f64) -> LimitEval {
        match self.layout {
            Layout::Triangle4 => eval_power::<5, true>(coeffs, u, v),
            Layout::Square3 => eval_power::<4, false>(coeffs, u, v),
            Layout::Square2 => eval_power::<3, false>(coeffs, u, v),
        }
    }

    /// Values of the monomials at (u, v), into `out` (length [`PowerBasis::len`]).
    pub fn values(&self, u: f64, v: f64, out: &mut [f64]) {
        let (pu, pv) = (powers(u), powers(v));
        for (o, &(a, b)) in out.iter_mut().zip(&self.exps) {
            *o = pu[0][a] * pv[0][b];
        }
    }

    /// Weights of the spline control points for the position at (u, v), into `out`.
    pub fn point_weights(&self, u: f64, v: f64, out: &mut [f64]) {
        let mut vals = [0.0; 16];
        self.values(u, v, &mut vals);
        out[..self.points].fill(0.0);
        for (row, &m) in self.to_power.chunks_exact(self.points).zip(&vals) {
            for (o, &w) in out.iter_mut().zip(row) {
                *o += m * w;
            }
        }
    }
}

/// Appends `Σ_j m[r][j] pts[j]` for every row `r` of the row-major matrix `mat` (rows of
/// `pts.len()` weights) to `out`.
///
/// Each row's sum runs over j in order from zero, as `Iterator::sum` would (so the results are
/// those bits), but four rows at a time: one row's sum is a chain of dependent additions that
/// waits on each one's latency, and four independent chains keep the adder busy. This is the
/// patch-data refill after every move (every irregular patch's shortcut is such a product).
pub(crate) fn rows_times_points(mat: &[f64], pts: &[Vec3], out: &mut Vec<Vec3>) {
    let k = pts.len();
    if k == 0 {
        out.extend(std::iter::repeat_n(Vec3::ZERO, mat.len()));
        return;
    }
    let mut blocks = mat.chunks_exact(4 * k);
    for block in &mut blocks {
        let (r0, rest) = block.split_at(k);
        let (r1, rest) = rest.split_at(k);
        let (r2, r3) = rest.split_at(k);
        let mut acc = [Vec3::ZERO; 4];
        for (j, &p) in pts.iter().enumerate() {
            acc[0] += p * r0[j];
            acc[1] += p * r1[j];
            acc[2] += p * r2[j];
            acc[3] += p * r3[j];
        }
        out.extend_from_slice(&acc);
    }
    for row in blocks.remainder().chunks_exact(k) {
        out.push(row.iter().zip(pts).map(|(&w, &p)| p * w).sum());
    }
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

    #[test]
    fn power_forms_match_the_bases() {
        let pts: Vec<Vec3> = (0..16)
            .map(|i| Vec3::new(i as f64, (i * i) as f64 * 0.1, (i as f64).sin()))
            .collect();
        for &(u, v) in &[(0.0, 0.0), (0.2, 0.3), (0.5, 0.25), (0.9, 0.05)] {
            let cases: [(PowerBasis, Vec<[f64; 16]>); 3] = [
                (PowerBasis::new(true, 4), pad(&loop_box(u, v))),
                (PowerBasis::new(false, 3), pad(&bicubic(u, v))),
                (PowerBasis::new(false, 2), pad(&biquadratic(u, v))),
            ];
            for (basis, weights) in cases {
                let mut coeffs = Vec::new();
                basis.coefficients(&pts[..basis.points], &mut coeffs);
                let e = basis.eval(&coeffs, u, v);
                let got = [e.point, e.du, e.dv, e.duu, e.duv, e.dvv];
                for (d, w) in weights.iter().enumerate() {
                    let want: Vec3 = w.iter().zip(&pts).map(|(&w, &p)| p * w).sum();
                    assert!(
                        (got[d] - want).length() < 1e-12,
                        "{d}: {} vs {want}",
                        got[d]
                    );
                }
                let mut pw = [0.0; 16];
                basis.point_weights(u, v, &mut pw);
                for i in 0..basis.points {
                    assert!((pw[i] - weights[0][i]).abs() < 1e-14);
                }
            }
        }
    }

    fn pad<const N: usize>(w: &Weights<N>) -> Vec<[f64; 16]> {
        w.iter()
            .map(|row| {
                let mut out = [0.0; 16];
                out[..N].copy_from_slice(row);
                out
            })
            .collect()
    }
}
