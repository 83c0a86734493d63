//! Face-list topology with edge tags, and one refinement step of each scheme on it.
//!
//! The same code refines a whole control mesh and the small neighbourhoods that limit
//! evaluation subdivides around extraordinary vertices, so evaluation and refinement cannot
//! disagree. A neighbourhood is a cut-out: edges on its rim have one face although the edge is
//! interior in the full mesh. Such *rim* edges are told apart from *open* (boundary) edges by a
//! tag, and points whose rule would need faces beyond the rim are left uncomputed.

use super::Scheme;
use crate::mesh::ControlMesh;
use std::collections::HashMap;

/// Missing face or point.
pub(crate) const NO: u32 = u32::MAX;

/// A new point as a weighted sum of old points.
pub(crate) type Stencil = Vec<(u32, f64)>;

/// Edge tags: sharp edges use the crease rules; open edges are mesh boundaries (also sharp).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub(crate) struct EdgeTag {
    /// Crease or boundary.
    pub sharp: bool,
    /// Boundary of the whole mesh.
    pub open: bool,
}

/// Polygon faces over `nv` vertices with edge adjacency and tags.
#[derive(Clone, Debug)]
pub(crate) struct Topo {
    pub nv: usize,
    pub face_starts: Vec<u32>,
    pub face_verts: Vec<u32>,
    /// Edge of corner `i`: from `face_verts[i]` to the next corner.
    pub face_edges: Vec<u32>,
    pub edges: Vec<[u32; 2]>,
    pub edge_faces: Vec<[u32; 2]>,
    pub edge_tags: Vec<EdgeTag>,
    vert_edge_starts: Vec<u32>,
    vert_edges: Vec<u32>,
}

impl Topo {
    /// Builds adjacency for faces given as `starts`/`verts` (CSR); `tag(a, b)` gives the tag of
    /// edge `{a, b}` and is asked once per edge.
    pub fn new(
        nv: usize,
        face_starts: Vec<u32>,
        face_verts: Vec<u32>,
        mut tag: impl FnMut(u32, u32) -> EdgeTag,
    ) -> Topo {
        let mut index: HashMap<(u32, u32), u32> = HashMap::with_capacity(face_verts.len());
        let mut edges = Vec::new();
        let mut edge_faces: Vec<[u32; 2]> = Vec::new();
        let mut face_edges = vec![NO; face_verts.len()];
        for f in 0..face_starts.len() - 1 {
            let (s, e) = (face_starts[f] as usize, face_starts[f + 1] as usize);
            for i in s..e {
                let a = face_verts[i];
                let b = face_verts[if i + 1 == e { s } else { i + 1 }];
                let key = (a.min(b), a.max(b));
                let id = *index.entry(key).or_insert_with(|| {
                    edges.push([key.0, key.1]);
                    edge_faces.push([NO, NO]);
                    (edges.len() - 1) as u32
                });
                let slot = &mut edge_faces[id as usize];
                if slot[0] == NO {
                    slot[0] = f as u32;
                } else {
                    slot[1] = f as u32;
                }
                face_edges[i] = id;
            }
        }
        let edge_tags = edges.iter().map(|&[a, b]| tag(a, b)).collect();
        let mut counts = vec![0u32; nv + 1];
        for &[a, b] in &edges {
            counts[a as usize + 1] += 1;
            counts[b as usize + 1] += 1;
        }
        for i in 0..nv {
            counts[i + 1] += counts[i];
        }
        let mut fill = counts.clone();
        let mut vert_edges = vec![0; edges.len() * 2];
        for (e, &[a, b]) in edges.iter().enumerate() {
            for v in [a, b] {
                vert_edges[fill[v as usize] as usize] = e as u32;
                fill[v as usize] += 1;
            }
        }
        Topo {
            nv,
            face_starts,
            face_verts,
            face_edges,
            edges,
            edge_faces,
            edge_tags,
            vert_edge_starts: counts,
            vert_edges,
        }
    }

    pub fn num_faces(&self) -> usize {
        self.face_starts.len() - 1
    }

    pub fn face(&self, f: u32) -> &[u32] {
        &self.face_verts
            [self.face_starts[f as usize] as usize..self.face_starts[f as usize + 1] as usize]
    }

    fn face_edge_ids(&self, f: u32) -> &[u32] {
        &self.face_edges
            [self.face_starts[f as usize] as usize..self.face_starts[f as usize + 1] as usize]
    }

