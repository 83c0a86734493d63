//! A half-edge control mesh: the connectivity that subdivision, limit evaluation and the
//! fitter's remeshing (flips, splits, 1→4 refinement) walk over.
//!
//! Faces are oriented counter-clockwise; half-edge `h` runs from `origin(h)` to
//! `origin(next(h))` with its face on the left. Open boundaries have half-edges without a twin.
//! Edges may be tagged *sharp* (crease); boundary edges behave as sharp in every scheme.

use super::validate::TopologyError;
use super::{MeshError, PolyMesh};
use crate::geom::Point3;
use std::collections::HashMap;

/// Marks a missing half-edge (no twin: boundary) or a vertex without faces.
pub const NONE: u32 = u32::MAX;

/// Why a [`ControlMesh`] could not be built.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum ControlMeshError {
    /// The polygon data itself is invalid.
    #[error(transparent)]
    Mesh(#[from] MeshError),
    /// The connectivity is not an oriented 2-manifold (with boundary).
    #[error(transparent)]
    Topology(#[from] TopologyError),
}

/// An oriented 2-manifold polygon mesh with boundary, stored as half-edges.
#[derive(Clone, Debug)]
pub struct ControlMesh {
    positions: Vec<Point3>,
    origin: Vec<u32>,
    next: Vec<u32>,
    prev: Vec<u32>,
    twin: Vec<u32>,
    face: Vec<u32>,
    sharp: Vec<bool>,
    face_he: Vec<u32>,
    vert_he: Vec<u32>,
}

impl ControlMesh {
    /// Builds the half-edge structure of `mesh`, rejecting non-manifold input.
    pub fn try_new(mesh: &PolyMesh) -> Result<ControlMesh, TopologyError> {
        ControlMesh::from_faces_checked(mesh.positions().to_vec(), mesh.faces())
    }

    /// Builds from positions and faces (each at least 3 in-range indices).
    pub fn from_faces<F, I>(
        positions: Vec<Point3>,
        faces: F,
    ) -> Result<ControlMesh, ControlMeshError>
    where
        F: IntoIterator<Item = I>,
        I: AsRef<[u32]>,
    {
        let faces: Vec<Vec<u32>> = faces.into_iter().map(|f| f.as_ref().to_vec()).collect();
        let poly = PolyMesh::try_new(positions, &faces)?;
        Ok(ControlMesh::try_new(&poly)?)
    }

    fn from_faces_checked<'a>(
        positions: Vec<Point3>,
        faces: impl Iterator<Item = &'a [u32]>,
    ) -> Result<ControlMesh, TopologyError> {
        let mut m = ControlMesh {
            vert_he: vec![NONE; positions.len()],
            positions,
            origin: Vec::new(),
            next: Vec::new(),
            prev: Vec::new(),
            twin: Vec::new(),
            face: Vec::new(),
            sharp: Vec::new(),
            face_he: Vec::new(),
        };
        let mut directed: HashMap<(u32, u32), u32> = HashMap::new();
        let mut undirected: HashMap<(u32, u32), usize> = HashMap::new();
        for (fi, f) in faces.enumerate() {
            for (k, &v) in f.iter().enumerate() {
                if f[..k].contains(&v) {
                    return Err(TopologyError::DegenerateFace {
                        face: fi,
                        vertex: v,
                    });
                }
            }
            let base = m.origin.len() as u32;
            let n = f.len() as u32;
            m.face_he.push(base);
            for k in 0..n {
                let (a, b) = (f[k as usize], f[((k + 1) % n) as usize]);
                m.origin.push(a);
                m.next.push(base + (k + 1) % n);
                m.prev.push(base + (k + n - 1) % n);
                m.twin.push(NONE);
                m.face.push(fi as u32);
                m.sharp.push(false);
                *undirected.entry((a.min(b), a.max(b))).or_default() += 1;
                if directed.insert((a, b), base + k).is_some() {
                    return Err(edge_error(&undirected, a, b));
                }
            }
        }
        if let Some((&(a, b), &faces)) = undirected.iter().filter(|(_, &c)| c > 2).min() {
            return Err(TopologyError::NonManifoldEdge { a, b, faces });
        }
        for (&(a, b), &h) in &directed {
            if let Some(&t) = directed.get(&(b, a)) {
                m.twin[h as usize] = t;
            }
        }
        m.link_vertices()?;
        m.tag_boundary_sharp();
        Ok(m)
    }

    /// Sets each vertex's outgoing half-edge (the boundary one if any) and checks that the faces
    /// around every vertex form a single fan.
    fn link_vertices(&mut self) -> Result<(), TopologyError> {
        let mut outgoing = vec![0usize; self.positions.len()];
        for h in 0..self.origin.len() {
            let v = self.origin[h] as usize;
            outgoing[v] += 1;
            if self.vert_he[v] == NONE || self.twin[h] == NONE {
                self.vert_he[v] = h as u32;
            }
        }
        for (v, &expected) in outgoing.iter().enumerate().take(self.positions.len()) {
            if self.vert_he[v] == NONE {
                continue;
            }
            let fan = self.outgoing(v as u32).count();
            if fan != expected {
                let boundary_out = (0..self.origin.len())
                    .filter(|&h| self.origin[h] == v as u32 && self.twin[h] == NONE)
                    .count();
                return Err(TopologyError::NonManifoldVertex {
                    vertex: v as u32,
                    fans: boundary_out.max(2),
                });
            }
        }
        Ok(())
    }

    fn tag_boundary_sharp(&mut self) {
        for h in 0..self.twin.len() {
            if self.twin[h] == NONE {
                self.sharp[h] = true;
            }
        }
    }

    /// Vertex positions.
    pub fn positions(&self) -> &[Point3] {
        &self.positions
    }

    /// Replaces the positions (same count); returns false and changes nothing otherwise.
    pub fn set_positions(&mut self, positions: &[Point3]) -> bool {
        if positions.len() != self.positions.len() {
            return false;
        }
        self.positions.copy_from_slice(positions);
        true
    }

    /// Number of vertices (including ones that belong to no face).
    pub fn num_vertices(&self) -> usize {
        self.positions.len()
    }

    /// Number of faces.
    pub fn num_faces(&self) -> usize {
        self.face_he.len()
    }

    /// Number of half-edges.
    pub fn num_half_edges(&self) -> usize {
        self.origin.len()
    }

    /// Number of (undirected) edges.
    pub fn num_edges(&self) -> usize {
        (0..self.origin.len())
            .filter(|&h| self.twin[h] == NONE || (h as u32) < self.twin[h])
            .count()
    }

    /// V − E + F.
    pub fn euler_characteristic(&self) -> i64 {
        let used = self.vert_he.iter().filter(|&&h| h != NONE).count() as i64;
        used - self.num_edges() as i64 + self.num_faces() as i64
    }

    /// Origin vertex of half-edge `h`.
    pub fn origin(&self, h: u32) -> u32 {
        self.origin[h as usize]
    }
    /// Target vertex of half-edge `h`.
    pub fn target(&self, h: u32) -> u32 {
        self.origin[self.next[h as usize] as usize]
    }
    /// Next half-edge around the same face.
    pub fn next(&self, h: u32) -> u32 {
        self.next[h as usize]
    }
    /// Previous half-edge around the same face.
    pub fn prev(&self, h: u32) -> u32 {
        self.prev[h as usize]
    }
    /// Opposite half-edge, or [`NONE`] on an open boundary.
    pub fn twin(&self, h: u32) -> u32 {
        self.twin[h as usize]
    }
    /// Face on the left of `h`.
    pub fn face_of(&self, h: u32) -> u32 {
        self.face[h as usize]
    }
    /// Whether the edge of `h` is sharp (crease or open boundary).
    pub fn is_sharp(&self, h: u32) -> bool {
        self.sharp[h as usize]
    }
    /// Whether the edge of `h` is on an open boundary.
    pub fn is_boundary_edge(&self, h: u32) -> bool {
        self.twin[h as usize] == NONE
    }
    /// First half-edge of face `f` (its origin is the face's first corner).
    pub fn face_half_edge(&self, f: u32) -> u32 {
        self.face_he[f as usize]
    }
    /// An outgoing half-edge of `v` (the boundary one for boundary vertices), or [`NONE`].
    pub fn vertex_half_edge(&self, v: u32) -> u32 {
        self.vert_he[v as usize]
    }

    /// Half-edges of face `f` in order, starting at its first corner.
    pub fn face_half_edges(&self, f: u32) -> impl Iterator<Item = u32> + '_ {
        let start = self.face_he[f as usize];
        let mut h = start;
        let mut done = false;
        std::iter::from_fn(move || {
            if done {
                return None;
            }
            let out = h;
            h = self.next[h as usize];
            done = h == start;
            Some(out)
        })
    }

    /// Corner vertices of face `f` in order.
    pub fn face_vertices(&self, f: u32) -> impl Iterator<Item = u32> + '_ {
        self.face_half_edges(f).map(|h| self.origin[h as usize])
    }

    /// Number of corners of face `f`.
    pub fn face_len(&self, f: u32) -> usize {
        self.face_half_edges(f).count()
    }

    /// Fails unless face `f` is a triangle: flips and edge splits are defined on triangles only.
    fn check_triangle(&self, f: u32) -> Result<(), TopologyError> {
        let len = self.face_len(f);
        if len == 3 {
            return Ok(());
        }
        Err(TopologyError::WrongFaceSize {
            face: f as usize,
            len,
            needed: 3,
        })
    }

    /// Outgoing half-edges of `v` in counter-clockwise order (starting at the boundary one).
    pub fn outgoing(&self, v: u32) -> impl Iterator<Item = u32> + '_ {
        let start = self.vert_he[v as usize];
        let mut h = start;
        std::iter::from_fn(move || {
            if h == NONE {
                return None;
            }
            let out = h;
            let t = self.twin[self.prev[h as usize] as usize];
            h = if t == start { NONE } else { t };
            Some(out)
        })
    }

    /// Whether `v` lies on an open boundary.
    pub fn is_boundary_vertex(&self, v: u32) -> bool {
        let h = self.vert_he[v as usize];
        h != NONE && self.twin[h as usize] == NONE
    }

    /// Number of edges at `v`.
    pub fn valence(&self, v: u32) -> usize {
        self.outgoing(v).count() + usize::from(self.is_boundary_vertex(v))
    }

    /// Appends the neighbours of `v` in counter-clockwise order to `out` (for a boundary vertex
    /// the first and last are its boundary neighbours).
    pub fn one_ring(&self, v: u32, out: &mut Vec<u32>) {
        let mut last = NONE;
        for h in self.outgoing(v) {
            out.push(self.target(h));
            last = h;
        }
        if self.is_boundary_vertex(v) && last != NONE {
            out.push(self.origin(self.prev(last)));
        }
    }

    /// Faces around `v` in counter-clockwise order.
    pub fn vertex_faces(&self, v: u32) -> impl Iterator<Item = u32> + '_ {
        self.outgoing(v).map(|h| self.face[h as usize])
    }

    /// The half-edge from `a` to `b`, if there is one.
    pub fn find_half_edge(&self, a: u32, b: u32) -> Option<u32> {
        if a as usize >= self.positions.len() {
            return None;
        }
        self.outgoing(a).find(|&h| self.target(h) == b)
    }

    /// The half-edge of edge `{a, b}` that has a face (either direction).
    fn edge_half_edge(&self, a: u32, b: u32) -> Result<u32, TopologyError> {
        self.find_half_edge(a, b)
            .or_else(|| self.find_half_edge(b, a))
            .ok_or(TopologyError::NoSuchEdge { a, b })
    }

    /// Tags edge `{a, b}` sharp (crease) or smooth. Boundary edges stay sharp.
    pub fn set_sharp(&mut self, a: u32, b: u32, sharp: bool) -> Result<(), TopologyError> {
        let h = self.edge_half_edge(a, b)?;
        let t = self.twin[h as usize];
        if t == NONE {
            return Ok(());
        }
        self.sharp[h as usize] = sharp;
        self.sharp[t as usize] = sharp;
        Ok(())
    }

    /// Whether every face is a triangle.
    pub fn is_triangle_mesh(&self) -> bool {
        (0..self.num_faces() as u32).all(|f| self.face_len(f) == 3)
    }

    /// Whether every face is a quad.
    pub fn is_quad_mesh(&self) -> bool {
        (0..self.num_faces() as u32).all(|f| self.face_len(f) == 4)
    }

    /// The faces as a [`PolyMesh`] (same vertex order).
    pub fn to_poly_mesh(&self) -> Result<PolyMesh, MeshError> {
        let faces: Vec<Vec<u32>> = (0..self.num_faces() as u32)
            .map(|f| self.face_vertices(f).collect())
            .collect();
        PolyMesh::try_new(self.positions.clone(), faces)
    }

    /// Sharp interior edges as vertex pairs `[a, b]` with `a < b`, sorted (the form
    /// [`crate::mesh::Features::edges`] and [`crate::mesh::Simplified::creases`] take).
    pub fn creases(&self) -> Vec<[u32; 2]> {
        let mut out: Vec<[u32; 2]> = (0..self.origin.len() as u32)
            .filter(|&h| self.sharp[h as usize] && self.twin[h as usize] != NONE)
            .map(|h| {
                let (a, b) = (self.origin(h), self.target(h));
                [a.min(b), a.max(b)]
            })
            .collect();
        out.sort_unstable();
        out.dedup();
        out
    }

    /// Flips the interior edge `{a, b}` shared by two triangles: it then joins the two
    /// opposite vertices. Refused on boundary edges and when the new edge already exists.
    pub fn flip_edge(&mut self, a: u32, b: u32) -> Result<(), TopologyError> {
        let h = self.edge_half_edge(a, b)?;
        let t = self.twin[h as usize];
        if t == NONE {
            return Err(TopologyError::CannotFlip {
                a,
                b,
                reason: "it is a boundary edge",
            });
        }
        for f in [self.face[h as usize], self.face[t as usize]] {
            self.check_triangle(f)?;
        }
        let (h1, h2) = (self.next(h), self.prev(h));
        let (t1, t2) = (self.next(t), self.prev(t));
        let (c, d) = (self.origin(h2), self.origin(t2));
        if self.find_half_edge(c, d).is_some() || self.find_half_edge(d, c).is_some() {
            return Err(TopologyError::CannotFlip {
                a,
                b,
                reason: "the flipped edge already exists",
            });
        }
        let (fh, ft) = (self.face[h as usize], self.face[t as usize]);
        // New triangles: (h: d→c, h2: c→a, t1: a→d) and (t: c→d, t2: d→b, h1: b→c).
        self.origin[h as usize] = d;
        self.origin[t as usize] = c;
        self.link_triangle(h, h2, t1, fh);
        self.link_triangle(t, t2, h1, ft);
        for v in [a, b, c, d] {
            self.relink_vertex(v);
        }
        Ok(())
    }

    fn link_triangle(&mut self, x: u32, y: u32, z: u32, f: u32) {
        for (p, q) in [(x, y), (y, z), (z, x)] {
            self.next[p as usize] = q;
            self.prev[q as usize] = p;
        }
        for e in [x, y, z] {
            self.face[e as usize] = f;
        }
        self.face_he[f as usize] = x;
    }

    /// Re-picks the outgoing half-edge of `v` after a local edit (boundary one first).
    fn relink_vertex(&mut self, v: u32) {
        let current = self.vert_he[v as usize];
        if current != NONE
            && self.origin[current as usize] == v
            && self.twin[current as usize] == NONE
        {
            return;
        }
        // Walk clockwise from any outgoing half-edge until the boundary or back to the start.
        let start = if current != NONE && self.origin[current as usize] == v {
            current
        } else {
            match (0..self.origin.len() as u32).find(|&h| self.origin[h as usize] == v) {
                Some(h) => h,
                None => {
                    self.vert_he[v as usize] = NONE;
                    return;
                }
            }
        };
        let mut h = start;
        loop {
            let t = self.twin[h as usize];
            if t == NONE {
                break;
            }
            h = self.next[t as usize];
            if h == start {
                break;
            }
        }
        self.vert_he[v as usize] = h;
    }

    /// Splits edge `{a, b}` at `point`, splitting each adjacent triangle in two. Returns the new
    /// vertex. Sharpness carries over to both halves.
    pub fn split_edge(&mut self, a: u32, b: u32, point: Point3) -> Result<u32, TopologyError> {
        let h = self.edge_half_edge(a, b)?;
        let t = self.twin[h as usize];
        for e in [h, t] {
            if e == NONE {
                continue;
            }
            self.check_triangle(self.face[e as usize])?;
        }
        let m = self.positions.len() as u32;
        self.positions.push(point);
        self.vert_he.push(NONE);
        let sharp = self.sharp[h as usize];
        let h_new = self.split_triangle_side(h, m, sharp);
        if t != NONE {
            let t_new = self.split_triangle_side(t, m, sharp);
            // h: x→m now (x = origin(h)); t: y→m; the far halves h_new: m→y, t_new: m→x.
            self.twin[h as usize] = t_new;
            self.twin[t_new as usize] = h;
            self.twin[t as usize] = h_new;
            self.twin[h_new as usize] = t;
        }
        let (x, y) = (self.origin(h), self.origin(h_new));
        for v in [x, y, m] {
            self.relink_vertex(v);
        }
        let c = self.origin(self.prev(h));
        self.relink_vertex(c);
        if t != NONE {
            let d = self.origin(self.prev(t));
            self.relink_vertex(d);
        }
        Ok(m)
    }

    /// Splits the triangle of `h` (x→y, then y→c, c→x) by a new vertex `m` on `h`: `h` becomes
    /// x→m in triangle (x, m, c) and a new half-edge m→y starts triangle (m, y, c). Returns it.
    fn split_triangle_side(&mut self, h: u32, m: u32, sharp: bool) -> u32 {
        let (hn, hp) = (self.next(h), self.prev(h));
        let c = self.origin(hp);
        let f_old = self.face[h as usize];
        let f_new = self.face_he.len() as u32;
        self.face_he.push(NONE);
        let base = self.origin.len() as u32;
        // base: m→y (new face), base+1: c→m (new face), base+2: m→c (old face).
        for (o, s) in [(m, sharp), (c, false), (m, false)] {
            self.origin.push(o);
            self.next.push(NONE);
            self.prev.push(NONE);
            self.twin.push(NONE);
            self.face.push(NONE);
            self.sharp.push(s);
        }
        let (my, cm, mc) = (base, base + 1, base + 2);
        self.twin[cm as usize] = mc;
        self.twin[mc as usize] = cm;
        self.link_triangle(h, mc, hp, f_old);
        self.link_triangle(my, hn, cm, f_new);
        my
    }

    /// Refines the given triangles 1→4 (a new vertex at each edge midpoint) and splits their
    /// neighbours 1→2 (1→3 when two of their edges were split, 1→4 when three) so the mesh
    /// stays conforming: the patent's local refinement (SPEC §1.8). Returns each new vertex
    /// with the edge `(a, b)` it splits. Creases carry over to both halves of a split edge.
    pub fn refine_triangles(
        &mut self,
        faces: &[u32],
    ) -> Result<Vec<(u32, u32, u32)>, TopologyError> {
        let count = self.num_faces();
        let mut mids: HashMap<(u32, u32), u32> = HashMap::new();
        let mut created = Vec::new();
        for &f in faces {
            if f as usize >= count {
                return Err(TopologyError::NoSuchFace {
                    face: f as usize,
                    count,
                });
            }
            let len = self.face_len(f);
            if len != 3 {
                return Err(TopologyError::WrongFaceSize {
                    face: f as usize,
                    len,
                    needed: 3,
                });
            }
            for h in self.face_half_edges(f) {
                let (a, b) = (self.origin(h), self.target(h));
                let key = (a.min(b), a.max(b));
                if let std::collections::hash_map::Entry::Vacant(slot) = mids.entry(key) {
                    let m = (self.positions.len() + created.len()) as u32;
                    slot.insert(m);
                    created.push((m, key.0, key.1));
                }
            }
        }
        let mut positions = self.positions.clone();
        for &(_, a, b) in &created {
            positions.push((self.positions[a as usize] + self.positions[b as usize]) * 0.5);
        }
        let mid = |a: u32, b: u32| mids.get(&(a.min(b), a.max(b))).copied();
        let mut new_faces: Vec<Vec<u32>> = Vec::with_capacity(count + 3 * faces.len());
        for f in 0..count as u32 {
            let corners: Vec<u32> = self.face_vertices(f).collect();
            split_face(&corners, &mid, &mut new_faces);
        }
        let mut creases = Vec::new();
        for [a, b] in self.creases() {
            match mid(a, b) {
                Some(m) => creases.extend([(a, m), (m, b)]),
                None => creases.push((a, b)),
            }
        }
        let mut rebuilt =
            ControlMesh::from_faces_checked(positions, new_faces.iter().map(|f| &f[..]))?;
        for (a, b) in creases {
            rebuilt.set_sharp(a, b, true)?;
        }
        *self = rebuilt;
        Ok(created)
    }
}

