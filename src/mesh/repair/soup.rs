//! The faces under repair, stored like [`PolyMesh`](crate::mesh::PolyMesh)'s (one offset per
//! face into one index array), with the input face each came from.
//!
//! A *corner* is a position in the index array; corner `c` also names the face side from
//! `idx[c]` to the next corner of its face, so one array of corners serves both the vertices of
//! faces and their edges.

/// Faces as offsets into one index array.
pub(super) struct Soup {
    /// Face `f` is `idx[starts[f]..starts[f + 1]]`.
    pub(super) starts: Vec<u32>,
    /// Vertex of each corner.
    pub(super) idx: Vec<u32>,
    /// Input face of each face, for the report.
    pub(super) origin: Vec<u32>,
    /// Face of each corner (empty when every face is a triangle: then it is `c / 3`).
    face_of: Vec<u32>,
}

impl Soup {
    /// A soup of the given faces (`starts` begins at 0 and has one entry more than `origin`).
    pub(super) fn new(starts: Vec<u32>, idx: Vec<u32>, origin: Vec<u32>) -> Soup {
        let mut face_of = Vec::new();
        if idx.len() != 3 * origin.len() {
            face_of = vec![0u32; idx.len()];
            for (f, w) in starts.windows(2).enumerate() {
                face_of[w[0] as usize..w[1] as usize].fill(f as u32);
            }
        }
        Soup {
            starts,
            idx,
            origin,
            face_of,
        }
    }

    /// Number of faces.
    pub(super) fn faces(&self) -> usize {
        self.origin.len()
    }

    /// The corners of face `f`.
    pub(super) fn corners(&self, f: usize) -> std::ops::Range<usize> {
        self.starts[f] as usize..self.starts[f + 1] as usize
    }

    /// The vertices of face `f`.
    pub(super) fn face(&self, f: usize) -> &[u32] {
        &self.idx[self.corners(f)]
    }

    /// The face of corner `c`.
    pub(super) fn face_of(&self, c: usize) -> usize {
        if self.face_of.is_empty() {
            c / 3
        } else {
            self.face_of[c] as usize
        }
    }

    /// The corner after `c` in its face (the far end of side `c`).
    pub(super) fn next(&self, c: usize) -> usize {
        if self.face_of.is_empty() {
            return if c % 3 == 2 { c - 2 } else { c + 1 };
        }
        let f = self.face_of[c] as usize;
        if c + 1 == self.starts[f + 1] as usize {
            self.starts[f] as usize
        } else {
            c + 1
        }
    }

    /// The corner before `c` in its face.
    pub(super) fn prev(&self, c: usize) -> usize {
        if self.face_of.is_empty() {
            return if c % 3 == 0 { c + 2 } else { c - 1 };
        }
        let f = self.face_of[c] as usize;
        if c == self.starts[f] as usize {
            self.starts[f + 1] as usize - 1
        } else {
            c - 1
        }
    }

    /// The same soup without the faces marked in `drop`.
    pub(super) fn without(&self, drop: &[bool]) -> Soup {
        let mut starts = vec![0u32];
        let mut idx = Vec::with_capacity(self.idx.len());
        let mut origin = Vec::with_capacity(self.faces());
        for f in (0..self.faces()).filter(|&f| !drop[f]) {
            idx.extend_from_slice(self.face(f));
            starts.push(idx.len() as u32);
            origin.push(self.origin[f]);
        }
        Soup::new(starts, idx, origin)
    }

    /// Reverses the orientation of face `f`, keeping its first corner first.
    pub(super) fn reverse(&mut self, f: usize) {
        let r = self.corners(f);
        self.idx[r.start + 1..r.end].reverse();
    }

    /// The parts of a [`PolyMesh`](crate::mesh::PolyMesh): face offsets and indices.
    pub(super) fn into_parts(self) -> (Vec<u32>, Vec<u32>) {
        (self.starts, self.idx)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn corners_walk_around_their_faces() {
        // A triangle and a quad.
        let s = Soup::new(vec![0, 3, 7], vec![0, 1, 2, 2, 1, 3, 4], vec![0, 1]);
        assert_eq!(s.faces(), 2);
        assert_eq!(s.face(1), &[2, 1, 3, 4]);
        assert_eq!((s.next(2), s.prev(0)), (0, 2));
        assert_eq!((s.next(6), s.prev(3), s.face_of(5)), (3, 6, 1));
        let mut t = s.without(&[true, false]);
        assert_eq!((t.faces(), t.origin[0]), (1, 1));
        t.reverse(0);
        assert_eq!(t.face(0), &[2, 4, 3, 1]);
    }
}
