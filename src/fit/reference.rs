//! The data as a surface, to measure the fit the other way round: how far the fitted surface
//! strays from the data (surface → data, "E_back"). E_avg and E_max only say how close the data
//! is to the surface; a surface can hold every data point and still have sheets and spikes where
//! no data point pulls on it (SPEC §6). This module measures those.
//!
//! The data surface is the data's triangles (the input mesh), in an R-tree (`rstar`) whose
//! nearest-neighbour query is exact. Bare points are measured to their own local planes
//! ([`super::surfels`]), and the mesh reconstructed from them only says where they have holes. A sample whose
//! nearest data point lies on a boundary edge of the data, or whose nearest boundary point is
//! hardly farther than its nearest data point ([`RIM_FACTOR`]), spans a hole or lies beyond the
//! data's outline — a surface may span holes (SPEC §6) — and is left out of the statistics. On a
//! closed mesh nothing is left out. The data's triangles are flat where the scanned surface is
//! not, so each distance is taken less the triangle's own [`sagitta`].

use super::surfels::Surfels;
use crate::geom::{Point3, Vec3};
use crate::mesh::PolyMesh;
use kiddo::immutable::float::kdtree::ImmutableKdTree;
use kiddo::SquaredEuclidean;
use rstar::{PointDistance, RStarInsertionStrategy, RTree, RTreeObject, RTreeParams, AABB};
use serde::{Deserialize, Serialize};

/// A sample whose nearest point on the data's boundary (the rim of a hole, the outline) is at
/// most this many times as far as its nearest data point spans a hole: a surface sagging across
/// a hole can come nearer to the data beyond the rim than to the rim itself, but not by much.
pub const RIM_FACTOR: f64 = 2.0;

/// Bare points: a sample within this many disc radii of its nearest point (a radius is the
/// distance to the point's 4th neighbour, about two point spacings) is measured whatever the
/// reconstruction's boundary says: a gap that narrow lies between neighbouring points, not over
/// a hole. Without it, homer's vertices as bare points fitted with Doo–Sabin "converged" at
/// E_back 0.94 % with a sheet 2.7 % from homer's mesh, 2.85 % from the nearest point where the
/// points are 1.1–1.5 % apart, over a hole that dropping the implicit surface's strays had
/// opened in the closed object's reconstruction.
pub const HOLE_RADII: f64 = 3.0;

/// How far from its nearest vertex of a triangle, in the longest edge of that vertex's
/// triangles, a query may lie and still start from it ([`DataSurface::seed_bound`]): farther,
/// the box that bound spans holds many triangles, and the R-tree's best-first search finds the
/// nearest sooner.
const SEED_REACH: f64 = 2.0;

/// How many triangles farther than the nearest found [`DataSurface::search_f32`] looks at
/// before it stops, when f32 cannot order them (equally near ones are all looked at).
const MAX_TIED: usize = 64;

/// The surface → data distances of one fitted surface: their largest and 99th-percentile values
/// in % of the data's bounding-box diagonal, over the samples that lie over data.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct BackStats {
    /// Largest distance of a surface sample to the data, % of the diagonal.
    pub max_pct: f64,
    /// 99th percentile of those distances, %.
    pub p99_pct: f64,
    /// Samples measured.
    pub samples: usize,
    /// Samples left out as spanning a hole of the data or lying beyond its outline.
    pub over_holes: usize,
}

impl BackStats {
    /// The statistics of surface → data `distances` (`None`: a sample over a hole), relative
    /// to a bounding-box `diagonal`.
    pub fn of(distances: &[Option<f64>], diagonal: f64) -> BackStats {
        BackStats::of_mixed(distances, distances.len(), diagonal)
    }

    /// [`BackStats::of`] where only the first `uniform` of `distances` sample the surface
    /// evenly and the rest sample parts of it more finely (where it strays): all count for
    /// the maximum, only the even ones for the percentile, which the fine ones would skew.
    pub(crate) fn of_mixed(distances: &[Option<f64>], uniform: usize, diagonal: f64) -> BackStats {
        let (even, fine) = distances.split_at(uniform.min(distances.len()));
        let mut d: Vec<f64> = even.iter().flatten().copied().collect();
        let fine: Vec<f64> = fine.iter().flatten().copied().collect();
        let samples = d.len() + fine.len();
        let over_holes = distances.len() - samples;
        if samples == 0 {
            return BackStats {
                over_holes,
                ..BackStats::default()
            };
        }
        let pct = if diagonal > 0.0 {
            100.0 / diagonal
        } else {
            0.0
        };
        let max = d.iter().chain(&fine).copied().fold(0.0f64, f64::max);
        let p99 = if d.is_empty() {
            max
        } else {
            let k = ((d.len() as f64 * 0.99).ceil() as usize).clamp(1, d.len()) - 1;
            *d.select_nth_unstable_by(k, f64::total_cmp).1
        };
        BackStats {
            max_pct: max * pct,
            p99_pct: p99 * pct,
            samples,
            over_holes,
        }
    }
}

