use super::MeshError;
use crate::geom::{check_coordinates, Aabb, Point3};

/// Points with optional polygon connectivity: what every reader produces and every writer takes.
///
/// Invariants, checked by [`PolyMesh::try_new`]: every coordinate is finite and within
/// ±[`COORDINATE_LIMIT`](crate::geom::COORDINATE_LIMIT), every face has at
/// least three vertices, and every face index is in range. Vertices that belong to no face are
/// allowed (scans have them, and they are data points all the same).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PolyMesh {
    positions: Vec<Point3>,
    /// Face `i` is `face_indices[face_starts[i]..face_starts[i + 1]]`; `face_starts[0] == 0`.
    face_starts: Vec<u32>,
    face_indices: Vec<u32>,
}

impl PolyMesh {
    /// A mesh from positions and faces, checked against the invariants above.
    pub fn try_new<F, I>(positions: Vec<Point3>, faces: F) -> Result<PolyMesh, MeshError>
    where
        F: IntoIterator<Item = I>,
        I: AsRef<[u32]>,
    {
        check_coordinates(&positions)?;
        if u32::try_from(positions.len()).is_err() {
            return Err(MeshError::TooLarge {
                what: "vertex count",
            });
        }
        let mut mesh = PolyMesh {
            positions,
            face_starts: vec![0],
            face_indices: Vec::new(),
        };
        for (face, f) in faces.into_iter().enumerate() {
            mesh.push_face(face, f.as_ref())?;
        }
        Ok(mesh)
    }

    /// A mesh from parts the caller has checked: finite positions, `face_starts` beginning at 0
    /// and increasing by at least 3, and every index of `face_indices` below the vertex count.
    /// For the crate's own algorithms, whose output meets these by construction.
    pub(crate) fn from_parts_unchecked(
        positions: Vec<Point3>,
        face_starts: Vec<u32>,
        face_indices: Vec<u32>,
    ) -> PolyMesh {
        PolyMesh {
            positions,
            face_starts,
            face_indices,
        }
    }

    /// The face storage as it is: face `i` is `indices[starts[i]..starts[i + 1]]`.
    pub(crate) fn raw_faces(&self) -> (&[u32], &[u32]) {
        (&self.face_starts, &self.face_indices)
    }

    /// The parts: positions, face offsets (face `i` is `indices[starts[i]..starts[i + 1]]`)
    /// and face indices.
    pub(crate) fn into_parts(self) -> (Vec<Point3>, Vec<u32>, Vec<u32>) {
        (self.positions, self.face_starts, self.face_indices)
    }

    /// Points only, no faces.
    pub fn from_points(positions: Vec<Point3>) -> Result<PolyMesh, MeshError> {
        PolyMesh::try_new(positions, std::iter::empty::<[u32; 3]>())
    }

    /// The mesh without the vertices `drop` (sorted indices) and the faces that use them, and
    /// the new index of every old vertex ([`crate::mesh::NONE`] for a dropped one). Vertices
    /// keep their order.
    pub fn without_vertices(&self, drop: &[u32]) -> (PolyMesh, Vec<u32>) {
        let mut new_index = vec![0; self.num_vertices()];
        for &v in drop {
            new_index[v as usize] = super::NONE;
        }
        let mut positions = Vec::with_capacity(self.num_vertices() - drop.len());
        for (v, slot) in new_index.iter_mut().enumerate() {
            if *slot != super::NONE {
                *slot = positions.len() as u32;
                positions.push(self.positions[v]);
            }
        }
        let mut mesh = PolyMesh {
            positions,
            face_starts: vec![0],
            face_indices: Vec::new(),
        };
        for f in self.faces() {
            if f.iter().all(|&v| new_index[v as usize] != super::NONE) {
                mesh.face_indices
                    .extend(f.iter().map(|&v| new_index[v as usize]));
                mesh.face_starts.push(mesh.face_indices.len() as u32);
            }
        }
        (mesh, new_index)
    }

    /// The mesh without the vertices no face uses (a trimmed tessellation keeps its whole
    /// grid of points), and the new index of every old vertex as [`PolyMesh::without_vertices`].
    pub fn without_unused_vertices(&self) -> (PolyMesh, Vec<u32>) {
        let mut used = vec![false; self.num_vertices()];
        for &v in &self.face_indices {
            used[v as usize] = true;
        }
        let drop: Vec<u32> = (0..self.num_vertices() as u32)
            .filter(|&v| !used[v as usize])
            .collect();
        self.without_vertices(&drop)
    }

    fn push_face(&mut self, face: usize, f: &[u32]) -> Result<(), MeshError> {
        if f.len() < 3 {
            return Err(MeshError::FaceTooSmall { face, len: f.len() });
        }
        let n = self.positions.len();
        if let Some(&index) = f.iter().find(|&&i| i as usize >= n) {
            return Err(MeshError::IndexOutOfRange {
                face,
                index: index.into(),
                vertex_count: n,
            });
        }
        self.face_indices.extend_from_slice(f);
        let end = u32::try_from(self.face_indices.len()).map_err(|_| MeshError::TooLarge {
            what: "face corner count",
        })?;
        self.face_starts.push(end);
        Ok(())
    }

