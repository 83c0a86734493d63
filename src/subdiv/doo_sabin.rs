//! Doo–Sabin refinement: a dual scheme. Every face corner gives a new point; the new mesh has a
//! face for each old face, each interior edge (a quad) and each interior vertex.

use super::topo::{key, EdgeTag, Refined, Stencil, Topo, NO};
use std::f64::consts::PI;

/// Doo–Sabin weight of corner `k` (counted from the corner whose point is made) in an n-gon:
/// α₀ = 1/4 + 5/(4n), α_k = (3 + 2 cos(2πk/n)) / (4n).
pub(crate) fn weight(n: usize, k: usize) -> f64 {
    let nf = n as f64;
    if k == 0 {
        0.25 + 5.0 / (4.0 * nf)
    } else {
        (3.0 + 2.0 * (2.0 * PI * k as f64 / nf).cos()) / (4.0 * nf)
    }
}

/// One Doo–Sabin step. Corner points of faces at an open boundary edge follow Chaikin's rule
/// (3/4, 1/4) along that edge, so boundary polygons converge to quadratic B-spline curves.
pub(crate) fn refine(t: &Topo) -> Refined {
    let mut points: Vec<Option<Stencil>> = Vec::with_capacity(t.face_verts.len());
    for f in 0..t.num_faces() as u32 {
        let c = t.face(f);
        let n = c.len();
        for j in 0..n {
            points.push(Some(corner_point(t, f, j, c)));
        }
    }
    let corner = |f: u32, v: u32| -> u32 {
        let i = t.corner_index(f, v).unwrap_or(0);
        t.face_starts[f as usize] + i as u32
    };
    let mut starts = vec![0u32];
    let mut verts: Vec<u32> = Vec::new();
    // New edges on the mesh boundary: along old open edges, and across the missing vertex faces
    // of boundary vertices. Edges cut by a neighbourhood's rim stay untagged (rim).
    let mut open: std::collections::HashSet<(u32, u32)> = std::collections::HashSet::new();
    let on_boundary = |v: u32| {
        t.vertex_edges(v)
            .iter()
            .any(|&e| t.edge_tags[e as usize].open)
    };
    for f in 0..t.num_faces() as u32 {
        let s = t.face_starts[f as usize];
        let n = t.face(f).len() as u32;
        verts.extend((0..n).map(|i| s + i));
        starts.push(verts.len() as u32);
        for (j, &e) in t.face_edges[s as usize..(s + n) as usize]
            .iter()
            .enumerate()
        {
            if t.edge_tags[e as usize].open {
                open.insert(key(s + j as u32, s + (j as u32 + 1) % n));
            }
        }
    }
    for (e, &[a, b]) in t.edges.iter().enumerate() {
        let [f0, f1] = t.edge_faces[e];
        if f1 == NO {
            continue;
        }
        // f is the face with a→b on its left.
        let (f, g) = if t
            .face(f0)
            .iter()
            .zip(t.face(f0).iter().cycle().skip(1))
            .any(|(&x, &y)| x == a && y == b)
        {
            (f0, f1)
        } else {
            (f1, f0)
        };
        verts.extend([corner(g, a), corner(g, b), corner(f, b), corner(f, a)]);
        starts.push(verts.len() as u32);
        for v in [a, b] {
            if on_boundary(v) {
                open.insert(key(corner(g, v), corner(f, v)));
            }
        }
    }
    let mut fan = Vec::new();
    for v in 0..t.nv as u32 {
        let edges = t.vertex_edges(v);
        if edges.is_empty() || edges.iter().any(|&e| t.edge_faces[e as usize][1] == NO) {
            continue;
        }
        let f = t.edge_faces[edges[0] as usize][0];
        fan.clear();
        t.fan(v, f, false, &mut fan);
        verts.extend(fan.iter().map(|&g| corner(g, v)));
        starts.push(verts.len() as u32);
    }
    let count = points.len();
    let topo = Topo::new(count, starts, verts, |a, b| {
        if open.contains(&(a, b)) {
            EdgeTag {
                sharp: true,
                open: true,
            }
        } else {
            EdgeTag::default()
        }
    });
    Refined { points, topo }
}

fn corner_point(t: &Topo, f: u32, j: usize, c: &[u32]) -> Stencil {
    let n = c.len();
    let es =
        &t.face_edges[t.face_starts[f as usize] as usize..t.face_starts[f as usize + 1] as usize];
    let (out_e, in_e) = (es[j], es[(j + n - 1) % n]);
    let open = |e: u32| t.edge_tags[e as usize].open;
    match (open(in_e), open(out_e)) {
        (true, true) => vec![
            (c[j], 0.5),
            (c[(j + 1) % n], 0.25),
            (c[(j + n - 1) % n], 0.25),
        ],
        (false, true) => vec![(c[j], 0.75), (c[(j + 1) % n], 0.25)],
        (true, false) => vec![(c[j], 0.75), (c[(j + n - 1) % n], 0.25)],
        (false, false) => (0..n).map(|k| (c[(j + k) % n], weight(n, k))).collect(),
    }
}

/// The limit point of an interior vertex: the centroid of the new points of its corners, which
/// every later Doo–Sabin step keeps (the vertex's face shrinks onto it). A vertex on an open
/// boundary gives itself.
pub(crate) fn vertex_limit(t: &Topo, v: u32) -> Option<Stencil> {
    let edges = t.vertex_edges(v);
    if edges.is_empty()
        || !t.is_complete(v)
        || edges.iter().any(|&e| t.edge_faces[e as usize][1] == NO)
    {
        return Some(vec![(v, 1.0)]);
    }
    let mut faces = Vec::new();
    t.fan(v, t.edge_faces[edges[0] as usize][0], false, &mut faces);
    let share = 1.0 / faces.len() as f64;
    let mut s = Vec::new();
    for &f in &faces {
        let c = t.face(f);
        let j = t.corner_index(f, v)?;
        s.extend(
            corner_point(t, f, j, c)
                .into_iter()
                .map(|(i, w)| (i, w * share)),
        );
    }
    Some(super::topo::merge(s))
}