/// The largest turn of the data's normals across one triangle that [`sagitta`] credits to the
/// triangle's flatness; more is a crease, which a smooth surface rounds off for real.
const MAX_TURN: f64 = std::f64::consts::FRAC_PI_6;

/// One data triangle in the R-tree: its corners (f32, compact storage, relative to
/// [`DataSurface::origin`]), which of its edges
/// and corners lie on the data's boundary (bit k: edge from corner k to corner k + 1; bit 3 + k:
/// corner k), and its [`sagitta`].
struct Triangle {
    corners: [[f32; 3]; 3],
    boundary: u8,
    sagitta: f32,
    /// Its index in the data's triangle list: the tie-break between triangles equally near a
    /// query (they may differ in sagitta), so the answer never depends on how it was found.
    index: u32,
}

impl Triangle {
    fn points(&self) -> [Point3; 3] {
        self.corners
            .map(|[x, y, z]| Point3::new(x as f64, y as f64, z as f64))
    }

    /// The squared distance from `p` to the triangle, in f64: what decides the nearest.
    fn dist_sq(&self, p: Point3) -> f64 {
        let [a, b, c] = self.points();
        (p - closest_on_triangle(p, a, b, c).0).length_squared()
    }
}

/// The tree's boxes and queries are f32, as the corners are: f64 boxes made every node of the
/// tree 80 bytes instead of 56 (rstar's node is an enum of a leaf and a parent, whose box is
/// two points), 221 bytes a data point on a 2-million-point scan. Queries round their boxes
/// outwards and every candidate's distance is then taken in f64 ([`Triangle::dist_sq`]), so
/// the answer is what an f64 tree gives.
impl RTreeObject for Triangle {
    type Envelope = AABB<[f32; 3]>;

    fn envelope(&self) -> Self::Envelope {
        let [a, b, c] = self.corners;
        let corner =
            |pick: fn(f32, f32) -> f32| std::array::from_fn(|k| pick(pick(a[k], b[k]), c[k]));
        AABB::from_corners(corner(f32::min), corner(f32::max))
    }
}

/// The distance to the f32 query point, for the R-tree's own best-first search
/// ([`DataSurface::nearest`] settles the answer in f64).
impl PointDistance for Triangle {
    fn distance_2(&self, p: &[f32; 3]) -> f32 {
        self.dist_sq(Point3::from_array(p.map(f64::from))) as f32
    }
}

/// The f32 box that holds the f64 box `lo`..`hi`: its corners rounded outwards.
fn outward_box(lo: Point3, hi: Point3) -> AABB<[f32; 3]> {
    let below = |x: f64| {
        let y = x as f32;
        if f64::from(y) > x {
            next_f32(y, -1)
        } else {
            y
        }
    };
    let above = |x: f64| {
        let y = x as f32;
        if f64::from(y) < x {
            next_f32(y, 1)
        } else {
            y
        }
    };
    AABB::from_corners(lo.to_array().map(below), hi.to_array().map(above))
}

/// The f32 next to finite or infinite `y` towards +∞ (`step` 1) or −∞ (−1); `f32::next_up`
/// and `next_down` need a newer Rust than the crate's minimum.
fn next_f32(y: f32, step: i32) -> f32 {
    if y.is_nan() || (y.is_infinite() && (y > 0.0) == (step > 0)) {
        return y;
    }
    if y == 0.0 {
        let tiny = f32::from_bits(1);
        return if step > 0 { tiny } else { -tiny };
    }
    let bits = y.to_bits();
    let away = (y > 0.0) == (step > 0);
    f32::from_bits(if away { bits + 1 } else { bits - 1 })
}

/// The triangles' R-tree nodes: up to [`NODE_SIZE`] children.
struct TreeParams;

/// Children per node of the triangles' R-tree. rstar's default of 6 makes a parent node (and
/// its allocation) for every 3–6 triangles; 24 makes a quarter as many. On the 2.2 M-point
/// scan at the defaults (Loop) peak RSS went 1,208 → 1,084 MB (543 → 487 bytes a point;
/// 12: 1,113 MB, 20: 1,105), and a query checks more boxes per node: the bunny's model C fit
/// spends 16 % more in its surface → data queries (1.49 → 1.73 s, 5 % of the whole fit).
/// The answers do not depend on it (the tie rule of [`DataSurface::nearest`]).
const NODE_SIZE: usize = 24;

impl RTreeParams for TreeParams {
    const MIN_SIZE: usize = NODE_SIZE / 2;
    const MAX_SIZE: usize = NODE_SIZE;
    const REINSERTION_COUNT: usize = NODE_SIZE / 3;
    type DefaultInsertionStrategy = RStarInsertionStrategy;
}

