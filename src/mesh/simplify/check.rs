//! The collapse test: whether merging the ends of an edge into one vertex at a given position
//! keeps the surface a manifold of the same topology, turns no face too far (or over), makes
//! no needle and no vertex of too high a valence.
//!
//! The test reads the live faces around the two ends, gathered once into a [`Ring`]: each face
//! as seen from its end (the next and previous corners, merged corners already renamed, and
//! its input normal), the sorted neighbours of each end, and the faces on the edge.

use super::engine::Engine;
use crate::geom::{Point3, Vec3};

/// Limits a collapse must respect.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Limits {
    /// Cosine of the largest rotation of a face normal that one collapse may cause.
    pub(super) min_normal_cos: f64,
    /// Triangles of lower quality (4√3·area / Σ edge², 1 for equilateral, 0 for degenerate)
    /// than this may not be created, unless the neighbourhood already had a worse one
    /// (needles are never made worse).
    pub(super) min_quality: f64,
    /// Largest valence the merged vertex may get, unless one of the ends already had more.
    pub(super) max_valence: usize,
    /// Cosine of the largest angle between a face's normal and the normal of the input it
    /// stands for.
    pub(super) min_reference_cos: f64,
}

/// A face around a vertex, seen from it: the face, the corner after the vertex and the corner
/// before it (in the face's orientation).
#[derive(Clone, Copy, Debug)]
pub(super) struct Corner {
    pub(super) face: u32,
    pub(super) next: u32,
    pub(super) prev: u32,
}

impl Corner {
    /// Whether the face has corner `v` besides the vertex it is seen from.
    fn has(&self, v: u32) -> bool {
        self.next == v || self.prev == v
    }
}

/// The live faces around an edge `a`–`b`, with what the test needs of them.
#[derive(Default)]
pub(super) struct Ring {
    around_a: Vec<Corner>,
    around_b: Vec<Corner>,
    nbr_a: Vec<u32>,
    nbr_b: Vec<u32>,
    /// The third corners of the faces on the edge (the first `shared` entries).
    opposite: [u32; 2],
    shared: usize,
}

impl Ring {
    /// Gathers the faces of `a` and `b` as they are now.
    pub(super) fn gather(&mut self, e: &Engine, a: u32, b: u32) {
        self.around_a.clear();
        self.around_b.clear();
        e.live_corners(a, &mut self.around_a);
        e.live_corners(b, &mut self.around_b);
        self.shared = 0;
        for c in self.around_a.iter().filter(|c| c.has(b)) {
            if self.shared == 2 {
                self.shared = 3; // a crowded edge: refused below
                break;
            }
            self.opposite[self.shared] = if c.next == b { c.prev } else { c.next };
            self.shared += 1;
        }
        neighbours(&self.around_a, e.is_boundary(a), &mut self.nbr_a);
        neighbours(&self.around_b, e.is_boundary(b), &mut self.nbr_b);
    }

    /// The third corners of the faces on the edge.
    pub(super) fn opposite(&self) -> &[u32] {
        &self.opposite[..self.shared.min(2)]
    }

