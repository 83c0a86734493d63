//! Doo–Sabin refinement: a dual scheme. Every face corner gives a new point; the new mesh has a
//! face for each old face, each interior edge (a quad) and each interior vertex.
//!
//! # Boundaries and creases
//!
//! Open boundaries and sharp (crease) edges are handled by one construction, the *ghost ring*:
//! the mesh is cut along every sharp edge, and every cut edge `a → b` gets a degenerate quad
//! `[b, a, a', b']` whose far corners are copies of `a` and `b`. Around a boundary vertex the
//! ghost quads of its two cut edges share the copy `a'`, so in the extended mesh every control
//! vertex is interior and the plain Doo–Sabin rules apply everywhere. Then:
//!
//! - the corner point of a ghost quad at `a` is `3/4 a + 1/4 b` (the quad weights 9, 3, 3, 1 / 16
//!   on a quad with doubled corners), i.e. the boundary polygon is refined by Chaikin's rule, so
//!   the boundary limit curve is the uniform quadratic B-spline of the boundary control polygon
//!   — the property Doo–Sabin boundary rules are designed for (Doo 1978; Nasri, "Polyhedral
//!   subdivision methods for free-form surfaces", ACM TOG 6(1), 1987);
//! - the ring commutes with refinement (the degenerate faces of a refined ring are exactly the
//!   ring of the refined mesh), so limit evaluation needs no special boundary rule: on a regular
//!   boundary the patches are plain biquadratic B-splines with the boundary row doubled, which
//!   interpolate the boundary curve (their cross-boundary derivative vanishes on the boundary
//!   itself, as for any biquadratic that interpolates a row of its control points);
//! - a crease is a boundary for the faces on both sides; both sides' limit curves are the
//!   quadratic B-spline of the crease polygon, so they meet along it with a sharp edge;
//! - at a vertex with three or more sharp edges (a corner) each sector also gets a fully
//!   degenerate quad `[a, a', a'', a''']`, which doubles the vertex in its boundary polygon: the
//!   crease curves end at the vertex and the sectors meet there.
//!
//! A crease chain that ends inside the surface (a dart) is treated as smooth: cutting it would
//! leave a slit whose tip does not refine into the slit of the refined mesh.

use super::topo::{key, EdgeTag, Refined, Stencil, Topo, NO};
use std::collections::HashMap;
use std::f64::consts::PI;

/// Doo–Sabin weight of corner `k` (counted from the corner whose point is made) in an n-gon:
/// α₀ = 1/4 + 5/(4n), α_k = (3 + 2 cos(2πk/n)) / (4n) (Doo & Sabin 1978, eq. for the
/// generalised biquadratic rule; for n = 4 it gives the tensor-product 9/16, 3/16, 1/16, 3/16).
pub(crate) fn weight(n: usize, k: usize) -> f64 {
    let nf = n as f64;
    if k == 0 {
        0.25 + 5.0 / (4.0 * nf)
    } else {
        (3.0 + 2.0 * libm::cos(2.0 * PI * k as f64 / nf)) / (4.0 * nf)
    }
}

/// A control mesh extended by the ghost ring (see the module docs). Faces `0..real_faces` are
/// the control faces with the same indices; vertices are sector copies of control vertices
/// (one per smooth sector around a vertex; an uncut vertex keeps its index) and ghost copies.
pub(crate) struct Extended {
    /// Extended connectivity; edges with one face are tagged open.
    pub topo: Topo,
    /// The control vertex of every extended vertex.
    pub owner: Vec<u32>,
    /// Whether an extended vertex is a ghost copy (the limit surface has no patch at it).
    pub ghost: Vec<bool>,
    /// Number of control faces.
    pub real_faces: usize,
    /// For every ghost face (index − `real_faces`): the control face whose cut edge it sits on.
    pub ghost_of: Vec<u32>,
    /// For every ghost face: the control edge (ends as control vertices) it sits on, or
    /// `[v, NO]` for the corner quad of vertex `v`.
    ghost_edge: Vec<[u32; 2]>,
}