/// A boundary edge of the data, for the distance to the data's rim.
struct Rim([[f64; 3]; 2]);

impl RTreeObject for Rim {
    type Envelope = AABB<[f64; 3]>;

    fn envelope(&self) -> Self::Envelope {
        let [a, b] = self.0.map(Point3::from_array);
        AABB::from_corners(a.min(b).to_array(), a.max(b).to_array())
    }
}

impl PointDistance for Rim {
    fn distance_2(&self, p: &[f64; 3]) -> f64 {
        let [a, b] = self.0.map(Point3::from_array);
        let p = Point3::from_array(*p);
        let ab = b - a;
        let t = ((p - a).dot(ab) / ab.length_squared().max(f64::MIN_POSITIVE)).clamp(0.0, 1.0);
        (p - (a + ab * t)).length_squared()
    }
}

/// The data's triangles, indexed for nearest-point queries.
pub struct DataSurface {
    /// The centre of the data's bounding box. Everything below is stored and queried relative
    /// to it: f32 corners of a scan in survey coordinates (UTM, millions of metres from the
    /// origin) would otherwise be rounded to a quarter of a metre.
    origin: Point3,
    tree: RTree<Triangle, TreeParams>,
    /// Where a query starts ([`DataSurface::seed_bound`]): the vertices of the data's
    /// triangles (relative to the origin), each with the longest edge of its triangles
    /// (`reach`, by the kd-tree's item).
    vertices: ImmutableKdTree<f32, u32, 3, 32>,
    reach: Vec<f32>,
    /// The boundary edges (none on a closed mesh).
    rim: RTree<Rim>,
    /// The data points in no triangle (a scanner's points in a hole of the mesh, say): the
    /// surface may pass between them. Each stands for a disc of surface as wide as the distance
    /// to its nearest other point (`loose_spacing`), so a sample's distance to one is counted
    /// less that spacing.
    loose: Option<ImmutableKdTree<f32, u32, 3, 32>>,
    loose_points: Vec<[f32; 3]>,
    loose_spacing: Vec<f32>,
    /// Bare points' discs ([`DataSurface::of_points`]): distances are measured to them, the
    /// triangles only tell holes.
    surfels: Option<Surfels>,
}

impl std::fmt::Debug for DataSurface {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DataSurface")
            .field("triangles", &self.tree.size())
            .field("loose points", &self.loose.as_ref().map_or(0, |t| t.size()))
            .finish()
    }
}

/// Where on the data surface a query landed.
struct Foot {
    /// The nearest point, relative to the origin.
    point: Point3,
    dist_sq: f64,
    on_boundary: bool,
    sagitta: f64,
}

impl DataSurface {
    /// The surface of `mesh`'s faces (polygons fanned into triangles); `None` without faces.
    pub fn of_mesh(mesh: &PolyMesh) -> Option<DataSurface> {
        let triangles = mesh.triangles();
        if triangles.is_empty() {
            return None;
        }
        let origin = mesh.bbox()?.center();
        let local: Vec<Point3> = mesh.positions().iter().map(|&p| p - origin).collect();
        let positions: Vec<[f32; 3]> = local.iter().map(|p| p.as_vec3().to_array()).collect();
        let boundary = boundary_edges(&triangles);
        let mut on_boundary = vec![false; positions.len()];
        for (t, &b) in triangles.iter().zip(&boundary) {
            for k in 0..3 {
                if b & (1 << k) != 0 {
                    on_boundary[t[k] as usize] = true;
                    on_boundary[t[(k + 1) % 3] as usize] = true;
                }
            }
        }
        let mut rim = Vec::new();
        for (t, &b) in triangles.iter().zip(&boundary) {
            for k in 0..3 {
                if b & (1 << k) != 0 {
                    let at = |i: u32| local[i as usize].to_array();
                    rim.push(Rim([at(t[k]), at(t[(k + 1) % 3])]));
                }
            }
        }
        let normals = vertex_normals(mesh.positions(), &triangles);
        let objects = triangles
            .iter()
            .zip(&boundary)
            .enumerate()
            .map(|(index, (t, &b))| Triangle {
                index: index as u32,
                corners: t.map(|i| positions[i as usize]),
                boundary: (0..3).fold(b, |m, k| {
                    m | (u8::from(on_boundary[t[k] as usize]) << (3 + k))
                }),
                sagitta: sagitta(
                    t.map(|i| mesh.positions()[i as usize]),
                    t.map(|i| normals[i as usize]),
                ) as f32,
            })
            .collect();
        let mut used = vec![false; positions.len()];
        for t in &triangles {
            for &v in t {
                used[v as usize] = true;
            }
        }
        let loose: Vec<[f32; 3]> = positions
            .iter()
            .zip(&used)
            .filter(|(_, &u)| !u)
            .map(|(p, _)| *p)
            .collect();
        let (vertices, reach) = seed_vertices(&positions, &triangles);
        let loose_tree = (!loose.is_empty()).then(|| ImmutableKdTree::new_from_slice(&loose));
        let loose_spacing = loose_tree
            .as_ref()
            .map_or_else(Vec::new, |t| spacing(&loose, t, &vertices));
        Some(DataSurface {
            origin,
            tree: RTree::bulk_load_with_params(objects),
            vertices,
            reach,
            rim: RTree::bulk_load(rim),
            loose: loose_tree,
            loose_points: loose,
            loose_spacing,
            surfels: None,
        })
    }

