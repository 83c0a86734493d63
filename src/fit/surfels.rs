//! The surface of bare points as discs ("surfels"): each data point stands for a small flat
//! disc of the scanned surface, in the plane of its nearest neighbours and as wide as the gap to
//! its neighbours, so that the discs together cover the surface the points were taken from.
//!
//! Bare points have no triangles to measure a fitted surface against (E_back, SPEC §6). The
//! mesh reconstructed from them is a poor stand-in: an implicit reconstruction is coarser than
//! the points and lies off them (on the corpus's vertices as bare points: spot's reconstruction
//! is up to 1.6 % of the diagonal from spot's own mesh, cheburashka's 9.6 %, the cow's 10.4 %),
//! so a fitted surface that lies on the points was measured as straying by as much. The discs
//! are measured from the points themselves. The reconstruction still says where the data has
//! holes (`DataSurface::of_points`).

use crate::geom::{principal_frame, Frame, Point3, Vec3};
use kiddo::immutable::float::kdtree::ImmutableKdTree;
use kiddo::SquaredEuclidean;
use std::num::NonZero;

/// Neighbours (the point itself included) whose least principal axis is a disc's normal.
const NORMAL_NEIGHBOURS: usize = 10;

/// A disc's radius is the distance to this nearest other point: on an even sampling the
/// fourth neighbour lies beyond the widest gap between the point's ring of neighbours, so the
/// discs overlap and leave no spot of the surface uncovered; a sparser neighbourhood gets wider
/// discs.
const RADIUS_NEIGHBOUR: usize = 4;

/// Discs tried per query, nearest centres first: the nearest centre's disc is not always the
/// nearest disc (a sample beside a wide disc of a sparse neighbour).
const QUERY_NEIGHBOURS: usize = 8;

/// The discs, in coordinates relative to the caller's origin (f32: compact storage).
pub(super) struct Surfels {
    tree: ImmutableKdTree<f32, u32, 3, 32>,
    centres: Vec<[f32; 3]>,
    /// Unit normals; zero where the neighbourhood is degenerate (coincident or collinear
    /// points), which makes that disc a ball.
    normals: Vec<[f32; 3]>,
    radii: Vec<f32>,
}

impl Surfels {
    /// The discs of `points` (relative to the caller's origin); `None` for no points.
    pub(super) fn new(points: &[Point3]) -> Option<Surfels> {
        if points.is_empty() {
            return None;
        }
        let centres: Vec<[f32; 3]> = points.iter().map(|p| p.as_vec3().to_array()).collect();
        let tree: ImmutableKdTree<f32, u32, 3, 32> = ImmutableKdTree::new_from_slice(&centres);
        let k = NonZero::new(
            NORMAL_NEIGHBOURS
                .max(RADIUS_NEIGHBOUR + 1)
                .min(points.len()),
        )?;
        let (normals, radii) = centres
            .iter()
            .map(|c| {
                let near = tree.nearest_n::<SquaredEuclidean>(c, k);
                let radius = near
                    .get(RADIUS_NEIGHBOUR)
                    .or(near.last())
                    .map_or(0.0, |n| n.distance.sqrt());
                let normal = plane_normal(near.iter().map(|n| at(&centres, n.item)));
                (normal.as_vec3().to_array(), radius)
            })
            .unzip();
        Some(Surfels {
            tree,
            centres,
            normals,
            radii,
        })
    }

    /// The distance from `p` (relative to the origin) to the nearest disc, and the nearest
    /// point of that disc.
    pub(super) fn closest(&self, p: Point3) -> Option<(f64, Point3)> {
        let k = NonZero::new(QUERY_NEIGHBOURS.min(self.centres.len()))?;
        let q = p.as_vec3().to_array();
        self.tree
            .nearest_n::<SquaredEuclidean>(&q, k)
            .iter()
            .map(|n| self.to_disc(n.item as usize, p))
            .min_by(|a, b| a.0.total_cmp(&b.0))
    }

    /// [`Surfels::closest`], and whether `p` lies within `radii` disc radii of its nearest
    /// point, from one search: there the points are dense enough to say where the surface
    /// is, so no hole of the data can be there, only a gap between neighbouring points.
    pub(super) fn closest_within(&self, p: Point3, radii: f64) -> Option<(f64, Point3, bool)> {
        let k = NonZero::new(QUERY_NEIGHBOURS.min(self.centres.len()))?;
        let near = self
            .tree
            .nearest_n::<SquaredEuclidean>(&p.as_vec3().to_array(), k);
        let nearest = near
            .iter()
            .min_by(|a, b| a.distance.total_cmp(&b.distance))?;
        let r = self
            .radii
            .get(nearest.item as usize)
            .copied()
            .unwrap_or(0.0) as f64;
        let within = (nearest.distance as f64).sqrt() <= radii * r;
        near.iter()
            .map(|n| self.to_disc(n.item as usize, p))
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .map(|(d, at)| (d, at, within))
    }