/// Which edges are cut: open edges, and sharp edges on crease chains that end on the boundary,
/// at a vertex with three or more sharp edges, or close into loops. A chain that ends inside the
/// surface (a dart) cannot be cut consistently under refinement and is treated as smooth.
fn cut_edges(t: &Topo) -> Vec<bool> {
    let mut cut: Vec<bool> = t
        .edge_tags
        .iter()
        .map(|tag| tag.sharp || tag.open)
        .collect();
    let mut count = vec![0usize; t.nv];
    for (e, &[a, b]) in t.edges.iter().enumerate() {
        if cut[e] {
            count[a as usize] += 1;
            count[b as usize] += 1;
        }
    }
    let mut changed = true;
    while changed {
        changed = false;
        for (e, &[a, b]) in t.edges.iter().enumerate() {
            if cut[e] && !t.edge_tags[e].open && (count[a as usize] == 1 || count[b as usize] == 1)
            {
                cut[e] = false;
                count[a as usize] -= 1;
                count[b as usize] -= 1;
                changed = true;
            }
        }
    }
    cut
}

/// Builds the ghost ring of `t` (a whole control mesh with edge tags).
pub(crate) fn extend(t: &Topo) -> Extended {
    let cut = cut_edges(t);
    let mut sharp_count = vec![0usize; t.nv];
    for (e, &[a, b]) in t.edges.iter().enumerate() {
        if cut[e] {
            sharp_count[a as usize] += 1;
            sharp_count[b as usize] += 1;
        }
    }
    // Sector copy of every face corner: faces around a vertex joined across uncut edges.
    let mut owner: Vec<u32> = (0..t.nv as u32).collect();
    let mut corner_vertex = vec![NO; t.face_verts.len()];
    let mut fan = Vec::new();
    let mut faces_at = Vec::new();
    for v in 0..t.nv as u32 {
        faces_at.clear();
        for &e in t.vertex_edges(v) {
            for f in t.edge_faces[e as usize] {
                if f != NO && !faces_at.contains(&f) {
                    faces_at.push(f);
                }
            }
        }
        let mut first = true;
        for &f in &faces_at {
            let Some(i) = t.corner_index(f, v) else {
                continue;
            };
            if corner_vertex[(t.face_starts[f as usize] as usize) + i] != NO {
                continue;
            }
            let id = if first {
                v
            } else {
                owner.push(v);
                (owner.len() - 1) as u32
            };
            first = false;
            fan.clear();
            sector_fan(t, &cut, v, f, &mut fan);
            for &g in &fan {
                if let Some(j) = t.corner_index(g, v) {
                    corner_vertex[t.face_starts[g as usize] as usize + j] = id;
                }
            }
        }
    }
    let mut ghost = vec![false; owner.len()];
    // Cut half-edges (sector copies at both ends) and the ghost copies at their ends.
    let mut cuts: Vec<(u32, u32, u32)> = Vec::new(); // (from, to, face)
    for f in 0..t.num_faces() as u32 {
        let s = t.face_starts[f as usize] as usize;
        let n = t.face(f).len();
        for i in 0..n {
            if cut[t.face_edges[s + i] as usize] {
                cuts.push((corner_vertex[s + i], corner_vertex[s + (i + 1) % n], f));
            }
        }
    }
    let new_ghost = |owner: &mut Vec<u32>, ghost: &mut Vec<bool>, of: u32| {
        owner.push(owner[of as usize]);
        ghost.push(true);
        (owner.len() - 1) as u32
    };
    // (copy used where the sector vertex is the origin, copy where it is the target).
    let mut ends: HashMap<u32, (u32, u32)> = HashMap::new();
    let mut corners = Vec::new();
    for &(a, _, f) in &cuts {
        if ends.contains_key(&a) {
            continue;
        }
        let real = owner[a as usize];
        let pair = if sharp_count[real as usize] >= 3 {
            let g_out = new_ghost(&mut owner, &mut ghost, a);
            let g_in = new_ghost(&mut owner, &mut ghost, a);
            let g_mid = new_ghost(&mut owner, &mut ghost, a);
            corners.push(([a, g_in, g_mid, g_out], f, real));
            (g_out, g_in)
        } else {
            let g = new_ghost(&mut owner, &mut ghost, a);
            (g, g)
        };
        ends.insert(a, pair);
    }
    let mut starts = t.face_starts.clone();
    let mut verts: Vec<u32> = corner_vertex;
    let mut ghost_of = Vec::new();
    let mut ghost_edge = Vec::new();
    for &(a, b, f) in &cuts {
        let (Some(&(a_out, _)), Some(&(_, b_in))) = (ends.get(&a), ends.get(&b)) else {
            continue;
        };
        verts.extend([b, a, a_out, b_in]);
        starts.push(verts.len() as u32);
        ghost_of.push(f);
        ghost_edge.push([owner[a as usize], owner[b as usize]]);
    }
    for (quad, f, real) in corners {
        verts.extend(quad);
        starts.push(verts.len() as u32);
        ghost_of.push(f);
        ghost_edge.push([real, NO]);
    }
    let mut topo = Topo::new(owner.len(), starts, verts, |_, _| EdgeTag::default());
    for e in 0..topo.edges.len() {
        if topo.edge_faces[e][1] == NO {
            topo.edge_tags[e] = EdgeTag {
                sharp: true,
                open: true,
            };
        }
    }
    Extended {
        topo,
        owner,
        ghost,
        real_faces: t.num_faces(),
        ghost_of,
        ghost_edge,
    }
}

