//! Local refinement and remeshing of triangle control meshes (SPEC §1.8).
//!
//! Refinement splits the marked triangles 1→4 and their neighbours 1→2 (red–green), so the
//! mesh stays conforming (no T-junctions). New points follow one step of the scheme's own
//! subdivision rules where that is possible, so the limit surface barely changes and the error
//! does not jump. Remeshing flips edges that lower the valence energy
//! R(M) = Σ (d(v) − d_opt(v))² or remove long thin triangles, never folding a triangle over.

use crate::geom::{Point3, Vec3};
use crate::mesh::PolyMesh;
use crate::subdiv::{Scheme, SubdivError};
use std::collections::{BTreeMap, HashMap, HashSet};

/// Where the new points of a split come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SplitRule {
    /// Loop subdivision masks: edge points 3/8, 3/8, 1/8, 1/8 (midpoints on the boundary and
    /// on creases), and old vertices whose every face is split move by Loop's vertex mask (the
    /// boundary mask along a boundary or crease line; corners stay); then the refined region
    /// has the same limit surface as before.
    Loop,
    /// Edge midpoints, old vertices kept: exact for piecewise-linear surfaces.
    Midpoint,
}

type Edge = (u32, u32);

fn edge(a: u32, b: u32) -> Edge {
    (a.min(b), a.max(b))
}

/// Triangles of `mesh`, or an error naming the first face that is not one.
pub fn triangles_of(mesh: &PolyMesh) -> Result<Vec<[u32; 3]>, SubdivError> {
    mesh.faces()
        .enumerate()
        .map(|(face, f)| match f {
            &[a, b, c] => Ok([a, b, c]),
            _ => Err(SubdivError::WrongFaceSize {
                face,
                len: f.len(),
                scheme: Scheme::Loop,
            }),
        })
        .collect()
}

/// For every edge, the faces on it with the vertex opposite the edge in each.
fn edge_faces(tris: &[[u32; 3]]) -> HashMap<Edge, Vec<(usize, u32)>> {
    let mut map: HashMap<Edge, Vec<(usize, u32)>> = HashMap::with_capacity(tris.len() * 2);
    for (f, t) in tris.iter().enumerate() {
        for k in 0..3 {
            map.entry(edge(t[k], t[(k + 1) % 3]))
                .or_default()
                .push((f, t[(k + 2) % 3]));
        }
    }
    map
}

/// Splits the `marked` triangles 1→4 and keeps the mesh conforming: a triangle with two or three
/// split edges is split 1→4 as well (repeated until stable), one with a single split edge 1→2.
/// Orientation is kept. `marked` has one flag per face; the crease edges `creases` get the
/// crease rules (see [`SplitRule::Loop`]).
pub fn split_triangles(
    mesh: &PolyMesh,
    marked: &[bool],
    rule: SplitRule,
    creases: &[[u32; 2]],
) -> Result<PolyMesh, SubdivError> {
    let sharp: HashSet<Edge> = creases.iter().map(|&[a, b]| edge(a, b)).collect();
    let tris = triangles_of(mesh)?;
    super::check_flags(marked, tris.len())?;
    let faces_on = edge_faces(&tris);
    let red = close_red_set(&tris, marked, &faces_on);
    let pos = mesh.positions();
    let mut positions = pos.to_vec();
    let mut mid: HashMap<Edge, u32> = HashMap::new();
    for (f, t) in tris.iter().enumerate().filter(|(f, _)| red[*f]) {
        let _ = f;
        for k in 0..3 {
            let e = edge(t[k], t[(k + 1) % 3]);
            if mid.contains_key(&e) {
                continue;
            }
            let p = edge_point(pos, e, &faces_on[&e], rule, sharp.contains(&e));
            mid.insert(e, super::index_u32(positions.len())?);
            positions.push(p);
        }
    }
    if rule == SplitRule::Loop {
        move_old_vertices(pos, &tris, &red, &faces_on, &sharp, &mut positions);
    }
    let mut faces = Vec::with_capacity(tris.len() + 3 * mid.len());
    for (f, &[a, b, c]) in tris.iter().enumerate() {
        let m = |x: u32, y: u32| mid.get(&edge(x, y)).copied();
        if red[f] {
            let (ab, bc, ca) = (m(a, b), m(b, c), m(c, a));
            if let (Some(ab), Some(bc), Some(ca)) = (ab, bc, ca) {
                faces.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
            }
            continue;
        }
        match (m(a, b), m(b, c), m(c, a)) {
            (Some(ab), None, None) => faces.extend([[a, ab, c], [ab, b, c]]),
            (None, Some(bc), None) => faces.extend([[b, bc, a], [bc, c, a]]),
            (None, None, Some(ca)) => faces.extend([[c, ca, b], [ca, a, b]]),
            _ => faces.push([a, b, c]),
        }
    }
    Ok(PolyMesh::try_new(positions, faces)?)
}

