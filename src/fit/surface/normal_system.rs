//! The sparse normal equations of a smoothed least-squares tensor-product B-spline fit
//! (SPEC §2): their band pattern, assembly from data points and per-patch energy blocks, and a
//! sparse Cholesky solve.
//!
//! Control point (i, j) couples with (i', j') when |i − i'| ≤ p and |j − j'| ≤ q, so the
//! matrix is a 2D grid graph with (2p + 1)(2q + 1)-point stencils. It is ordered by nested
//! dissection of that grid (separators of p rows or q columns, halves first, separator last),
//! which is what minimum-degree heuristics approximate on such graphs; knowing the grid, the
//! ordering costs nothing to compute and gives less fill than AMD (on bun000.ply at 28,362
//! control points: 7.05 M entries in the factor against 7.54 M, symbolic analysis 13 ms
//! against 31 ms). The symbolic factorisation and the factor's storage are kept for every solve
//! with the same knots.

use crate::geom::Point3;
use crate::spline::{BSplineSurface, KnotVector, MAX_DEGREE};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::perm::PermRef;
use faer::sparse::linalg::cholesky::{factorize_symbolic_cholesky, SymbolicCholesky};
use faer::sparse::linalg::cholesky::{LltRef, SymmetricOrdering};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{Conj, Mat, Par, Side};

use super::patches::PatchGrid;
use super::FitError;

/// Local basis functions of one patch, at most (MAX_DEGREE + 1)².
const MAX_LOCAL: usize = (MAX_DEGREE + 1) * (MAX_DEGREE + 1);

/// ∫ N_r^(k) N_s^(k) over one knot span, for k = 0..=3 and the p + 1 functions of the span.
pub(super) struct SpanGram {
    pub(super) degree: usize,
    pub(super) g: [[[f64; MAX_DEGREE + 1]; MAX_DEGREE + 1]; 4],
}

/// The Gram tables of span `span` of `kv`, exact by Gauss–Legendre quadrature (p + 1 nodes
/// integrate the degree-2p products exactly).
pub(super) fn span_gram(kv: &KnotVector, span: usize) -> SpanGram {
    let p = kv.degree();
    let k = kv.knots();
    let (a, b) = (k[span], k[span + 1]);
    let mut g = [[[0.0; MAX_DEGREE + 1]; MAX_DEGREE + 1]; 4];
    let (nodes, weights) = gauss_legendre(p + 1);
    let mut ders = [[0.0; MAX_DEGREE + 1]; 4];
    for (x, w) in nodes.iter().zip(&weights) {
        let t = 0.5 * (a + b) + 0.5 * (b - a) * x;
        let wt = 0.5 * (b - a) * w;
        kv.basis_ders(span, t, 3, &mut ders);
        for (order, gk) in g.iter_mut().enumerate() {
            for r in 0..=p {
                for s in 0..=p {
                    gk[r][s] += wt * ders[order][r] * ders[order][s];
                }
            }
        }
    }
    SpanGram { degree: p, g }
}

/// Calls `f(a, b, c, d, w2, w3)` for every pair of local basis products (a, b), (c, d) of one
/// cell, with the E2 and E3 weights of that pair.
pub(super) fn for_cell_pairs<F: FnMut(usize, usize, usize, usize, f64, f64)>(
    gu: &SpanGram,
    gv: &SpanGram,
    mut f: F,
) {
    let (u, v) = (&gu.g, &gv.g);
    for a in 0..=gu.degree {
        for b in 0..=gv.degree {
            for c in 0..=gu.degree {
                for d in 0..=gv.degree {
                    let w2 = u[2][a][c] * v[0][b][d]
                        + 2.0 * u[1][a][c] * v[1][b][d]
                        + u[0][a][c] * v[2][b][d];
                    let w3 = u[3][a][c] * v[0][b][d]
                        + 3.0 * u[2][a][c] * v[1][b][d]
                        + 3.0 * u[1][a][c] * v[2][b][d]
                        + u[0][a][c] * v[3][b][d];
                    f(a, b, c, d, w2, w3);
                }
            }
        }
    }
}

