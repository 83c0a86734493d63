//! How far a set of points lies from a triangle mesh: the measure of what simplification lost
//! (the distance of every original vertex to the simplified surface).

use crate::geom::{Aabb, Point3, Vec3};
use crate::mesh::PolyMesh;
use serde::Serialize;

/// Distances of points to a mesh, in the mesh's units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Deviation {
    /// Largest point-to-surface distance.
    pub max: f64,
    /// Root mean square of the distances.
    pub rms: f64,
    /// Mean distance.
    pub mean: f64,
}

impl Deviation {
    /// The same figures as percentages of `length` (usually the data's bounding-box diagonal).
    pub fn percent_of(&self, length: f64) -> Deviation {
        let s = if length > 0.0 { 100.0 / length } else { 0.0 };
        Deviation {
            max: self.max * s,
            rms: self.rms * s,
            mean: self.mean * s,
        }
    }
}

/// Distance from each of `points` to the triangles of `mesh` (polygons fan-triangulated), with
/// max/rms/mean. Returns `None` when the mesh has no faces or there are no points.
///
/// A bounding-volume hierarchy over the triangles makes this about O(n log m).
pub fn deviation(points: &[Point3], mesh: &PolyMesh) -> Option<Deviation> {
    let tris = corner_positions(mesh);
    if tris.is_empty() || points.is_empty() {
        return None;
    }
    let bvh = Bvh::build(&tris);
    let (mut max, mut sum, mut sum_sq) = (0.0f64, 0.0, 0.0);
    for &p in points {
        let d = bvh.nearest(&tris, p).0.sqrt();
        max = max.max(d);
        sum += d;
        sum_sq += d * d;
    }
    let n = points.len() as f64;
    Some(Deviation {
        max,
        rms: (sum_sq / n).sqrt(),
        mean: sum / n,
    })
}

/// Below this cosine between a simplified face's normal and the normal of the input surface it
/// covers, the face is folded over: a folded face points backwards (−1), while faces bridging
/// a groove or cutting a sharp corner may lie sideways (near 0).
const FOLDED_COS: f64 = -0.5;

/// The input a face covers has a direction only when its triangles agree: the length of their
/// summed area normals is at least this share of their summed areas. Two sheets facing apart
/// (both sides of a thin part, or an input that is two-sided in places) cancel, and no
/// orientation of a face between them could agree with both.
const COHERENT: f64 = 0.5;

/// The faces of a simplified mesh that point against the input surface they stand for.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Foldovers {
    /// Faces of the simplified mesh whose normal makes more than 120° with the area-weighted
    /// normal of the input triangles nearest to it, where those agree among themselves (see
    /// [`foldovers`]).
    pub count: usize,
    /// The first few of them (face indices of the simplified mesh).
    pub first: Vec<usize>,
    /// The smallest cosine between a simplified face and the input it covers (1 when no face
    /// covers any input).
    pub worst_cos: f64,
}

