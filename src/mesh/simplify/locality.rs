//! A spatial numbering of the working mesh, so that a collapse's neighbourhood sits in few
//! cache lines.
//!
//! Each collapse reads and writes the faces, positions, quadrics and links of a one-ring that
//! the queue picks anywhere on the surface; with the input's numbering (a scan's, about a
//! hundred indices between neighbours on the bunny) nearly every access missed the cache. In
//! Morton (Z-curve) order neighbours are mostly a few indices apart. Only the storage changes:
//! ties and the surviving end of a collapse are still decided by input indices, so the result
//! is the same.

use crate::geom::Point3;

/// Bits per coordinate of the Morton code (three of them fill 63 bits).
const BITS: u32 = 21;

/// A renumbering of vertices and faces and its inverse.
pub(super) struct Numbering {
    /// Input index of each working vertex.
    pub(super) vertex_input: Vec<u32>,
    /// Working index of each input vertex.
    pub(super) vertex_work: Vec<u32>,
    /// Working index of each input face.
    pub(super) face_work: Vec<u32>,
}

impl Numbering {
    /// The numbering that changes nothing.
    #[cfg(test)]
    pub(super) fn identity(vertices: usize, faces: usize) -> Numbering {
        let ids = |n: usize| (0..n as u32).collect::<Vec<u32>>();
        Numbering {
            vertex_input: ids(vertices),
            vertex_work: ids(vertices),
            face_work: ids(faces),
        }
    }

    /// Vertices in Morton order of their positions, faces in order of their lowest new
    /// vertex (ties in input order, so the numbering is deterministic).
    pub(super) fn spatial(pos: &[Point3], faces: &[[u32; 3]]) -> Numbering {
        let code = morton_codes(pos);
        let mut vertex_input: Vec<u32> = (0..pos.len() as u32).collect();
        vertex_input.sort_unstable_by_key(|&v| (code[v as usize], v));
        let vertex_work = inverse(&vertex_input);
        let mut face_order: Vec<(u32, u32)> = faces
            .iter()
            .enumerate()
            .map(|(f, t)| {
                (
                    t.map(|v| vertex_work[v as usize])
                        .into_iter()
                        .min()
                        .unwrap_or(0),
                    f as u32,
                )
            })
            .collect();
        face_order.sort_unstable();
        let face_input: Vec<u32> = face_order.into_iter().map(|(_, f)| f).collect();
        Numbering {
            vertex_input,
            vertex_work,
            face_work: inverse(&face_input),
        }
    }
}

/// The inverse of a permutation.
fn inverse(perm: &[u32]) -> Vec<u32> {
    let mut inv = vec![0; perm.len()];
    for (i, &p) in perm.iter().enumerate() {
        inv[p as usize] = i as u32;
    }
    inv
}

/// Morton code of each point in the points' bounding box (finite coordinates assumed; a flat
/// box axis gives 0 on that axis).
fn morton_codes(pos: &[Point3]) -> Vec<u64> {
    let lo = pos.iter().fold(Point3::INFINITY, |a, &p| a.min(p));
    let hi = pos.iter().fold(Point3::NEG_INFINITY, |a, &p| a.max(p));
    let cells = f64::from((1u32 << BITS) - 1);
    let scale = (hi - lo).map(|e| if e > 0.0 { cells / e } else { 0.0 });
    pos.iter()
        .map(|&p| {
            let q = ((p - lo) * scale).clamp(Point3::ZERO, Point3::splat(cells));
            spread(q.x as u64) | spread(q.y as u64) << 1 | spread(q.z as u64) << 2
        })
        .collect()
}

/// The low 21 bits of `x` moved to every third bit.
fn spread(x: u64) -> u64 {
    let mut x = x & 0x1f_ffff;
    x = (x | x << 32) & 0x1f_0000_0000_ffff;
    x = (x | x << 16) & 0x1f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    (x | x << 2) & 0x1249_2492_4924_9249
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spread_interleaves_bits() {
        assert_eq!(spread(0b1011), 0b1_000_001_001);
        assert_eq!(spread(0x1f_ffff), 0x1249_2492_4924_9249);
    }

    #[test]
    fn spatial_numbering_is_a_permutation_grouping_near_points() {
        // Two clusters given interleaved: the numbering puts each cluster together.
        let pos: Vec<Point3> = (0..40)
            .map(|k| {
                let far = if k % 2 == 0 { 0.0 } else { 100.0 };
                Point3::new(far + (k / 2) as f64 * 0.01, 1.0, 2.0)
            })
            .collect();
        let faces: Vec<[u32; 3]> = (0..38).map(|k| [k, k + 1, k + 2]).collect();
        let n = Numbering::spatial(&pos, &faces);
        let mut seen = n.vertex_input.clone();
        seen.sort_unstable();
        assert_eq!(seen, (0..40).collect::<Vec<u32>>());
        assert!(n.vertex_input[..20].iter().all(|&v| v % 2 == 0));
        for (w, &v) in n.vertex_input.iter().enumerate() {
            assert_eq!(n.vertex_work[v as usize], w as u32);
        }
        let mut faces_seen = n.face_work.clone();
        faces_seen.sort_unstable();
        assert_eq!(faces_seen, (0..38).collect::<Vec<u32>>());
    }
}
