//! The input's vertex–face incidence and edges, found once before simplification starts.
//!
//! The faces of each vertex are stored compressed (one offset per vertex, one array of face
//! ids), and each vertex sorts only its own few neighbours to find its edges, rather than one
//! sort of every face side of the mesh: on the bunny this setup took longer than a tenth of
//! the whole simplification.

/// An edge of the input, `a < b`, with how many faces it has and the lowest of them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct InputEdge {
    pub(super) a: u32,
    pub(super) b: u32,
    pub(super) faces: u32,
    pub(super) face: u32,
}

/// Which faces each vertex has, in face order.
pub(super) struct Incidence {
    /// Faces of vertex `v` are `faces[start[v]..start[v + 1]]`.
    start: Vec<u32>,
    faces: Vec<u32>,
}

impl Incidence {
    /// The incidence of `tris` over `vertices` vertices (indices checked by the caller).
    pub(super) fn new(vertices: usize, tris: &[[u32; 3]]) -> Incidence {
        let mut start = vec![0u32; vertices + 1];
        for &v in tris.iter().flatten() {
            start[v as usize + 1] += 1;
        }
        for v in 0..vertices {
            start[v + 1] += start[v];
        }
        let mut next = start.clone();
        let mut faces = vec![0u32; 3 * tris.len()];
        for (f, t) in tris.iter().enumerate() {
            for &v in t {
                faces[next[v as usize] as usize] = f as u32;
                next[v as usize] += 1;
            }
        }
        Incidence { start, faces }
    }

    /// The faces of `v`, in face order.
    pub(super) fn faces_of(&self, v: u32) -> &[u32] {
        let v = v as usize;
        &self.faces[self.start[v] as usize..self.start[v + 1] as usize]
    }

    /// Number of vertices with at least one face.
    pub(super) fn used_vertices(&self) -> usize {
        self.start.windows(2).filter(|w| w[1] > w[0]).count()
    }

    /// Every edge of `tris`, in order of `(a, b)`.
    pub(super) fn edges(&self, tris: &[[u32; 3]]) -> Vec<InputEdge> {
        let mut edges = Vec::with_capacity(3 * tris.len() / 2 + 3);
        let mut around: Vec<(u32, u32)> = Vec::new();
        for a in 0..self.start.len() as u32 - 1 {
            around.clear();
            for &f in self.faces_of(a) {
                around.extend(tris[f as usize].iter().filter(|&&b| b > a).map(|&b| (b, f)));
            }
            around.sort_unstable();
            for run in around.chunk_by(|x, y| x.0 == y.0) {
                edges.push(InputEdge {
                    a,
                    b: run[0].0,
                    faces: run.len() as u32,
                    face: run[0].1,
                });
            }
        }
        edges
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_triangles_share_one_edge() {
        // A square 0-1-2-3 split along 0–2, plus an unused vertex 4.
        let tris = [[0, 1, 2], [0, 2, 3]];
        let inc = Incidence::new(5, &tris);
        assert_eq!(inc.faces_of(0), &[0, 1]);
        assert_eq!(inc.faces_of(1), &[0]);
        assert!(inc.faces_of(4).is_empty());
        assert_eq!(inc.used_vertices(), 4);
        let e = |a, b, faces, face| InputEdge { a, b, faces, face };
        assert_eq!(
            inc.edges(&tris),
            vec![
                e(0, 1, 1, 0),
                e(0, 2, 2, 0),
                e(0, 3, 1, 1),
                e(1, 2, 1, 0),
                e(2, 3, 1, 1)
            ]
        );
    }
}