/// The marked faces plus every face that would otherwise get two or three split edges.
fn close_red_set(
    tris: &[[u32; 3]],
    marked: &[bool],
    faces_on: &HashMap<Edge, Vec<(usize, u32)>>,
) -> Vec<bool> {
    let mut red = marked.to_vec();
    let mut split: HashMap<Edge, ()> = HashMap::new();
    let mut queue: Vec<usize> = (0..tris.len()).filter(|&f| red[f]).collect();
    while let Some(f) = queue.pop() {
        let t = tris[f];
        for k in 0..3 {
            let e = edge(t[k], t[(k + 1) % 3]);
            if split.insert(e, ()).is_some() {
                continue;
            }
            for &(g, _) in &faces_on[&e] {
                if red[g] {
                    continue;
                }
                let tg = tris[g];
                let n = (0..3)
                    .filter(|&j| split.contains_key(&edge(tg[j], tg[(j + 1) % 3])))
                    .count();
                if n >= 2 {
                    red[g] = true;
                    queue.push(g);
                }
            }
        }
    }
    red
}

/// The new point on edge `a`–`b`: Loop's edge mask inside, the midpoint on the boundary and
/// on a crease (`sharp`), as Loop's crease rules (Hoppe et al. 1994) have it.
fn edge_point(
    pos: &[Point3],
    (a, b): Edge,
    faces: &[(usize, u32)],
    rule: SplitRule,
    sharp: bool,
) -> Point3 {
    let (pa, pb) = (pos[a as usize], pos[b as usize]);
    match (rule, faces) {
        (SplitRule::Loop, &[(_, c), (_, d)]) if !sharp => {
            (pa + pb) * 0.375 + (pos[c as usize] + pos[d as usize]) * 0.125
        }
        _ => (pa + pb) * 0.5,
    }
}

/// Loop's vertex mask for old vertices all of whose faces are split (interior: Loop's β;
/// boundary or crease, two such edges: 1/8, 3/4, 1/8 along them). Other vertices, and corners
/// and dart ends of the `sharp` edges, keep their place.
fn move_old_vertices(
    pos: &[Point3],
    tris: &[[u32; 3]],
    red: &[bool],
    faces_on: &HashMap<Edge, Vec<(usize, u32)>>,
    sharp: &HashSet<Edge>,
    out: &mut [Point3],
) {
    let n = pos.len();
    let mut all_red = vec![true; n];
    let mut touched = vec![false; n];
    for (f, t) in tris.iter().enumerate() {
        for &v in t {
            touched[v as usize] = true;
            all_red[v as usize] &= red[f];
        }
    }
    let mut ring: Vec<Vec<u32>> = vec![Vec::new(); n];
    let mut boundary: Vec<Vec<u32>> = vec![Vec::new(); n];
    let mut sorted: Vec<(&Edge, &Vec<(usize, u32)>)> = faces_on.iter().collect();
    sorted.sort_unstable_by_key(|(e, _)| **e);
    for (&(a, b), faces) in sorted {
        ring[a as usize].push(b);
        ring[b as usize].push(a);
        if faces.len() == 1 || sharp.contains(&(a, b)) {
            boundary[a as usize].push(b);
            boundary[b as usize].push(a);
        }
    }
    for v in (0..n).filter(|&v| touched[v] && all_red[v]) {
        let p = pos[v];
        out[v] = match (boundary[v].as_slice(), ring[v].len()) {
            (&[a, b], _) => p * 0.75 + (pos[a as usize] + pos[b as usize]) * 0.125,
            ([], k) if k >= 3 => {
                let beta = crate::subdiv::topo::loop_beta(k);
                let sum: Vec3 = ring[v].iter().map(|&w| pos[w as usize]).sum();
                p * (1.0 - k as f64 * beta) + sum * beta
            }
            _ => p,
        };
    }
}

