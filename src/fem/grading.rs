//! Element size from curvature, and the parameter lines that equidistribute it.
//!
//! The local element size is h = max(L / (1 + g κ L), L / [`MAX_REFINEMENT`]): the target size
//! L where the surface is flat, about 1 / (g κ) — g elements per radian of turning — where the
//! radius of curvature is much smaller than L, but never below L / 8, so curvature spikes (a
//! noisy fit's wrinkles, a fold) cannot blow up the count. A mesh line is then placed every unit
//! of ∫ ds / h along the surface.

use super::{FemError, FemSize, MAX_ELEMENTS};
use crate::geom::Vec3;

/// The largest principal curvature |κ| from the first and second derivatives; 0 where the
/// tangents are degenerate (no tangent plane, no curvature to grade by).
pub(super) fn max_curvature(du: Vec3, dv: Vec3, duu: Vec3, duv: Vec3, dvv: Vec3) -> f64 {
    let n = du.cross(dv);
    let area = n.length();
    let (e, f, g) = (du.dot(du), du.dot(dv), dv.dot(dv));
    let det = e * g - f * f;
    if area.is_nan() || area <= 0.0 || det.is_nan() || det <= 1e-12 * e * g {
        return 0.0;
    }
    let n = n / area;
    let (l, m, nn) = (duu.dot(n), duv.dot(n), dvv.dot(n));
    let gauss = (l * nn - m * m) / det;
    let mean = (e * nn - 2.0 * f * m + g * l) / (2.0 * det);
    let k = mean.abs() + (mean * mean - gauss).max(0.0).sqrt();
    if k.is_finite() {
        k
    } else {
        0.0
    }
}

/// How much smaller than L curvature may make an element.
pub const MAX_REFINEMENT: f64 = 8.0;

/// Elements per unit length at curvature `kappa`: 1 / h.
pub(super) fn density(size: f64, kappa: f64, grading: f64) -> f64 {
    (1.0 / size + grading * kappa).min(MAX_REFINEMENT / size)
}

/// A polyline's sampled length and curvature: `(segment length, curvature at its middle)`.
pub(super) type Samples = [(f64, f64)];

/// ∫ ds / h over the samples.
pub(super) fn elements_along(samples: &Samples, size: f64, grading: f64) -> f64 {
    samples
        .iter()
        .map(|&(ds, k)| ds * density(size, k, grading))
        .sum()
}