/// Gauss–Legendre nodes and weights on [−1, 1] with `n` points (exact for polynomials of
/// degree 2n − 1), by Newton's method on the Legendre polynomial.
fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut nodes = Vec::with_capacity(n);
    let mut weights = Vec::with_capacity(n);
    for i in 0..n {
        let mut x = libm::cos(std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5));
        let mut dp = 1.0;
        for _ in 0..100 {
            let (p, d) = legendre(n, x);
            dp = d;
            let dx = p / d;
            x -= dx;
            if dx.abs() < 1e-16 {
                break;
            }
        }
        let (_, d) = legendre(n, x);
        dp = if d != 0.0 { d } else { dp };
        nodes.push(x);
        weights.push(2.0 / ((1.0 - x * x) * dp * dp));
    }
    (nodes, weights)
}

/// P_n(x) and P_n'(x) by the three-term recurrence.
fn legendre(n: usize, x: f64) -> (f64, f64) {
    let (mut p0, mut p1) = (1.0, x);
    if n == 0 {
        return (1.0, 0.0);
    }
    for k in 2..=n {
        let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
        p0 = p1;
        p1 = p2;
    }
    let d = n as f64 * (x * p1 - p0) / (x * x - 1.0);
    (p1, d)
}

/// The stored band of one column c = i·nv + j of the upper triangle: rows (i', j') with
/// i − p ≤ i' ≤ i and |j − j'| ≤ q (j' ≤ j on row i' = i), in that order.
#[derive(Clone, Copy)]
struct ColumnBand {
    /// Offset of the column's first entry in the values.
    start: usize,
    /// First row index i' and column index j' of the band.
    i0: usize,
    j0: usize,
    /// Entries per band row (the last band row is cut at the diagonal).
    width: usize,
}

impl ColumnBand {
    /// Position of row r = (ri, rj), which must lie in the band.
    fn at(&self, ri: usize, rj: usize) -> usize {
        self.start + (ri - self.i0) * self.width + (rj - self.j0)
    }
}

/// The sparse normal matrix of one knot configuration: its upper triangle in compressed
/// columns, the numeric values, the symbolic Cholesky factorisation and the storage of the
/// numeric factor, reused by every solve.
pub(super) struct NormalSystem {
    shape: (usize, usize, usize, usize),
    col_ptr: Vec<usize>,
    symbolic: SymbolicSparseColMat<usize>,
    factor: SymbolicCholesky<usize>,
    values: Vec<f64>,
    factor_values: Vec<f64>,
}

impl NormalSystem {
    /// The pattern of an `nu × nv` control grid of degrees (p, q) (column c = i·nv + j keeps
    /// its rows r ≤ c, ordered by (i', j')) and its symbolic factorisation.
    pub(super) fn new(nu: usize, nv: usize, p: usize, q: usize) -> Result<NormalSystem, FitError> {
        let n = nu * nv;
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::new();
        col_ptr.push(0);
        for c in 0..n {
            let (i, j) = (c / nv, c % nv);
            for ii in i.saturating_sub(p)..=i {
                let j_end = if ii == i { j } else { (j + q).min(nv - 1) };
                for jj in j.saturating_sub(q)..=j_end {
                    row_idx.push(ii * nv + jj);
                }
            }
            col_ptr.push(row_idx.len());
        }
        let nnz = row_idx.len();
        let symbolic = SymbolicSparseColMat::new_checked(n, n, col_ptr.clone(), None, row_idx);
        let order = nested_dissection(nu, nv, p, q);
        let mut inverse = vec![0; n];
        for (k, &o) in order.iter().enumerate() {
            inverse[o] = k;
        }
        let perm = PermRef::new_checked(&order, &inverse, n);
        let factor = factorize_symbolic_cholesky(
            symbolic.as_ref(),
            Side::Upper,
            SymmetricOrdering::Custom(perm),
            Default::default(),
        )
        .map_err(|e| FitError::Solver {
            reason: format!("symbolic factorisation of {n} control points: {e:?}"),
        })?;
        Ok(NormalSystem {
            shape: (nu, nv, p, q),
            col_ptr,
            symbolic,
            factor_values: Vec::new(),
            factor,
            values: vec![0.0; nnz],
        })
    }

    /// The grid this system was built for: (nu, nv, p, q).
    pub(super) fn shape(&self) -> (usize, usize, usize, usize) {
        self.shape
    }

    /// Zeroes the matrix for a new assembly.
    pub(super) fn clear(&mut self) {
        self.values.fill(0.0);
    }

    /// The stored band of column `c`.
    fn band(&self, c: usize) -> ColumnBand {
        let (_, nv, p, q) = self.shape;
        let (i, j) = (c / nv, c % nv);
        let (i0, j0) = (i.saturating_sub(p), j.saturating_sub(q));
        ColumnBand {
            start: self.col_ptr[c],
            i0,
            j0,
            width: (j + q).min(nv - 1) - j0 + 1,
        }
    }