/// Improves a triangle mesh by edge flips: a flip is made when it lowers the valence energy
/// R(M) = Σ (d(v) − d_opt(v))² (d_opt 6 inside, 4 on the boundary) without making the smallest
/// angle of the pair much worse, or when it removes a thin triangle (smallest angle under 15°)
/// without raising R(M) by more than 2. Flips need the two triangles to be nearly coplanar (so
/// the shape is kept), and both new triangles to keep the orientation (no fold-over).
/// Deterministic: edges are visited in sorted order. Returns the number of flips. The crease
/// edges `creases` are never flipped (a flip would cut the crease line).
///
/// Only edges next to a vertex numbered `first_new` or higher are considered (an end or an
/// opposite corner): after a split those are the new midpoints, so the flips stay in the region
/// the split changed, where the rest of the mesh was already improved by earlier passes (and
/// a refinement of a few faces does not pay for a pass over the whole mesh). 0 considers all.
pub fn improve_by_flips(
    mesh: &mut PolyMesh,
    passes: usize,
    first_new: u32,
    creases: &[[u32; 2]],
) -> Result<usize, SubdivError> {
    let mut tris = triangles_of(mesh)?;
    let pos = mesh.positions().to_vec();
    let fixed: HashSet<Edge> = creases.iter().map(|&[a, b]| edge(a, b)).collect();
    let mut total = 0;
    for _ in 0..passes {
        let flips = flip_pass(&pos, &mut tris, first_new, &fixed);
        total += flips;
        if flips == 0 {
            break;
        }
    }
    if total > 0 {
        *mesh = PolyMesh::try_new(pos, tris)?;
    }
    Ok(total)
}

fn flip_pass(
    pos: &[Point3],
    tris: &mut [[u32; 3]],
    first_new: u32,
    fixed: &HashSet<Edge>,
) -> usize {
    let faces_on = edge_faces(tris);
    let mut valence = vec![0i64; pos.len()];
    let mut on_boundary = vec![false; pos.len()];
    for (&(a, b), faces) in &faces_on {
        valence[a as usize] += 1;
        valence[b as usize] += 1;
        if faces.len() != 2 {
            on_boundary[a as usize] = true;
            on_boundary[b as usize] = true;
        }
    }
    let ordered: BTreeMap<Edge, &Vec<(usize, u32)>> =
        faces_on.iter().map(|(e, f)| (*e, f)).collect();
    let mut touched = vec![false; tris.len()];
    let mut flips = 0;
    for (&(a, b), faces) in &ordered {
        let &[(f1, c1), (f2, c2)] = faces.as_slice() else {
            continue;
        };
        if a.max(b).max(c1).max(c2) < first_new
            || fixed.contains(&(a, b))
            || touched[f1]
            || touched[f2]
            || c1 == c2
            || faces_on.contains_key(&edge(c1, c2))
        {
            continue;
        }
        // Orient: f1 = (x, y, c) with x→y, f2 = (y, x, d).
        let (x, y) = if follows(tris[f1], a, b) {
            (a, b)
        } else {
            (b, a)
        };
        let (c, d) = (c1, c2);
        if !follows(tris[f2], y, x) {
            continue; // inconsistent orientation: leave it alone
        }
        let energy = |v: u32, delta: i64| {
            let v = v as usize;
            let opt = if on_boundary[v] { 4 } else { 6 };
            (valence[v] + delta - opt).pow(2)
        };
        let before = energy(x, 0) + energy(y, 0) + energy(c, 0) + energy(d, 0);
        let after = energy(x, -1) + energy(y, -1) + energy(c, 1) + energy(d, 1);
        let (new1, new2) = ([x, d, c], [d, y, c]);
        let old_min = min_angle(pos, tris[f1]).min(min_angle(pos, tris[f2]));
        let new_min = min_angle(pos, new1).min(min_angle(pos, new2));
        let valence_gain = after < before && new_min >= 0.75 * old_min;
        let thin_gain =
            old_min < 15f64.to_radians() && new_min > 1.5 * old_min && after <= before + 2;
        if !(valence_gain || thin_gain)
            || !flip_keeps_shape(pos, [tris[f1], tris[f2]], [new1, new2])
        {
            continue;
        }
        tris[f1] = new1;
        tris[f2] = new2;
        touched[f1] = true;
        touched[f2] = true;
        for (v, delta) in [(x, -1), (y, -1), (c, 1), (d, 1)] {
            valence[v as usize] += delta;
        }
        flips += 1;
    }
    flips
}

