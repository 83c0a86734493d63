//! Element quality of a quad mesh on a surface: aspect ratio, skew angle and the scaled
//! Jacobian, whose sign against the surface normal tells an inverted element.

use crate::geom::{Point3, Vec3};
use serde::Serialize;

/// The quality figures of a FEM quad mesh.
///
/// Per element: the **aspect ratio** is its longest edge over its shortest (1 for a square);
/// the **skew angle** the largest deviation of a corner angle from 90°; the **scaled Jacobian**
/// the smallest over the four corners of (a × b) · n / (|a| |b|), with a and b the corner's two
/// edges in counter-clockwise order and n the element's normal, negated when it points against
/// the surface normal (1 for a rectangle, ≤ 0 for an inverted, bow-tie or degenerate element).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct FemQuality {
    /// Number of quadrilaterals.
    pub elements: usize,
    /// Number of nodes.
    pub nodes: usize,
    /// Smallest aspect ratio.
    pub aspect_min: f64,
    /// Mean aspect ratio.
    pub aspect_mean: f64,
    /// Largest aspect ratio.
    pub aspect_max: f64,
    /// Largest skew angle, degrees.
    pub skew_max_deg: f64,
    /// Mean over the elements of their skew angle, degrees.
    pub skew_mean_deg: f64,
    /// Smallest scaled Jacobian.
    pub jacobian_min: f64,
    /// Elements whose scaled Jacobian is ≤ 0 (inverted or degenerate).
    pub inverted: usize,
    /// Elements across a fold of the surface itself: the surface normals at two of their
    /// corners point against each other. A mesh that follows the surface inverts there
    /// whatever its lines; the fit, not the mesher, is at fault.
    pub on_folds: usize,
    /// Inverted elements not across a fold of the surface: the mesher's own failures.
    pub inverted_off_folds: usize,
}

/// Whether the surface normals at an element's corners point against each other.
pub(super) fn across_fold(n: &[Vec3; 4]) -> bool {
    (0..4).any(|a| (a + 1..4).any(|b| n[a].dot(n[b]) < 0.0))
}

/// Whether the element at `p` with surface normals `n` at its corners is inverted (or
/// degenerate): its scaled Jacobian is ≤ 0.
pub(super) fn inverted(p: [Point3; 4], n: [Vec3; 4]) -> bool {
    element(p, n).2 <= 0.0
}

/// The figures of one element: (aspect ratio, skew degrees, scaled Jacobian). The corner
/// Jacobians are taken about the element's own normal (its diagonals' cross product, as
/// Verdict does for quads in 3D), signed by whether that normal agrees with the surface
/// normals `n` at the corners, so an element turned against the surface counts as inverted.
fn element(p: [Point3; 4], n: [Vec3; 4]) -> (f64, f64, f64) {
    let own = (p[2] - p[0]).cross(p[3] - p[1]).normalize_or_zero();
    let side = own.dot(n.iter().copied().sum::<Vec3>());
    let sign = if side < 0.0 { -1.0 } else { 1.0 };
    let (mut lo, mut hi) = (f64::INFINITY, 0.0_f64);
    let (mut skew, mut jac) = (0.0_f64, f64::INFINITY);
    for k in 0..4 {
        let a = p[(k + 1) % 4] - p[k];
        let b = p[(k + 3) % 4] - p[k];
        let (la, lb) = (a.length(), b.length());
        lo = lo.min(la);
        hi = hi.max(la);
        let c = a.cross(b);
        let sj = if la > 0.0 && lb > 0.0 {
            sign * c.dot(own) / (la * lb)
        } else {
            0.0
        };
        jac = jac.min(if sj.is_finite() { sj } else { 0.0 });
        let angle = libm::atan2(c.length(), a.dot(b)).to_degrees();
        skew = skew.max(if angle.is_finite() {
            (90.0 - angle).abs()
        } else {
            90.0
        });
    }
    let aspect = if lo > 0.0 && hi.is_finite() {
        hi / lo
    } else {
        f64::MAX
    };
    (aspect, skew, jac)
}

/// The quality of `quads` over `nodes`, with `normals` the unit surface normal at every node
/// (zero where the surface has none).
pub(super) fn measure(nodes: &[Point3], normals: &[Vec3], quads: &[[u32; 4]]) -> FemQuality {
    let mut q = FemQuality {
        elements: quads.len(),
        nodes: nodes.len(),
        aspect_min: f64::MAX,
        jacobian_min: 1.0,
        ..FemQuality::default()
    };
    let (mut aspect_sum, mut skew_sum) = (0.0, 0.0);
    for quad in quads {
        let at = |k: usize| quad[k] as usize;
        let p = [0, 1, 2, 3].map(|k| nodes[at(k)]);
        let n = [0, 1, 2, 3].map(|k| normals[at(k)]);
        let (aspect, skew, jac) = element(p, n);
        q.aspect_min = q.aspect_min.min(aspect);
        q.aspect_max = q.aspect_max.max(aspect);
        q.skew_max_deg = q.skew_max_deg.max(skew);
        q.jacobian_min = q.jacobian_min.min(jac);
        let fold = across_fold(&n);
        q.inverted += usize::from(jac <= 0.0);
        q.on_folds += usize::from(fold);
        q.inverted_off_folds += usize::from(jac <= 0.0 && !fold);
        aspect_sum += aspect.min(1e300);
        skew_sum += skew;
    }
    if quads.is_empty() {
        q.aspect_min = 0.0;
    } else {
        q.aspect_mean = aspect_sum / quads.len() as f64;
        q.skew_mean_deg = skew_sum / quads.len() as f64;
    }
    q
}

#[cfg(test)]
mod tests {
    use super::*;

    const UP: [Vec3; 4] = [Vec3::Z; 4];

    #[test]
    fn a_rectangle_is_perfect_but_long() {
        let p =
            [(0.0, 0.0), (2.0, 0.0), (2.0, 1.0), (0.0, 1.0)].map(|(x, y)| Point3::new(x, y, 0.0));
        let (aspect, skew, jac) = element(p, UP);
        assert_eq!(aspect, 2.0);
        assert!(skew.abs() < 1e-12 && (jac - 1.0).abs() < 1e-12);
    }

    #[test]
    fn a_rhombus_is_skewed_and_a_flipped_square_inverted() {
        let s = 0.5_f64.sqrt();
        let p = [(0.0, 0.0), (1.0, 0.0), (1.0 + s, s), (s, s)].map(|(x, y)| Point3::new(x, y, 0.0));
        let (_, skew, jac) = element(p, UP);
        assert!((skew - 45.0).abs() < 1e-9 && (jac - s).abs() < 1e-12);
        let q =
            [(0.0, 0.0), (0.0, 1.0), (1.0, 1.0), (1.0, 0.0)].map(|(x, y)| Point3::new(x, y, 0.0));
        let m = measure(&q, &UP, &[[0, 1, 2, 3]]);
        assert_eq!(m.inverted, 1);
        assert!((m.jacobian_min + 1.0).abs() < 1e-12);
    }
}