/// Fold-overs of `coarse` against `original`: every input triangle (polygons fan-triangulated)
/// is assigned to the simplified triangle nearest to its centroid, and each simplified face is
/// compared with the summed area normals of the triangles assigned to it when they are
/// coherent (their sum at least half their summed areas). Input triangles that face away from
/// a triangle they share a vertex with (by more than 120°: fins, flattened pockets, both sides
/// of a sheet) do not count: no face can agree with both sides of them.
pub fn foldovers(original: &PolyMesh, coarse: &PolyMesh) -> Foldovers {
    let tris: Vec<[Point3; 3]> = corner_positions(coarse);
    let mut out = Foldovers {
        count: 0,
        first: Vec::new(),
        worst_cos: 1.0,
    };
    if tris.is_empty() {
        return out;
    }
    let bvh = Bvh::build(&tris);
    let mut covered = vec![Vec3::ZERO; tris.len()];
    let mut area = vec![0.0; tris.len()];
    let input = original.triangles();
    let two_sided = folded_back(original.positions(), &input);
    let pos = original.positions();
    for (t, _) in input.iter().zip(&two_sided).filter(|(_, &x)| !x) {
        let [a, b, c] = t.map(|v| pos[v as usize]);
        let (_, k) = bvh.nearest(&tris, (a + b + c) / 3.0);
        let n = (b - a).cross(c - a);
        covered[k] += n;
        area[k] += n.length();
    }
    for (k, t) in tris.iter().enumerate() {
        let coherent = covered[k].length() >= COHERENT * area[k] && area[k] > 0.0;
        let n = (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero();
        let cos = n.dot(covered[k].normalize_or_zero());
        if !coherent || n == Vec3::ZERO {
            continue;
        }
        out.worst_cos = out.worst_cos.min(cos);
        if cos < FOLDED_COS {
            out.count += 1;
            if out.first.len() < 5 {
                out.first.push(k);
            }
        }
    }
    out
}

/// Whether each of `tris` faces away (by more than 120°) from a triangle it shares a vertex
/// with.
fn folded_back(pos: &[Point3], tris: &[[u32; 3]]) -> Vec<bool> {
    let normal = |t: &[u32; 3]| {
        let [a, b, c] = t.map(|v| pos[v as usize]);
        (b - a).cross(c - a).normalize_or_zero()
    };
    let mut start = vec![0u32; pos.len() + 1];
    for t in tris {
        for &v in t {
            start[v as usize + 1] += 1;
        }
    }
    for v in 0..pos.len() {
        start[v + 1] += start[v];
    }
    let mut fill = start.clone();
    let mut around = vec![0u32; 3 * tris.len()];
    for (f, t) in tris.iter().enumerate() {
        for &v in t {
            around[fill[v as usize] as usize] = f as u32;
            fill[v as usize] += 1;
        }
    }
    let mut out = vec![false; tris.len()];
    let mut normals = Vec::new();
    for w in start.windows(2) {
        let faces = &around[w[0] as usize..w[1] as usize];
        normals.clear();
        normals.extend(faces.iter().map(|&f| normal(&tris[f as usize])));
        for i in 0..faces.len() {
            for j in 0..i {
                if normals[i].dot(normals[j]) < FOLDED_COS {
                    out[faces[i] as usize] = true;
                    out[faces[j] as usize] = true;
                }
            }
        }
    }
    out
}

/// The corner positions of every triangle of `mesh` (polygons fan-triangulated).
fn corner_positions(mesh: &PolyMesh) -> Vec<[Point3; 3]> {
    mesh.triangles()
        .iter()
        .map(|t| t.map(|i| mesh.positions()[i as usize]))
        .collect()
}

/// Squared distance from `p` to triangle `t` (Ericson, Real-Time Collision Detection §5.1.5).
pub(crate) fn point_triangle_dist_sq(p: Point3, t: &[Point3; 3]) -> f64 {
    let [a, b, c] = *t;
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return ap.length_squared();
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return bp.length_squared();
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return (p - (a + ab * v)).length_squared();
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return cp.length_squared();
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return (p - (a + ac * w)).length_squared();
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (p - (b + (c - b) * w)).length_squared();
    }
    let denom = va + vb + vc;
    if denom == 0.0 || denom.is_nan() {
        // Degenerate triangle: nearest of its edges' end points is a safe upper bound.
        return ap
            .length_squared()
            .min(bp.length_squared())
            .min(cp.length_squared());
    }
    let (v, w) = (vb / denom, vc / denom);
    (p - (a + ab * v + ac * w)).length_squared()
}

/// Squared distance from `p` to box `b` (0 inside).
fn box_dist_sq(b: &Aabb, p: Point3) -> f64 {
    let d = (b.min - p).max(p - b.max).max(Point3::ZERO);
    d.length_squared()
}

/// A node: a box, and either two children or a range of triangles.
struct Node {
    bbox: Aabb,
    /// Two children, or a leaf's range in [`Bvh::order`].
    kind: NodeKind,
}

enum NodeKind {
    /// Indices of the two child nodes.
    Inner(u32, u32),
    /// Start and end of the node's triangles in [`Bvh::order`].
    Leaf(u32, u32),
}

/// Bounding-volume hierarchy over triangles, split at the median centroid on the longest axis.
struct Bvh {
    nodes: Vec<Node>,
    /// Triangle indices, permuted so that every node's triangles are contiguous.
    order: Vec<u32>,
}

const LEAF_SIZE: usize = 4;

impl Bvh {
    fn build(tris: &[[Point3; 3]]) -> Bvh {
        let mut bvh = Bvh {
            nodes: Vec::with_capacity(2 * tris.len() / LEAF_SIZE + 1),
            order: (0..tris.len() as u32).collect(),
        };
        let centroids: Vec<Point3> = tris.iter().map(|t| (t[0] + t[1] + t[2]) / 3.0).collect();
        bvh.build_node(tris, &centroids, 0, tris.len());
        bvh
    }