    /// Adds a symmetric block over the (p + 1)(q + 1) control points of the patch whose first
    /// control point is (fu, fv): `value(k, l)` for local indices l ≤ k (local index k is
    /// (k / (q + 1), k % (q + 1)), increasing with the global index).
    fn add_block<F: FnMut(usize, usize) -> f64>(&mut self, (fu, fv): (usize, usize), mut value: F) {
        let (_, nv, p, q) = self.shape;
        let m = (p + 1) * (q + 1);
        let mut rows = [(0usize, 0usize); MAX_LOCAL];
        for (k, r) in rows.iter_mut().enumerate().take(m) {
            *r = (fu + k / (q + 1), fv + k % (q + 1));
        }
        for k in 0..m {
            let (ci, cj) = rows[k];
            let band = self.band(ci * nv + cj);
            for (l, &(ri, rj)) in rows.iter().enumerate().take(k + 1) {
                self.values[band.at(ri, rj)] += value(k, l);
            }
        }
    }

    /// Adds the data points (point, (u, v)): their basis products to the matrix and their
    /// weighted coordinates to the right-hand side; returns how many there were.
    ///
    /// Points of one knot-span cell touch the same (p + 1)(q + 1) control points, so their
    /// products are summed in a small dense block per cell first and scattered into the sparse
    /// matrix once per cell: the per-point work is then plain multiply-adds on a contiguous
    /// block, without locating each entry in the sparse pattern.
    pub(super) fn add_points<'a, I>(
        &mut self,
        s: &BSplineSurface,
        samples: I,
        rhs: &mut Mat<f64>,
    ) -> usize
    where
        I: Iterator<Item = (&'a Point3, &'a [f64; 2])>,
    {
        let (nu, nv, p, q) = self.shape;
        let m = (p + 1) * (q + 1);
        let tri = m * (m + 1) / 2;
        let cells_v = nv - q;
        let mut block_of = vec![usize::MAX; (nu - p) * cells_v];
        let mut blocks: Vec<f64> = Vec::new();
        let mut firsts: Vec<(usize, usize)> = Vec::new();
        let mut count = 0;
        for (pt, t) in samples {
            count += 1;
            let b = s.basis(t[0], t[1]);
            let cell = b.first_u * cells_v + b.first_v;
            if block_of[cell] == usize::MAX {
                block_of[cell] = firsts.len();
                firsts.push((b.first_u, b.first_v));
                blocks.resize(blocks.len() + tri, 0.0);
            }
            let slot = block_of[cell];
            let mut w = [0.0; MAX_LOCAL];
            for r in 0..=p {
                for c in 0..=q {
                    w[r * (q + 1) + c] = b.bu[r] * b.bv[c];
                }
            }
            let block = &mut blocks[slot * tri..(slot + 1) * tri];
            let mut pos = 0;
            for k in 0..m {
                let wk = w[k];
                for (dst, wl) in block[pos..=pos + k].iter_mut().zip(&w[..=k]) {
                    *dst += wk * wl;
                }
                pos += k + 1;
                let c = (b.first_u + k / (q + 1)) * nv + b.first_v + k % (q + 1);
                rhs[(c, 0)] += wk * pt.x;
                rhs[(c, 1)] += wk * pt.y;
                rhs[(c, 2)] += wk * pt.z;
            }
        }
        for (slot, &first) in firsts.iter().enumerate() {
            let block = &blocks[slot * tri..(slot + 1) * tri];
            // Block entry (k, l), l ≤ k, is stored at k(k + 1)/2 + l.
            self.add_block(first, |k, l| block[k * (k + 1) / 2 + l]);
        }
        count
    }

    /// Adds the per-patch weighted E2 and E3 Gram blocks: patch i gets β2·`weights[i][0]` and
    /// β3·`weights[i][1]`.
    ///
    /// With U_k, V_k the span Gram tables of the k-th derivatives, the block entry of the pair
    /// (a, b), (c, d) is β2 (U2 V0 + 2 U1 V1 + U0 V2) + β3 (U3 V0 + 3 U2 V1 + 3 U1 V2 + U0 V3),
    /// evaluated as Σ_k U_k[a][c] W_k[b][d] with the four W_k combined once per patch.
    pub(super) fn add_energies(
        &mut self,
        s: &BSplineSurface,
        grid: &PatchGrid,
        weights: &[[f64; 2]],
        beta2: f64,
        beta3: f64,
    ) {
        if beta2 == 0.0 && beta3 == 0.0 {
            return;
        }
        let (_, _, p, q) = self.shape;
        let grams_v: Vec<SpanGram> = (0..grid.v.len())
            .map(|c| span_gram(s.knots_v(), grid.v.knot_index(c)))
            .collect();
        for cu in 0..grid.u.len() {
            let gu = span_gram(s.knots_u(), grid.u.knot_index(cu));
            let fu = grid.u.knot_index(cu) - p;
            for (cv, gv) in grams_v.iter().enumerate() {
                let fv = grid.v.knot_index(cv) - q;
                let [w2, w3] = weights[cu * grid.v.len() + cv];
                if w2 == 0.0 && w3 == 0.0 {
                    continue;
                }
                let w = combined_v_tables(gv, beta2 * w2, beta3 * w3);
                let u = &gu.g;
                self.add_block((fu, fv), |k, l| {
                    let (a, b, c, d) = (k / (q + 1), k % (q + 1), l / (q + 1), l % (q + 1));
                    u[0][a][c] * w[0][b][d]
                        + u[1][a][c] * w[1][b][d]
                        + u[2][a][c] * w[2][b][d]
                        + u[3][a][c] * w[3][b][d]
                });
            }
        }
    }

    /// Factorises numerically (reusing the symbolic factorisation and the factor's storage)
    /// and solves for the three coordinate columns.
    pub(super) fn solve(&mut self, mut rhs: Mat<f64>) -> Result<Vec<Point3>, FitError> {
        let par = Par::Seq;
        let out_of_memory = |what: &str| FitError::Solver {
            reason: format!("out of memory for the {what} of {} unknowns", rhs.nrows()),
        };
        self.factor_values.resize(self.factor.len_val(), 0.0);
        let mut mem = MemBuffer::try_new(
            self.factor
                .factorize_numeric_llt_scratch::<f64>(par, Default::default()),
        )
        .map_err(|_| out_of_memory("factorisation"))?;
        let mat = SparseColMatRef::new(self.symbolic.as_ref(), &self.values);
        let llt: LltRef<'_, usize, f64> = self
            .factor
            .factorize_numeric_llt(
                &mut self.factor_values,
                mat,
                Side::Upper,
                Default::default(),
                par,
                MemStack::new(&mut mem),
                Default::default(),
            )
            .map_err(|e| FitError::Solver {
                reason: format!(
                    "the normal matrix is not positive definite ({e:?}); too few points for \
                     the control points, or raise beta2"
                ),
            })?;
        let mut mem = MemBuffer::try_new(self.factor.solve_in_place_scratch::<f64>(3, par))
            .map_err(|_| out_of_memory("solve"))?;
        llt.solve_in_place_with_conj(Conj::No, rhs.as_mut(), par, MemStack::new(&mut mem));
        let out: Vec<Point3> = (0..rhs.nrows())
            .map(|i| Point3::new(rhs[(i, 0)], rhs[(i, 1)], rhs[(i, 2)]))
            .collect();
        if out.iter().any(|p| !p.is_finite()) {
            return Err(FitError::Solver {
                reason: "the solution is not finite; raise beta2".into(),
            });
        }
        Ok(out)
    }
}

