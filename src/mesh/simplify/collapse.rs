//! The working triangle mesh of the simplifier: vertex–face incidence, the validity tests of an
//! edge collapse (topology, fold-over, triangle shape) and the collapse itself.
//!
//! Incidence lists (each vertex knows its faces) rather than half-edges, so that inputs with
//! non-manifold edges or vertices are still represented; such places are simply never collapsed.

use super::incidence::{Incidence, InputEdge};
use super::locality::Numbering;
use super::quadric::Quadric;
use crate::geom::{Point3, Vec3};

/// Limits a collapse must respect to keep the surface's shape and triangle quality.
#[derive(Clone, Copy, Debug)]
pub(super) struct Limits {
    /// Cosine of the largest rotation of a face normal that a collapse may cause.
    pub(super) min_normal_cos: f64,
    /// Triangles of lower quality than this may not be created, unless the neighbourhood
    /// already had a worse one (so needles are never made worse).
    pub(super) min_quality: f64,
}

/// Quality of a triangle in [0, 1]: 1 for equilateral, 0 for degenerate (4√3·area / Σ edge²).
fn quality(a: Point3, b: Point3, c: Point3) -> f64 {
    let twice_area = (b - a).cross(c - a).length();
    let sum_sq = (b - a).length_squared() + (c - b).length_squared() + (a - c).length_squared();
    if sum_sq > 0.0 {
        2.0 * 3f64.sqrt() * twice_area / sum_sq
    } else {
        0.0
    }
}

/// A neighbour of a vertex and the id of the edge to it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Link {
    pub(super) nbr: u32,
    pub(super) edge: u32,
}

/// A triangle of the working mesh, with what the fold-over test needs of it in one place (the
/// test reads both for every face around a collapse, and they used to be two cache misses).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Face {
    /// The vertices, in the input's orientation.
    pub(super) corners: [u32; 3],
    /// The unit normal in the input: a face may never turn against it, which catches
    /// fold-overs built up by many small rotations.
    ref_normal: Vec3,
}

/// The mesh being simplified.
pub(super) struct Work {
    pub(super) pos: Vec<Point3>,
    pub(super) quadric: Vec<Quadric>,
    pub(super) faces: Vec<Face>,
    pub(super) tri_alive: Vec<bool>,
    /// Faces incident to each vertex; empty for removed or unreferenced vertices.
    pub(super) vfaces: Vec<Vec<u32>>,
    /// Each vertex's neighbours sorted by index, with the ids of the edges to them: kept up to
    /// date by [`Work::collapse`] so that the link condition needs no sorting, and edge ids
    /// stay stable for the queue. Ids of removed edges are never reused.
    pub(super) adj: Vec<Vec<Link>>,
    /// Each edge's ends, lower index first (stale for removed edges).
    pub(super) ends: Vec<[u32; 2]>,
    /// Whether each vertex has an incident edge with a single face.
    boundary: Vec<bool>,
    /// Number of vertices with at least one face.
    pub(super) live: usize,
    /// How working indices relate to the input's (see [`Work::renumber`]).
    pub(super) numbering: Numbering,
    scratch: Vec<u32>,
    /// A spare link list, so that rebuilding `u`'s links does not allocate.
    spare_links: Vec<Link>,
}