    pub fn vertex_edges(&self, v: u32) -> &[u32] {
        &self.vert_edges[self.vert_edge_starts[v as usize] as usize
            ..self.vert_edge_starts[v as usize + 1] as usize]
    }

    /// The faces on `edges`, each once, in order of first appearance (the vertex stencils sum
    /// over the faces around a vertex, which its edges reach).
    fn faces_of_edges(&self, edges: &[u32]) -> Vec<u32> {
        let mut faces = Vec::new();
        for &e in edges {
            for f in self.edge_faces[e as usize] {
                if f != NO && !faces.contains(&f) {
                    faces.push(f);
                }
            }
        }
        faces
    }

    pub fn other_end(&self, e: u32, v: u32) -> u32 {
        let [a, b] = self.edges[e as usize];
        if a == v {
            b
        } else {
            a
        }
    }

    /// An edge with one face that is not a mesh boundary: the cut of a neighbourhood.
    pub fn is_rim(&self, e: u32) -> bool {
        self.edge_faces[e as usize][1] == NO && !self.edge_tags[e as usize].open
    }

    /// Whether all faces around `v` are present.
    pub fn is_complete(&self, v: u32) -> bool {
        self.vertex_edges(v).iter().all(|&e| !self.is_rim(e))
    }

    pub fn sharp_count(&self, v: u32) -> usize {
        self.vertex_edges(v)
            .iter()
            .filter(|&&e| self.edge_tags[e as usize].sharp)
            .count()
    }

    pub fn other_face(&self, e: u32, f: u32) -> u32 {
        let [a, b] = self.edge_faces[e as usize];
        if a == f {
            b
        } else {
            a
        }
    }

    /// Position of `v` among the corners of `f`.
    pub fn corner_index(&self, f: u32, v: u32) -> Option<usize> {
        self.face(f).iter().position(|&x| x == v)
    }

    /// Edges of `f` into and out of corner `v`.
    pub fn corner_edges(&self, f: u32, v: u32) -> Option<(u32, u32)> {
        let i = self.corner_index(f, v)?;
        let ids = self.face_edge_ids(f);
        let n = ids.len();
        Some((ids[(i + n - 1) % n], ids[i]))
    }

    /// Faces around `v` starting at `f`: counter-clockwise until the fan closes or ends, then
    /// clockwise from `f`. With `stop_at_sharp`, sharp edges end the walk (the sector of `f`).
    pub fn fan(&self, v: u32, f: u32, stop_at_sharp: bool, out: &mut Vec<u32>) {
        out.push(f);
        let start = out.len() - 1;
        let mut closed = false;
        for ccw in [true, false] {
            if closed {
                break;
            }
            let mut g = f;
            loop {
                let Some((inc, outg)) = self.corner_edges(g, v) else {
                    return;
                };
                let e = if ccw { inc } else { outg };
                if stop_at_sharp && self.edge_tags[e as usize].sharp {
                    break;
                }
                let h = self.other_face(e, g);
                if h == NO {
                    break;
                }
                if h == f {
                    closed = true;
                    break;
                }
                if out[start..].contains(&h) {
                    break;
                }
                out.push(h);
                g = h;
            }
        }
    }

    /// One refinement step of a primal scheme (Loop, Catmull–Clark): the new points as
    /// stencils over the old ones (`None` where the rule needs faces beyond a rim) and the new
    /// faces. Children of face `f` come in order; see [`children_per_face`]. Doo–Sabin's dual
    /// step is `doo_sabin::refine`; `step::refine_step` picks the one of a scheme.
    pub fn refine_primal(&self, scheme: Scheme) -> Refined {
        let (nv, ne, nf) = (self.nv, self.edges.len(), self.num_faces());
        let with_faces = scheme == Scheme::CatmullClark;
        let mut points: Vec<Option<Stencil>> = Vec::with_capacity(nv + ne + nf);
        for v in 0..nv as u32 {
            points.push(self.vertex_rule(scheme, v));
        }
        for e in 0..ne as u32 {
            points.push(self.edge_rule(scheme, e));
        }
        if with_faces {
            for f in 0..nf as u32 {
                points.push(Some(self.face_point(f)));
            }
        }
        let mut starts = vec![0u32];
        let mut verts = Vec::new();
        let mut tags: HashMap<(u32, u32), EdgeTag> = HashMap::new();
        let ep = |e: u32| nv as u32 + e;
        for f in 0..nf as u32 {
            let c = self.face(f);
            let es = self.face_edge_ids(f);
            let n = c.len();
            for i in 0..n {
                let tag = self.edge_tags[es[i] as usize];
                if tag.sharp {
                    let m = ep(es[i]);
                    tags.insert(key(c[i], m), tag);
                    tags.insert(key(m, c[(i + 1) % n]), tag);
                }
            }
            if scheme == Scheme::Loop && n == 3 {
                let (m0, m1, m2) = (ep(es[0]), ep(es[1]), ep(es[2]));
                for t in [[c[0], m0, m2], [m0, c[1], m1], [m2, m1, c[2]], [m1, m2, m0]] {
                    verts.extend_from_slice(&t);
                    starts.push(verts.len() as u32);
                }
            } else {
                let fp = (nv + ne) as u32 + f;
                for i in 0..n {
                    let q = [c[i], ep(es[i]), fp, ep(es[(i + n - 1) % n])];
                    verts.extend_from_slice(&q);
                    starts.push(verts.len() as u32);
                }
            }
        }
        let count = points.len();
        let topo = Topo::new(count, starts, verts, |a, b| {
            tags.get(&(a, b)).copied().unwrap_or_default()
        });
        Refined { points, topo }
    }

