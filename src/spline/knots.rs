use super::SplineError;
use std::sync::OnceLock;

/// Largest supported B-spline degree. Higher degrees are numerically poor for fitting and the
/// fixed-size scratch arrays below depend on it.
pub const MAX_DEGREE: usize = 7;

/// A non-decreasing knot sequence with its degree p. The parameter domain is
/// `[knots[p], knots[len - p - 1]]`, and there are `len - p - 1` basis functions.
#[derive(Clone, Debug)]
pub struct KnotVector {
    degree: usize,
    knots: Vec<f64>,
    /// Evaluation tables, built at the first basis evaluation: knot insertion makes a new
    /// knot vector per knot, and the vectors in between (a batch of insertions, or one of a
    /// curve fit's refinements) are never evaluated.
    tables: OnceLock<SpanTables>,
}

/// Two knot vectors are equal when their degrees and knots are (the tables follow from them).
impl PartialEq for KnotVector {
    fn eq(&self, other: &Self) -> bool {
        self.degree == other.degree && self.knots == other.knots
    }
}

/// What evaluation needs beyond the knots.
#[derive(Clone, Debug)]
struct SpanTables {
    /// The basis in power form, per span (see [`SpanPolynomials`]).
    poly: SpanPolynomials,
    /// Where to start looking for a parameter's span (see [`SpanLookup`]).
    lookup: SpanLookup,
}

/// Buckets of equal parameter width over the domain, two per span, each holding the span of
/// its start: [`KnotVector::find_span`] walks from there, a step or two on any knot vector
/// the fits make, instead of a binary search over all knots (which was a sixth of the time
/// of a B-spline surface fit's foot-point search).
#[derive(Clone, Debug)]
struct SpanLookup {
    start: f64,
    /// Buckets per unit parameter.
    scale: f64,
    spans: Vec<usize>,
}

impl SpanLookup {
    /// Longest walk before falling back to a binary search (knots clustered far below the
    /// bucket width).
    const MAX_WALK: usize = 8;

    fn of(degree: usize, knots: &[f64]) -> SpanLookup {
        let n = knots.len() - degree - 1;
        let (start, end) = (knots[degree], knots[n]);
        let buckets = 2 * (n - degree);
        let scale = buckets as f64 / (end - start);
        let mut spans = Vec::with_capacity(buckets);
        let mut i = degree;
        for b in 0..buckets {
            let t = start + b as f64 / scale;
            while i + 1 < n && knots[i + 1] <= t {
                i += 1;
            }
            spans.push(i);
        }
        SpanLookup {
            start,
            scale,
            spans,
        }
    }
}

/// The p + 1 non-zero basis functions of every non-empty span i as polynomials in the local
/// parameter t = (u − knots[i]) / h_i, h_i = knots[i + 1] − knots[i]: N_{i−p+j}(u) =
/// Σ_m c_jm t^m.
///
/// Why: evaluating them by Horner's rule (with the derivatives) takes a few multiply-adds per
/// function and no division, where the Cox–de Boor triangle (A2.3) divides by knot differences
/// at every call; basis evaluation is the innermost loop of every foot-point search and of the
/// normal-equation assembly. The coefficients are the Taylor coefficients at the span start,
/// c_jm = N^(m)(knots[i]) h^m / m!, taken from A2.3 once per knot vector; since
/// |N^(m)| ≲ 1 / h^m they are of order one and the form is well conditioned on [0, 1].
#[derive(Clone, Debug)]
struct SpanPolynomials {
    /// Per span index i − p (i = p..n): (p + 1)² coefficients, row j = function, then 1/h_i
    /// (zero for an empty span, which keeps to A2.3).
    table: Vec<f64>,
}

/// m! / (m − r)! for m, r ≤ MAX_DEGREE: the factor of t^(m−r) in the r-th derivative of t^m.
const FALLING: [[f64; MAX_DEGREE + 1]; MAX_DEGREE + 1] = falling_factorials();

