//! Local conforming refinement of quad control meshes (Catmull–Clark; SPEC §1.8).
//!
//! Marked quads are split 1→4. Their neighbours then have split edges, and a mesh stays
//! conforming and all-quad only if every quad has an even number of split edges (a disc cut
//! into quads has an even number of boundary edges), so the split edges are closed with
//! templates:
//! - four split edges: 1→4 around a centre;
//! - two opposite split edges: 2 quads;
//! - two adjacent split edges: 3 quads around a new centre (the corner template);
//! - three: the fourth edge is split as well.
//!
//! Quads left with one split edge are paired: from each, the cheapest chain of unsplit edges
//! to another such quad, or to the open boundary, is split too (a T-join in the dual graph), so
//! every quad on the chain gets two more split edges and its ends one each. Chains prefer quads
//! without split edges, and turns whose far corner has a low valence (the corner template adds
//! an edge there).
//!
//! New points follow Catmull–Clark's rules: face centroids, edge points (a + b + F₀ + F₁)/4
//! (midpoints on the boundary), and old vertices all of whose quads are split 1→4 move by the
//! vertex rule, so where a whole neighbourhood is split the limit surface does not change.
//! Old vertices keep their indices; edge points and centres follow.

use crate::geom::Point3;
use crate::mesh::PolyMesh;
use crate::mesh::{check_oriented_edges, TopologyError};
use crate::subdiv::{Scheme, SubdivError};
use std::cmp::Reverse;
use std::collections::{BinaryHeap, HashMap, HashSet};

/// No face / no point.
const NO: u32 = u32::MAX;
/// Search states one pairing chain may visit before its quad is split whole instead.
const MAX_SEARCH: usize = 20_000;
/// Cost of crossing one edge in a pairing chain.
const STEP: u64 = 4;
/// Extra cost of a chain through a quad that already has two split edges (it becomes 1→4).
const THROUGH_SPLIT: u64 = 12;
/// Extra cost of a turn (corner template), plus this again per valence above 4 at its far
/// corner.
const TURN: u64 = 2;

type Quad = [u32; 4];

/// Quads of `mesh`, or an error naming the first face that is not one.
fn quads_of(mesh: &PolyMesh) -> Result<Vec<Quad>, SubdivError> {
    mesh.faces()
        .enumerate()
        .map(|(i, f)| match f {
            &[a, b, c, d] => Ok([a, b, c, d]),
            _ => Err(SubdivError::WrongFaceSize {
                face: i,
                len: f.len(),
                scheme: Scheme::CatmullClark,
            }),
        })
        .collect()
}

/// The edges of a quad mesh: ends, the faces on either side (`NO` past a boundary), the four
/// edges of every quad (edge `k` runs from corner `k` to corner `k + 1`), the quads' corners
/// and vertex valences.
struct QuadEdges {
    corners: Vec<Quad>,
    ends: Vec<[u32; 2]>,
    faces: Vec<[u32; 2]>,
    of_face: Vec<[u32; 4]>,
    valence: Vec<u32>,
}

impl QuadEdges {
    fn new(quads: &[Quad], nv: usize) -> Result<QuadEdges, SubdivError> {
        let mut index: HashMap<(u32, u32), u32> = HashMap::with_capacity(quads.len() * 2);
        let mut edges = QuadEdges {
            corners: quads.to_vec(),
            ends: Vec::new(),
            faces: Vec::new(),
            of_face: Vec::with_capacity(quads.len()),
            valence: vec![0; nv],
        };
        for (f, q) in quads.iter().enumerate() {
            let mut ids = [0u32; 4];
            for k in 0..4 {
                let (a, b) = (q[k], q[(k + 1) % 4]);
                let next = edges.ends.len() as u32;
                let id = *index.entry((a.min(b), a.max(b))).or_insert(next);
                if id == next {
                    edges.ends.push([a, b]);
                    edges.faces.push([f as u32, NO]);
                    edges.valence[a as usize] += 1;
                    edges.valence[b as usize] += 1;
                } else if edges.faces[id as usize][1] == NO {
                    edges.faces[id as usize][1] = f as u32;
                } else {
                    return Err(TopologyError::NonManifoldEdge { a, b, faces: 3 }.into());
                }
                ids[k] = id;
            }
            edges.of_face.push(ids);
        }
        Ok(edges)
    }

    /// The face across edge `e` from face `f` (`NO` at a boundary).
    fn across(&self, e: u32, f: u32) -> u32 {
        let [a, b] = self.faces[e as usize];
        if a == f {
            b
        } else {
            a
        }
    }

