//! Consistent orientation per connected component: a breadth-first walk over glued sides
//! decides for every face whether it must be turned over to agree with its neighbours.
//!
//! Where the walk meets a glued side whose faces cannot agree (a Möbius-like, non-orientable
//! component), the glue is cut: the side becomes a boundary of both faces, and the fan split
//! that follows separates them. Each component keeps the orientation of the majority of its
//! faces, so a mesh with a few inverted faces keeps its outward normals.

use super::soup::Soup;
use crate::mesh::NONE;

/// Which faces to turn over, and the components found on the way.
pub(super) struct Orientation {
    /// Whether each face must be reversed.
    pub(super) flip: Vec<bool>,
    /// Component of each face (numbered in order of their lowest face).
    pub(super) component: Vec<u32>,
    /// Number of faces of each component.
    pub(super) sizes: Vec<usize>,
    /// Corners whose glued side was cut (one per cut edge).
    pub(super) cut: Vec<u32>,
    /// Number of components that needed a cut.
    pub(super) non_orientable: usize,
}

/// Orients every component of `soup` along the glued sides `twin`, cutting (setting to
/// [`NONE`]) the glue that cannot be made consistent.
pub(super) fn orient(soup: &Soup, twin: &mut [u32]) -> Orientation {
    let mut o = Orientation {
        flip: vec![false; soup.faces()],
        component: vec![NONE; soup.faces()],
        sizes: Vec::new(),
        cut: Vec::new(),
        non_orientable: 0,
    };
    let mut queue = Vec::new();
    for seed in 0..soup.faces() {
        if o.component[seed] != NONE {
            continue;
        }
        queue.clear();
        let cuts_before = o.cut.len();
        o.walk(soup, twin, seed, &mut queue);
        o.keep_majority(&queue);
        o.sizes.push(queue.len());
        o.non_orientable += usize::from(o.cut.len() > cuts_before);
    }
    o
}

impl Orientation {
    /// Gives the component of `seed` its number and every face of it a flip, breadth first;
    /// the faces end up in `queue`.
    fn walk(&mut self, soup: &Soup, twin: &mut [u32], seed: usize, queue: &mut Vec<u32>) {
        let id = self.sizes.len() as u32;
        self.component[seed] = id;
        queue.push(seed as u32);
        let mut head = 0;
        while head < queue.len() {
            let f = queue[head] as usize;
            head += 1;
            for c in soup.corners(f) {
                let t = twin[c];
                if t == NONE {
                    continue;
                }
                let g = soup.face_of(t as usize);
                // Sides running the same way need exactly one of their faces turned.
                let same_way = soup.idx[c] == soup.idx[t as usize];
                let want = self.flip[f] ^ same_way;
                if self.component[g] == NONE {
                    self.component[g] = id;
                    self.flip[g] = want;
                    queue.push(g as u32);
                } else if self.flip[g] != want {
                    twin[c] = NONE;
                    twin[t as usize] = NONE;
                    self.cut.push(c as u32);
                }
            }
        }
    }

    /// Turns the whole component over when more than half of its `faces` were to be flipped.
    fn keep_majority(&mut self, faces: &[u32]) {
        let flipped = faces.iter().filter(|&&f| self.flip[f as usize]).count();
        if 2 * flipped > faces.len() {
            for &f in faces {
                self.flip[f as usize] = !self.flip[f as usize];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::edges::pair;
    use super::*;

    fn soup(faces: &[[u32; 3]]) -> Soup {
        let idx: Vec<u32> = faces.iter().flatten().copied().collect();
        let starts = (0..=faces.len() as u32).map(|f| 3 * f).collect();
        Soup::new(starts, idx, (0..faces.len() as u32).collect())
    }

    #[test]
    fn the_minority_is_flipped() {
        // A fan of four triangles around vertex 0, the second one written backwards.
        let s = soup(&[[0, 1, 2], [0, 3, 2], [0, 3, 4], [0, 4, 5]]);
        let mut twin = pair(&s, 6).twin;
        let o = orient(&s, &mut twin);
        assert_eq!(o.flip, vec![false, true, false, false]);
        assert_eq!((o.sizes.clone(), o.cut.len()), (vec![4], 0));
    }

    #[test]
    fn a_moebius_strip_is_cut_once() {
        // Six triangles around a strip whose ends are glued with a half twist.
        let s = soup(&[
            [0, 1, 3],
            [1, 4, 3],
            [1, 2, 4],
            [2, 5, 4],
            [2, 3, 5],
            [3, 0, 5],
        ]);
        let mut twin = pair(&s, 6).twin;
        let o = orient(&s, &mut twin);
        assert_eq!(o.non_orientable, 1);
        assert!(!o.cut.is_empty());
        assert_eq!(o.sizes, vec![6]);
    }
}