    /// Vertex positions.
    pub fn positions(&self) -> &[Point3] {
        &self.positions
    }

    /// Number of vertices (points).
    pub fn num_vertices(&self) -> usize {
        self.positions.len()
    }

    /// Number of faces (polygons of any size).
    pub fn num_faces(&self) -> usize {
        self.face_starts.len().saturating_sub(1)
    }

    /// The vertex indices of face `i`. Panics if `i >= num_faces()` (a caller bug, not bad data).
    pub fn face(&self, i: usize) -> &[u32] {
        &self.face_indices[self.face_starts[i] as usize..self.face_starts[i + 1] as usize]
    }

    /// All faces in order.
    pub fn faces(&self) -> impl ExactSizeIterator<Item = &[u32]> + '_ {
        (0..self.num_faces()).map(move |i| self.face(i))
    }

    /// Whether the mesh has no faces (a bare point set).
    pub fn is_point_cloud(&self) -> bool {
        self.num_faces() == 0
    }

    /// Faces fan-triangulated: an n-gon gives n − 2 triangles.
    pub fn triangles(&self) -> Vec<[u32; 3]> {
        let mut out =
            Vec::with_capacity(self.face_indices.len().saturating_sub(2 * self.num_faces()));
        for f in self.faces() {
            for k in 1..f.len() - 1 {
                out.push([f[0], f[k], f[k + 1]]);
            }
        }
        out
    }

    /// Number of triangles that [`PolyMesh::triangles`] gives, without building them.
    pub fn num_triangles(&self) -> usize {
        self.faces().map(|f| f.len() - 2).sum()
    }

    /// Bounding box of all vertices, or `None` for an empty mesh.
    pub fn bbox(&self) -> Option<Aabb> {
        Aabb::from_points(&self.positions)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(x: f64) -> Point3 {
        Point3::new(x, 0.0, 0.0)
    }

    #[test]
    fn quad_triangulates_to_two() {
        let m =
            PolyMesh::try_new(vec![p(0.0), p(1.0), p(2.0), p(3.0)], [vec![0, 1, 2, 3]]).unwrap();
        assert_eq!(m.num_faces(), 1);
        assert_eq!(m.triangles(), vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(m.num_triangles(), 2);
    }

    #[test]
    fn rejects_bad_faces_and_coordinates() {
        let e = PolyMesh::try_new(vec![p(0.0), p(1.0), p(2.0)], [[0, 1, 5]]).unwrap_err();
        assert!(matches!(
            e,
            MeshError::IndexOutOfRange {
                face: 0,
                index: 5,
                vertex_count: 3
            }
        ));
        let e = PolyMesh::try_new(vec![p(0.0), p(1.0)], [vec![0, 1]]).unwrap_err();
        assert!(matches!(e, MeshError::FaceTooSmall { face: 0, len: 2 }));
        let e = PolyMesh::from_points(vec![p(0.0), p(f64::NAN)]).unwrap_err();
        assert!(matches!(e, MeshError::NonFiniteVertex { vertex: 1 }));
        let e = PolyMesh::from_points(vec![p(0.0), p(1.0), p(-1e308)]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "vertex 2 has coordinate -1e308, beyond ±3.4e38 (the largest an f32 holds; geofit \
             renders and stores positions as f32)"
        );
    }

    #[test]
    fn dropping_vertices_drops_their_faces_and_renumbers_the_rest() {
        let m = PolyMesh::try_new(
            vec![p(0.0), p(1.0), p(2.0), p(3.0), p(4.0)],
            [vec![0, 1, 2], vec![1, 3, 4], vec![2, 3, 4, 0]],
        )
        .unwrap();
        let (kept, new_index) = m.without_vertices(&[1]);
        assert_eq!(new_index, vec![0, crate::mesh::NONE, 1, 2, 3]);
        assert_eq!(kept.positions(), &[p(0.0), p(2.0), p(3.0), p(4.0)]);
        assert_eq!(kept.faces().collect::<Vec<_>>(), vec![&[1u32, 2, 3, 0][..]]);
    }

    #[test]
    fn unused_vertices_are_dropped_and_the_faces_renumbered() {
        let m = PolyMesh::try_new(vec![p(0.0), p(1.0), p(2.0), p(3.0)], [vec![1, 3, 2]]).unwrap();
        let (kept, new_index) = m.without_unused_vertices();
        assert_eq!(new_index, vec![crate::mesh::NONE, 0, 1, 2]);
        assert_eq!(kept.positions(), &[p(1.0), p(2.0), p(3.0)]);
        assert_eq!(kept.faces().collect::<Vec<_>>(), vec![&[0u32, 2, 1][..]]);
    }
}