impl NormalSystem {
    /// Row `c` of the assembled matrix times `x` (one control point per column).
    pub(super) fn row_times(&self, c: usize, x: &[Point3]) -> Point3 {
        let (nu, nv, p, q) = self.shape;
        let (ci, cj) = (c / nv, c % nv);
        let mut y = Point3::ZERO;
        for ri in ci.saturating_sub(p)..(ci + p + 1).min(nu) {
            for rj in cj.saturating_sub(q)..(cj + q + 1).min(nv) {
                let r = ri * nv + rj;
                // The upper triangle holds entry (c, r) in the later of the two columns.
                let (col, (i, j)) = if r <= c { (c, (ri, rj)) } else { (r, (ci, cj)) };
                y += self.values[self.band(col).at(i, j)] * x[r];
            }
        }
        y
    }

    /// The system of the control points in `rows × cols` of the grid alone (the others held
    /// fixed), its values copied from this one.
    pub(super) fn window(
        &self,
        rows: std::ops::Range<usize>,
        cols: std::ops::Range<usize>,
    ) -> Result<NormalSystem, FitError> {
        let (_, nv, p, q) = self.shape;
        let (wu, wv) = (rows.len(), cols.len());
        let mut sub = NormalSystem::new(wu, wv, p.min(wu - 1), q.min(wv - 1))?;
        for c in 0..wu * wv {
            let local = sub.band(c);
            let global = self.band((rows.start + c / wv) * nv + cols.start + c % wv);
            let (ci, cj) = (c / wv, c % wv);
            for ri in local.i0..=ci {
                let j_end = if ri == ci {
                    cj
                } else {
                    local.j0 + local.width - 1
                };
                for rj in local.j0..=j_end {
                    sub.values[local.at(ri, rj)] =
                        self.values[global.at(rows.start + ri, cols.start + rj)];
                }
            }
        }
        Ok(sub)
    }
}