const fn falling_factorials() -> [[f64; MAX_DEGREE + 1]; MAX_DEGREE + 1] {
    let mut f = [[0.0; MAX_DEGREE + 1]; MAX_DEGREE + 1];
    let mut m = 0;
    while m <= MAX_DEGREE {
        let mut r = 0;
        let mut v = 1.0;
        while r <= m {
            f[m][r] = v;
            v *= (m - r) as f64;
            r += 1;
        }
        m += 1;
    }
    f
}

impl SpanPolynomials {
    fn stride(p: usize) -> usize {
        (p + 1) * (p + 1) + 1
    }

    fn of(degree: usize, knots: &[f64]) -> SpanPolynomials {
        let p = degree;
        let n = knots.len() - p - 1;
        let stride = Self::stride(p);
        let mut table = vec![0.0; (n - p) * stride];
        let mut ders = [[0.0; MAX_DEGREE + 1]; MAX_DEGREE + 1];
        for (i, entry) in (p..n).zip(table.chunks_exact_mut(stride)) {
            let h = knots[i + 1] - knots[i];
            // An empty span, or one so short that 1/h overflows, keeps to A2.3.
            if h <= 0.0 || !(1.0 / h).is_finite() {
                continue;
            }
            basis_ders_cox_de_boor(p, knots, i, knots[i], p, &mut ders);
            let mut scale = 1.0;
            for m in 0..=p {
                for j in 0..=p {
                    entry[j * (p + 1) + m] = ders[m][j] * scale / FALLING[m][m];
                }
                scale *= h;
            }
            entry[stride - 1] = 1.0 / h;
        }
        SpanPolynomials { table }
    }

    /// Basis functions of `span` and derivatives up to `d` at `u` into `out` (rows 0..=d,
    /// entries from N on zero), or false for an empty or unknown span.
    fn eval<const N: usize>(
        &self,
        knots: &[f64],
        span: usize,
        u: f64,
        d: usize,
        out: &mut [[f64; MAX_DEGREE + 1]],
    ) -> bool {
        let p = N - 1;
        let stride = Self::stride(p);
        let Some(entry) = span
            .checked_sub(p)
            .and_then(|s| self.table.get(s * stride..(s + 1) * stride))
        else {
            return false;
        };
        let inv_h = entry[stride - 1];
        if inv_h == 0.0 {
            return false;
        }
        let t = (u - knots[span]) * inv_h;
        for row in out.iter_mut().take(d + 1) {
            row.fill(0.0);
        }
        let mut scale = 1.0;
        for (r, row) in out.iter_mut().enumerate().take(d.min(p) + 1) {
            for j in 0..N {
                let c = &entry[j * N..(j + 1) * N];
                let mut acc = 0.0;
                for m in (r..N).rev() {
                    acc = acc * t + FALLING[m][r] * c[m];
                }
                row[j] = acc * scale;
            }
            scale *= inv_h;
        }
        true
    }
}

impl KnotVector {
    /// A knot vector, checked: degree 1..=[`MAX_DEGREE`], at least 2(p+1) finite non-decreasing
    /// knots, no interior multiplicity above p + 1, and a non-empty domain.
    pub fn try_new(degree: usize, knots: Vec<f64>) -> Result<KnotVector, SplineError> {
        if degree == 0 || degree > MAX_DEGREE {
            return Err(SplineError::BadDegree {
                degree,
                max: MAX_DEGREE,
            });
        }
        let needed = 2 * (degree + 1);
        if knots.len() < needed {
            return Err(SplineError::TooFewKnots {
                found: knots.len(),
                needed,
                degree,
            });
        }
        if let Some(index) = knots.iter().position(|k| !k.is_finite()) {
            return Err(SplineError::NonFiniteKnot { index });
        }
        if let Some(i) = (1..knots.len()).find(|&i| knots[i] < knots[i - 1]) {
            return Err(SplineError::DecreasingKnots {
                index: i,
                prev: knots[i - 1],
                next: knots[i],
            });
        }
        check_multiplicity(degree, &knots)?;
        let (start, end) = (knots[degree], knots[knots.len() - degree - 1]);
        if end <= start {
            return Err(SplineError::EmptyDomain { start, end });
        }
        Ok(KnotVector {
            degree,
            knots,
            tables: OnceLock::new(),
        })
    }

