//! Draw buffers: the one place where core f64 geometry becomes f32 for the GPU, and the flat
//! arrays (positions, normals, wireframe edges) the pipelines draw from.

use crate::geom::Point3;

/// Core points as a flat `x, y, z, x, y, z, …` f32 buffer: the only f64 → f32 conversion of the
/// crate. Rounds to nearest; values beyond f32's range become ±inf (the core keeps coordinates
/// finite, and anything that large is far outside any scan).
pub fn to_f32_xyz(points: &[Point3]) -> Vec<f32> {
    points
        .iter()
        .flat_map(|p| [p.x as f32, p.y as f32, p.z as f32])
        .collect()
}

/// Smooth vertex normals for a triangle mesh, area-weighted, computed in f64 and returned as a
/// flat f32 buffer like [`to_f32_xyz`]. Vertices on no triangle (or only on degenerate ones) get
/// +Y so that they still shade, instead of NaN.
pub fn vertex_normals(points: &[Point3], triangles: &[[u32; 3]]) -> Vec<f32> {
    let mut sums = vec![Point3::ZERO; points.len()];
    for t in triangles {
        let [a, b, c] = t.map(|i| i as usize);
        let (Some(&pa), Some(&pb), Some(&pc)) = (points.get(a), points.get(b), points.get(c))
        else {
            continue;
        };
        // The cross product's length is twice the area: larger triangles weigh more.
        let n = (pb - pa).cross(pc - pa);
        for i in [a, b, c] {
            sums[i] += n;
        }
    }
    let normals: Vec<Point3> = sums
        .into_iter()
        .map(|n| n.try_normalize().unwrap_or(Point3::Y))
        .collect();
    to_f32_xyz(&normals)
}

/// The edges of triangles as a line-list index buffer (two indices per edge), each shared edge
/// once, for the wireframe overlay. Sorted, so the result does not depend on hashing.
pub fn triangle_edges(indices: &[u32]) -> Vec<u32> {
    let mut edges: Vec<(u32, u32)> = indices
        .chunks_exact(3)
        .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
        .map(|(a, b)| (a.min(b), a.max(b)))
        .collect();
    edges.sort_unstable();
    edges.dedup();
    edges.into_iter().flat_map(|(a, b)| [a, b]).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn converts_and_shades_a_square() {
        let p = [
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(1.0, 1.0, 0.0),
            Point3::new(0.0, 1.0, 0.0),
            Point3::new(5.0, 5.0, 5.0),
        ];
        assert_eq!(to_f32_xyz(&p[1..2]), vec![1.0, 0.0, 0.0]);
        let n = vertex_normals(&p, &[[0, 1, 2], [0, 2, 3]]);
        assert_eq!(&n[..3], &[0.0, 0.0, 1.0]);
        assert_eq!(&n[12..], &[0.0, 1.0, 0.0], "a lone vertex gets +Y, not NaN");
        assert_eq!(
            triangle_edges(&[0, 1, 2, 0, 2, 3]),
            vec![0, 1, 0, 2, 0, 3, 1, 2, 2, 3]
        );
    }
}