    fn face_point(&self, f: u32) -> Stencil {
        let c = self.face(f);
        let w = 1.0 / c.len() as f64;
        c.iter().map(|&v| (v, w)).collect()
    }

    fn vertex_rule(&self, scheme: Scheme, v: u32) -> Option<Stencil> {
        let edges = self.vertex_edges(v);
        if edges.is_empty() {
            return Some(vec![(v, 1.0)]);
        }
        let sharp: Vec<u32> = edges
            .iter()
            .filter(|&&e| self.edge_tags[e as usize].sharp)
            .map(|&e| self.other_end(e, v))
            .collect();
        match sharp.len() {
            2 => return Some(vec![(v, 0.75), (sharp[0], 0.125), (sharp[1], 0.125)]),
            n if n > 2 => return Some(vec![(v, 1.0)]),
            _ => {}
        }
        if !self.is_complete(v) {
            return None;
        }
        let n = edges.len() as f64;
        match scheme {
            Scheme::Loop => {
                let beta = loop_beta(edges.len());
                let mut s = vec![(v, 1.0 - n * beta)];
                s.extend(edges.iter().map(|&e| (self.other_end(e, v), beta)));
                Some(s)
            }
            _ => {
                let mut s = vec![(v, (n - 2.0) / n)];
                let w = 1.0 / (n * n);
                s.extend(edges.iter().map(|&e| (self.other_end(e, v), w)));
                for f in self.faces_of_edges(edges) {
                    for (u, fw) in self.face_point(f) {
                        s.push((u, w * fw));
                    }
                }
                Some(merge(s))
            }
        }
    }

    fn edge_rule(&self, scheme: Scheme, e: u32) -> Option<Stencil> {
        let [a, b] = self.edges[e as usize];
        if self.edge_tags[e as usize].sharp {
            return Some(vec![(a, 0.5), (b, 0.5)]);
        }
        let [f0, f1] = self.edge_faces[e as usize];
        if f1 == NO {
            return None;
        }
        match scheme {
            Scheme::Loop => {
                let opp = |f: u32| self.face(f).iter().copied().find(|&x| x != a && x != b);
                let (c, d) = (opp(f0)?, opp(f1)?);
                Some(vec![(a, 0.375), (b, 0.375), (c, 0.125), (d, 0.125)])
            }
            _ => {
                let mut s = vec![(a, 0.25), (b, 0.25)];
                for f in [f0, f1] {
                    s.extend(self.face_point(f).into_iter().map(|(u, w)| (u, 0.25 * w)));
                }
                Some(merge(s))
            }
        }
    }

    /// Limit stencils of vertices `0..n`: the Doo–Sabin ones when given (that scheme's limit
    /// points come from the vertex faces, not from a mask), otherwise each vertex's
    /// [`Topo::limit_stencil`].
    pub fn limit_stencils(
        &self,
        scheme: Scheme,
        n: usize,
        doo_sabin: Option<Vec<Stencil>>,
    ) -> Vec<Option<Stencil>> {
        match doo_sabin {
            Some(limits) => limits.into_iter().map(Some).collect(),
            None => (0..n as u32)
                .map(|v| self.limit_stencil(scheme, v))
                .collect(),
        }
    }