    /// The surface of bare `points`: each point's disc in the plane of its neighbours
    /// ([`Surfels`]), with `reconstruction` (the mesh made of the points) telling where the
    /// points have holes or end. A reconstruction is coarser than the points and lies off
    /// them, so distances to its triangles would count a surface on the points as straying.
    /// `None` without points or without faces.
    pub fn of_points(points: &[Point3], reconstruction: &PolyMesh) -> Option<DataSurface> {
        let mut surface = DataSurface::of_mesh(reconstruction)?;
        let local: Vec<Point3> = points.iter().map(|&p| p - surface.origin).collect();
        surface.surfels = Some(Surfels::new(&local)?);
        Some(surface)
    }

    /// The distance from `p` to the data surface, less the [`sagitta`] of the data triangle
    /// nearest to it, or `None` when `p`'s nearest data point is on the data's boundary (over a
    /// hole, or beyond the outline).
    pub fn distance(&self, p: Point3) -> Option<f64> {
        self.closest(p).map(|(d, _)| d)
    }

    /// [`DataSurface::distance`] with the nearest data point it is measured to (the point a
    /// straying surface is pulled towards).
    pub fn closest(&self, p: Point3) -> Option<(f64, Point3)> {
        let p = p - self.origin;
        if let (Some(surfels), 0, None) = (&self.surfels, self.rim.size(), &self.loose) {
            // A closed reconstruction has no hole to tell: only the discs matter.
            return p
                .is_finite()
                .then(|| surfels.closest(p))
                .flatten()
                .map(|(d, at)| (d, at + self.origin));
        }
        let foot = self.nearest(p)?;
        let loose = self.loose.as_ref().map(|t| {
            let q = [p.x as f32, p.y as f32, p.z as f32];
            let n = t.nearest_one::<SquaredEuclidean>(&q);
            let spacing = self
                .loose_spacing
                .get(n.item as usize)
                .copied()
                .unwrap_or(0.0);
            let at = self
                .loose_points
                .get(n.item as usize)
                .map_or(p, |&c| Point3::from_array(c.map(f64::from)));
            (((n.distance as f64).sqrt() - spacing as f64).max(0.0), at)
        });
        if let Some((d, at)) = loose.filter(|(d, _)| d * d < foot.dist_sq) {
            return Some((d, at + self.origin));
        }
        // Bare points: near a point (a few disc radii) is no hole, whatever the
        // reconstruction's boundary says there (an implicit surface's dropped strays open
        // holes in closed objects where the points are sparse).
        let near = self
            .surfels
            .as_ref()
            .and_then(|s| s.closest_within(p, HOLE_RADII));
        let sampled = near.is_some_and(|(_, _, within)| within);
        let near_rim = || {
            self.rim
                .locate_within_distance(p.to_array(), RIM_FACTOR * RIM_FACTOR * foot.dist_sq)
                .next()
                .is_some()
        };
        if !sampled && (foot.on_boundary || near_rim()) {
            return None;
        }
        if self.surfels.is_some() {
            return near.map(|(d, at, _)| (d, at + self.origin));
        }
        Some((
            (foot.dist_sq.sqrt() - foot.sagitta).max(0.0),
            foot.point + self.origin,
        ))
    }

    /// The distance of every one of `samples` to the data ([`DataSurface::distance`]), on
    /// several threads when there are many (the same result on any number).
    pub fn distances(&self, samples: &[Point3]) -> Vec<Option<f64>> {
        super::parallel::map(samples, |&p| self.distance(p))
    }

    /// The surface → data statistics of `samples` (points of a fitted surface), relative to a
    /// bounding-box `diagonal`.
    pub fn measure(&self, samples: &[Point3], diagonal: f64) -> BackStats {
        BackStats::of(&self.distances(samples), diagonal)
    }