/// W_0..W_3 of [`NormalSystem::add_energies`] for one v-span: β2 V2 + β3 V3,
/// 2 β2 V1 + 3 β3 V2, β2 V0 + 3 β3 V1 and β3 V0.
fn combined_v_tables(
    gv: &SpanGram,
    b2: f64,
    b3: f64,
) -> [[[f64; MAX_DEGREE + 1]; MAX_DEGREE + 1]; 4] {
    let v = &gv.g;
    let mut w = [[[0.0; MAX_DEGREE + 1]; MAX_DEGREE + 1]; 4];
    for b in 0..=gv.degree {
        for d in 0..=gv.degree {
            w[0][b][d] = b2 * v[2][b][d] + b3 * v[3][b][d];
            w[1][b][d] = 2.0 * b2 * v[1][b][d] + 3.0 * b3 * v[2][b][d];
            w[2][b][d] = b2 * v[0][b][d] + 3.0 * b3 * v[1][b][d];
            w[3][b][d] = b3 * v[0][b][d];
        }
    }
    w
}

/// Nested-dissection elimination order of the `nu × nv` control grid whose points couple
/// within p rows and q columns: `order[k]` is the k-th control point eliminated.
fn nested_dissection(nu: usize, nv: usize, p: usize, q: usize) -> Vec<usize> {
    let mut order = Vec::with_capacity(nu * nv);
    dissect(&mut order, nv, (0..nu, 0..nv), (p, q));
    order
}

/// Orders the block `rows × cols` of the grid: a block small enough (or too thin to cut) row
/// by row; otherwise cut across its longer side (in units of the coupling reach) by a
/// separator of p rows or q columns, each half ordered recursively, the separator last.
fn dissect(
    order: &mut Vec<usize>,
    nv: usize,
    (rows, cols): (std::ops::Range<usize>, std::ops::Range<usize>),
    (p, q): (usize, usize),
) {
    const LEAF: usize = 64;
    let (h, w) = (rows.len(), cols.len());
    let (cut_rows, cut_cols) = (h > 2 * p + 2, w > 2 * q + 2);
    if h * w <= LEAF || !(cut_rows || cut_cols) {
        append_block(order, nv, rows, cols);
        return;
    }
    if cut_rows && (h * q >= w * p || !cut_cols) {
        let m = rows.start + (h - p) / 2;
        dissect(order, nv, (rows.start..m, cols.clone()), (p, q));
        dissect(order, nv, (m + p..rows.end, cols.clone()), (p, q));
        append_block(order, nv, m..m + p, cols);
    } else {
        let m = cols.start + (w - q) / 2;
        dissect(order, nv, (rows.clone(), cols.start..m), (p, q));
        dissect(order, nv, (rows.clone(), m + q..cols.end), (p, q));
        append_block(order, nv, rows, m..m + q);
    }
}