/// The element size whose mesh has about `target` elements, given `count(L)`, the element
/// count at size L (not increasing in L): bisection on log L between `scale · 1e-9` and
/// `scale · 10`, keeping the size whose count is nearest the target.
pub(super) fn size_for_count(target: usize, scale: f64, count: impl Fn(f64) -> f64) -> f64 {
    let (mut lo, mut hi) = (libm::log(scale * 1e-9), libm::log(scale * 10.0));
    let goal = target as f64;
    let mut best = (f64::INFINITY, scale);
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        let n = count(libm::exp(mid));
        if (n - goal).abs() < best.0 {
            best = ((n - goal).abs(), libm::exp(mid));
        }
        if n > goal {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    best.1
}

/// The target size of `size`: L itself, or the size giving about N elements by `count`.
pub(super) fn resolve_size(
    size: FemSize,
    scale: f64,
    count: impl Fn(f64) -> f64,
) -> Result<f64, FemError> {
    let l = match size {
        FemSize::Edge(l) => l,
        FemSize::Count(n) => size_for_count(n, scale, &count),
    };
    let estimated = count(l);
    if estimated.is_nan() || estimated > MAX_ELEMENTS as f64 {
        return Err(FemError::TooMany {
            estimated: if estimated.is_finite() {
                estimated
            } else {
                f64::MAX
            },
            max: MAX_ELEMENTS,
        });
    }
    Ok(l)
}

/// `n` parameter values from `t[0]` to `t[last]` (both included, `n − 1` intervals) that cut the
/// piecewise-linear cumulative of `weight` (one value per sample `t[i]`, trapezoid rule) into
/// equal parts. Each weight is floored at a millionth of the largest, so the cumulative rises
/// strictly and the lines are distinct and increasing.
pub(super) fn equidistribute(t: &[f64], weight: &[f64], intervals: usize) -> Vec<f64> {
    let top = weight.iter().copied().fold(0.0, f64::max);
    let floor = if top > 0.0 { top * 1e-6 } else { 1.0 };
    let mut cum = vec![0.0; t.len()];
    for i in 1..t.len() {
        let w = 0.5 * (weight[i - 1].max(floor) + weight[i].max(floor));
        cum[i] = cum[i - 1] + w * (t[i] - t[i - 1]);
    }
    let total = cum[t.len() - 1];
    let mut out = Vec::with_capacity(intervals + 1);
    let mut seg = 1;
    for k in 0..=intervals {
        let goal = total * k as f64 / intervals as f64;
        while seg < t.len() - 1 && cum[seg] < goal {
            seg += 1;
        }
        let (c0, c1) = (cum[seg - 1], cum[seg]);
        let s = if c1 > c0 {
            ((goal - c0) / (c1 - c0)).clamp(0.0, 1.0)
        } else {
            0.0
        };
        out.push(t[seg - 1] + s * (t[seg] - t[seg - 1]));
    }
    out[0] = t[0];
    out[intervals] = t[t.len() - 1];
    out
}

/// Intervals for an integral of `elements` ∫ ds / h: at least one.
pub(super) fn intervals(elements: f64) -> usize {
    (elements - 1e-9).ceil().max(1.0) as usize
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn curvature_of_a_sphere_is_one_over_its_radius() {
        // S(u, v) = r (cos u cos v, sin u cos v, sin v) at u = 0.3, v = 0.2.
        let (r, u, v) = (2.5_f64, 0.3_f64, 0.2_f64);
        let s = |u: f64, v: f64| Vec3::new(u.cos() * v.cos(), u.sin() * v.cos(), v.sin()) * r;
        let h = 1e-4;
        let du = (s(u + h, v) - s(u - h, v)) / (2.0 * h);
        let dv = (s(u, v + h) - s(u, v - h)) / (2.0 * h);
        let duu = (s(u + h, v) - 2.0 * s(u, v) + s(u - h, v)) / (h * h);
        let dvv = (s(u, v + h) - 2.0 * s(u, v) + s(u, v - h)) / (h * h);
        let duv =
            (s(u + h, v + h) - s(u + h, v - h) - s(u - h, v + h) + s(u - h, v - h)) / (4.0 * h * h);
        let k = max_curvature(du, dv, duu, duv, dvv);
        assert!((k - 1.0 / r).abs() < 1e-4, "{k}");
        assert_eq!(max_curvature(du, du, duu, duv, dvv), 0.0);
    }

    #[test]
    fn equidistributed_lines_follow_the_weight() {
        let t: Vec<f64> = (0..=100).map(|i| i as f64 / 100.0).collect();
        // Weight 3 on the right half, 1 on the left: three quarters of the lines on the right.
        let w: Vec<f64> = t.iter().map(|&x| if x > 0.5 { 3.0 } else { 1.0 }).collect();
        let lines = equidistribute(&t, &w, 8);
        assert_eq!(lines.len(), 9);
        assert!(lines.windows(2).all(|p| p[1] > p[0]));
        assert_eq!((lines[0], lines[8]), (0.0, 1.0));
        assert!((lines[2] - 0.5).abs() < 0.02, "{lines:?}");
    }

    #[test]
    fn size_for_count_hits_the_target() {
        // Area 6 with square elements: N(L) = 6 / L².
        let l = size_for_count(600, 3.0, |l| (6.0 / (l * l)).floor());
        assert!((6.0 / (l * l) - 600.0).abs() < 1.0, "{l}");
    }
}