    /// Exact limit position of vertex `v` as a stencil (limit mask), if its faces are present.
    pub fn limit_stencil(&self, scheme: Scheme, v: u32) -> Option<Stencil> {
        let edges = self.vertex_edges(v);
        let sharp: Vec<u32> = edges
            .iter()
            .filter(|&&e| self.edge_tags[e as usize].sharp)
            .map(|&e| self.other_end(e, v))
            .collect();
        if edges.is_empty() || sharp.len() > 2 {
            return Some(vec![(v, 1.0)]);
        }
        if sharp.len() == 2 {
            // The crease/boundary curve is a uniform cubic B-spline: 1/6, 2/3, 1/6.
            return Some(vec![
                (v, 2.0 / 3.0),
                (sharp[0], 1.0 / 6.0),
                (sharp[1], 1.0 / 6.0),
            ]);
        }
        if !self.is_complete(v) {
            return None;
        }
        let n = edges.len();
        match scheme {
            Scheme::Loop => {
                let beta = loop_beta(n);
                let chi = 1.0 / (3.0 / (8.0 * beta) + n as f64);
                let mut s = vec![(v, 1.0 - n as f64 * chi)];
                s.extend(edges.iter().map(|&e| (self.other_end(e, v), chi)));
                Some(s)
            }
            _ => {
                // Catmull–Clark on quads: (n² v + 4 Σ edge neighbours + Σ diagonals) / (n (n + 5)).
                let nf = n as f64;
                let d = nf * (nf + 5.0);
                let mut s = vec![(v, nf * nf / d)];
                s.extend(edges.iter().map(|&e| (self.other_end(e, v), 4.0 / d)));
                for f in self.faces_of_edges(edges) {
                    let c = self.face(f);
                    if c.len() != 4 {
                        return None;
                    }
                    let i = self.corner_index(f, v)?;
                    s.push((c[(i + 2) % 4], 1.0 / d));
                }
                Some(s)
            }
        }
    }
}

impl Topo {
    /// The edge-tagged topology of a control mesh (sharp and open edges tagged).
    pub fn of_control_mesh(mesh: &ControlMesh) -> Topo {
        let mut starts = vec![0u32];
        let mut verts = Vec::new();
        for f in 0..mesh.num_faces() as u32 {
            verts.extend(mesh.face_vertices(f));
            starts.push(verts.len() as u32);
        }
        Topo::new(mesh.num_vertices(), starts, verts, |a, b| {
            let h = mesh
                .find_half_edge(a, b)
                .or_else(|| mesh.find_half_edge(b, a));
            match h {
                Some(h) => EdgeTag {
                    sharp: mesh.is_sharp(h),
                    open: mesh.is_boundary_edge(h),
                },
                None => EdgeTag::default(),
            }
        })
    }
}

/// Result of [`Topo::refine_primal`] and `doo_sabin::refine`.
pub(crate) struct Refined {
    pub points: Vec<Option<Stencil>>,
    pub topo: Topo,
}

/// Loop's vertex weight of a vertex with `n` neighbours, as Loop (1987) defines it and
/// OpenSubdiv, MeshLab and the patent use it: β = (5/8 − (3/8 + ¼ cos 2π/n)²) / n. Warren's
/// simpler 3/(8n) (libigl) agrees at valences 3 and 6 only, and an exported cage refined by
/// another tool would give another surface elsewhere; so refinement, limit masks and exact
/// evaluation all use this one.
pub(crate) fn loop_beta(n: usize) -> f64 {
    let n = n as f64;
    let c = 0.375 + 0.25 * libm::cos(2.0 * std::f64::consts::PI / n);
    (0.625 - c * c) / n
}

pub(crate) fn key(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

/// Sums duplicate indices of a stencil.
pub(crate) fn merge(mut s: Stencil) -> Stencil {
    s.sort_by_key(|&(i, _)| i);
    let mut out: Stencil = Vec::with_capacity(s.len());
    for (i, w) in s {
        match out.last_mut() {
            Some(last) if last.0 == i => last.1 += w,
            _ => out.push((i, w)),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    #[test]
    fn loop_beta_is_loops() {
        // Valence 6 is the regular 1/16 and valence 3 the 3/16 of Warren's form too; at other
        // valences Loop's weight differs from Warren's 3/(8n).
        assert!((super::loop_beta(6) - 1.0 / 16.0).abs() < 1e-15);
        assert!((super::loop_beta(3) - 3.0 / 16.0).abs() < 1e-15);
        let b4 = (0.625 - 0.375f64.powi(2)) / 4.0;
        assert!((super::loop_beta(4) - b4).abs() < 1e-15);
        assert!((super::loop_beta(4) - 3.0 / 32.0).abs() > 1e-3);
    }
}