    /// Number of split edges of every quad.
    fn counts(&self, split: &[bool]) -> Vec<u8> {
        self.of_face
            .iter()
            .map(|es| es.iter().filter(|&&e| split[e as usize]).count() as u8)
            .collect()
    }
}

/// Splits the `marked` quads of `mesh` 1→4 (one flag per face) and closes the split with
/// transition templates so the mesh stays all-quad, conforming and consistently oriented.
/// New points come from Catmull–Clark's masks (see the module docs), with the crease rules
/// on the crease edges `creases` (midpoints; the boundary mask along crease lines).
pub fn split_quads(
    mesh: &PolyMesh,
    marked: &[bool],
    creases: &[[u32; 2]],
) -> Result<PolyMesh, SubdivError> {
    let quads = quads_of(mesh)?;
    super::check_flags(marked, quads.len())?;
    check_oriented_edges(mesh)?;
    let edges = QuadEdges::new(&quads, mesh.num_vertices())?;
    let sharp: HashSet<(u32, u32)> = creases.iter().map(|&[a, b]| (a.min(b), a.max(b))).collect();
    let is_sharp = |e: usize| {
        let [a, b] = edges.ends[e];
        sharp.contains(&(a.min(b), a.max(b)))
    };
    let split = close_split(&quads, &edges, marked);
    let counts = edges.counts(&split);
    let pos = mesh.positions();
    let mut positions = moved_vertices(pos, &quads, &edges, &counts, &is_sharp);
    let centroid = |f: usize| quads[f].iter().map(|&v| pos[v as usize]).sum::<Point3>() * 0.25;
    let mut edge_point = vec![NO; edges.ends.len()];
    for (e, _) in split.iter().enumerate().filter(|(_, &s)| s) {
        let [a, b] = edges.ends[e];
        let mid = pos[a as usize] + pos[b as usize];
        let p = match edges.faces[e] {
            [f0, f1] if f1 != NO && !is_sharp(e) => {
                (mid + centroid(f0 as usize) + centroid(f1 as usize)) * 0.25
            }
            _ => mid * 0.5,
        };
        edge_point[e] = super::index_u32(positions.len())?;
        positions.push(p);
    }
    let mut faces = Vec::with_capacity(quads.len() + 3 * edge_point.len());
    for (f, q) in quads.iter().enumerate() {
        let m = edges.of_face[f].map(|e| edge_point[e as usize]);
        let centre = || -> Result<u32, SubdivError> {
            positions.push(centroid(f));
            super::index_u32(positions.len() - 1)
        };
        template(q, m, centre, &mut faces)?;
    }
    Ok(PolyMesh::try_new(positions, faces)?)
}

/// Appends the quads that replace `q`, whose edge points are `m` (`NO` where an edge is not
/// split); `centre` adds the new centre point when the template needs one.
fn template(
    q: &Quad,
    m: [u32; 4],
    mut centre: impl FnMut() -> Result<u32, SubdivError>,
    out: &mut Vec<Quad>,
) -> Result<(), SubdivError> {
    let s = m.map(|p| p != NO);
    let k = |i: usize| i % 4;
    match s.iter().filter(|&&x| x).count() {
        0 => out.push(*q),
        4 => {
            let c = centre()?;
            for i in 0..4 {
                out.push([q[i], m[i], c, m[k(i + 3)]]);
            }
        }
        2 => {
            let Some(i) = (0..4).find(|&i| s[i] && (s[k(i + 1)] || s[k(i + 2)])) else {
                return Err(odd_count(q));
            };
            if s[k(i + 2)] {
                out.push([q[i], m[i], m[k(i + 2)], q[k(i + 3)]]);
                out.push([m[i], q[k(i + 1)], q[k(i + 2)], m[k(i + 2)]]);
            } else {
                let c = centre()?;
                let (a, b, cc, d) = (q[i], q[k(i + 1)], q[k(i + 2)], q[k(i + 3)]);
                let (ab, bc) = (m[i], m[k(i + 1)]);
                out.extend([[a, ab, c, d], [ab, b, bc, c], [bc, cc, d, c]]);
            }
        }
        _ => return Err(odd_count(q)),
    }
    Ok(())
}

/// Internal consistency error: the closure left a quad with an odd number of split edges.
fn odd_count(q: &Quad) -> SubdivError {
    SubdivError::Internal {
        what: format!("quad {q:?} has an odd number of split edges after closure"),
    }
}