    fn build_node(&mut self, tris: &[[Point3; 3]], cent: &[Point3], lo: usize, hi: usize) -> u32 {
        let corners: Vec<Point3> = self.order[lo..hi]
            .iter()
            .flat_map(|&i| tris[i as usize])
            .collect();
        let bbox = Aabb::from_points(&corners).unwrap_or(Aabb {
            min: Point3::ZERO,
            max: Point3::ZERO,
        });
        let id = self.nodes.len() as u32;
        self.nodes.push(Node {
            bbox,
            kind: NodeKind::Leaf(lo as u32, hi as u32),
        });
        if hi - lo > LEAF_SIZE {
            let ext = bbox.max - bbox.min;
            let axis = if ext.x >= ext.y && ext.x >= ext.z {
                0
            } else if ext.y >= ext.z {
                1
            } else {
                2
            };
            let mid = (lo + hi) / 2;
            self.order[lo..hi].select_nth_unstable_by(mid - lo, |&a, &b| {
                cent[a as usize][axis]
                    .total_cmp(&cent[b as usize][axis])
                    .then(a.cmp(&b))
            });
            let left = self.build_node(tris, cent, lo, mid);
            let right = self.build_node(tris, cent, mid, hi);
            self.nodes[id as usize].kind = NodeKind::Inner(left, right);
        }
        id
    }

    /// The squared distance from `p` to the nearest triangle, and that triangle.
    fn nearest(&self, tris: &[[Point3; 3]], p: Point3) -> (f64, usize) {
        let mut best = f64::INFINITY;
        let mut best_t = 0;
        let mut stack = vec![0u32];
        while let Some(n) = stack.pop() {
            let node = &self.nodes[n as usize];
            if box_dist_sq(&node.bbox, p) >= best {
                continue;
            }
            match node.kind {
                NodeKind::Leaf(lo, hi) => {
                    for &t in &self.order[lo as usize..hi as usize] {
                        let d = point_triangle_dist_sq(p, &tris[t as usize]);
                        if d < best {
                            (best, best_t) = (d, t as usize);
                        }
                    }
                }
                NodeKind::Inner(l, r) => {
                    let dl = box_dist_sq(&self.nodes[l as usize].bbox, p);
                    let dr = box_dist_sq(&self.nodes[r as usize].bbox, p);
                    // Visit the nearer child first: push it last.
                    if dl < dr {
                        stack.extend([r, l]);
                    } else {
                        stack.extend([l, r]);
                    }
                }
            }
        }
        (best, best_t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn triangle_distance_regions() {
        let t = [Point3::ZERO, Point3::X, Point3::Y];
        let d = |x, y, z| point_triangle_dist_sq(Point3::new(x, y, z), &t);
        assert!((d(0.2, 0.2, 2.0) - 4.0).abs() < 1e-12); // face
        assert!((d(-1.0, -1.0, 0.0) - 2.0).abs() < 1e-12); // vertex a
        assert!((d(0.5, -1.0, 0.0) - 1.0).abs() < 1e-12); // edge ab
        assert!((d(1.0, 1.0, 0.0) - 0.5).abs() < 1e-12); // edge bc
        assert!((d(3.0, 0.0, 0.0) - 4.0).abs() < 1e-12); // vertex b
    }

    #[test]
    fn bvh_agrees_with_brute_force() {
        let mut pos = Vec::new();
        let mut faces = Vec::new();
        let n = 12u32;
        for j in 0..n {
            for i in 0..n {
                let (x, y) = (i as f64, j as f64);
                pos.push(Point3::new(x, y, (x * 0.7).sin() + (y * 0.3).cos()));
            }
        }
        for j in 0..n - 1 {
            for i in 0..n - 1 {
                let a = j * n + i;
                faces.push([a, a + 1, a + n + 1]);
                faces.push([a, a + n + 1, a + n]);
            }
        }
        let mesh = PolyMesh::try_new(pos, faces).expect("valid grid");
        let tris: Vec<[Point3; 3]> = mesh
            .triangles()
            .iter()
            .map(|t| t.map(|i| mesh.positions()[i as usize]))
            .collect();
        let bvh = Bvh::build(&tris);
        for k in 0..200 {
            let k = k as f64;
            let p = Point3::new(
                (k * 0.37) % 13.0 - 1.0,
                (k * 0.73) % 13.0 - 1.0,
                (k * 0.11) % 4.0 - 2.0,
            );
            let brute = tris
                .iter()
                .map(|t| point_triangle_dist_sq(p, t))
                .fold(f64::INFINITY, f64::min);
            assert!((bvh.nearest(&tris, p).0 - brute).abs() < 1e-12);
        }
    }
}