/// Splits one face given the midpoints of its split edges: triangles with all three edges split
/// go 1→4, with one or two go 1→2 or 1→3; other faces are kept.
fn split_face(c: &[u32], mid: &impl Fn(u32, u32) -> Option<u32>, out: &mut Vec<Vec<u32>>) {
    if c.len() != 3 {
        out.push(c.to_vec());
        return;
    }
    let m = [mid(c[0], c[1]), mid(c[1], c[2]), mid(c[2], c[0])];
    match m {
        [Some(m0), Some(m1), Some(m2)] => {
            out.extend([
                vec![c[0], m0, m2],
                vec![m0, c[1], m1],
                vec![m2, m1, c[2]],
                vec![m0, m1, m2],
            ]);
        }
        [None, None, None] => out.push(c.to_vec()),
        _ => {
            // Rotate so the first split edge is c0→c1, then fan from its midpoint.
            let k = (0..3)
                .find(|&k| m[k].is_some() && m[(k + 2) % 3].is_none())
                .unwrap_or(0);
            let (a, b, d) = (c[k], c[(k + 1) % 3], c[(k + 2) % 3]);
            let (Some(mab), mbd) = (m[k], m[(k + 1) % 3]) else {
                out.push(c.to_vec());
                return;
            };
            match mbd {
                None => out.extend([vec![a, mab, d], vec![mab, b, d]]),
                Some(mbd) => out.extend([vec![a, mab, d], vec![mab, b, mbd], vec![mab, mbd, d]]),
            }
        }
    }
}

fn edge_error(undirected: &HashMap<(u32, u32), usize>, a: u32, b: u32) -> TopologyError {
    let faces = undirected.get(&(a.min(b), a.max(b))).copied().unwrap_or(0);
    if faces > 2 {
        TopologyError::NonManifoldEdge { a, b, faces }
    } else {
        TopologyError::InconsistentOrientation { a, b }
    }
}
