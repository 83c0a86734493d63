//! Splitting vertices into their fans: the corners of a vertex that are joined through glued
//! sides form one fan, and each fan beyond the first gets its own copy of the vertex.
//!
//! Two cones touching at their tips, or a page detached from a book, leave a vertex whose
//! faces cannot be walked around in one go; after the split every vertex has one fan, which is
//! what subdivision and the half-edge mesh need. Copies share the position of their vertex.

use super::soup::Soup;
use crate::mesh::NONE;

/// The vertex of every corner after the split.
pub(super) struct Fans {
    /// New vertex of each corner: the old one for a vertex's first fan, a copy for the others.
    pub(super) corner_vertex: Vec<u32>,
    /// The vertex each copy was made from; copy `k` is vertex `vertices + k`.
    pub(super) copy_of: Vec<u32>,
    /// Vertices with more than one fan, in order.
    pub(super) split: Vec<u32>,
}

/// Splits every vertex of `soup` (below `vertices`) into its fans along the glued sides `twin`.
pub(super) fn split(soup: &Soup, twin: &[u32], vertices: usize) -> Fans {
    let (starts, corners) = corners_by_vertex(soup, vertices);
    let mut fans = Fans {
        corner_vertex: vec![NONE; soup.idx.len()],
        copy_of: Vec::new(),
        split: Vec::new(),
    };
    let mut stack = Vec::new();
    for (v, w) in starts.windows(2).enumerate() {
        let mut count = 0;
        for &c in &corners[w[0] as usize..w[1] as usize] {
            if fans.corner_vertex[c as usize] != NONE {
                continue;
            }
            let id = if count == 0 {
                v as u32
            } else {
                fans.copy_of.push(v as u32);
                (vertices + fans.copy_of.len() - 1) as u32
            };
            count += 1;
            fans.claim_fan(soup, twin, c as usize, id, &mut stack);
        }
        if count > 1 {
            fans.split.push(v as u32);
        }
    }
    fans
}

impl Fans {
    /// Gives vertex `id` to corner `start` and every corner of the same vertex reachable from
    /// it across glued sides.
    fn claim_fan(
        &mut self,
        soup: &Soup,
        twin: &[u32],
        start: usize,
        id: u32,
        stack: &mut Vec<u32>,
    ) {
        let v = soup.idx[start];
        self.corner_vertex[start] = id;
        stack.push(start as u32);
        while let Some(c) = stack.pop() {
            let c = c as usize;
            // The two sides of the face at this corner: the one leaving it and the one arriving.
            for side in [c, soup.prev(c)] {
                let t = twin[side];
                if t == NONE {
                    continue;
                }
                let t = t as usize;
                let other = if soup.idx[t] == v { t } else { soup.next(t) };
                if self.corner_vertex[other] == NONE {
                    self.corner_vertex[other] = id;
                    stack.push(other as u32);
                }
            }
        }
    }
}

/// The corners of every vertex (corners of `v` are `corners[starts[v]..starts[v + 1]]`, in
/// order).
fn corners_by_vertex(soup: &Soup, vertices: usize) -> (Vec<u32>, Vec<u32>) {
    let mut starts = vec![0u32; vertices + 1];
    for &v in &soup.idx {
        starts[v as usize + 1] += 1;
    }
    for v in 0..vertices {
        starts[v + 1] += starts[v];
    }
    let mut fill = starts.clone();
    let mut corners = vec![0u32; soup.idx.len()];
    for (c, &v) in soup.idx.iter().enumerate() {
        corners[fill[v as usize] as usize] = c as u32;
        fill[v as usize] += 1;
    }
    (starts, corners)
}

#[cfg(test)]
mod tests {
    use super::super::edges::pair;
    use super::*;

    #[test]
    fn two_fans_touching_at_a_vertex_get_two_vertices() {
        // Two triangles sharing only vertex 0 (a bow tie), and a third glued to the first.
        let idx = vec![0, 1, 2, 0, 3, 4, 2, 1, 5];
        let s = Soup::new(vec![0, 3, 6, 9], idx, vec![0, 1, 2]);
        let twin = pair(&s, 6).twin;
        let f = split(&s, &twin, 6);
        assert_eq!(f.split, vec![0]);
        assert_eq!(f.copy_of, vec![0]);
        assert_eq!(f.corner_vertex[..6], [0, 1, 2, 6, 3, 4]);
        assert_eq!(f.corner_vertex[6..], [2, 1, 5]);
    }
}