impl Work {
    /// The working mesh of the input's `pos` and `tris` (free of degenerate and duplicate
    /// faces), with their incidence, edges and vertex quadrics, stored in `numbering`'s order.
    pub(super) fn new(
        pos: &[Point3],
        tris: &[[u32; 3]],
        incidence: &Incidence,
        edges: &[InputEdge],
        quadric: &[Quadric],
        numbering: Numbering,
    ) -> Work {
        let (input, vw) = (&numbering.vertex_input, &numbering.vertex_work);
        let mut faces = vec![Face::default(); tris.len()];
        for (t, &f) in tris.iter().zip(&numbering.face_work) {
            let [a, b, c] = t.map(|i| pos[i as usize]);
            faces[f as usize] = Face {
                corners: t.map(|v| vw[v as usize]),
                ref_normal: (b - a).cross(c - a).normalize_or_zero(),
            };
        }
        // Room for the faces and links a vertex gains in its first collapses.
        let valence = |w: u32| incidence.faces_of(input[w as usize]).len();
        let mut vfaces: Vec<Vec<u32>> = (0..pos.len() as u32)
            .map(|w| Vec::with_capacity(valence(w) + 4))
            .collect();
        for (f, face) in faces.iter().enumerate() {
            for &v in &face.corners {
                vfaces[v as usize].push(f as u32);
            }
        }
        let mut adj: Vec<Vec<Link>> = (0..pos.len() as u32)
            .map(|w| Vec::with_capacity(valence(w) + 4))
            .collect();
        let mut boundary = vec![false; pos.len()];
        let mut ends = Vec::with_capacity(edges.len());
        for (e, edge) in edges.iter().enumerate() {
            let (a, b) = (vw[edge.a as usize], vw[edge.b as usize]);
            ends.push([a.min(b), a.max(b)]);
            adj[a as usize].push(Link {
                nbr: b,
                edge: e as u32,
            });
            adj[b as usize].push(Link {
                nbr: a,
                edge: e as u32,
            });
            if edge.faces == 1 {
                boundary[a as usize] = true;
                boundary[b as usize] = true;
            }
        }
        for links in &mut adj {
            links.sort_unstable_by_key(|l| l.nbr);
        }
        Work {
            pos: input.iter().map(|&i| pos[i as usize]).collect(),
            quadric: input.iter().map(|&i| quadric[i as usize]).collect(),
            tri_alive: vec![true; faces.len()],
            faces,
            vfaces,
            adj,
            ends,
            boundary,
            live: incidence.used_vertices(),
            numbering,
            scratch: Vec::new(),
            spare_links: Vec::new(),
        }
    }

    /// The ends of edge `edge`, the one with the lower input index first: it survives the
    /// collapse and comes first in the placement, as it did before the renumbering.
    pub(super) fn edge_ends(&self, edge: u32) -> (u32, u32) {
        let [a, b] = self.ends[edge as usize];
        let input = &self.numbering.vertex_input;
        if input[a as usize] < input[b as usize] {
            (a, b)
        } else {
            (b, a)
        }
    }

    /// Sorted distinct neighbours of `v` into `out`, found from its faces; returns whether `v`
    /// is on a boundary (an incident edge with only one face).
    fn neighbours(&self, v: u32, out: &mut Vec<u32>) -> bool {
        out.clear();
        for &f in &self.vfaces[v as usize] {
            out.extend(
                self.faces[f as usize]
                    .corners
                    .iter()
                    .copied()
                    .filter(|&w| w != v),
            );
        }
        out.sort_unstable();
        let mut boundary = false;
        let mut i = 0;
        while i < out.len() {
            let run = out[i..].iter().take_while(|&&w| w == out[i]).count();
            boundary |= run == 1;
            i += run;
        }
        out.dedup();
        boundary
    }

    /// Whether collapsing edge `u`–`v` keeps the surface a manifold of the same topology: the
    /// link condition (common neighbours are exactly the opposite vertices of the edge's faces,
    /// with the boundary counted as a virtual vertex), no orphaned vertex, no duplicate face.
    fn topology_allows(&self, u: u32, v: u32) -> bool {
        let mut opposite = [u32::MAX; 2];
        let mut k = 0;
        for &f in &self.vfaces[u as usize] {
            let t = self.faces[f as usize].corners;
            if t.contains(&v) {
                if k == 2 {
                    return false; // non-manifold edge
                }
                opposite[k] = t.iter().copied().find(|&w| w != u && w != v).unwrap_or(u);
                k += 1;
            }
        }
        if k == 0 {
            return false;
        }
        let surviving = self.vfaces[u as usize].len() + self.vfaces[v as usize].len() - 2 * k;
        if surviving == 0
            || opposite[..k]
                .iter()
                .any(|&x| self.vfaces[x as usize].len() < 2)
        {
            return false;
        }
        let common = count_common(&self.adj[u as usize], &self.adj[v as usize]);
        let (bu, bv) = (self.boundary[u as usize], self.boundary[v as usize]);
        if common != k || (k == 2 && bu && bv) {
            return false;
        }
        // Tetrahedron-like case: a face v-x-y with x, y the opposite vertices would duplicate u-x-y.
        !(k == 2
            && self.vfaces[v as usize].iter().any(|&f| {
                let t = self.faces[f as usize].corners;
                !t.contains(&u) && t.contains(&opposite[0]) && t.contains(&opposite[1])
            }))
    }