    /// A clamped (open) knot vector with `n` basis functions and uniform interior knots on
    /// `[0, 1]`. `n` must be at least `degree + 1`.
    pub fn clamped_uniform(degree: usize, n: usize) -> Result<KnotVector, SplineError> {
        let interior = n.saturating_sub(degree + 1);
        let mut knots = vec![0.0; degree + 1];
        knots.extend((1..=interior).map(|i| i as f64 / (interior + 1) as f64));
        knots.extend(std::iter::repeat_n(1.0, degree + 1));
        KnotVector::try_new(degree, knots)
    }

    /// The degree p.
    pub fn degree(&self) -> usize {
        self.degree
    }

    /// The knots.
    pub fn knots(&self) -> &[f64] {
        &self.knots
    }

    /// Number of basis functions (control points along this direction).
    pub fn num_basis(&self) -> usize {
        self.knots.len() - self.degree - 1
    }

    /// The parameter domain `[knots[p], knots[n]]`.
    pub fn domain(&self) -> (f64, f64) {
        (
            self.knots[self.degree],
            self.knots[self.knots.len() - self.degree - 1],
        )
    }

    /// `u` clamped into the domain; NaN maps to the domain start.
    pub fn clamp(&self, u: f64) -> f64 {
        let (a, b) = self.domain();
        if u.is_nan() {
            a
        } else {
            u.clamp(a, b)
        }
    }

    /// The knot span index i with `knots[i] <= u < knots[i+1]` (A2.1), for `u` clamped into the
    /// domain; the domain end belongs to the last non-empty span.
    pub fn find_span(&self, u: f64) -> usize {
        let u = self.clamp(u);
        let n = self.num_basis();
        if u >= self.knots[n] {
            // Last non-empty span: step back over the clamped end knots.
            let mut i = n - 1;
            while i > self.degree && self.knots[i] >= self.knots[n] {
                i -= 1;
            }
            return i;
        }
        // The largest i with knots[i] <= u: walk from the bucket's span (stepping back first
        // if rounding put u in the next bucket), else search (also before the tables exist).
        let Some(tables) = self.tables.get() else {
            return self.knots[self.degree..=n].partition_point(|&k| k <= u) + self.degree - 1;
        };
        let table = &tables.lookup;
        let bucket = ((u - table.start) * table.scale) as usize;
        let mut i = table.spans[bucket.min(table.spans.len() - 1)];
        while i > self.degree && self.knots[i] > u {
            i -= 1;
        }
        for _ in 0..SpanLookup::MAX_WALK {
            if self.knots[i + 1] > u {
                return i;
            }
            i += 1;
        }
        let upper = self.knots[i..=n].partition_point(|&k| k <= u) + i;
        upper - 1
    }

    /// The p + 1 non-zero basis functions N_{span-p..=span}(u) and their derivatives up to order
    /// `d` (A2.3): `out[k][j]` is the k-th derivative of N_{span-p+j}. Derivatives above the
    /// degree are zero. `u` is clamped into the domain.
    pub fn basis_ders(&self, span: usize, u: f64, d: usize, out: &mut [[f64; MAX_DEGREE + 1]]) {
        let u = self.clamp(u);
        let k = &self.knots;
        let poly = &self
            .tables
            .get_or_init(|| SpanTables {
                poly: SpanPolynomials::of(self.degree, k),
                lookup: SpanLookup::of(self.degree, k),
            })
            .poly;
        // One instance per degree: fixed loop bounds let the compiler unroll the Horner sums.
        let done = match self.degree {
            1 => poly.eval::<2>(k, span, u, d, out),
            2 => poly.eval::<3>(k, span, u, d, out),
            3 => poly.eval::<4>(k, span, u, d, out),
            4 => poly.eval::<5>(k, span, u, d, out),
            5 => poly.eval::<6>(k, span, u, d, out),
            6 => poly.eval::<7>(k, span, u, d, out),
            _ => poly.eval::<{ MAX_DEGREE + 1 }>(k, span, u, d, out),
        };
        if !done {
            basis_ders_cox_de_boor(self.degree, k, span, u, d, out);
        }
    }