    /// The nearest point of the data surface to `p` (relative to the origin), and whether it
    /// lies on the data's boundary.
    ///
    /// Why not the R-tree's own nearest-neighbour query: its best-first search with a heap took
    /// a third of a bunny fit (every iteration measures tens of thousands of samples, each
    /// hardly off the data). A sample near the data is about as near to the nearest vertex of
    /// a triangle, so that distance is a close bound ([`DataSurface::seed_bound`]) and the
    /// R-tree only has to list the few triangles whose boxes reach within it. Of the triangles
    /// equally near, the first in the data's order counts, however they were found.
    fn nearest<'a>(&'a self, p: Point3) -> Option<Foot> {
        if !p.is_finite() {
            return None;
        }
        let mut best: Option<(f64, &'a Triangle)> = None;
        let mut consider = |t: &'a Triangle| {
            let d = t.dist_sq(p);
            if best.is_none_or(|(bd, bt)| d < bd || (d == bd && t.index < bt.index)) {
                best = Some((d, t));
            }
        };
        match self.seed_bound(p) {
            Some(bound) => {
                // Widened by a little more than rounding: the box must hold the nearest point.
                let r = bound.sqrt() * (1.0 + 1e-9) + f64::EPSILON * p.abs().max_element();
                self.tree
                    .locate_in_envelope_intersecting(&outward_box(p - r, p + r))
                    .for_each(&mut consider);
            }
            None => self.search_f32(p, &mut consider),
        }
        let t = best?.1;
        let [a, b, c] = t.points();
        let (point, feature) = closest_on_triangle(p, a, b, c);
        let mask = t.boundary;
        let on_boundary = match feature {
            Feature::Face => false,
            Feature::Edge(k) => mask & (1 << k) != 0,
            Feature::Vertex(k) => mask & (1 << (3 + k)) != 0,
        };
        Some(Foot {
            point,
            dist_sq: (p - point).length_squared(),
            on_boundary,
            sagitta: t.sagitta as f64,
        })
    }

    /// The R-tree's best-first search from `p` rounded to f32, handing `consider` every
    /// triangle that can be the nearest to `p` itself: the rounding moves the query by
    /// `shift`, so the f32 order can put a triangle up to `shift` nearer or farther than it
    /// is, and the search goes on until the f32 distances pass the nearest exact one found by
    /// more than that (or [`MAX_TIED`] triangles later, for a query so far out that f32 cannot
    /// tell the triangles apart at all).
    fn search_f32<'a>(&'a self, p: Point3, consider: &mut impl FnMut(&'a Triangle)) {
        let q = p.as_vec3();
        let shift = (p - q.as_dvec3()).length();
        let mut nearest = f64::INFINITY;
        let mut beyond = 0;
        for (t, d) in self
            .tree
            .nearest_neighbor_iter_with_distance_2(&q.to_array())
        {
            // The f32 distance is rounded too: a relative 1e-6 covers it.
            if f64::from(d).sqrt() * (1.0 - 1e-6) > nearest + 2.0 * shift {
                break;
            }
            let exact = t.dist_sq(p).sqrt();
            if exact > nearest {
                beyond += 1;
                if beyond > MAX_TIED {
                    break;
                }
            }
            nearest = nearest.min(exact);
            consider(t);
        }
    }

    /// An upper bound of the squared distance from `p` to the data's triangles that is close
    /// to it: the distance to the nearest vertex of a triangle, widened by the f32 rounding of
    /// the kd-tree's query and distance. `None` where that bound would be loose — `p` farther
    /// from the vertex than [`SEED_REACH`] of its triangles' longest edge — and the R-tree's
    /// own search is quicker.
    ///
    /// Why the vertex and not the nearest of its triangles (a tighter bound, 2026-12-07
    /// before): that needed every vertex's triangles and their corners beside the R-tree,
    /// 68 bytes a data point on a 2-million-point scan; the box the vertex's distance spans
    /// holds a few more triangles, whose distances are cheap.
    fn seed_bound(&self, p: Point3) -> Option<f64> {
        let q = p.as_vec3();
        let near = self.vertices.nearest_one::<SquaredEuclidean>(&q.to_array());
        let shift = (p - q.as_dvec3()).length();
        let reach = f64::from(*self.reach.get(near.item as usize)?);
        let r = f64::from(near.distance).sqrt() * (1.0 + 1e-5) + shift;
        (r <= SEED_REACH * reach).then_some(r * r)
    }
}

/// The distance from each of the `loose` points (in the kd-tree `tree`) to its nearest other
/// data point: another loose one or a vertex of the triangles (`vertices`).
fn spacing(
    loose: &[[f32; 3]],
    tree: &ImmutableKdTree<f32, u32, 3, 32>,
    vertices: &ImmutableKdTree<f32, u32, 3, 32>,
) -> Vec<f32> {
    let two = std::num::NonZero::<usize>::new(2).unwrap_or(std::num::NonZero::<usize>::MIN);
    loose
        .iter()
        .map(|q| {
            // The nearest loose point is the point itself.
            let other = tree.nearest_n::<SquaredEuclidean>(q, two);
            let other = other.get(1).map_or(f32::INFINITY, |n| n.distance);
            let vertex = vertices.nearest_one::<SquaredEuclidean>(q).distance;
            other.min(vertex).sqrt()
        })
        .collect()
}