/// The edges to split: every edge of a marked quad, then what gives every quad an even count:
/// quads with three split edges get the fourth, and quads with one are paired by chains.
fn close_split(quads: &[Quad], edges: &QuadEdges, marked: &[bool]) -> Vec<bool> {
    let mut split = vec![false; edges.ends.len()];
    for (f, _) in marked.iter().enumerate().filter(|(_, &m)| m) {
        for &e in &edges.of_face[f] {
            split[e as usize] = true;
        }
    }
    // Every round splits at least one more edge, so this ends (at worst with all split).
    loop {
        complete_triples(edges, &mut split);
        let mut counts = edges.counts(&split);
        let odd: Vec<u32> = (0..quads.len() as u32)
            .filter(|&f| counts[f as usize] % 2 == 1)
            .collect();
        if odd.is_empty() {
            return split;
        }
        for f in odd {
            if counts[f as usize] % 2 == 0 {
                continue;
            }
            let chain = cheapest_chain(edges, &split, &counts, f)
                .unwrap_or_else(|| edges.of_face[f as usize].to_vec());
            for e in chain {
                if split[e as usize] {
                    continue;
                }
                split[e as usize] = true;
                for g in edges.faces[e as usize] {
                    if g != NO {
                        counts[g as usize] += 1;
                    }
                }
            }
        }
    }
}

/// Splits the fourth edge of every quad with three, until none is left.
fn complete_triples(edges: &QuadEdges, split: &mut [bool]) {
    let mut queue: Vec<u32> = (0..edges.of_face.len() as u32).collect();
    while let Some(f) = queue.pop() {
        let es = edges.of_face[f as usize];
        if es.iter().filter(|&&e| split[e as usize]).count() != 3 {
            continue;
        }
        if let Some(&e) = es.iter().find(|&&e| !split[e as usize]) {
            split[e as usize] = true;
            let g = edges.across(e, f);
            if g != NO {
                queue.push(g);
            }
        }
    }
}

/// The cheapest chain of unsplit edges from quad `start` to another quad with an odd count of
/// split edges or across the open boundary (Dijkstra over edge crossings); `None` when the
/// search gives up after [`MAX_SEARCH`] states. A chain's edges are distinct.
fn cheapest_chain(
    edges: &QuadEdges,
    split: &[bool],
    counts: &[u8],
    start: u32,
) -> Option<Vec<u32>> {
    // State 2e + s: edge e crossed into its side s (the face `edges.faces[e][s]`).
    let state = |e: u32, into: u32| 2 * e + u32::from(edges.faces[e as usize][0] != into);
    let mut best: HashMap<u32, (u64, u32)> = HashMap::new();
    let mut heap = BinaryHeap::new();
    for &e in edges.of_face[start as usize].iter() {
        if !split[e as usize] {
            let s = state(e, edges.across(e, start));
            best.insert(s, (STEP, NO));
            heap.push(Reverse((STEP, s)));
        }
    }
    let mut visited = 0;
    while let Some(Reverse((cost, s))) = heap.pop() {
        if best.get(&s).is_some_and(|&(c, _)| c < cost) {
            continue;
        }
        visited += 1;
        if visited > MAX_SEARCH {
            return None;
        }
        let e = s / 2;
        let h = edges.faces[e as usize][(s % 2) as usize];
        if h == NO || (h != start && counts[h as usize] % 2 == 1) {
            return Some(trace(&best, s));
        }
        if h == start {
            continue;
        }
        for (k2, &e2) in edges.of_face[h as usize].iter().enumerate() {
            if e2 == e || split[e2 as usize] {
                continue;
            }
            let next = cost + STEP + pass_cost(edges, counts[h as usize], h, e, k2);
            let s2 = state(e2, edges.across(e2, h));
            if best.get(&s2).is_none_or(|&(c, _)| next < c) {
                best.insert(s2, (next, s));
                heap.push(Reverse((next, s2)));
            }
        }
    }
    None
}

/// Extra cost of a chain entering quad `h` over edge `e` and leaving over its edge `k2`.
fn pass_cost(edges: &QuadEdges, count: u8, h: u32, e: u32, k2: usize) -> u64 {
    if count == 2 {
        return THROUGH_SPLIT;
    }
    let es = edges.of_face[h as usize];
    let k1 = es.iter().position(|&x| x == e).unwrap_or(k2);
    if (k1 + 2) % 4 == k2 {
        return 0;
    }
    // Edges k and k + 1 meet at corner k + 1; the far corner is k + 3.
    let first = if (k1 + 1) % 4 == k2 { k1 } else { k2 };
    let d = edges.corners[h as usize][(first + 3) % 4];
    TURN * (1 + u64::from(edges.valence[d as usize].saturating_sub(4)))
}

/// The edges of the chain that ends with state `s`.
fn trace(best: &HashMap<u32, (u64, u32)>, mut s: u32) -> Vec<u32> {
    let mut chain = Vec::new();
    while s != NO {
        chain.push(s / 2);
        s = best.get(&s).map_or(NO, |&(_, prev)| prev);
    }
    chain
}