/// Whether directed edge a→b is an edge of triangle `t` in its order.
fn follows(t: [u32; 3], a: u32, b: u32) -> bool {
    (0..3).any(|k| t[k] == a && t[(k + 1) % 3] == b)
}

fn normal(pos: &[Point3], t: [u32; 3]) -> Vec3 {
    let [a, b, c] = t.map(|i| pos[i as usize]);
    (b - a).cross(c - a)
}

fn min_angle(pos: &[Point3], t: [u32; 3]) -> f64 {
    let p = t.map(|i| pos[i as usize]);
    (0..3)
        .map(|k| {
            let (u, v) = (p[(k + 1) % 3] - p[k], p[(k + 2) % 3] - p[k]);
            u.angle_between(v)
        })
        .filter(|a| a.is_finite())
        .fold(f64::INFINITY, f64::min)
        .min(std::f64::consts::PI)
}

/// The old pair is nearly flat (normals within 30°) and each new triangle is non-degenerate and
/// faces the same way as the old pair.
fn flip_keeps_shape(pos: &[Point3], old: [[u32; 3]; 2], new: [[u32; 3]; 2]) -> bool {
    let (n1, n2) = (normal(pos, old[0]), normal(pos, old[1]));
    let (m1, m2) = (normal(pos, new[0]), normal(pos, new[1]));
    let unit = |v: Vec3| v.try_normalize();
    let (Some(n1), Some(n2), Some(m1), Some(m2)) = (unit(n1), unit(n2), unit(m1), unit(m2)) else {
        return false;
    };
    let avg = (n1 + n2).normalize_or_zero();
    n1.dot(n2) > libm::cos(30f64.to_radians()) && m1.dot(avg) > 0.5 && m2.dot(avg) > 0.5
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> PolyMesh {
        let p = vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(1.0, 1.0, 0.0),
            Point3::new(0.0, 1.0, 0.0),
        ];
        PolyMesh::try_new(p, [[0, 1, 2], [0, 2, 3]]).expect("valid")
    }

    #[test]
    fn red_green_split_is_conforming() {
        let m =
            split_triangles(&square(), &[true, false], SplitRule::Midpoint, &[]).expect("split");
        // 1→4 plus the neighbour 1→2, one new point per edge of the red face.
        assert_eq!(m.num_faces(), 6);
        assert_eq!(m.num_vertices(), 7);
        crate::mesh::check_oriented_edges(&m).expect("manifold");
        let area: f64 = m
            .triangles()
            .iter()
            .map(|&t| normal(m.positions(), t).length() * 0.5)
            .sum();
        assert!((area - 1.0).abs() < 1e-12);
    }

    #[test]
    fn flip_removes_thin_pair() {
        let p = vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(10.0, 0.0, 0.0),
            Point3::new(5.0, 0.3, 0.0),
            Point3::new(5.0, -0.3, 0.0),
        ];
        let mut m = PolyMesh::try_new(p, [[0, 1, 2], [1, 0, 3]]).expect("valid");
        assert_eq!(improve_by_flips(&mut m, 3, 4, &[]).expect("none new"), 0);
        assert_eq!(improve_by_flips(&mut m, 3, 3, &[]).expect("flips"), 1);
        crate::mesh::check_oriented_edges(&m).expect("manifold");
        assert!(m.faces().all(|f| f.contains(&2) && f.contains(&3)));
    }
}