    /// The p + 1 non-zero basis values at `u` and the index of the first of them.
    pub fn basis(&self, u: f64) -> (usize, [f64; MAX_DEGREE + 1]) {
        let span = self.find_span(u);
        let mut out = [[0.0; MAX_DEGREE + 1]; 1];
        self.basis_ders(span, u, 0, &mut out);
        (span - self.degree, out[0])
    }
}

/// A2.3 for degree `p`: see [`basis_ders_n`].
fn basis_ders_cox_de_boor(
    p: usize,
    k: &[f64],
    span: usize,
    u: f64,
    d: usize,
    out: &mut [[f64; MAX_DEGREE + 1]],
) {
    // One instance per degree: the scratch tables then have the degree's own size.
    match p {
        1 => basis_ders_n::<2>(k, span, u, d, out),
        2 => basis_ders_n::<3>(k, span, u, d, out),
        3 => basis_ders_n::<4>(k, span, u, d, out),
        4 => basis_ders_n::<5>(k, span, u, d, out),
        5 => basis_ders_n::<6>(k, span, u, d, out),
        6 => basis_ders_n::<7>(k, span, u, d, out),
        _ => basis_ders_n::<{ MAX_DEGREE + 1 }>(k, span, u, d, out),
    }
}

/// A2.3 for degree p = N − 1: the N non-zero basis functions at `u` in `span` and their
/// derivatives up to order `d` into `out[k][j]` (rows 0..=d; entries from N on are zeroed).
fn basis_ders_n<const N: usize>(
    k: &[f64],
    span: usize,
    u: f64,
    d: usize,
    out: &mut [[f64; MAX_DEGREE + 1]],
) {
    let p = N - 1;
    let mut ndu = [[0.0; N]; N];
    // Reciprocals of the knot differences in ndu's lower triangle: the derivative rows divide
    // by them again, so each difference is divided once.
    let mut inv = [[0.0; N]; N];
    let mut left = [0.0; N];
    let mut right = [0.0; N];
    ndu[0][0] = 1.0;
    for j in 1..=p {
        left[j] = u - k[span + 1 - j];
        right[j] = k[span + j] - u;
        let mut saved = 0.0;
        for r in 0..j {
            ndu[j][r] = right[r + 1] + left[j - r];
            inv[j][r] = 1.0 / ndu[j][r];
            let temp = ndu[r][j - 1] * inv[j][r];
            ndu[r][j] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        ndu[j][j] = saved;
    }
    for row in out.iter_mut().take(d + 1) {
        row.fill(0.0);
    }
    for j in 0..=p {
        out[0][j] = ndu[j][p];
    }
    derivative_rows::<N>(d.min(p), &ndu, &inv, out);
}

/// Rows 1..=d of A2.3 for degree N − 1: derivatives of the basis functions from the triangular
/// table `ndu` (`inv` holds the reciprocals of its lower triangle).
fn derivative_rows<const N: usize>(
    d: usize,
    ndu: &[[f64; N]; N],
    inv: &[[f64; N]; N],
    out: &mut [[f64; MAX_DEGREE + 1]],
) {
    let p = N - 1;
    let mut a = [[0.0; N]; 2];
    for r in 0..=p {
        let (mut s1, mut s2) = (0usize, 1usize);
        a[0][0] = 1.0;
        for k in 1..=d {
            let mut dval = 0.0;
            let rk = r as isize - k as isize;
            let pk = p - k;
            if r >= k {
                a[s2][0] = a[s1][0] * inv[pk + 1][rk as usize];
                dval = a[s2][0] * ndu[rk as usize][pk];
            }
            let j1 = if rk >= -1 { 1 } else { (-rk) as usize };
            let j2 = if (r as isize - 1) <= pk as isize {
                k - 1
            } else {
                p - r
            };
            for j in j1..=j2 {
                let idx = (rk + j as isize) as usize;
                a[s2][j] = (a[s1][j] - a[s1][j - 1]) * inv[pk + 1][idx];
                dval += a[s2][j] * ndu[idx][pk];
            }
            if r <= pk {
                a[s2][k] = -a[s1][k - 1] * inv[pk + 1][r];
                dval += a[s2][k] * ndu[r][pk];
            }
            out[k][r] = dval;
            std::mem::swap(&mut s1, &mut s2);
        }
    }
    let mut factor = p as f64;
    for (k, row) in out.iter_mut().enumerate().take(d + 1).skip(1) {
        for v in row.iter_mut().take(p + 1) {
            *v *= factor;
        }
        factor *= (p - k) as f64;
    }
}

/// Rejects knots repeated more than p + 1 times.
fn check_multiplicity(degree: usize, knots: &[f64]) -> Result<(), SplineError> {
    let mut start = 0;
    for i in 1..=knots.len() {
        if i == knots.len() || knots[i] != knots[start] {
            let multiplicity = i - start;
            if multiplicity > degree + 1 {
                let (index, value, limit) = (start, knots[start], degree + 1);
                return Err(SplineError::KnotMultiplicity {
                    index,
                    value,
                    multiplicity,
                    limit,
                });
            }
            start = i;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn kv() -> KnotVector {
        KnotVector::try_new(
            3,
            vec![0.0, 0.0, 0.0, 0.0, 0.3, 0.5, 0.5, 0.8, 1.0, 1.0, 1.0, 1.0],
        )
        .unwrap()
    }

    #[test]
    fn spans_cover_domain() {
        let k = kv();
        assert_eq!(k.num_basis(), 8);
        assert_eq!(k.find_span(0.0), 3);
        assert_eq!(k.find_span(0.3), 4);
        assert_eq!(k.find_span(0.5), 6);
        assert_eq!(k.find_span(1.0), 7);
        assert_eq!(k.find_span(7.0), 7);
        assert_eq!(k.find_span(f64::NAN), 3);
    }

    #[test]
    fn rejects_bad_knots() {
        assert!(matches!(
            KnotVector::try_new(0, vec![0.0, 1.0]),
            Err(SplineError::BadDegree { .. })
        ));
        assert!(matches!(
            KnotVector::try_new(2, vec![0.0; 5]),
            Err(SplineError::TooFewKnots { .. })
        ));
        let k = vec![0.0, 0.0, 1.0, 0.5, 1.0, 1.0];
        assert!(matches!(
            KnotVector::try_new(2, k),
            Err(SplineError::DecreasingKnots { index: 3, .. })
        ));
        let k = vec![0.0, 0.0, f64::NAN, 1.0];
        assert!(matches!(
            KnotVector::try_new(1, k),
            Err(SplineError::NonFiniteKnot { index: 2 })
        ));
        assert!(matches!(
            KnotVector::try_new(1, vec![0.0; 4]),
            Err(SplineError::KnotMultiplicity { .. })
        ));
        let k = vec![0.0, 0.0, 0.5, 0.5, 0.5, 1.0, 1.0];
        assert!(matches!(
            KnotVector::try_new(1, k),
            Err(SplineError::KnotMultiplicity {
                multiplicity: 3,
                ..
            })
        ));
    }

    proptest! {
        #[test]
        fn partition_of_unity_and_derivative_sums(u in -0.1f64..1.1) {
            let k = kv();
            let span = k.find_span(u);
            let mut d = [[0.0; MAX_DEGREE + 1]; 4];
            k.basis_ders(span, u, 3, &mut d);
            let sums: Vec<f64> = d.iter().map(|row| row.iter().sum()).collect();
            prop_assert!((sums[0] - 1.0).abs() < 1e-12);
            for s in &sums[1..] { prop_assert!(s.abs() < 1e-9); }
            prop_assert!(d[0].iter().all(|&n| n >= -1e-15));
        }

        #[test]
        fn derivatives_match_finite_differences(u in 0.01f64..0.99, i in 0usize..8) {
            let k = kv();
            let h = 1e-6;
            let value = |t: f64, order: usize| {
                let span = k.find_span(t);
                let mut d = [[0.0; MAX_DEGREE + 1]; 3];
                k.basis_ders(span, t, 2, &mut d);
                let first = span - 3;
                if i >= first && i <= span { d[order][i - first] } else { 0.0 }
            };
            // Skip parameters next to a knot, where the derivative jumps.
            prop_assume!(k.knots().iter().all(|&t| (t - u).abs() > 1e-3));
            let fd1 = (value(u + h, 0) - value(u - h, 0)) / (2.0 * h);
            prop_assert!((fd1 - value(u, 1)).abs() < 1e-5, "first derivative {} vs {}", fd1, value(u, 1));
            let fd2 = (value(u + h, 1) - value(u - h, 1)) / (2.0 * h);
            prop_assert!((fd2 - value(u, 2)).abs() < 1e-3, "second derivative {} vs {}", fd2, value(u, 2));
        }

        #[test]
        fn span_lookup_matches_a_binary_search(
            p in 1usize..=4,
            gaps in proptest::collection::vec(0.0f64..1.0, 1..40),
            cluster in 0usize..3,
            at in -0.1f64..1.1,
        ) {
            // Increasing interior knots, some squeezed into a tiny interval (long walks).
            let mut knots = vec![0.0; p + 1];
            let mut t = 0.0;
            for (i, g) in gaps.iter().enumerate() {
                t += if i % 3 == cluster { g * 1e-6 } else { *g };
                knots.push(t);
            }
            let end = t + 0.5;
            knots.extend(std::iter::repeat_n(end, p + 1));
            let k = KnotVector::try_new(p, knots).expect("valid knots");
            let n = k.num_basis();
            let probes = [at * end, t, k.knots()[p + gaps.len() / 2], end];
            // Before the tables exist find_span searches; after, it walks from the buckets.
            let searched: Vec<usize> = probes.iter().map(|&u| k.find_span(u)).collect();
            let mut scratch = [[0.0; MAX_DEGREE + 1]; 1];
            k.basis_ders(p, k.knots()[p], 0, &mut scratch);
            for (&u, &before) in probes.iter().zip(&searched) {
                let span = k.find_span(u);
                prop_assert_eq!(span, before, "u {}", u);
                let c = k.clamp(u);
                let expected = if c >= k.knots()[n] {
                    span // the domain end: checked by spans_cover_domain
                } else {
                    k.knots()[p..=n].partition_point(|&x| x <= c) + p - 1
                };
                prop_assert_eq!(span, expected, "u {}", u);
                prop_assert!(k.knots()[span] <= c && c <= k.knots()[span + 1]);
                prop_assert!(k.knots()[span] < k.knots()[span + 1]);
            }
        }

        #[test]
        fn power_form_matches_cox_de_boor(
            p in 1usize..=MAX_DEGREE,
            gaps in proptest::collection::vec(0u8..4, 1..12),
            at in 0.0f64..1.0,
        ) {
            // Interior knots from integer gaps (0 repeats a knot), multiplicity at most p + 1.
            let mut knots = vec![0.0; p + 1];
            let mut t = 0.0;
            for g in &gaps {
                t += f64::from(*g);
                let repeats = knots.iter().filter(|&&k| k == t).count();
                if t > 0.0 && repeats < p {
                    knots.push(t);
                }
            }
            let end = t + 1.0;
            knots.extend(std::iter::repeat_n(end, p + 1));
            let k = KnotVector::try_new(p, knots).expect("valid knots");
            let u = at * end;
            let span = k.find_span(u);
            let mut fast = [[0.0; MAX_DEGREE + 1]; MAX_DEGREE + 1];
            let mut exact = [[0.0; MAX_DEGREE + 1]; MAX_DEGREE + 1];
            k.basis_ders(span, u, p, &mut fast);
            basis_ders_cox_de_boor(p, k.knots(), span, u, p, &mut exact);
            for order in 0..=p {
                // Derivatives scale like 1/h^order: compare relative to the largest entry.
                let size = exact[order].iter().fold(1.0f64, |m, x| m.max(x.abs()));
                for j in 0..=MAX_DEGREE {
                    prop_assert!(
                        (fast[order][j] - exact[order][j]).abs() <= 1e-11 * size,
                        "degree {} order {} function {}: {} vs {}",
                        p, order, j, fast[order][j], exact[order][j]
                    );
                }
            }
        }
    }
}
