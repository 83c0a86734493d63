//! The first step of a repair: faces that cannot be part of any surface are dropped — those
//! with fewer than three distinct corners and those of zero area.

use super::report::RepairReport;
use super::soup::Soup;
use crate::geom::{Point3, Vec3};
use crate::mesh::PolyMesh;

/// A face is of zero area when twice its area is below this fraction of the sum of its
/// squared side lengths: collinear corners to within rounding (a sliver of height h and
/// length l has the ratio h / 2l).
const ZERO_AREA_RATIO: f64 = 1e-12;

/// Whether a face whose doubled area is `twice_area` and whose squared sides sum to `sides`
/// has an area (false for NaN: an overflowed area is no area).
pub(crate) fn has_area(twice_area: f64, sides: f64) -> bool {
    twice_area > ZERO_AREA_RATIO * sides
}

/// The input's faces without degenerate and zero-area ones (counted in `report`). Repeated
/// corners in a row (`a a b c`) are merged first, as exporters write them for triangles
/// stored as quads; a corner repeated elsewhere in a face pinches it, and the face is dropped.
pub(super) fn clean(mesh: &PolyMesh, report: &mut RepairReport) -> Soup {
    let pos = mesh.positions();
    let mut starts = Vec::with_capacity(mesh.num_faces() + 1);
    starts.push(0u32);
    let mut idx = Vec::with_capacity(3 * mesh.num_faces());
    let mut origin = Vec::with_capacity(mesh.num_faces());
    let mut merged = Vec::new();
    for (f, face) in mesh.faces().enumerate() {
        merge_repeats(face, &mut merged);
        if merged.len() < 3 || has_repeat(&merged) {
            report.degenerate_faces.add(f);
        } else if zero_area(pos, &merged) {
            report.zero_area_faces.add(f);
        } else {
            idx.extend_from_slice(&merged);
            starts.push(idx.len() as u32);
            origin.push(f as u32);
        }
    }
    Soup::new(starts, idx, origin)
}

/// `face` with runs of one vertex (cyclically) reduced to one corner, into `out`.
fn merge_repeats(face: &[u32], out: &mut Vec<u32>) {
    out.clear();
    if let [a, b, c] = *face {
        if a != b && b != c && c != a {
            out.extend_from_slice(face);
            return;
        }
    }
    for (k, &v) in face.iter().enumerate() {
        if v != face[(k + 1) % face.len()] {
            out.push(v);
        }
    }
    if out.is_empty() && !face.is_empty() {
        out.push(face[0]);
    }
}

/// Whether a vertex occurs twice in `face`.
fn has_repeat(face: &[u32]) -> bool {
    if let [a, b, c] = *face {
        return a == b || b == c || a == c;
    }
    (1..face.len()).any(|k| face[..k].contains(&face[k]))
}

/// Whether the polygon `face` has zero area: its Newell normal (twice the area vector) is
/// negligible against its squared sides.
fn zero_area(pos: &[Point3], face: &[u32]) -> bool {
    if let [a, b, c] = *face {
        let [a, b, c] = [a, b, c].map(|v| pos[v as usize]);
        let sides = (b - a).length_squared() + (c - b).length_squared() + (a - c).length_squared();
        return !has_area((b - a).cross(c - a).length(), sides);
    }
    let mut normal = Vec3::ZERO;
    let mut sides = 0.0;
    let origin = pos[face[0] as usize];
    for k in 0..face.len() {
        let a = pos[face[k] as usize] - origin;
        let b = pos[face[(k + 1) % face.len()] as usize] - origin;
        normal += a.cross(b);
        sides += (b - a).length_squared();
    }
    !has_area(normal.length(), sides)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn repeated_corners_merge_or_pinch() {
        let mut out = Vec::new();
        merge_repeats(&[1, 1, 2, 3], &mut out);
        assert_eq!(out, vec![1, 2, 3]);
        merge_repeats(&[1, 2, 3, 1], &mut out);
        assert_eq!(out, vec![1, 2, 3]);
        merge_repeats(&[4, 4, 4], &mut out);
        assert_eq!(out, vec![4]);
        assert!(has_repeat(&[1, 2, 1, 3]));
        assert!(!has_repeat(&[1, 2, 3, 4]));
    }

    #[test]
    fn collinear_and_coincident_corners_have_zero_area() {
        let pos = [
            Point3::ZERO,
            Point3::X,
            Point3::new(2.0, 0.0, 0.0),
            Point3::Y,
            Point3::X,
        ];
        assert!(zero_area(&pos, &[0, 1, 2]));
        assert!(zero_area(&pos, &[0, 1, 4]));
        assert!(!zero_area(&pos, &[0, 1, 3]));
        // A thin but real sliver stays.
        let thin = [Point3::ZERO, Point3::X, Point3::new(0.5, 1e-6, 0.0)];
        assert!(!zero_area(&thin, &[0, 1, 2]));
    }
}
