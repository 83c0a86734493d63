//! Garland–Heckbert error quadrics: the sum of squared distances to a set of weighted planes,
//! stored as the symmetric form Q(x) = xᵀAx + 2bᵀx + c.

use crate::geom::{Point3, Vec3};
use glam::DMat3;
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

    fn matrix(&self) -> DMat3 {
        DMat3::from_cols_array(&[
            self.a00, self.a01, self.a02, self.a01, self.a11, self.a12, self.a02, self.a12,
            self.a22,
        ])
    }

    /// The error at `p`; never negative (rounding is clamped).
    pub(super) fn eval(&self, p: Point3) -> f64 {
        let ap = self.matrix() * p;
        (p.dot(ap) + 2.0 * self.b.dot(p) + self.c).max(0.0)
    }

    /// The point minimising the error, or `None` when A is (nearly) singular. Solved by
    /// cofactors (what `DMat3::inverse` does, computed once for the singularity test too).
    pub(super) fn minimizer(&self) -> Option<Point3> {
        let a = self.matrix();
        let cof = [
            a.y_axis.cross(a.z_axis),
            a.z_axis.cross(a.x_axis),
            a.x_axis.cross(a.y_axis),
        ];
        let det = a.x_axis.dot(cof[0]);
        let norm_sq = [self.a00, self.a11, self.a22]
            .iter()
            .map(|v| v * v)
            .sum::<f64>()
            + 2.0 * (self.a01 * self.a01 + self.a02 * self.a02 + self.a12 * self.a12);
        let scale = norm_sq * norm_sq.sqrt();
        if det.is_nan() || det.abs() <= SINGULAR_RATIO * scale {
            return None;
        }
        let inv_det = 1.0 / det;
        let inverse = DMat3::from_cols(cof[0] * inv_det, cof[1] * inv_det, cof[2] * inv_det);
        let x = inverse.transpose() * (-self.b);
        x.is_finite().then_some(x)
    }

    /// The point minimising the error on the segment `p`–`q` (closed form of a 1D quadratic).
    pub(super) fn minimizer_on_segment(&self, p: Point3, q: Point3) -> Point3 {
        let d = q - p;
        let a = self.matrix();
        // Q(p + t d) = t² dᵀAd + 2t (dᵀAp + bᵀd) + const.
        let curv = d.dot(a * d);
        let slope = d.dot(a * p) + self.b.dot(d);
        if curv.is_nan() || curv <= 0.0 {
            return p;
        }
        let t = (-slope / curv).clamp(0.0, 1.0);
        p + d * t
    }
}

impl AddAssign for Quadric {
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
