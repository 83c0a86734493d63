//! Garland–Heckbert error quadrics: the sum of squared distances to a set of weighted planes,
//! stored as the symmetric form Q(x) = xᵀAx + 2bᵀx + c.

use crate::geom::{Point3, Vec3};
use std::ops::AddAssign;

/// A symmetric 4×4 error quadric (10 coefficients).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct Quadric {
    a00: f64,
    a01: f64,
    a02: f64,
    a11: f64,
    a12: f64,
    a22: f64,
    b: Vec3,
    c: f64,
}

/// Below this ratio of |det A| to the cube of A's Frobenius norm, A is treated as singular: the
/// planes do not pin a point down (flat or cylindrical regions) and the solve would amplify noise.
const SINGULAR_RATIO: f64 = 1e-9;

impl Quadric {
    /// `weight` × squared distance to the plane through `point` with unit normal `normal`.
    pub(super) fn plane(normal: Vec3, point: Point3, weight: f64) -> Quadric {
        let n = normal;
        let d = -n.dot(point);
        Quadric {
            a00: weight * n.x * n.x,
            a01: weight * n.x * n.y,
            a02: weight * n.x * n.z,
            a11: weight * n.y * n.y,
            a12: weight * n.y * n.z,
            a22: weight * n.z * n.z,
            b: n * (weight * d),
            c: weight * d * d,
        }
    }

    /// `A v`.
    #[inline]
    fn mul(&self, v: Vec3) -> Vec3 {
        Vec3::new(
            self.a00 * v.x + self.a01 * v.y + self.a02 * v.z,
            self.a01 * v.x + self.a11 * v.y + self.a12 * v.z,
            self.a02 * v.x + self.a12 * v.y + self.a22 * v.z,
        )
    }

    /// The error at `p`; never negative (rounding is clamped). Written out, as the simplifier
    /// evaluates it for every edge in every pass.
    #[inline]
    pub(super) fn eval(&self, p: Point3) -> f64 {
        let (x, y, z) = (p.x, p.y, p.z);
        let quadratic = self.a00 * x * x
            + self.a11 * y * y
            + self.a22 * z * z
            + 2.0 * (self.a01 * x * y + self.a02 * x * z + self.a12 * y * z);
        (quadratic + 2.0 * self.b.dot(p) + self.c).max(0.0)
    }

    /// The point minimising the error, or `None` when A is (nearly) singular: `-A⁻¹b` from the
    /// six cofactors of the symmetric A, whose determinant also serves the singularity test.
    #[inline]
    pub(super) fn minimizer(&self) -> Option<Point3> {
        let (a00, a01, a02, a11, a12, a22) =
            (self.a00, self.a01, self.a02, self.a11, self.a12, self.a22);
        let c00 = a11 * a22 - a12 * a12;
        let c01 = a02 * a12 - a01 * a22;
        let c02 = a01 * a12 - a02 * a11;
        let det = a00 * c00 + a01 * c01 + a02 * c02;
        let norm_sq = a00 * a00 + a11 * a11 + a22 * a22 + 2.0 * (a01 * a01 + a02 * a02 + a12 * a12);
        if det.is_nan() || det.abs() <= SINGULAR_RATIO * norm_sq * norm_sq.sqrt() {
            return None;
        }
        let c11 = a00 * a22 - a02 * a02;
        let c12 = a01 * a02 - a00 * a12;
        let c22 = a00 * a11 - a01 * a01;
        let b = self.b;
        let x = Point3::new(
            c00 * b.x + c01 * b.y + c02 * b.z,
            c01 * b.x + c11 * b.y + c12 * b.z,
            c02 * b.x + c12 * b.y + c22 * b.z,
        ) * (-1.0 / det);
        x.is_finite().then_some(x)
    }

    /// The point minimising the error on the segment `p`–`q` (closed form of a 1D quadratic;
    /// along a direction of no curvature, the lower end).
    #[inline]
    pub(super) fn minimizer_on_segment(&self, p: Point3, q: Point3) -> Point3 {
        let d = q - p;
        // Q(p + t d) = t² dᵀAd + 2t (dᵀAp + bᵀd) + const.
        let curv = d.dot(self.mul(d));
        let slope = d.dot(self.mul(p)) + self.b.dot(d);
        if curv.is_nan() || curv <= 0.0 {
            return if slope < 0.0 { q } else { p };
        }
        let t = (-slope / curv).clamp(0.0, 1.0);
        p + d * t
    }
}

/// How far (in edge lengths from the edge midpoint) the quadric's optimum may lie before it is
/// distrusted as the product of a nearly singular system.
const MAX_OPTIMUM_OFFSET: f64 = 2.0;

/// The best position for the vertex that replaces edge `pu`–`pv` under the summed quadric `q`,
/// and its error: the optimum of `q` when it is well defined and near the edge, else the
/// optimum on the edge.
#[inline]
pub(super) fn placement(q: &Quadric, pu: Point3, pv: Point3) -> (Point3, f64) {
    let mid = (pu + pv) * 0.5;
    let reach_sq = MAX_OPTIMUM_OFFSET * MAX_OPTIMUM_OFFSET * pu.distance_squared(pv);
    let optimum = q
        .minimizer()
        .filter(|x| x.distance_squared(mid) <= reach_sq);
    let target = optimum.unwrap_or_else(|| q.minimizer_on_segment(pu, pv));
    (target, q.eval(target))
}

impl AddAssign for Quadric {
    #[inline]
    fn add_assign(&mut self, o: Quadric) {
        self.a00 += o.a00;
        self.a01 += o.a01;
        self.a02 += o.a02;
        self.a11 += o.a11;
        self.a12 += o.a12;
        self.a22 += o.a22;
        self.b += o.b;
        self.c += o.c;
    }
}

impl std::ops::Add for Quadric {
    type Output = Quadric;
    #[inline]
    fn add(mut self, o: Quadric) -> Quadric {
        self += o;
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn three_planes_meet_in_their_corner() {
        let corner = Point3::new(1.0, 2.0, 3.0);
        let q = Quadric::plane(Vec3::X, corner, 1.0)
            + Quadric::plane(Vec3::Y, corner, 2.0)
            + Quadric::plane(Vec3::Z, corner, 3.0);
        let x = q.minimizer().expect("three independent planes");
        assert!((x - corner).length() < 1e-12);
        assert!(q.eval(x) < 1e-20);
        assert!((q.eval(corner + Vec3::X) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn one_plane_is_singular_and_segment_minimum_is_clamped() {
        let q = Quadric::plane(Vec3::Z, Point3::ZERO, 1.0);
        assert!(q.minimizer().is_none());
        let m = q.minimizer_on_segment(Point3::new(0.0, 0.0, 1.0), Point3::new(0.0, 0.0, -3.0));
        assert!(m.z.abs() < 1e-12);
        let m = q.minimizer_on_segment(Point3::new(0.0, 0.0, 1.0), Point3::new(0.0, 0.0, 2.0));
        assert_eq!(m, Point3::new(0.0, 0.0, 1.0));
    }
}