/// The kd-tree of the vertices of `triangles` (of `positions`) and, by its items, the
/// longest edge of each vertex's triangles.
fn seed_vertices(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
) -> (ImmutableKdTree<f32, u32, 3, 32>, Vec<f32>) {
    let mut longest = vec![-1.0f32; positions.len()];
    for t in triangles {
        let [a, b, c] = t.map(|i| Point3::from_array(positions[i as usize].map(f64::from)));
        let edge = a.distance(b).max(b.distance(c)).max(c.distance(a)) as f32;
        for &v in t {
            longest[v as usize] = longest[v as usize].max(edge);
        }
    }
    let used: Vec<usize> = (0..positions.len())
        .filter(|&v| longest[v] >= 0.0)
        .collect();
    let points: Vec<[f32; 3]> = used.iter().map(|&v| positions[v]).collect();
    let reach = used.iter().map(|&v| longest[v]).collect();
    (ImmutableKdTree::new_from_slice(&points), reach)
}

/// How far a smooth surface through the corners of a data triangle may bulge from the flat
/// triangle because the data is faceted, not because the fit strays. On a sphere through the
/// corners of an equilateral triangle of edge h whose vertex normals turn by θ (radius h/θ),
/// the centre of the triangle lies (h²/3)/(2 · h/θ) = hθ/6 inside it. θ is the largest angle
/// between the corners' vertex normals (at most [`MAX_TURN`]), h the longest edge. On a unit
/// icosphere of 642 vertices (edges 0.13) that is 0.0028, 0.08 % of its diagonal: more than
/// the default E_max tolerance, on the data's side alone.
fn sagitta(corners: [Point3; 3], normals: [Vec3; 3]) -> f64 {
    let mut h = 0.0f64;
    let mut turn = 0.0f64;
    for k in 0..3 {
        let j = (k + 1) % 3;
        h = h.max(corners[k].distance(corners[j]));
        turn = turn.max(libm::acos(normals[k].dot(normals[j]).clamp(-1.0, 1.0)));
    }
    let s = h * turn.min(MAX_TURN) / 6.0;
    if s.is_finite() {
        s
    } else {
        0.0
    }
}

/// Area-weighted vertex normals of `triangles` (zero for a vertex of no or only degenerate
/// triangles).
fn vertex_normals(positions: &[Point3], triangles: &[[u32; 3]]) -> Vec<Vec3> {
    crate::geom::area_weighted_normal_sums(positions, triangles)
        .iter()
        .map(|n| n.normalize_or_zero())
        .collect()
}

/// Which part of a triangle a closest point lies on.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Feature {
    Face,
    /// Edge from corner k to corner k + 1.
    Edge(usize),
    /// Corner k.
    Vertex(usize),
}

/// The closest point of triangle abc to p (Ericson, Real-Time Collision Detection 5.1.5), and
/// the feature it lies on.
fn closest_on_triangle(p: Point3, a: Point3, b: Point3, c: Point3) -> (Point3, Feature) {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, Feature::Vertex(0));
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return (b, Feature::Vertex(1));
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return (a + ab * (d1 / (d1 - d3)), Feature::Edge(0));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return (c, Feature::Vertex(2));
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return (a + ac * (d2 / (d2 - d6)), Feature::Edge(2));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (b + (c - b) * w, Feature::Edge(1));
    }
    let denom = va + vb + vc;
    if denom.is_nan() || denom.abs() <= f64::MIN_POSITIVE {
        // A degenerate (zero-area) triangle: its nearest corner.
        let best = [a, b, c]
            .into_iter()
            .enumerate()
            .min_by(|x, y| {
                (p - x.1)
                    .length_squared()
                    .total_cmp(&(p - y.1).length_squared())
            })
            .map_or(0, |(k, _)| k);
        return ([a, b, c][best], Feature::Vertex(best));
    }
    let (v, w) = (vb / denom, vc / denom);
    (a + ab * v + ac * w, Feature::Face)
}

