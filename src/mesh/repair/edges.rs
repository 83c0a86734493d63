//! Pairing the face sides that share an edge: two sides on one edge are glued (twins), one
//! side is a boundary, and more than two make a non-manifold edge, of which two sides are
//! glued and the others left open.
//!
//! Sides are grouped by their lower vertex with a counting pass (one offset per vertex), and
//! each vertex sorts only its own few sides by the other end: linear in the mesh size, with no
//! hash map.

use super::soup::Soup;
use crate::mesh::NONE;

/// How the sides of a soup pair up.
pub(super) struct Pairing {
    /// The twin of each corner's side (the side of the other face on its edge), or [`NONE`].
    pub(super) twin: Vec<u32>,
    /// Faces with the same vertices as a lower-numbered face.
    pub(super) duplicates: Vec<u32>,
    /// Edges with more than two faces, as vertex pairs.
    pub(super) crowded: Vec<[u32; 2]>,
    /// The sides left open on those edges (one per face beyond the glued two).
    pub(super) unpaired: Vec<u32>,
}

/// Pairs the sides of `soup`, whose vertices are below `vertices`.
pub(super) fn pair(soup: &Soup, vertices: usize) -> Pairing {
    let (starts, keyed) = sides_by_low_end(soup, vertices);
    let mut pairing = Pairing {
        twin: vec![NONE; soup.idx.len()],
        duplicates: Vec::new(),
        crowded: Vec::new(),
        unpaired: Vec::new(),
    };
    let mut duplicate = vec![false; soup.faces()];
    let mut group = Vec::new();
    for (lo, w) in starts.windows(2).enumerate() {
        for run in keyed[w[0] as usize..w[1] as usize].chunk_by(|a, b| a >> 32 == b >> 32) {
            group.clear();
            group.extend(run.iter().map(|&k| k as u32));
            let edge = [lo as u32, (run[0] >> 32) as u32];
            pairing.add_edge(soup, edge, &group, &mut duplicate);
        }
    }
    pairing
}

impl Pairing {
    /// Records the sides `group` of one edge.
    fn add_edge(&mut self, soup: &Soup, edge: [u32; 2], group: &[u32], duplicate: &mut [bool]) {
        if group.len() < 2 {
            return;
        }
        self.find_duplicates(soup, group, duplicate);
        let first = group[0];
        // Prefer a partner running the other way: it joins the two faces with consistent
        // orientation.
        let partner = group[1..]
            .iter()
            .copied()
            .find(|&c| soup.idx[c as usize] != soup.idx[first as usize])
            .unwrap_or(group[1]);
        self.twin[first as usize] = partner;
        self.twin[partner as usize] = first;
        if group.len() > 2 {
            self.crowded.push(edge);
            let rest = group[1..].iter().filter(|&&c| c != partner);
            self.unpaired.extend(rest);
        }
    }

    /// Marks the faces on one edge that repeat the vertices of an earlier face there.
    fn find_duplicates(&mut self, soup: &Soup, group: &[u32], duplicate: &mut [bool]) {
        for (i, &a) in group.iter().enumerate() {
            for &b in &group[i + 1..] {
                let (f, g) = (soup.face_of(a as usize), soup.face_of(b as usize));
                let later = f.max(g);
                if !duplicate[later] && !duplicate[f.min(g)] && same_vertices(soup, f, g) {
                    duplicate[later] = true;
                    self.duplicates.push(later as u32);
                }
            }
        }
    }
}

/// Whether faces `f` and `g` have the same vertices (in any order). Faces repeat no vertex
/// (see `clean`), so the same count and one set inside the other suffice.
fn same_vertices(soup: &Soup, f: usize, g: usize) -> bool {
    let (a, b) = (soup.face(f), soup.face(g));
    a.len() == b.len() && a.iter().all(|v| b.contains(v))
}

/// Every side keyed `high end << 32 | corner`, grouped by its low end (group of vertex `v` is
/// `keyed[starts[v]..starts[v + 1]]`) and sorted within each group.
fn sides_by_low_end(soup: &Soup, vertices: usize) -> (Vec<u32>, Vec<u64>) {
    let ends = |c: usize| {
        let (a, b) = (soup.idx[c], soup.idx[soup.next(c)]);
        (a.min(b), a.max(b))
    };
    let mut starts = vec![0u32; vertices + 1];
    for c in 0..soup.idx.len() {
        starts[ends(c).0 as usize + 1] += 1;
    }
    for v in 0..vertices {
        starts[v + 1] += starts[v];
    }
    let mut fill = starts.clone();
    let mut keyed = vec![0u64; soup.idx.len()];
    for c in 0..soup.idx.len() {
        let (lo, hi) = ends(c);
        keyed[fill[lo as usize] as usize] = u64::from(hi) << 32 | c as u64;
        fill[lo as usize] += 1;
    }
    for w in starts.windows(2) {
        keyed[w[0] as usize..w[1] as usize].sort_unstable();
    }
    (starts, keyed)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn soup(faces: &[&[u32]]) -> Soup {
        let mut starts = vec![0];
        let mut idx = Vec::new();
        for f in faces {
            idx.extend_from_slice(f);
            starts.push(idx.len() as u32);
        }
        Soup::new(starts, idx, (0..faces.len() as u32).collect())
    }

    #[test]
    fn shared_sides_are_twins_and_a_third_face_stays_open() {
        // Three triangles on edge 0–1 (a book of three pages), the third written like the first.
        let s = soup(&[&[0, 1, 2], &[1, 0, 3], &[0, 1, 4]]);
        let p = pair(&s, 5);
        assert_eq!((p.twin[0], p.twin[3]), (3, 0));
        assert_eq!(p.crowded, vec![[0, 1]]);
        assert_eq!(p.unpaired, vec![6]);
        assert!(p.duplicates.is_empty());
        assert_eq!(p.twin[1], NONE);
    }

    #[test]
    fn repeated_faces_are_found_in_any_order_or_orientation() {
        let s = soup(&[&[0, 1, 2], &[2, 1, 0], &[0, 1, 2, 3], &[1, 2, 3, 0]]);
        let p = pair(&s, 4);
        let mut d = p.duplicates.clone();
        d.sort_unstable();
        assert_eq!(d, vec![1, 3]);
    }
}
