//! Local refinement of Doo–Sabin control meshes (SPEC §1.8 for a dual scheme).
//!
//! Doo–Sabin accepts any polygons, so a local split stays valid without transition templates:
//! a marked n-gon becomes n quads around its centroid through its edge midpoints, and a
//! neighbour that receives a midpoint on an edge simply gains a corner (an (n + 1)-gon). The
//! new points are the centroid and the edge midpoints of the control polygon; the centroid of
//! a face is a point of the Doo–Sabin limit surface (face centroids are kept by every step).

use crate::geom::Point3;
use crate::mesh::check_oriented_edges;
use crate::mesh::PolyMesh;
use crate::subdiv::SubdivError;
use std::collections::HashMap;

/// Splits the `marked` faces of `mesh` (one flag per face) into quads around their centroids
/// and inserts the new edge midpoints into the unmarked neighbours. Old vertices keep their
/// indices; midpoints and centroids follow.
pub fn split_polygons(mesh: &PolyMesh, marked: &[bool]) -> Result<PolyMesh, SubdivError> {
    super::check_flags(marked, mesh.num_faces())?;
    let pos = mesh.positions();
    let mut positions = pos.to_vec();
    let mut mid: HashMap<(u32, u32), u32> = HashMap::new();
    let index = super::index_u32;
    for (f, face) in mesh.faces().enumerate() {
        if !marked[f] {
            continue;
        }
        for k in 0..face.len() {
            let (a, b) = (face[k], face[(k + 1) % face.len()]);
            let key = (a.min(b), a.max(b));
            if let std::collections::hash_map::Entry::Vacant(slot) = mid.entry(key) {
                slot.insert(index(positions.len())?);
                positions.push((pos[a as usize] + pos[b as usize]) * 0.5);
            }
        }
    }
    let m = |a: u32, b: u32| mid.get(&(a.min(b), a.max(b))).copied();
    let mut faces: Vec<Vec<u32>> = Vec::with_capacity(mesh.num_faces() + mid.len());
    for (f, face) in mesh.faces().enumerate() {
        let n = face.len();
        if marked[f] {
            let c = index(positions.len())?;
            let centroid = face.iter().map(|&v| pos[v as usize]).sum::<Point3>() / n.max(1) as f64;
            positions.push(centroid);
            for k in 0..n {
                let (prev, v, next) = (face[(k + n - 1) % n], face[k], face[(k + 1) % n]);
                if let (Some(a), Some(b)) = (m(v, next), m(prev, v)) {
                    faces.push(vec![v, a, c, b]);
                }
            }
        } else {
            let mut out = Vec::with_capacity(n + 2);
            for k in 0..n {
                let (v, next) = (face[k], face[(k + 1) % n]);
                out.push(v);
                if let Some(p) = m(v, next) {
                    out.push(p);
                }
            }
            faces.push(out);
        }
    }
    let out = PolyMesh::try_new(positions, faces)?;
    check_oriented_edges(&out)?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid() -> PolyMesh {
        let mut p = Vec::new();
        for j in 0..3 {
            for i in 0..3 {
                p.push(Point3::new(i as f64, j as f64, 0.0));
            }
        }
        let id = |i: u32, j: u32| j * 3 + i;
        let faces: Vec<[u32; 4]> = (0..2)
            .flat_map(|j| {
                (0..2).map(move |i| [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)])
            })
            .collect();
        PolyMesh::try_new(p, faces).unwrap()
    }

    #[test]
    fn split_face_gives_quads_and_neighbours_gain_corners() {
        let g = grid();
        let out = split_polygons(&g, &[true, false, false, false]).unwrap();
        // 4 midpoints + 1 centroid; the split face becomes 4 quads.
        assert_eq!(out.num_vertices(), 9 + 5);
        assert_eq!(out.num_faces(), 4 + 3);
        let sizes: Vec<usize> = out.faces().map(|f| f.len()).collect();
        assert_eq!(sizes.iter().filter(|&&s| s == 5).count(), 2);
        assert!(out.positions().iter().all(|p| p.is_finite()));
        // Orientation is kept: every new face has a positive area about +z.
        for f in out.faces() {
            let p: Vec<Point3> = f.iter().map(|&v| out.positions()[v as usize]).collect();
            let mut area = 0.0;
            for k in 0..p.len() {
                let (a, b) = (p[k], p[(k + 1) % p.len()]);
                area += a.x * b.y - b.x * a.y;
            }
            assert!(area > 0.0);
        }
    }

    #[test]
    fn wrong_flag_count_is_an_error() {
        assert!(split_polygons(&grid(), &[true]).is_err());
    }
}