    /// Whether moving `u` and `v` to `p` keeps every surviving face within the normal-rotation
    /// limit and avoids creating needles.
    fn geometry_allows(&self, u: u32, v: u32, p: Point3, limits: &Limits) -> bool {
        let mut min_new = f64::INFINITY;
        for (w, face) in self.moved_faces(u, v) {
            let old = face.corners.map(|i| self.pos[i as usize]);
            let new = face
                .corners
                .map(|i| if i == w { p } else { self.pos[i as usize] });
            let n_old = (old[1] - old[0]).cross(old[2] - old[0]);
            let n_new = (new[1] - new[0]).cross(new[2] - new[0]);
            let len = n_old.length() * n_new.length();
            if n_new == Vec3::ZERO
                || n_old.dot(n_new) < limits.min_normal_cos * len
                || n_new.dot(face.ref_normal) < 0.0
            {
                return false;
            }
            min_new = min_new.min(quality(new[0], new[1], new[2]));
        }
        // The old triangles' quality only matters when a new one falls below the limit.
        min_new >= limits.min_quality
            || min_new
                >= self
                    .moved_faces(u, v)
                    .map(|(_, f)| {
                        let [a, b, c] = f.corners.map(|i| self.pos[i as usize]);
                        quality(a, b, c)
                    })
                    .fold(f64::INFINITY, f64::min)
    }