/// Faces around `v` reachable from `f` without crossing a cut edge.
fn sector_fan(t: &Topo, cut: &[bool], v: u32, f: u32, out: &mut Vec<u32>) {
    out.push(f);
    for ccw in [true, false] {
        let mut g = f;
        while let Some((inc, outg)) = t.corner_edges(g, v) {
            let e = if ccw { inc } else { outg };
            if cut[e as usize] {
                break;
            }
            let h = t.other_face(e, g);
            if h == NO || out.contains(&h) {
                break;
            }
            out.push(h);
            g = h;
        }
    }
}

/// One Doo–Sabin step with the interior rules only: used on extended meshes and on the local
/// neighbourhoods of limit evaluation. Edges with two faces give quads, vertices whose edges all
/// have two faces give vertex faces; new edges along open edges and across the missing vertex
/// faces of open vertices are tagged open (edges cut by a neighbourhood's rim stay untagged).
pub(crate) fn refine(t: &Topo) -> Refined {
    let mut points: Vec<Option<Stencil>> = Vec::with_capacity(t.face_verts.len());
    for f in 0..t.num_faces() as u32 {
        let c = t.face(f);
        for j in 0..c.len() {
            points.push(Some(corner_point(c, j)));
        }
    }
    let corner = |f: u32, v: u32| -> u32 {
        let i = t.corner_index(f, v).unwrap_or(0);
        t.face_starts[f as usize] + i as u32
    };
    let mut starts = vec![0u32];
    let mut verts: Vec<u32> = Vec::new();
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

/// The new point of corner `j` of the face with corners `c`.
fn corner_point(c: &[u32], j: usize) -> Stencil {
    let n = c.len();
    (0..n).map(|k| (c[(j + k) % n], weight(n, k))).collect()
}

/// One Doo–Sabin step of a whole control mesh with its boundaries and creases (the ghost-ring
/// rules of the module docs): the points are stencils over the control vertices; the corner
/// points of the control faces come first, in face order, then the points on boundary and
/// crease curves. Edges on crease curves are tagged sharp, edges on the boundary open.
pub(crate) fn refine_control(t: &Topo) -> Refined {
    let ext = extend(t);
    let r = refine(&ext.topo);
    let et = &ext.topo;
    // Representative of every refined point: control-face corners keep their own; ghost-face
    // corners are shared by both sides of a crease and by the copies of a vertex.
    let real_corners = et.face_starts[ext.real_faces] as usize;
    let mut id = vec![NO; r.points.len()];
    let mut points: Vec<Option<Stencil>> = Vec::with_capacity(r.points.len());
    let map_owner = |s: &Stencil| -> Stencil {
        super::topo::merge(s.iter().map(|&(i, w)| (ext.owner[i as usize], w)).collect())
    };
    for (p, s) in r.points.iter().enumerate().take(real_corners) {
        id[p] = points.len() as u32;
        points.push(s.as_ref().map(map_owner));
    }
    let mut shared: HashMap<(u32, u32, u32), u32> = HashMap::new();
    for g in ext.real_faces..et.num_faces() {
        let [a, b] = ext.ghost_edge[g - ext.real_faces];
        let s = et.face_starts[g] as usize;
        for (j, &v) in et.face(g as u32).iter().enumerate() {
            let at = ext.owner[v as usize];
            let k = if b == NO {
                (a, NO, at)
            } else {
                (a.min(b), a.max(b), at)
            };
            let next = points.len() as u32;
            let slot = *shared.entry(k).or_insert(next);
            if slot == next {
                points.push(r.points[s + j].as_ref().map(map_owner));
            }
            id[s + j] = slot;
        }
    }
    let ghost_point = |i: u32| i as usize >= real_corners;
    let mut starts = vec![0u32];
    let mut verts: Vec<u32> = Vec::new();
    let mut face = Vec::new();
    for f in 0..r.topo.num_faces() as u32 {
        face.clear();
        for &p in r.topo.face(f) {
            let q = id[p as usize];
            if face.last() != Some(&q) {
                face.push(q);
            }
        }
        while face.len() > 1 && face.first() == face.last() {
            face.pop();
        }
        if face.len() >= 3 {
            verts.extend_from_slice(&face);
            starts.push(verts.len() as u32);
        }
    }
    let count = points.len();
    let mut topo = Topo::new(count, starts, verts, |a, b| EdgeTag {
        sharp: ghost_point(a) && ghost_point(b),
        open: false,
    });
    for e in 0..topo.edges.len() {
        if topo.edge_faces[e][1] == NO {
            topo.edge_tags[e] = EdgeTag {
                sharp: true,
                open: true,
            };
        }
    }
    Refined { points, topo }
}

/// The limit point of every vertex of a control mesh: the centroid of the new points around it
/// in the extended mesh (its vertex face, which every later step keeps). For a vertex split by
/// creases, the sector of its first face.
pub(crate) fn vertex_limits(t: &Topo) -> Vec<Stencil> {
    limits_of(&extend(t), t.nv)
}

/// [`vertex_limits`] from the extended mesh of a control mesh with `nv` vertices.
pub(crate) fn limits_of(ext: &Extended, nv: usize) -> Vec<Stencil> {
    (0..nv as u32)
        .map(|v| {
            sector_limit(&ext.topo, v)
                .map(|s| {
                    super::topo::merge(
                        s.into_iter()
                            .map(|(i, w)| (ext.owner[i as usize], w))
                            .collect(),
                    )
                })
                .unwrap_or_else(|| vec![(v, 1.0)])
        })
        .collect()
}

/// The centroid of the corner points around vertex `v` of an extended mesh, if its fan closes.
fn sector_limit(t: &Topo, v: u32) -> Option<Stencil> {
    let edges = t.vertex_edges(v);
    if edges.is_empty()
        || !t.is_complete(v)
        || edges.iter().any(|&e| t.edge_faces[e as usize][1] == NO)
    {
        return None;
    }
    let mut faces = Vec::new();
    t.fan(v, t.edge_faces[edges[0] as usize][0], false, &mut faces);
    let share = 1.0 / faces.len() as f64;
    let mut s = Vec::new();
    for &f in &faces {
        let c = t.face(f);
        let j = t.corner_index(f, v)?;
        s.extend(corner_point(c, j).into_iter().map(|(i, w)| (i, w * share)));
    }
    Some(super::topo::merge(s))
}