/// Old vertices: those all of whose quads are split 1→4 move by Catmull–Clark's vertex rule
/// (interior: ((n − 2) V + Σ neighbours / n + Σ face centroids / n) / n; boundary or crease
/// line: (a + 6 V + b) / 8 along it); the others keep their place, as do corners and dart
/// ends of the crease edges (`is_sharp`, by edge index).
fn moved_vertices(
    pos: &[Point3],
    quads: &[Quad],
    edges: &QuadEdges,
    counts: &[u8],
    is_sharp: &impl Fn(usize) -> bool,
) -> Vec<Point3> {
    let n = pos.len();
    let mut all_split = vec![true; n];
    let mut touched = vec![false; n];
    let mut centroids = vec![Point3::ZERO; n];
    for (f, q) in quads.iter().enumerate() {
        let c = q.iter().map(|&v| pos[v as usize]).sum::<Point3>() * 0.25;
        for &v in q {
            touched[v as usize] = true;
            all_split[v as usize] &= counts[f] == 4;
            centroids[v as usize] += c;
        }
    }
    let mut ring = vec![Point3::ZERO; n];
    let mut rim: Vec<Vec<u32>> = vec![Vec::new(); n];
    for (e, &[a, b]) in edges.ends.iter().enumerate() {
        ring[a as usize] += pos[b as usize];
        ring[b as usize] += pos[a as usize];
        if edges.faces[e][1] == NO || is_sharp(e) {
            rim[a as usize].push(b);
            rim[b as usize].push(a);
        }
    }
    let mut out = pos.to_vec();
    for v in (0..n).filter(|&v| touched[v] && all_split[v]) {
        let k = f64::from(edges.valence[v]);
        out[v] = match rim[v].as_slice() {
            [] if k >= 3.0 => (pos[v] * (k - 2.0) + (ring[v] + centroids[v]) / k) / k,
            &[a, b] => pos[v] * 0.75 + (pos[a as usize] + pos[b as usize]) * 0.125,
            _ => pos[v],
        };
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An n × n grid of unit quads in the plane z = 0.
    fn grid(n: u32) -> PolyMesh {
        let mut p = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                p.push(Point3::new(f64::from(i), f64::from(j), 0.0));
            }
        }
        let id = |i: u32, j: u32| j * (n + 1) + i;
        let mut q = Vec::new();
        for j in 0..n {
            for i in 0..n {
                q.push([id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        PolyMesh::try_new(p, q).expect("grid")
    }

    fn area(m: &PolyMesh) -> f64 {
        let p = m.positions();
        m.faces()
            .map(|f| {
                let [a, b, c, d] = [f[0], f[1], f[2], f[3]].map(|i| p[i as usize]);
                0.5 * (c - a).cross(d - b).z
            })
            .sum()
    }

    #[test]
    fn one_marked_quad_in_a_grid_closes_with_templates() {
        let g = grid(5);
        let mut marked = vec![false; 25];
        marked[12] = true;
        let m = split_quads(&g, &marked, &[]).expect("split");
        check_oriented_edges(&m).expect("manifold");
        assert!(m.faces().all(|f| f.len() == 4));
        // Planar and every new point inside its old face: the area is kept, nothing flips.
        assert!((area(&m) - 25.0).abs() < 1e-12);
        assert!(m.faces().all(|f| {
            let p = m.positions();
            let [a, b, c, d] = [f[0], f[1], f[2], f[3]].map(|i| p[i as usize]);
            (b - a).cross(c - a).z > 0.0 && (c - a).cross(d - a).z > 0.0
        }));
        // 4 children for the marked quad; its neighbours were paired, so growth stays local.
        assert!(
            m.num_faces() > 28 && m.num_faces() < 45,
            "{}",
            m.num_faces()
        );
    }

    #[test]
    fn all_marked_is_one_catmull_clark_step() {
        let g = grid(3);
        let m = split_quads(&g, &[true; 9], &[]).expect("split");
        assert_eq!(m.num_faces(), 36);
        assert_eq!(m.num_vertices(), 16 + 24 + 9);
        // On a flat grid Catmull–Clark keeps interior points (the inner vertex (1, 1) stays).
        assert!((m.positions()[5] - Point3::new(1.0, 1.0, 0.0)).length() < 1e-12);
    }

    #[test]
    fn rejects_triangles_and_wrong_flag_count() {
        let t = PolyMesh::try_new(vec![Point3::ZERO, Point3::X, Point3::Y], [[0u32, 1, 2]])
            .expect("triangle");
        assert!(split_quads(&t, &[true], &[]).is_err());
        assert!(split_quads(&grid(2), &[true], &[]).is_err());
    }
}