    /// The faces the collapse of `a`–`b` removes, each with the faces that inherit its input
    /// normal: the faces across its other two sides (which become neighbours), where they
    /// exist.
    pub(super) fn removed_faces(
        &self,
        a: u32,
        b: u32,
    ) -> impl Iterator<Item = (u32, [Option<u32>; 2])> + '_ {
        let heir = |around: &[Corner], x: u32, other: u32| {
            around
                .iter()
                .find(|c| c.has(x) && !c.has(other))
                .map(|c| c.face)
        };
        self.around_a
            .iter()
            .filter(move |c| c.has(b))
            .map(move |c| {
                let x = if c.next == b { c.prev } else { c.next };
                (
                    c.face,
                    [heir(&self.around_a, x, b), heir(&self.around_b, x, a)],
                )
            })
    }

    /// Faces the merged vertex keeps.
    pub(super) fn surviving_faces(&self) -> usize {
        self.around_a.len() + self.around_b.len() - 2 * self.shared
    }

    /// Whether collapsing `a`–`b` keeps the surface a manifold of the same topology: the link
    /// condition (the common neighbours of the ends are exactly the opposite corners of the
    /// edge's faces, with the boundary as a virtual vertex joined to every boundary vertex),
    /// no vertex left without faces and no face doubled.
    pub(super) fn topology_allows(&self, e: &Engine, a: u32, b: u32) -> bool {
        let k = self.shared;
        if k == 0 || k > 2 || self.surviving_faces() == 0 {
            return false;
        }
        if self.opposite().iter().any(|&w| e.face_count(w) < 2) {
            return false;
        }
        if count_common(&self.nbr_a, &self.nbr_b) != k {
            return false;
        }
        // An inner edge between two boundary vertices would pinch the surface there.
        if k == 2 && e.is_boundary(a) && e.is_boundary(b) {
            return false;
        }
        // Faces a–x–y and b–x–y over the two opposite corners would become one face twice
        // (a tetrahedron cannot shrink).
        let [x, y] = self.opposite;
        let spans = |around: &[Corner]| around.iter().any(|c| c.has(x) && c.has(y));
        !(k == 2 && spans(&self.around_a) && spans(&self.around_b))
    }

    /// The valence of the merged vertex, if the collapse may create it: at most `max`, or no
    /// more than one of the ends has already.
    pub(super) fn valence_allows(&self, max: usize) -> bool {
        let merged = count_union(&self.nbr_a, &self.nbr_b) - 2;
        merged <= max || merged <= self.nbr_a.len().max(self.nbr_b.len())
    }

    /// Whether moving `a` and `b` to `p` keeps every surviving face within the rotation limit,
    /// facing the way its input face did, and free of new needles.
    pub(super) fn geometry_allows(
        &self,
        e: &Engine,
        a: u32,
        b: u32,
        p: Point3,
        l: &Limits,
    ) -> bool {
        let limit = l.min_quality * l.min_quality / 12.0;
        let mut needles = false;
        for (end, other, around) in [(a, b, &self.around_a), (b, a, &self.around_b)] {
            let x = e.pos(end);
            for c in around.iter().filter(|c| !c.has(other)) {
                let (u, w) = (e.pos(c.next), e.pos(c.prev));
                let n_old = (u - x).cross(w - x);
                let n_new = (u - p).cross(w - p);
                if n_new == Vec3::ZERO
                    || !within(e.reference_normal(c.face), n_new, l.min_reference_cos)
                    || !within(n_old, n_new, l.min_normal_cos)
                {
                    return false;
                }
                // `shape` below the limit, without its division.
                let sum_sq = side_sum_sq(p, u, w);
                needles |= n_new.length_squared() < limit * sum_sq * sum_sq;
            }
        }
        // The old triangles' shape only matters when a new one is below the limit.
        !needles || self.worst_old_shape(e, a, b) <= self.worst_new_shape(e, a, b, p)
    }

    /// The smallest [`shape`] of the faces around the edge after moving `a` and `b` to `p`.
    fn worst_new_shape(&self, e: &Engine, a: u32, b: u32, p: Point3) -> f64 {
        let mut worst = f64::INFINITY;
        for (other, around) in [(b, &self.around_a), (a, &self.around_b)] {
            for c in around.iter().filter(|c| !c.has(other)) {
                let (u, w) = (e.pos(c.next), e.pos(c.prev));
                worst = worst.min(shape((u - p).cross(w - p), p, u, w));
            }
        }
        worst
    }

    /// The smallest [`shape`] of the faces around the edge before the collapse (those that
    /// survive it).
    fn worst_old_shape(&self, e: &Engine, a: u32, b: u32) -> f64 {
        let mut worst = f64::INFINITY;
        for (end, other, around) in [(a, b, &self.around_a), (b, a, &self.around_b)] {
            let x = e.pos(end);
            for c in around.iter().filter(|c| !c.has(other)) {
                let (u, w) = (e.pos(c.next), e.pos(c.prev));
                worst = worst.min(shape((u - x).cross(w - x), x, u, w));
            }
        }
        worst
    }
}

/// Whether the rotation from normal `n_old` to `n_new` has a cosine of at least `min_cos`
/// (which is not negative: rotations beyond a right angle are never allowed), without roots.
fn within(n_old: Vec3, n_new: Vec3, min_cos: f64) -> bool {
    let dot = n_old.dot(n_new);
    dot >= 0.0 && dot * dot >= min_cos * min_cos * n_old.length_squared() * n_new.length_squared()
}

/// The squared triangle quality over 12 (|n|² / (Σ edge²)², n the doubled-area normal of the
/// triangle `a`, `b`, `c`): the quality test without roots.
fn shape(n: Vec3, a: Point3, b: Point3, c: Point3) -> f64 {
    let sum_sq = side_sum_sq(a, b, c);
    if sum_sq > 0.0 {
        n.length_squared() / (sum_sq * sum_sq)
    } else {
        0.0
    }
}

/// The sum of the squared sides of the triangle `a`, `b`, `c`.
fn side_sum_sq(a: Point3, b: Point3, c: Point3) -> f64 {
    (b - a).length_squared() + (c - b).length_squared() + (a - c).length_squared()
}

/// The neighbours of a vertex from its faces `around`, sorted, into `out`. The faces around a
/// vertex form one fan, so their next corners are distinct and are all its neighbours, except
/// on a boundary, where the previous corner of the fan's first face is missing.
fn neighbours(around: &[Corner], boundary: bool, out: &mut Vec<u32>) {
    out.clear();
    out.extend(around.iter().map(|c| c.next));
    if boundary {
        let first = around.iter().map(|c| c.prev).find(|w| !out.contains(w));
        out.extend(first);
    }
    out.sort_unstable();
}

/// Number of values in both sorted lists.
fn count_common(a: &[u32], b: &[u32]) -> usize {
    let (mut i, mut j, mut n) = (0, 0, 0);
    while i < a.len() && j < b.len() {
        match a[i].cmp(&b[j]) {
            std::cmp::Ordering::Less => i += 1,
            std::cmp::Ordering::Greater => j += 1,
            std::cmp::Ordering::Equal => {
                n += 1;
                i += 1;
                j += 1;
            }
        }
    }
    n
}

/// Number of distinct values in two sorted lists.
fn count_union(a: &[u32], b: &[u32]) -> usize {
    a.len() + b.len() - count_common(a, b)
}