/// Per triangle, the bit mask of its edges that no other triangle shares.
fn boundary_edges(triangles: &[[u32; 3]]) -> Vec<u8> {
    // Every edge of every triangle under its undirected key, sorted: a key that occurs once is
    // open. A sort, not a hash map: hashing the 13 M edges of a 2.2 M-point scan took 4.5 s of
    // its 19 s set-up.
    let key = |a: u32, b: u32| (u64::from(a.min(b)) << 32) | u64::from(a.max(b));
    let mut edges: Vec<(u64, usize)> = triangles
        .iter()
        .enumerate()
        .flat_map(|(i, t)| (0..3).map(move |k| (key(t[k], t[(k + 1) % 3]), 3 * i + k)))
        .collect();
    edges.sort_unstable_by_key(|&(k, _)| k);
    let mut open = vec![0u8; triangles.len()];
    for run in edges.chunk_by(|a, b| a.0 == b.0) {
        if let [(_, e)] = run {
            open[e / 3] |= 1 << (e % 3);
        }
    }
    open
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Vec3;

    #[test]
    fn an_edge_is_open_when_no_other_triangle_has_it() {
        // Triangles over few vertices (so edges repeat, in both directions, and some
        // triangles are degenerate), against counting every edge among all the others.
        let mut state = 12345u64;
        let mut next = |n: u64| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 33) % n) as u32
        };
        let triangles: Vec<[u32; 3]> = (0..300).map(|_| [next(12), next(12), next(12)]).collect();
        let key = |a: u32, b: u32| (a.min(b), a.max(b));
        let edges = |t: &[u32; 3]| {
            (0..3)
                .map(|k| key(t[k], t[(k + 1) % 3]))
                .collect::<Vec<_>>()
        };
        let all: Vec<_> = triangles.iter().flat_map(edges).collect();
        let open = boundary_edges(&triangles);
        for (t, &mask) in triangles.iter().zip(&open) {
            for (k, e) in edges(t).into_iter().enumerate() {
                let once = all.iter().filter(|&&x| x == e).count() == 1;
                assert_eq!(mask & (1 << k) != 0, once, "{t:?} edge {k}");
            }
        }
        assert!(open.iter().any(|&m| m != 0) && open.iter().any(|&m| m != 7));
    }

    #[test]
    fn fine_samples_count_for_the_maximum_but_not_the_percentile() {
        // 200 even samples at 1 (one over a hole), then 10 fine ones at 5, one at 9.
        let mut d = vec![Some(1.0); 200];
        d[7] = None;
        d.extend(vec![Some(5.0); 10]);
        d.push(Some(9.0));
        let s = BackStats::of_mixed(&d, 200, 100.0);
        assert_eq!((s.max_pct, s.p99_pct), (9.0, 1.0));
        assert_eq!((s.samples, s.over_holes), (210, 1));
        let all = BackStats::of(&d, 100.0);
        assert_eq!((all.max_pct, all.p99_pct), (9.0, 5.0));
        // Only fine samples: the percentile is the maximum.
        let s = BackStats::of_mixed(&d[200..], 0, 100.0);
        assert_eq!((s.max_pct, s.p99_pct), (9.0, 9.0));
    }

    /// The seeded search ([`DataSurface::nearest`]) finds what a search of every triangle
    /// finds — the same distance, and of equally near triangles the first, whose sagitta and
    /// boundary flags count — for queries on, near and far from an uneven, bumpy mesh with
    /// holes and loose vertices.
    #[test]
    fn seeded_search_finds_the_nearest_triangle_of_all() {
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut random = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let n = 24;
        let mut positions = Vec::new();
        for i in 0..n {
            for j in 0..n {
                let (x, y) = (i as f64 + 0.4 * random(), j as f64 + 0.4 * random());
                positions.push(Point3::new(x, y, (0.7 * x).sin() * (0.4 * y).cos() * 2.0));
            }
        }
        let mut faces = Vec::new();
        for i in 0..n - 1 {
            for j in 0..n - 1 {
                if random() < 0.08 {
                    continue; // a hole
                }
                let v = (i * n + j) as u32;
                faces.push([v, v + 1, v + n as u32 + 1]);
                faces.push([v, v + n as u32 + 1, v + n as u32]);
            }
        }
        positions.push(Point3::new(5.0, 5.0, 9.0)); // in no face
        let mesh = PolyMesh::try_new(positions, faces).expect("valid");
        let s = DataSurface::of_mesh(&mesh).expect("faces");
        let everything: Vec<&Triangle> = s.tree.iter().collect();
        for k in 0..3000 {
            let height = [0.0, 0.05, 0.5, 3.0, 30.0][k % 5];
            let p = Point3::new(
                -3.0 + (n as f64 + 6.0) * random(),
                -3.0 + (n as f64 + 6.0) * random(),
                (2.0 * random() - 1.0) * height,
            );
            let foot = s.nearest(p - s.origin).expect("finite");
            let q = p - s.origin;
            let best = everything
                .iter()
                .min_by(|a, b| {
                    a.dist_sq(q)
                        .total_cmp(&b.dist_sq(q))
                        .then(a.index.cmp(&b.index))
                })
                .expect("triangles");
            assert_eq!(foot.dist_sq, best.dist_sq(q), "query {k} at {p:?}");
            assert_eq!(foot.sagitta, best.sagitta as f64, "query {k} at {p:?}");
        }
        // Beyond what f32 can tell apart (the tree's boxes are f32), a query still gets a
        // triangle at its distance, and soon.
        for far in [1e12, 1e30, 1e300] {
            let p = Point3::new(far, -far, 0.5 * far);
            let foot = s.nearest(p).expect("finite");
            let nearest = everything
                .iter()
                .map(|t| t.dist_sq(p))
                .fold(f64::INFINITY, f64::min);
            assert!(
                foot.dist_sq.is_finite() || far > 1e150,
                "{far}: {}",
                foot.dist_sq
            );
            assert!(
                foot.dist_sq <= nearest * (1.0 + 1e-6),
                "{far}: {} > {nearest}",
                foot.dist_sq
            );
        }
    }

    /// A unit square in z = 0 made of two triangles (open: four boundary edges).
    fn square() -> PolyMesh {
        let p = vec![
            Point3::ZERO,
            Point3::X,
            Point3::new(1.0, 1.0, 0.0),
            Point3::Y,
        ];
        PolyMesh::try_new(p, vec![[0u32, 1, 2], [0, 2, 3]]).expect("valid")
    }

    #[test]
    fn distances_above_the_data_and_beyond_its_outline() {
        let s = DataSurface::of_mesh(&square()).expect("faces");
        let above = Point3::new(0.3, 0.6, 0.0) + Vec3::Z * 0.1;
        assert!((s.distance(above).expect("over data") - 0.1).abs() < 1e-6);
        // As high above the square as its rim is near: spans the square like a hole would.
        assert_eq!(s.distance(Point3::new(0.3, 0.6, 0.25)), None);
        // Beyond the outline the nearest point is on a boundary edge: left out.
        assert_eq!(s.distance(Point3::new(2.0, 0.5, 0.1)), None);
        assert_eq!(s.distance(Point3::new(-1.0, -1.0, 0.0)), None);
    }

    /// The pull target of a sample is the data point its distance is measured to: below it on
    /// the square, a loose point for a sample nearer to that, none over the rim.
    #[test]
    fn closest_data_point_of_a_sample() {
        let s = DataSurface::of_mesh(&square()).expect("faces");
        let (d, q) = s.closest(Point3::new(0.3, 0.6, 0.1)).expect("over data");
        assert!((d - 0.1).abs() < 1e-6 && (q - Point3::new(0.3, 0.6, 0.0)).length() < 1e-6);
        assert_eq!(s.closest(Point3::new(2.0, 0.5, 0.1)), None);
        let mut p = square().positions().to_vec();
        p.push(Point3::new(0.5, 0.5, 1.0));
        let with_loose = PolyMesh::try_new(p, vec![[0u32, 1, 2], [0, 2, 3]]).expect("valid");
        let s = DataSurface::of_mesh(&with_loose).expect("faces");
        let (_, q) = s
            .closest(Point3::new(0.5, 0.5, 0.9))
            .expect("near the loose point");
        assert!((q - Point3::new(0.5, 0.5, 1.0)).length() < 1e-6, "{q:?}");
    }

    #[test]
    fn statistics_of_a_bulge() {
        let s = DataSurface::of_mesh(&square()).expect("faces");
        // 99 samples on the data, one 0.1 above it: max 0.1 (5 % of 2), p99 0.
        let mut samples: Vec<Point3> = (0..99)
            .map(|i| Point3::new(0.1 + 0.008 * i as f64, 0.5, 0.0))
            .collect();
        samples.push(Point3::new(0.5, 0.5, 0.1));
        let b = s.measure(&samples, 2.0);
        assert!((b.max_pct - 5.0).abs() < 1e-4, "{b:?}");
        assert!(b.p99_pct < 1e-4, "{b:?}");
        assert_eq!((b.samples, b.over_holes), (100, 0));
    }

    #[test]
    fn closest_point_features() {
        let (a, b, c) = (Point3::ZERO, Point3::X, Point3::Y);
        assert_eq!(
            closest_on_triangle(Point3::new(-1.0, -1.0, 0.0), a, b, c).1,
            Feature::Vertex(0)
        );
        assert_eq!(
            closest_on_triangle(Point3::new(0.5, -1.0, 0.0), a, b, c).1,
            Feature::Edge(0)
        );
        assert_eq!(
            closest_on_triangle(Point3::new(1.0, 1.0, 0.0), a, b, c).1,
            Feature::Edge(1)
        );
        assert_eq!(
            closest_on_triangle(Point3::new(-1.0, 0.5, 0.0), a, b, c).1,
            Feature::Edge(2)
        );
        let (p, f) = closest_on_triangle(Point3::new(0.2, 0.2, 3.0), a, b, c);
        assert_eq!(f, Feature::Face);
        assert!((p - Point3::new(0.2, 0.2, 0.0)).length() < 1e-15);
    }
}