    /// The faces around `u` and `v` that survive their collapse, each with the end it has.
    fn moved_faces(&self, u: u32, v: u32) -> impl Iterator<Item = (u32, Face)> + '_ {
        [u, v].into_iter().flat_map(move |w| {
            self.vfaces[w as usize]
                .iter()
                .map(|&f| self.faces[f as usize])
                .filter(move |f| !(f.corners.contains(&u) && f.corners.contains(&v)))
                .map(move |f| (w, f))
        })
    }

    /// Whether edge `u`–`v` may collapse to `p`.
    pub(super) fn allows(&self, u: u32, v: u32, p: Point3, limits: &Limits) -> bool {
        self.topology_allows(u, v) && self.geometry_allows(u, v, p, limits)
    }

    /// Collapses `v` into `u`, which moves to `p`, and pushes the ids of the edges this
    /// removes onto `removed`. The caller has checked [`Work::allows`].
    pub(super) fn collapse(&mut self, u: u32, v: u32, p: Point3, removed: &mut Vec<u32>) {
        let mut opposite = [u32::MAX; 2];
        let faces_v = std::mem::take(&mut self.vfaces[v as usize]);
        for f in faces_v {
            let t = &mut self.faces[f as usize].corners;
            if t.contains(&u) {
                self.tri_alive[f as usize] = false;
                let t = *t;
                for w in t.into_iter().filter(|&w| w != v) {
                    self.vfaces[w as usize].retain(|&g| g != f);
                    if w != u {
                        opposite[usize::from(opposite[0] != u32::MAX)] = w;
                    }
                }
            } else {
                for w in t.iter_mut().filter(|w| **w == v) {
                    *w = u;
                }
                self.vfaces[u as usize].push(f);
            }
        }
        let qv = self.quadric[v as usize];
        self.quadric[u as usize] += qv;
        self.pos[u as usize] = p;
        self.live -= 1;
        self.merge_links(u, v, removed);
        // Only the opposite vertices lose faces around an edge, so only their boundary status
        // (besides `u`'s) can change, and only if they had an edge with one face.
        let on_boundary = opposite.map(|x| x != u32::MAX && self.boundary[x as usize]);
        for (x, _) in opposite.into_iter().zip(on_boundary).filter(|(_, b)| *b) {
            let mut scratch = std::mem::take(&mut self.scratch);
            self.boundary[x as usize] = self.neighbours(x, &mut scratch);
            self.scratch = scratch;
        }
    }

    /// Rebuilds `u`'s links after `v` merged into it: an edge to a neighbour keeps `u`'s id
    /// if `u` had one, else takes over `v`'s; every other edge of `u` and `v` is removed.
    ///
    /// Away from boundaries every edge of the two ends but `u`–`v` survives (an edge `x`–`u`
    /// only vanishes with `x`–`v` when both had the removed face `u`–`v`–`x` alone, which makes
    /// all three boundary vertices), so the new neighbours are the union of the old ones and
    /// the faces need not be walked.
    fn merge_links(&mut self, u: u32, v: u32, removed: &mut Vec<u32>) {
        let interior = !self.boundary[u as usize] && !self.boundary[v as usize];
        let old_u = std::mem::take(&mut self.adj[u as usize]);
        let old_v = std::mem::take(&mut self.adj[v as usize]);
        let mut nbrs = std::mem::take(&mut self.scratch);
        if interior {
            sorted_union(&old_u, &old_v, &mut nbrs);
            nbrs.retain(|&w| w != u && w != v);
        } else {
            self.boundary[u as usize] = self.neighbours(u, &mut nbrs);
        }
        let mut links = std::mem::take(&mut self.spare_links);
        links.clear();
        let (mut i, mut j) = (0, 0);
        for &w in nbrs.iter().chain(std::iter::once(&u32::MAX)) {
            while i < old_u.len() && old_u[i].nbr < w {
                self.remove_link(old_u[i], u, v, removed);
                i += 1;
            }
            while j < old_v.len() && old_v[j].nbr < w {
                self.remove_link(old_v[j], v, u, removed);
                j += 1;
            }
            let from_u = old_u.get(i).filter(|l| l.nbr == w).copied();
            let from_v = old_v.get(j).filter(|l| l.nbr == w).copied();
            i += usize::from(from_u.is_some());
            j += usize::from(from_v.is_some());
            match (from_u, from_v) {
                (Some(keep), Some(drop)) => {
                    self.remove_link(drop, v, u, removed);
                    links.push(keep);
                }
                (Some(keep), None) => links.push(keep),
                (None, Some(moved)) => {
                    self.relink(moved.edge, w, u);
                    links.push(moved);
                }
                (None, None) => {}
            }
        }
        self.adj[u as usize] = links;
        self.spare_links = old_u;
        self.scratch = nbrs;
    }

    /// Removes edge `link` of vertex `from` (whose links are being rebuilt): from the other
    /// end's links, unless that is `partner` (the edge `u`–`v`, whose links both go).
    fn remove_link(&mut self, link: Link, from: u32, partner: u32, removed: &mut Vec<u32>) {
        if link.nbr == partner {
            // Edge u–v: seen from both ends, recorded once.
            if from < partner {
                removed.push(link.edge);
            }
            return;
        }
        self.adj[link.nbr as usize].retain(|l| l.edge != link.edge);
        removed.push(link.edge);
    }

    /// Makes edge `edge` of `w` lead to `new` instead, in `w`'s sorted links and in `ends`.
    fn relink(&mut self, edge: u32, w: u32, new: u32) {
        self.ends[edge as usize] = [w.min(new), w.max(new)];
        let links = &mut self.adj[w as usize];
        for l in links.iter_mut().filter(|l| l.edge == edge) {
            l.nbr = new;
        }
        links.sort_unstable_by_key(|l| l.nbr);
    }
}

/// The neighbours in either of two sorted link lists, sorted, into `out`.
fn sorted_union(a: &[Link], b: &[Link], out: &mut Vec<u32>) {
    out.clear();
    let (mut i, mut j) = (0, 0);
    while i < a.len() || j < b.len() {
        let x = a.get(i).map_or(u32::MAX, |l| l.nbr);
        let y = b.get(j).map_or(u32::MAX, |l| l.nbr);
        let w = x.min(y);
        i += usize::from(x == w);
        j += usize::from(y == w);
        out.push(w);
    }
}

