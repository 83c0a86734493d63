//! Doo–Sabin refinement: a dual scheme. Every face corner gives a new point; the new mesh has a
//! face for each old face, each interior edge (a quad) and each interior vertex.

use super::topo::{EdgeTag, Refined, Stencil, Topo, NO};
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
    for f in 0..t.num_faces() as u32 {
        let s = t.face_starts[f as usize];
        verts.extend((0..t.face(f).len() as u32).map(|i| s + i));
        starts.push(verts.len() as u32);
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
    let topo = Topo::new(count, starts, verts, |_, _| EdgeTag::default());
    let topo = retag_open(topo);
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

/// Marks one-face edges of a refined whole mesh as open boundary.
fn retag_open(mut topo: Topo) -> Topo {
    for e in 0..topo.edges.len() {
        if topo.edge_faces[e][1] == NO {
            topo.edge_tags[e] = EdgeTag {
                sharp: true,
                open: true,
            };
        }
    }
    topo
}