/// Appends a block of the grid row by row.
fn append_block(
    order: &mut Vec<usize>,
    nv: usize,
    rows: std::ops::Range<usize>,
    cols: std::ops::Range<usize>,
) {
    for i in rows {
        order.extend(cols.clone().map(|j| i * nv + j));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_legendre_integrates_polynomials_exactly() {
        for n in 1..=8 {
            let (x, w) = gauss_legendre(n);
            for deg in 0..2 * n {
                let integral: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(deg as i32)).sum();
                let exact = if deg % 2 == 1 {
                    0.0
                } else {
                    2.0 / (deg as f64 + 1.0)
                };
                assert!((integral - exact).abs() < 1e-13, "n {n} degree {deg}");
            }
        }
    }

    #[test]
    fn pattern_positions_are_consistent() {
        let sys = NormalSystem::new(5, 6, 2, 3).expect("pattern");
        let rows = sys.symbolic.row_idx();
        for c in 0..30 {
            let band = sys.band(c);
            for (k, &r) in rows[sys.col_ptr[c]..sys.col_ptr[c + 1]].iter().enumerate() {
                assert_eq!(band.at(r / 6, r % 6), sys.col_ptr[c] + k);
            }
        }
    }

    #[test]
    fn nested_dissection_is_a_permutation_with_less_fill_than_amd() {
        for (nu, nv, p, q) in [(1, 1, 1, 1), (7, 3, 2, 1), (40, 23, 3, 3), (120, 90, 3, 2)] {
            let order = nested_dissection(nu, nv, p, q);
            let mut seen = vec![false; nu * nv];
            for &o in &order {
                assert!(!seen[o], "{o} twice");
                seen[o] = true;
            }
            assert!(
                seen.iter().all(|&s| s),
                "{nu} × {nv}: not every point ordered"
            );
        }
        // The fill of the factor: nested dissection against faer's AMD on a 120 × 90 grid.
        let sys = NormalSystem::new(120, 90, 3, 3).expect("pattern");
        let amd = factorize_symbolic_cholesky(
            sys.symbolic.as_ref(),
            Side::Upper,
            SymmetricOrdering::Amd,
            Default::default(),
        )
        .expect("amd");
        assert!(
            sys.factor.len_val() < amd.len_val(),
            "nested dissection {} against AMD {}",
            sys.factor.len_val(),
            amd.len_val()
        );
    }

    /// A 9 × 8 grid system (p = q = 3) with deterministic, diagonally dominant values.
    fn dominant_system() -> NormalSystem {
        let (nu, nv) = (9, 8);
        let mut sys = NormalSystem::new(nu, nv, 3, 3).expect("pattern");
        for c in 0..nu * nv {
            let band = sys.band(c);
            for k in band.start..sys.col_ptr[c + 1] {
                sys.values[k] = ((k * 7919) % 13) as f64 / 13.0 - 0.5;
            }
            sys.values[sys.col_ptr[c + 1] - 1] = 60.0 + c as f64;
        }
        sys
    }

    #[test]
    fn rows_times_a_vector_match_the_dense_product() {
        let sys = dominant_system();
        let n = 72;
        let mut dense = vec![vec![0.0; n]; n];
        let rows = sys.symbolic.row_idx();
        for c in 0..n {
            for k in sys.col_ptr[c]..sys.col_ptr[c + 1] {
                dense[rows[k]][c] = sys.values[k];
                dense[c][rows[k]] = sys.values[k];
            }
        }
        let x: Vec<Point3> = (0..n)
            .map(|i| Point3::new(i as f64, (i * i) as f64 * 0.01, 1.0 - i as f64))
            .collect();
        for (c, row) in dense.iter().enumerate() {
            let want: Point3 = row.iter().zip(&x).map(|(a, x)| *a * *x).sum();
            assert!((sys.row_times(c, &x) - want).length() < 1e-9, "row {c}");
        }
    }

    #[test]
    fn a_window_solve_zeroes_the_residual_inside_and_the_whole_window_is_the_system() {
        let mut sys = dominant_system();
        let b: Vec<Point3> = (0..72).map(|i| Point3::splat(1.0 + i as f64)).collect();
        let to_mat = |v: &[Point3]| Mat::<f64>::from_fn(v.len(), 3, |i, d| v[i][d]);
        let full = sys.solve(to_mat(&b)).expect("full solve");
        let mut whole = sys.window(0..9, 0..8).expect("whole");
        let again = whole.solve(to_mat(&b)).expect("window solve");
        for (a, f) in again.iter().zip(&full) {
            assert!((*a - *f).length() < 1e-12);
        }
        // From x = 0, one solve of rows 2..7 × columns 1..6: the residual vanishes there.
        let (rows, cols) = (2..7, 1..6);
        let mut sub = sys.window(rows.clone(), cols.clone()).expect("window");
        let index = |k: usize| (rows.start + k / 5) * 8 + cols.start + k % 5;
        let r: Vec<Point3> = (0..25).map(|k| b[index(k)]).collect();
        let mut x = vec![Point3::ZERO; 72];
        for (k, d) in sub.solve(to_mat(&r)).expect("sub").into_iter().enumerate() {
            x[index(k)] = d;
        }
        for k in 0..25 {
            let g = index(k);
            assert!((b[g] - sys.row_times(g, &x)).length() < 1e-10, "row {g}");
        }
    }
}