/// Number of neighbours present in both sorted link lists.
fn count_common(a: &[Link], b: &[Link]) -> usize {
    let (mut i, mut j, mut n) = (0, 0, 0);
    while i < a.len() && j < b.len() {
        match a[i].nbr.cmp(&b[j].nbr) {
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

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(n: u32) -> Work {
        let mut pos = Vec::new();
        for j in 0..n {
            for i in 0..n {
                pos.push(Point3::new(i as f64, j as f64, 0.0));
            }
        }
        let mut tris = Vec::new();
        for j in 0..n - 1 {
            for i in 0..n - 1 {
                let a = j * n + i;
                tris.push([a, a + 1, a + n + 1]);
                tris.push([a, a + n + 1, a + n]);
            }
        }
        let incidence = Incidence::new(pos.len(), &tris);
        let edges = incidence.edges(&tris);
        let quadric = vec![Quadric::default(); pos.len()];
        let numbering = Numbering::identity(pos.len(), tris.len());
        Work::new(&pos, &tris, &incidence, &edges, &quadric, numbering)
    }

    const LOOSE: Limits = Limits {
        min_normal_cos: 0.0,
        min_quality: 0.0,
    };

    #[test]
    fn interior_edge_joining_two_boundary_vertices_is_refused() {
        // 3×3 vertices: edge 1–4 joins boundary vertex 1 to centre 4 (allowed); in a 2×2 grid
        // the diagonal 0–3 joins two boundary vertices (refused: it would pinch the disc).
        let w = grid(3);
        assert!(w.allows(4, 1, w.pos[4], &LOOSE));
        let w = grid(2);
        assert!(!w.allows(0, 3, w.pos[0], &LOOSE));
        assert!(w.allows(0, 1, w.pos[0], &LOOSE));
    }

    #[test]
    fn collapse_moves_faces_and_counts() {
        let mut w = grid(3);
        let before = w.tri_alive.iter().filter(|&&a| a).count();
        let mut removed = Vec::new();
        w.collapse(4, 5, Point3::new(1.5, 1.0, 0.0), &mut removed);
        // Edge 4–5 and one of each pair 4–x, 5–x of the two faces' opposite vertices x.
        assert_eq!(removed.len(), 3);
        assert_eq!(w.live, 8);
        assert_eq!(w.tri_alive.iter().filter(|&&a| a).count(), before - 2);
        assert!(w.vfaces[5].is_empty());
        assert!(w
            .faces
            .iter()
            .map(|f| f.corners)
            .zip(&w.tri_alive)
            .all(|(t, &a)| !a || !t.contains(&5)));
    }

    #[test]
    fn flipping_move_is_refused() {
        let w = grid(3);
        // Moving the merged vertex beyond vertex 7 (at (1, 2)) flips face 4-8-7.
        assert!(!w.allows(4, 1, Point3::new(1.0, 2.5, 0.0), &LOOSE));
    }

    /// The links and boundary flags recomputed from the faces, as `collapse` should keep them.
    fn assert_links_match_faces(w: &Work) {
        let mut nbrs = Vec::new();
        for v in 0..w.pos.len() as u32 {
            let boundary = w.neighbours(v, &mut nbrs);
            let linked: Vec<u32> = w.adj[v as usize].iter().map(|l| l.nbr).collect();
            assert_eq!(linked, nbrs, "neighbours of {v}");
            if !nbrs.is_empty() {
                assert_eq!(w.boundary[v as usize], boundary, "boundary flag of {v}");
            }
            for l in &w.adj[v as usize] {
                assert_eq!(w.ends[l.edge as usize], [v.min(l.nbr), v.max(l.nbr)]);
                assert!(w.adj[l.nbr as usize].contains(&Link {
                    nbr: v,
                    edge: l.edge
                }));
            }
        }
    }

    #[test]
    fn links_follow_collapses() {
        let mut w = grid(6);
        assert_links_match_faces(&w);
        let mut removed = Vec::new();
        let mut gone = std::collections::BTreeSet::new();
        // Interior, boundary and corner collapses, and more where earlier ones left edges.
        let mut done = 0;
        for (u, v) in [
            (14, 15),
            (14, 20),
            (0, 1),
            (2, 8),
            (22, 28),
            (29, 35),
            (14, 21),
            (7, 14),
            (0, 7),
            (9, 16),
            (16, 22),
        ] {
            if !w.allows(u, v, w.pos[u as usize], &LOOSE) {
                continue;
            }
            done += 1;
            removed.clear();
            w.collapse(u, v, w.pos[u as usize], &mut removed);
            assert_links_match_faces(&w);
            for e in &removed {
                assert!(gone.insert(*e), "edge {e} removed twice");
            }
        }
        assert!(done >= 8, "only {done} collapses");
        let linked: std::collections::BTreeSet<u32> =
            w.adj.iter().flatten().map(|l| l.edge).collect();
        assert!(linked.is_disjoint(&gone));
        assert_eq!(linked.len() + gone.len(), w.ends.len());
    }
}
