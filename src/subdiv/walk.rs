//! Walking a parameter across patch edges: after a Newton step leaves a patch, find the patch
//! that holds the point, mapping parameters through the shared edge (neighbouring patches are
//! unfolded into one plane across it), and clamp onto the domain at open boundaries.

use super::sites::DooSabinSites;
use super::topo::NO;
use super::{Scheme, SurfaceParam};
use crate::mesh::{ControlMesh, NONE};

/// Patches crossed at most by one relocation.
const MAX_STEPS: usize = 32;

pub(crate) fn relocate(
    mesh: &ControlMesh,
    scheme: Scheme,
    patch: u32,
    u: f64,
    v: f64,
) -> SurfaceParam {
    let clean = |x: f64| if x.is_finite() { x } else { 0.0 };
    let (u, v) = (clean(u), clean(v));
    if patch as usize >= mesh.num_faces() {
        return SurfaceParam {
            patch: 0,
            u: 0.0,
            v: 0.0,
        };
    }
    match scheme {
        Scheme::Loop => walk_triangles(mesh, patch, u, v),
        _ => walk_quads(mesh, patch, u, v),
    }
}

fn walk_triangles(mesh: &ControlMesh, mut f: u32, u: f64, v: f64) -> SurfaceParam {
    let mut w = [1.0 - u - v, u, v];
    for _ in 0..MAX_STEPS {
        let k = (0..3).min_by(|&a, &b| w[a].total_cmp(&w[b])).unwrap_or(0);
        if w[k] >= 0.0 {
            break;
        }
        // The edge opposite corner k runs from corner k+1 to corner k+2.
        let h = mesh.face_half_edges(f).nth((k + 1) % 3).unwrap_or(NONE);
        let t = if h == NONE { NONE } else { mesh.twin(h) };
        if t == NONE {
            break;
        }
        let (a, b) = (mesh.origin(h), mesh.target(h));
        let g = mesh.face_of(t);
        let mut next = [0.0; 3];
        for (i, c) in mesh.face_vertices(g).enumerate() {
            next[i] = if c == a {
                w[(k + 1) % 3] + w[k]
            } else if c == b {
                w[(k + 2) % 3] + w[k]
            } else {
                -w[k]
            };
        }
        w = next;
        f = g;
    }
    // Clamp onto the triangle: drop negative weights and renormalise.
    for x in &mut w {
        *x = x.max(0.0);
    }
    let s: f64 = w.iter().sum();
    let (u, v) = if s > 0.0 {
        (w[1] / s, w[2] / s)
    } else {
        (0.0, 0.0)
    };
    SurfaceParam { patch: f, u, v }
}

/// (along, outward) coordinates of (u, v) relative to side `j` of the unit square.
fn to_edge(j: usize, u: f64, v: f64) -> (f64, f64) {
    match j {
        0 => (u, -v),
        1 => (v, u - 1.0),
        2 => (1.0 - u, v - 1.0),
        _ => (1.0 - v, -u),
    }
}

fn from_edge(j: usize, t: f64, s: f64) -> (f64, f64) {
    match j {
        0 => (t, -s),
        1 => (1.0 + s, t),
        2 => (1.0 - t, 1.0 + s),
        _ => (-s, 1.0 - t),
    }
}

/// The side of the unit square that (u, v) lies furthest beyond (0: v = 0, 1: u = 1, 2: v = 1,
/// 3: u = 0), or `None` inside the square.
fn exit_side(u: f64, v: f64) -> Option<usize> {
    let out = [-v, u - 1.0, v - 1.0, -u];
    let j = (0..4)
        .max_by(|&a, &b| out[a].total_cmp(&out[b]))
        .unwrap_or(0);
    // Written so that a NaN coordinate keeps walking, as the loops always did.
    if out[j] <= 0.0 {
        None
    } else {
        Some(j)
    }
}

fn walk_quads(mesh: &ControlMesh, mut f: u32, mut u: f64, mut v: f64) -> SurfaceParam {
    for _ in 0..MAX_STEPS {
        let Some(j) = exit_side(u, v) else {
            break;
        };
        let h = mesh.face_half_edges(f).nth(j).unwrap_or(NONE);
        let t = if h == NONE { NONE } else { mesh.twin(h) };
        if t == NONE {
            break;
        }
        let g = mesh.face_of(t);
        let Some(k) = mesh.face_half_edges(g).position(|x| x == t) else {
            break;
        };
        let (along, outward) = to_edge(j, u, v);
        (u, v) = from_edge(k, 1.0 - along, -outward);
        f = g;
    }
    SurfaceParam {
        patch: f,
        u: u.clamp(0.0, 1.0),
        v: v.clamp(0.0, 1.0),
    }
}

/// Walks a Doo–Sabin parameter across patch edges. Patch (f, v) has corners (0, 0) at face f's
/// centroid, (1, 0) and (0, 1) at the centroids of the faces of f's edges into and out of v,
/// and (1, 1) at v: its sides lead to the patches (f, previous corner), (face across the
/// incoming edge, v), (face across the outgoing edge, v) and (f, next corner), whose sides 3,
/// 2, 1 and 0 run along the same curves in the opposite direction. Sides with no patch behind
/// them (boundary and crease curves) clamp.
pub(crate) fn walk_doo_sabin(ds: &DooSabinSites, patch: u32, u: f64, v: f64) -> SurfaceParam {
    let clean = |x: f64| if x.is_finite() { x } else { 0.0 };
    let (mut u, mut v) = (clean(u), clean(v));
    let mut p = if (patch as usize) < ds.sites.len() {
        patch
    } else {
        0
    };
    for _ in 0..MAX_STEPS {
        let Some(j) = exit_side(u, v) else {
            break;
        };
        let Some(q) = neighbour(ds, p, j) else {
            break;
        };
        let (along, outward) = to_edge(j, u, v);
        (u, v) = from_edge(3 - j, 1.0 - along, -outward);
        p = q;
    }
    SurfaceParam {
        patch: p,
        u: u.clamp(0.0, 1.0),
        v: v.clamp(0.0, 1.0),
    }
}

/// The patch across side `j` of Doo–Sabin patch `p`, if there is one.
fn neighbour(ds: &DooSabinSites, p: u32, j: usize) -> Option<u32> {
    let t = &ds.ext.topo;
    let (f, v) = *ds.sites.get(p as usize)?;
    let corners = t.face(f);
    let n = corners.len();
    let i = t.corner_index(f, v)?;
    let (inc, out) = t.corner_edges(f, v)?;
    let (g, at) = match j {
        0 => (f, corners[(i + n - 1) % n]),
        3 => (f, corners[(i + 1) % n]),
        1 => (t.other_face(inc, f), v),
        _ => (t.other_face(out, f), v),
    };
    if g == NO {
        return None;
    }
    let k = t.corner_index(g, at)?;
    let q = ds.corner_patch[t.face_starts[g as usize] as usize + k];
    (q != NO).then_some(q)
}
