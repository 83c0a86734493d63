//! The working triangle mesh of the simplifier: vertex–face incidence, the validity tests of an
//! edge collapse (topology, fold-over, triangle shape) and the collapse itself.
//!
//! Incidence lists (each vertex knows its faces) rather than half-edges, so that inputs with
//! non-manifold edges or vertices are still represented; such places are simply never collapsed.

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

/// The mesh being simplified.
pub(super) struct Work {
    pub(super) pos: Vec<Point3>,
    pub(super) quadric: Vec<Quadric>,
    pub(super) tris: Vec<[u32; 3]>,
    pub(super) tri_alive: Vec<bool>,
    /// Each face's unit normal in the input: a face may never turn against it, which catches
    /// fold-overs built up by many small rotations.
    ref_normal: Vec<Vec3>,
    /// Faces incident to each vertex; empty for removed or unreferenced vertices.
    pub(super) vfaces: Vec<Vec<u32>>,
    /// Number of vertices with at least one face.
    pub(super) live: usize,
    scratch_u: Vec<u32>,
    scratch_v: Vec<u32>,
}

impl Work {
    /// A working mesh over `pos` and `tris` (already free of degenerate and duplicate faces).
    pub(super) fn new(pos: Vec<Point3>, tris: Vec<[u32; 3]>) -> Work {
        let mut vfaces = vec![Vec::new(); pos.len()];
        for (f, t) in tris.iter().enumerate() {
            for &v in t {
                vfaces[v as usize].push(f as u32);
            }
        }
        let live = vfaces.iter().filter(|f| !f.is_empty()).count();
        let ref_normal = tris
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| pos[i as usize]);
                (b - a).cross(c - a).normalize_or_zero()
            })
            .collect();
        Work {
            ref_normal,
            quadric: vec![Quadric::default(); pos.len()],
            tri_alive: vec![true; tris.len()],
            pos,
            tris,
            vfaces,
            live,
            scratch_u: Vec::new(),
            scratch_v: Vec::new(),
        }
    }

    /// Sorted distinct neighbours of `v` into `out`; returns whether `v` is on a boundary (an
    /// incident edge with only one face).
    fn neighbours(&self, v: u32, out: &mut Vec<u32>) -> bool {
        out.clear();
        for &f in &self.vfaces[v as usize] {
            out.extend(self.tris[f as usize].iter().copied().filter(|&w| w != v));
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

    /// Distinct neighbours of `v`, sorted.
    pub(super) fn neighbour_list(&self, v: u32) -> Vec<u32> {
        let mut out = Vec::new();
        self.neighbours(v, &mut out);
        out
    }

    /// Whether collapsing edge `u`–`v` keeps the surface a manifold of the same topology: the
    /// link condition (common neighbours are exactly the opposite vertices of the edge's faces,
    /// with the boundary counted as a virtual vertex), no orphaned vertex, no duplicate face.
    fn topology_allows(&mut self, u: u32, v: u32) -> bool {
        let mut opposite = [u32::MAX; 2];
        let mut k = 0;
        for &f in &self.vfaces[u as usize] {
            let t = self.tris[f as usize];
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
        let (mut nu, mut nv) = (
            std::mem::take(&mut self.scratch_u),
            std::mem::take(&mut self.scratch_v),
        );
        let bu = self.neighbours(u, &mut nu);
        let bv = self.neighbours(v, &mut nv);
        let common = count_common(&nu, &nv);
        self.scratch_u = nu;
        self.scratch_v = nv;
        if common != k || (k == 2 && bu && bv) {
            return false;
        }
        // Tetrahedron-like case: a face v-x-y with x, y the opposite vertices would duplicate u-x-y.
        !(k == 2
            && self.vfaces[v as usize].iter().any(|&f| {
                let t = self.tris[f as usize];
                !t.contains(&u) && t.contains(&opposite[0]) && t.contains(&opposite[1])
            }))
    }

    /// Whether moving `u` and `v` to `p` keeps every surviving face within the normal-rotation
    /// limit and avoids creating needles.
    fn geometry_allows(&self, u: u32, v: u32, p: Point3, limits: &Limits) -> bool {
        let mut min_old = f64::INFINITY;
        let mut min_new = f64::INFINITY;
        for &w in &[u, v] {
            for &f in &self.vfaces[w as usize] {
                let t = self.tris[f as usize];
                if t.contains(&u) && t.contains(&v) {
                    continue;
                }
                let old = t.map(|i| self.pos[i as usize]);
                let new = t.map(|i| if i == w { p } else { self.pos[i as usize] });
                let n_old = (old[1] - old[0]).cross(old[2] - old[0]);
                let n_new = (new[1] - new[0]).cross(new[2] - new[0]);
                let len = n_old.length() * n_new.length();
                if n_new == Vec3::ZERO
                    || n_old.dot(n_new) < limits.min_normal_cos * len
                    || n_new.dot(self.ref_normal[f as usize]) < 0.0
                {
                    return false;
                }
                min_old = min_old.min(quality(old[0], old[1], old[2]));
                min_new = min_new.min(quality(new[0], new[1], new[2]));
            }
        }
        min_new >= limits.min_quality.min(min_old)
    }

    /// Whether edge `u`–`v` may collapse to `p`.
    pub(super) fn allows(&mut self, u: u32, v: u32, p: Point3, limits: &Limits) -> bool {
        self.topology_allows(u, v) && self.geometry_allows(u, v, p, limits)
    }

    /// Collapses `v` into `u`, which moves to `p`. The caller has checked [`Work::allows`].
    pub(super) fn collapse(&mut self, u: u32, v: u32, p: Point3) {
        let faces_v = std::mem::take(&mut self.vfaces[v as usize]);
        for f in faces_v {
            let t = &mut self.tris[f as usize];
            if t.contains(&u) {
                self.tri_alive[f as usize] = false;
                let t = *t;
                for w in t.into_iter().filter(|&w| w != v) {
                    self.vfaces[w as usize].retain(|&g| g != f);
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
    }
}

/// Number of values present in both sorted, deduplicated slices.
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
        Work::new(pos, tris)
    }

    const LOOSE: Limits = Limits {
        min_normal_cos: 0.0,
        min_quality: 0.0,
    };

    #[test]
    fn interior_edge_joining_two_boundary_vertices_is_refused() {
        // 3×3 vertices: edge 1–4 joins boundary vertex 1 to centre 4 (allowed); in a 2×2 grid
        // the diagonal 0–3 joins two boundary vertices (refused: it would pinch the disc).
        let mut w = grid(3);
        assert!(w.allows(4, 1, w.pos[4], &LOOSE));
        let mut w = grid(2);
        assert!(!w.allows(0, 3, w.pos[0], &LOOSE));
        assert!(w.allows(0, 1, w.pos[0], &LOOSE));
    }

    #[test]
    fn collapse_moves_faces_and_counts() {
        let mut w = grid(3);
        let before = w.tri_alive.iter().filter(|&&a| a).count();
        w.collapse(4, 5, Point3::new(1.5, 1.0, 0.0));
        assert_eq!(w.live, 8);
        assert_eq!(w.tri_alive.iter().filter(|&&a| a).count(), before - 2);
        assert!(w.vfaces[5].is_empty());
        assert!(w
            .tris
            .iter()
            .zip(&w.tri_alive)
            .all(|(t, &a)| !a || !t.contains(&5)));
    }

    #[test]
    fn flipping_move_is_refused() {
        let mut w = grid(3);
        // Moving the merged vertex beyond vertex 7 (at (1, 2)) flips face 4-8-7.
        assert!(!w.allows(4, 1, Point3::new(1.0, 2.5, 0.0), &LOOSE));
    }
}
