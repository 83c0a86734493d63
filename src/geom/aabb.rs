use super::Point3;
use serde::{Deserialize, Serialize};

/// An axis-aligned bounding box. `min <= max` component-wise for a non-empty box.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Aabb {
    /// Smallest corner.
    pub min: Point3,
    /// Largest corner.
    pub max: Point3,
}

impl Aabb {
    /// The box around `points`, or `None` when there are none.
    pub fn from_points(points: &[Point3]) -> Option<Aabb> {
        let first = *points.first()?;
        let mut b = Aabb {
            min: first,
            max: first,
        };
        for &p in &points[1..] {
            b.min = b.min.min(p);
            b.max = b.max.max(p);
        }
        Some(b)
    }

    /// Length of the box diagonal: the scale that relative tolerances (in %) refer to.
    pub fn diagonal(&self) -> f64 {
        (self.max - self.min).length()
    }

    /// Centre of the box.
    pub fn center(&self) -> Point3 {
        (self.min + self.max) * 0.5
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_of_points() {
        let b = Aabb::from_points(&[Point3::new(1.0, -2.0, 3.0), Point3::new(-1.0, 2.0, 0.0)])
            .expect("non-empty");
        assert_eq!(b.min, Point3::new(-1.0, -2.0, 0.0));
        assert_eq!(b.max, Point3::new(1.0, 2.0, 3.0));
        assert!((b.diagonal() - (4.0f64 + 16.0 + 9.0).sqrt()).abs() < 1e-12);
        assert!(Aabb::from_points(&[]).is_none());
    }
}