    /// The distance from `p` to disc `i` and the disc's point nearest to `p`.
    fn to_disc(&self, i: usize, p: Point3) -> (f64, Point3) {
        let c = at(&self.centres, i as u32);
        let n = Vec3::from_array(self.normals[i].map(f64::from));
        let r = self.radii[i] as f64;
        let d = p - c;
        let height = d.dot(n);
        let lateral = d - n * height;
        let across = lateral.length();
        let beyond = (across - r).max(0.0);
        let foot = if across > r {
            c + lateral * (r / across)
        } else {
            c + lateral
        };
        ((height * height + beyond * beyond).sqrt(), foot)
    }
}

fn at(centres: &[[f32; 3]], i: u32) -> Point3 {
    centres
        .get(i as usize)
        .map_or(Point3::ZERO, |c| Point3::from_array(c.map(f64::from)))
}

/// The least principal axis of `points`, or zero when they span no plane.
fn plane_normal(points: impl Iterator<Item = Point3> + Clone) -> Vec3 {
    let Frame { values, axes, .. } = principal_frame(points);
    if values[1] > 1e-12 * values[2] && values[2] > 0.0 && axes[0].is_finite() {
        axes[0]
    } else {
        Vec3::ZERO
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 21 × 21 grid of spacing 0.1 in z = 0.
    fn plane() -> Vec<Point3> {
        (0..21 * 21)
            .map(|k| Point3::new((k % 21) as f64 * 0.1, (k / 21) as f64 * 0.1, 0.0))
            .collect()
    }

    /// On the sampled plane, between the points, the distance is the height above it (the
    /// discs cover the gaps); beside the grid it grows as the distance to the last discs' rim.
    #[test]
    fn discs_cover_the_sampled_plane() {
        let s = Surfels::new(&plane()).expect("points");
        for (x, y) in [(0.05, 0.05), (1.03, 0.97), (0.55, 1.45)] {
            let (d, foot) = s.closest(Point3::new(x, y, 0.02)).expect("discs");
            assert!((d - 0.02).abs() < 1e-6, "({x}, {y}): {d}");
            assert!((foot - Point3::new(x, y, 0.0)).length() < 1e-6);
            let (d, _) = s.closest(Point3::new(x, y, 0.0)).expect("discs");
            assert!(d < 1e-6, "on the plane: {d}");
        }
        // 1 beyond the grid's edge at x = 2: the edge's discs reach 0.14 past it (the 4th
        // neighbour of an edge point is a diagonal one).
        let (d, _) = s.closest(Point3::new(3.0, 1.0, 0.0)).expect("discs");
        assert!((0.75..=0.95).contains(&d), "{d}");
    }

    /// A sample above the middle of a sphere's sampling is measured to the sphere, not to the
    /// nearest point: the distance is the height less the discs' small sagitta.
    #[test]
    fn discs_follow_a_curved_surface() {
        let n = 2000;
        let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
        let points: Vec<Point3> = (0..n)
            .map(|i| {
                let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
                let r = (1.0 - z * z).sqrt();
                let a = golden * i as f64;
                Point3::new(r * a.cos(), r * a.sin(), z)
            })
            .collect();
        let s = Surfels::new(&points).expect("points");
        for dir in [Vec3::X, Vec3::new(1.0, 2.0, -0.5).normalize(), -Vec3::Z] {
            for height in [0.0, 0.01, 0.05] {
                let (d, _) = s
                    .closest(Point3::ZERO + dir * (1.0 + height))
                    .expect("discs");
                assert!((d - height).abs() < 0.004, "{dir:?} {height}: {d}");
            }
        }
    }

    /// Coincident points make balls, not NaN.
    #[test]
    fn degenerate_neighbourhoods() {
        let s = Surfels::new(&[Point3::ONE; 5]).expect("points");
        let (d, foot) = s.closest(Point3::new(1.0, 1.0, 2.0)).expect("discs");
        assert!((d - 1.0).abs() < 1e-6 && foot.is_finite(), "{d} {foot:?}");
        assert!(Surfels::new(&[]).is_none());
    }
}
