//! Exact limit evaluation by local subdivision over a shared graph of patch types.
//!
//! A patch is a control face with its neighbourhood (every face touching one of its corners).
//! If the neighbourhood is regular, the limit is a closed-form spline over it (box spline or
//! bicubic B-spline, with phantom points reflected across boundaries and creases where that is
//! exact). Otherwise the neighbourhood is subdivided once with the scheme's own rules and the
//! parameter moves into one of the child patches, until a regular child is reached; the limit
//! at an extraordinary vertex itself comes from the scheme's limit mask.
//!
//! The subdivision matrices depend only on the neighbourhood's connectivity, so neighbourhoods
//! are put in a canonical order and interned: all patches and sub-patches of the same shape
//! share one node, and the sub-patch at an extraordinary vertex maps to itself after the first
//! step (a self-loop in the graph), as in Stam's eigen-analysis but without eigenvectors.

use super::basis::{bicubic_lattice, rows_times_points, PowerBasis, LOOP_LATTICE};
use super::topo::{key, EdgeTag, Stencil, Topo, NO};
use super::{LimitEval, Scheme, SubdivError};
use crate::geom::{Point3, Vec3};
use std::collections::HashMap;

/// Most control points one neighbourhood may have (sizes the stack buffers of evaluation).
pub(crate) const MAX_LOCAL: usize = 64;
/// Subdivision depth after which a parameter counts as being at the extraordinary vertex
/// (sub-patch size 2⁻⁴⁰ of the patch).
const MAX_DEPTH: usize = 40;
/// Extra levels allowed after moving to the sub-patch centre at [`MAX_DEPTH`].
const EXTRA_DEPTH: usize = 24;
/// Levels of local subdivision flattened into a [`Shortcut`]: a sample goes deeper with
/// probability about 4^-depth, so almost every evaluation is one polynomial. Each level adds
/// cached data that every control-point update refills: on the bunny fit, 3 levels made the
/// foot points 20 % cheaper than 2 for a third more refilling; 4 cost more than they saved.
const SHORTCUT_DEPTH: usize = 3;

/// Affine map from a parent patch's parameters into a child's: `child = m · (p − origin)`.
#[derive(Clone, Copy, Debug)]
struct ChildMap {
    origin: [f64; 2],
    m: [[f64; 2]; 2],
}

impl ChildMap {
    fn new(q0: [f64; 2], q1: [f64; 2], q2: [f64; 2]) -> ChildMap {
        let a = [
            [q1[0] - q0[0], q2[0] - q0[0]],
            [q1[1] - q0[1], q2[1] - q0[1]],
        ];
        let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
        let m = [
            [a[1][1] / det, -a[0][1] / det],
            [-a[1][0] / det, a[0][0] / det],
        ];
        ChildMap { origin: q0, m }
    }

    fn apply(&self, u: f64, v: f64) -> (f64, f64) {
        let (du, dv) = (u - self.origin[0], v - self.origin[1]);
        (
            self.m[0][0] * du + self.m[0][1] * dv,
            self.m[1][0] * du + self.m[1][1] * dv,
        )
    }
}

/// A sparse matrix (rows of weights over local points): subdivision stencils have a handful
/// of non-zeros per row, so evaluation cost follows the stencil sizes, not `k²`.
#[derive(Clone)]
struct Sparse {
    starts: Vec<u32>,
    cols: Vec<u16>,
    vals: Vec<f64>,
}

impl Sparse {
    fn from_dense(rows: usize, k: usize, dense: &[f64]) -> Sparse {
        let mut m = Sparse {
            starts: vec![0],
            cols: Vec::new(),
            vals: Vec::new(),
        };
        for r in 0..rows {
            for (j, &w) in dense[r * k..(r + 1) * k].iter().enumerate() {
                if w != 0.0 {
                    m.cols.push(j as u16);
                    m.vals.push(w);
                }
            }
            m.starts.push(m.cols.len() as u32);
        }
        m
    }

    fn rows(&self) -> usize {
        self.starts.len() - 1
    }

    fn row(&self, r: usize) -> impl Iterator<Item = (usize, f64)> + '_ {
        let (a, b) = (self.starts[r] as usize, self.starts[r + 1] as usize);
        self.cols[a..b]
            .iter()
            .zip(&self.vals[a..b])
            .map(|(&c, &w)| (c as usize, w))
    }

    /// `dst[r] = Σ_j m[r][j] src[j]`.
    fn apply(&self, src: &[Vec3], dst: &mut [Vec3]) {
        for (r, d) in dst.iter_mut().enumerate().take(self.rows()) {
            *d = self.row(r).map(|(j, w)| src[j] * w).sum();
        }
    }

    /// `out[j] += Σ_r w[r] m[r][j]` (weights pulled back through the matrix).
    fn pull_back(&self, w: &[f64], out: &mut [f64]) {
        for (r, &wr) in w.iter().enumerate().take(self.rows()) {
            if wr != 0.0 {
                for (j, m) in self.row(r) {
                    out[j] += wr * m;
                }
            }
        }
    }
}

#[derive(Clone)]
struct Child {
    node: u32,
    k: usize,
    /// `k × parent k`: child points from parent points.
    mat: Sparse,
    map: ChildMap,
}

#[derive(Clone)]
enum Node {
    /// Placeholder while the node is being built.
    Pending,
    /// Closed-form patch: `gather` (`nb × k`) makes the spline's control points.
    Regular { k: usize, gather: Sparse },
    /// Subdivide: one child per sub-patch, and the limit masks of the corners.
    Split {
        k: usize,
        children: Vec<Child>,
        corner_masks: Vec<Vec<(u16, f64)>>,
    },
}

/// The interned patch shapes of one surface.
#[derive(Clone)]
pub(crate) struct Graph {
    scheme: Scheme,
    nodes: Vec<Node>,
    index: HashMap<Vec<u32>, u32>,
    pending: Vec<(u32, Topo, Kind)>,
    /// The scheme's regular patch in power form.
    power: PowerBasis,
    shortcuts: Vec<Shortcut>,
    shortcut_of: HashMap<u32, u32>,
}

/// The first [`SHORTCUT_DEPTH`] levels of a patch shape's descent, flattened: every regular
/// leaf's power coefficients and every deeper sub-patch's points written as one dense matrix over
/// the patch's local points. A surface multiplies these by its control points once per update
/// ([`Graph::fill_shortcut`]); evaluation then looks the parameter's cell up in a grid and
/// evaluates one polynomial instead of subdividing per sample.
///
/// A leaf's polynomial is rewritten in the patch's own parameters, relative to the leaf's origin
/// (w = (u, v) − origin), so that it gives the patch's derivatives directly. The child maps of
/// every scheme are ±2 times a rotation by a multiple of 90° (or the identity), so the rewrite only
/// permutes coefficients, flips signs and scales them by powers of two: it is exact, and keeps
/// a tensor-product or total-degree monomial set as it is.
#[derive(Clone)]
struct Shortcut {
    /// The entry of every cell of the [`GRID`] × [`GRID`] grid over the patch domain (two
    /// triangles per square for Loop: see [`Graph::cell`]).
    grid: Vec<u16>,
    entries: Vec<Entry>,
    /// Local points of the root.
    k: usize,
    /// Length of a patch's cached data (sum of the entries' lengths).
    len: usize,
}

/// Cells per side of a shortcut's lookup grid: the finest sub-patches of a shortcut.
const GRID: usize = 1 << SHORTCUT_DEPTH;

#[derive(Clone)]
enum Entry {
    /// A regular sub-patch: `mat` (monomials × k) gives its power coefficients in
    /// w = (u, v) − `origin` (or, with `map`, in the sub-patch's own parameters
    /// `map.apply(u, v)`, when they could not be rewritten).
    Leaf {
        offset: usize,
        origin: [f64; 2],
        map: Option<ChildMap>,
        mat: Vec<f64>,
    },
    /// A sub-patch at the shortcut's depth that needs more subdivision: `mat` (`kd × k`) gives
    /// its local points, and [`Graph::eval`] continues from `node` at `map.apply(u, v)`.
    Deep {
        offset: usize,
        node: u32,
        kd: usize,
        map: ChildMap,
        mat: Vec<f64>,
    },
}

/// The descent tree of a shortcut while it is built.
enum Tree {
    Split(Vec<(usize, ChildMap)>),
    End(usize),
}

/// The composite map of descending through `inner` then `outer`: `outer(inner(p))`.
fn compose(outer: &ChildMap, inner: &ChildMap) -> ChildMap {
    // outer(inner(p)) = mo (mi (p − oi) − oo) = mo mi (p − oi − mi⁻¹ oo).
    let mi = inner.m;
    let det = mi[0][0] * mi[1][1] - mi[0][1] * mi[1][0];
    let inv = [
        [mi[1][1] / det, -mi[0][1] / det],
        [-mi[1][0] / det, mi[0][0] / det],
    ];
    let oo = outer.origin;
    ChildMap {
        origin: [
            inner.origin[0] + inv[0][0] * oo[0] + inv[0][1] * oo[1],
            inner.origin[1] + inv[1][0] * oo[0] + inv[1][1] * oo[1],
        ],
        m: mul2(outer.m, mi),
    }
}

/// The matrix (`exps.len()`², row-major, new monomial by old) that rewrites power coefficients
/// in q = m w into coefficients in w, or `None` when the result leaves the monomial set `exps`.
fn substitution(exps: &[(usize, usize)], m: [[f64; 2]; 2]) -> Option<Vec<f64>> {
    const N: usize = 9;
    type Poly = [[f64; N]; N];
    let times_linear = |p: &Poly, a: f64, b: f64| -> Option<Poly> {
        // p · (a w₁ + b w₂)
        let mut out = [[0.0; N]; N];
        for i in 0..N {
            for j in 0..N {
                if p[i][j] == 0.0 {
                    continue;
                }
                if i + 1 >= N || j + 1 >= N {
                    return None;
                }
                out[i + 1][j] += p[i][j] * a;
                out[i][j + 1] += p[i][j] * b;
            }
        }
        Some(out)
    };
    let n = exps.len();
    let mut t = vec![0.0; n * n];
    for (col, &(ea, eb)) in exps.iter().enumerate() {
        let mut p = [[0.0; N]; N];
        p[0][0] = 1.0;
        for _ in 0..ea {
            p = times_linear(&p, m[0][0], m[0][1])?;
        }
        for _ in 0..eb {
            p = times_linear(&p, m[1][0], m[1][1])?;
        }
        for (i, row) in p.iter().enumerate() {
            for (j, &c) in row.iter().enumerate().filter(|(_, &c)| c != 0.0) {
                let r = exps.iter().position(|&e| e == (i, j))?;
                t[r * n + col] += c;
            }
        }
    }
    Some(t)
}

/// Dense `rows × k` product of a sparse `rows × m` matrix and a dense `m × k` one.
fn sparse_times_dense(a: &Sparse, b: &[f64], k: usize) -> Vec<f64> {
    let mut out = vec![0.0; a.rows() * k];
    for r in 0..a.rows() {
        let row = &mut out[r * k..(r + 1) * k];
        for (j, w) in a.row(r) {
            for (o, &x) in row.iter_mut().zip(&b[j * k..(j + 1) * k]) {
                *o += w * x;
            }
        }
    }
    out
}

/// A canonical neighbourhood of one face: local faces and where each local point came from.
/// Its [`Topo`] is only built when the shape is new to the graph ([`Neighbourhood::topo`]).
pub(crate) struct Neighbourhood {
    pub source: Vec<u32>,
    starts: Vec<u32>,
    verts: Vec<u32>,
    /// Tags of the local edges in order of first appearance (the order of [`Topo::new`]).
    tags: Vec<EdgeTag>,
    key: Vec<u32>,
    kind: Kind,
}

impl Neighbourhood {
    /// Number of local points.
    fn len(&self) -> usize {
        self.source.len()
    }

    fn topo(self) -> (Topo, Kind) {
        let mut tags = self.tags.into_iter();
        let topo = Topo::new(self.source.len(), self.starts, self.verts, |_, _| {
            tags.next().unwrap_or_default()
        });
        (topo, self.kind)
    }
}

/// The local index of `v`, appending it to `source` if new (neighbourhoods are small, so a
/// linear scan beats hashing).
fn local_index(source: &mut Vec<u32>, v: u32) -> u32 {
    match source.iter().position(|&x| x == v) {
        Some(i) => i as u32,
        None => {
            source.push(v);
            (source.len() - 1) as u32
        }
    }
}

/// Gathers the faces around every corner of `f` in a canonical order: corners first, then the
/// fans of the corners in turn (counter-clockwise from `f`, then clockwise).
pub(crate) fn neighbourhood(src: &Topo, f: u32) -> Neighbourhood {
    let mut source: Vec<u32> = src.face(f).to_vec();
    let mut faces = vec![f];
    let mut fan = Vec::new();
    for &c in src.face(f) {
        fan.clear();
        src.fan(c, f, false, &mut fan);
        for &g in &fan {
            if faces.contains(&g) {
                continue;
            }
            faces.push(g);
            let gv = src.face(g);
            let start = gv.iter().position(|&x| x == c).unwrap_or(0);
            for i in 0..gv.len() {
                local_index(&mut source, gv[(start + i) % gv.len()]);
            }
        }
    }
    finish(src, source, &faces, Kind::Face)
}

/// What a neighbourhood is the neighbourhood of: a face (Loop, Catmull–Clark patches), a
/// vertex (Doo–Sabin patches: the vertex's faces), or a control vertex whose fan is refined
/// once to reach the Doo–Sabin patch of one face corner (the root of a Doo–Sabin patch).
#[derive(Clone, Copy, PartialEq, Eq)]
pub(crate) enum Kind {
    Face,
    Vertex,
    DooSabinRoot,
}

/// Gathers the faces around vertex `v` counter-clockwise from `f` (local vertex 0 is `v`).
pub(crate) fn vertex_neighbourhood(src: &Topo, v: u32, f: u32, kind: Kind) -> Neighbourhood {
    let mut source = vec![v];
    let mut faces = Vec::new();
    src.fan(v, f, false, &mut faces);
    for &g in &faces {
        let gv = src.face(g);
        let start = gv.iter().position(|&x| x == v).unwrap_or(0);
        for i in 0..gv.len() {
            local_index(&mut source, gv[(start + i) % gv.len()]);
        }
    }
    finish(src, source, &faces, kind)
}

/// Lays out the local faces of `faces` (face 0 rotated to start at local vertex 0, the others
/// at their smallest local index) with their edge tags, and the key that identifies the shape.
fn finish(src: &Topo, source: Vec<u32>, faces: &[u32], kind: Kind) -> Neighbourhood {
    let mut starts = vec![0u32];
    let mut verts = Vec::new();
    let mut key_out = vec![kind as u32, source.len() as u32, faces.len() as u32];
    let mut gv = Vec::new();
    let mut gt = Vec::new();
    let mut edges: Vec<(u32, u32)> = Vec::new();
    let mut tags: Vec<EdgeTag> = Vec::new();
    for (n, &g) in faces.iter().enumerate() {
        gv.clear();
        gv.extend(
            src.face(g)
                .iter()
                .map(|v| source.iter().position(|x| x == v).unwrap_or(0) as u32),
        );
        let ids = &src.face_edges
            [src.face_starts[g as usize] as usize..src.face_starts[g as usize + 1] as usize];
        gt.clear();
        gt.extend(ids.iter().map(|&e| src.edge_tags[e as usize]));
        let rot = if n == 0 {
            gv.iter().position(|&x| x == 0).unwrap_or(0)
        } else {
            (0..gv.len()).min_by_key(|&i| gv[i]).unwrap_or(0)
        };
        key_out.push(gv.len() as u32);
        for i in 0..gv.len() {
            let r = (rot + i) % gv.len();
            let (a, b) = (gv[r], gv[(r + 1) % gv.len()]);
            verts.push(a);
            key_out.push(a);
            if !edges.contains(&key(a, b)) {
                edges.push(key(a, b));
                tags.push(gt[r]);
            }
        }
        starts.push(verts.len() as u32);
    }
    key_out.extend(
        tags.iter()
            .map(|t| u32::from(t.sharp) | (u32::from(t.open) << 1)),
    );
    Neighbourhood {
        source,
        starts,
        verts,
        tags,
        key: key_out,
        kind,
    }
}

/// Parameters of the corners of a patch.
fn corner_params(scheme: Scheme) -> &'static [[f64; 2]] {
    match scheme {
        Scheme::Loop => &[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]],
        _ => &[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]],
    }
}

/// Parameter maps of the children that [`Topo::refine`] makes of face 0, in its order.
fn child_maps(scheme: Scheme) -> Vec<ChildMap> {
    let mid = |a: [f64; 2], b: [f64; 2]| [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0];
    let c = corner_params(scheme);
    match scheme {
        Scheme::Loop => {
            let (m0, m1, m2) = (mid(c[0], c[1]), mid(c[1], c[2]), mid(c[2], c[0]));
            vec![
                ChildMap::new(c[0], m0, m2),
                ChildMap::new(m0, c[1], m1),
                ChildMap::new(m2, m1, c[2]),
                ChildMap::new(m1, m2, m0),
            ]
        }
        _ => (0..4)
            .map(|i| ChildMap::new(c[i], mid(c[i], c[(i + 1) % 4]), mid(c[i], c[(i + 3) % 4])))
            .collect(),
    }
}

/// Which child of face 0 holds (u, v), in the order of [`child_maps`].
fn pick_child(scheme: Scheme, u: f64, v: f64) -> usize {
    match scheme {
        Scheme::Loop => {
            if u >= 0.5 {
                1
            } else if v >= 0.5 {
                2
            } else if u + v <= 0.5 {
                0
            } else {
                3
            }
        }
        _ => match (u >= 0.5, v >= 0.5) {
            (false, false) => 0,
            (true, false) => 1,
            (true, true) => 2,
            (false, true) => 3,
        },
    }
}

fn domain_centre(scheme: Scheme) -> (f64, f64) {
    match scheme {
        Scheme::Loop => (1.0 / 3.0, 1.0 / 3.0),
        _ => (0.5, 0.5),
    }
}

/// Lattice coordinates of the neighbourhood's points, unfolded from face 0 across smooth edges.
fn unfold(topo: &Topo, scheme: Scheme) -> Option<Vec<Option<(i32, i32)>>> {
    let n = if scheme == Scheme::Loop { 3 } else { 4 };
    let mut coords: Vec<Option<(i32, i32)>> = vec![None; topo.nv];
    let start: &[(i32, i32)] = if scheme == Scheme::DooSabin {
        &[(0, 0), (-1, 0), (-1, -1), (0, -1)]
    } else if n == 3 {
        &[(0, 0), (1, 0), (0, 1)]
    } else {
        &[(0, 0), (1, 0), (1, 1), (0, 1)]
    };
    if topo.face(0).len() != n {
        return None;
    }
    for (i, &v) in topo.face(0).iter().enumerate() {
        coords[v as usize] = Some(start[i]);
    }
    let mut done = vec![false; topo.num_faces()];
    done[0] = true;
    let mut queue = vec![0u32];
    while let Some(g) = queue.pop() {
        let gv = topo.face(g).to_vec();
        let ids = topo.face_edges
            [topo.face_starts[g as usize] as usize..topo.face_starts[g as usize + 1] as usize]
            .to_vec();
        let at = |v: u32, coords: &Vec<Option<(i32, i32)>>| coords[v as usize];
        for i in 0..n {
            let e = ids[i];
            if topo.edge_tags[e as usize].sharp {
                continue;
            }
            let h = topo.other_face(e, g);
            if h == NO || done[h as usize] {
                continue;
            }
            let hv = topo.face(h);
            if hv.len() != n {
                return None;
            }
            let (a, b) = (gv[i], gv[(i + 1) % n]);
            let (pa, pb) = (at(a, &coords)?, at(b, &coords)?);
            let j = hv.iter().position(|&x| x == a)?;
            let news: Vec<(u32, (i32, i32))> = if n == 3 {
                let pc = at(gv[(i + 2) % 3], &coords)?;
                vec![(hv[(j + 1) % 3], (pa.0 + pb.0 - pc.0, pa.1 + pb.1 - pc.1))]
            } else {
                let pp = at(gv[(i + 3) % 4], &coords)?;
                let pq = at(gv[(i + 2) % 4], &coords)?;
                vec![
                    (hv[(j + 1) % 4], (2 * pa.0 - pp.0, 2 * pa.1 - pp.1)),
                    (hv[(j + 2) % 4], (2 * pb.0 - pq.0, 2 * pb.1 - pq.1)),
                ]
            };
            for (v, p) in news {
                match coords[v as usize] {
                    Some(q) if q != p => return None,
                    _ => coords[v as usize] = Some(p),
                }
            }
            done[h as usize] = true;
            queue.push(h);
        }
    }
    Some(coords)
}

/// Whether a corner allows a closed-form patch: smooth with the regular valence, or on a
/// straight crease or open boundary: two sharp edges with half the regular valence's faces on
/// the patch's side (three triangles, two quads), where reflected phantom points reproduce the
/// cubic B-spline crease rule exactly. A grid corner (one face between its sharp edges) is not
/// regular: the crease rule smooths it, while reflected phantoms would make it interpolate the
/// control vertex.
///
/// Until 2026-12-07 this asked for two triangles or three quads, which no straight crease or
/// boundary has, so every patch along one was evaluated by subdividing towards it: correct,
/// but a point on the edge itself went 40 levels deep (about a quarter of the warm foot points'
/// time on the bunny, whose holes leave ~100 points on open edges, and 29 % of a Loop fit of
/// the range scan bun000), and its second derivatives, scaled back from 2⁻⁴⁰, were off by up to
/// 1 % (`tests/common/surface_checks.rs` now checks them along creases and boundaries).
fn corner_is_regular(topo: &Topo, scheme: Scheme, c: u32) -> bool {
    if !topo.is_complete(c) {
        return false;
    }
    let n = if scheme == Scheme::Loop { 3 } else { 4 };
    let mut fan = Vec::new();
    match topo.sharp_count(c) {
        0 => {
            topo.fan(c, 0, false, &mut fan);
            let valence = if n == 3 { 6 } else { 4 };
            topo.vertex_edges(c).len() == valence && fan.iter().all(|&g| topo.face(g).len() == n)
        }
        2 => {
            // Half the regular valence on each side: 3 triangles or 2 quads.
            let side = if n == 3 { 3 } else { 2 };
            topo.fan(c, 0, true, &mut fan);
            fan.len() == side && fan.iter().all(|&g| topo.face(g).len() == n)
        }
        _ => false,
    }
}

/// The `nb × k` matrix that makes a regular patch's spline control points, or `None` if the
/// neighbourhood is not regular.
fn regular_gather(topo: &Topo, scheme: Scheme) -> Option<Vec<f64>> {
    if scheme == Scheme::DooSabin {
        return doo_sabin_gather(topo);
    }
    let corners = topo.face(0).to_vec();
    if !corners.iter().all(|&c| corner_is_regular(topo, scheme, c)) {
        return None;
    }
    let coords = unfold(topo, scheme)?;
    let mut at: HashMap<(i32, i32), Option<u32>> = HashMap::new();
    for (v, c) in coords.iter().enumerate() {
        if let Some(p) = c {
            at.entry(*p)
                .and_modify(|x| *x = None)
                .or_insert(Some(v as u32));
        }
    }
    let find = |p: (i32, i32)| at.get(&p).copied().flatten();
    let k = topo.nv;
    match scheme {
        Scheme::Loop => {
            let sharp: std::collections::HashSet<(u32, u32)> = topo
                .edges
                .iter()
                .zip(&topo.edge_tags)
                .filter(|(_, t)| t.sharp)
                .map(|(&[a, b], _)| (a, b))
                .collect();
            let is_sharp = |a: u32, b: u32| sharp.contains(&key(a, b));
            const NBRS: [(i32, i32); 6] = [(1, 0), (0, 1), (-1, 1), (-1, 0), (0, -1), (1, -1)];
            let mut g = vec![0.0; 12 * k];
            for (r, &p) in LOOP_LATTICE.iter().enumerate() {
                if let Some(i) = find(p) {
                    g[r * k + i as usize] = 1.0;
                    continue;
                }
                // A phantom point: the half-turn image, about the midpoint of an adjacent
                // sharp edge, of the real point on the other side.
                let phantom = (0..6).find_map(|t| {
                    let (d1, d2) = (NBRS[t], NBRS[(t + 1) % 6]);
                    let a = find((p.0 + d1.0, p.1 + d1.1))?;
                    let b = find((p.0 + d2.0, p.1 + d2.1))?;
                    let c = find((p.0 + d1.0 + d2.0, p.1 + d1.1 + d2.1))?;
                    is_sharp(a, b).then_some((a, b, c))
                })?;
                g[r * k + phantom.0 as usize] += 1.0;
                g[r * k + phantom.1 as usize] += 1.0;
                g[r * k + phantom.2 as usize] -= 1.0;
            }
            Some(g)
        }
        _ => {
            let ids = &topo.face_edges[0..4];
            let side = |s: usize| topo.edge_tags[ids[s] as usize].sharp;
            // Reflection of a phantom index across a sharp side: P(-1) = 2P(0) - P(1).
            let axis = |i: i32, low: bool, high: bool| -> Vec<(f64, i32)> {
                match i {
                    -1 if low => vec![(2.0, 0), (-1.0, 1)],
                    2 if high => vec![(2.0, 1), (-1.0, 0)],
                    _ => vec![(1.0, i)],
                }
            };
            let mut g = vec![0.0; 16 * k];
            for (r, &(i, j)) in bicubic_lattice().iter().enumerate() {
                for (wi, ii) in axis(i, side(3), side(1)) {
                    for (wj, jj) in axis(j, side(0), side(2)) {
                        g[r * k + find((ii, jj))? as usize] += wi * wj;
                    }
                }
            }
            Some(g)
        }
    }
}

/// A Doo–Sabin vertex patch is regular when the vertex has four quads around it: the patch is
/// then the biquadratic B-spline over their nine points.
fn doo_sabin_gather(topo: &Topo) -> Option<Vec<f64>> {
    if !topo.is_complete(0) || topo.vertex_edges(0).len() != 4 || topo.num_faces() != 4 {
        return None;
    }
    if (0..4).any(|g| topo.face(g).len() != 4) {
        return None;
    }
    let coords = unfold(topo, Scheme::DooSabin)?;
    let k = topo.nv;
    let mut g = vec![0.0; 9 * k];
    for (v, c) in coords.iter().enumerate() {
        let (i, j) = (*c)?;
        if !(-1..=1).contains(&i) || !(-1..=1).contains(&j) {
            return None;
        }
        let r = (3 * (j + 1) + (i + 1)) as usize;
        if g[r * k..(r + 1) * k].iter().any(|&w| w != 0.0) {
            return None;
        }
        g[r * k + v] = 1.0;
    }
    Some(g)
}

impl Graph {
    pub fn new(scheme: Scheme) -> Graph {
        let power = match scheme {
            Scheme::Loop => PowerBasis::new(true, 4),
            Scheme::CatmullClark => PowerBasis::new(false, 3),
            Scheme::DooSabin => PowerBasis::new(false, 2),
        };
        Graph {
            scheme,
            nodes: Vec::new(),
            index: HashMap::new(),
            pending: Vec::new(),
            power,
            shortcuts: Vec::new(),
            shortcut_of: HashMap::new(),
        }
    }

    /// The scheme's regular patch in power form.
    pub fn power(&self) -> &PowerBasis {
        &self.power
    }

    /// Length of a patch's cached data: power coefficients for a `direct` patch, shortcut
    /// `shortcut`'s data otherwise.
    pub fn cache_len(&self, direct: bool, shortcut: u32) -> usize {
        match direct {
            true => self.power.len(),
            false => self.shortcuts.get(shortcut as usize).map_or(0, |s| s.len),
        }
    }

    /// The shortcut of the patch shape `node`, built on first request.
    pub fn shortcut(&mut self, node: u32) -> u32 {
        if let Some(&id) = self.shortcut_of.get(&node) {
            return id;
        }
        let k = match &self.nodes[node as usize] {
            Node::Regular { k, .. } | Node::Split { k, .. } => *k,
            Node::Pending => 0,
        };
        let mut identity = vec![0.0; k * k];
        for i in 0..k {
            identity[i * k + i] = 1.0;
        }
        let mut tree = Vec::new();
        let mut entries = Vec::new();
        let root_map = ChildMap {
            origin: [0.0, 0.0],
            m: [[1.0, 0.0], [0.0, 1.0]],
        };
        self.shortcut_cell(node, 0, identity, root_map, k, &mut tree, &mut entries);
        let mut len = 0;
        for entry in &mut entries {
            match entry {
                Entry::Leaf { offset, .. } => {
                    *offset = len;
                    len += self.power.len();
                }
                Entry::Deep { offset, kd, .. } => {
                    *offset = len;
                    len += *kd;
                }
            }
        }
        let grid = self.cell_centres().map(|(u, v)| {
            let mut at = 0;
            let (mut u, mut v) = (u, v);
            while let Tree::Split(children) = &tree[at] {
                let ci = if children.len() == 1 {
                    0
                } else {
                    pick_child(self.scheme, u, v)
                };
                let Some(&(next, map)) = children.get(ci) else {
                    break;
                };
                (u, v) = map.apply(u, v);
                at = next;
            }
            match tree[at] {
                Tree::End(e) => e as u16,
                Tree::Split(_) => 0,
            }
        });
        let id = self.shortcuts.len() as u32;
        self.shortcuts.push(Shortcut {
            grid: grid.collect(),
            entries,
            k,
            len,
        });
        self.shortcut_of.insert(node, id);
        id
    }

    /// A point inside every cell of a shortcut's grid, in the order of [`Graph::cell`].
    fn cell_centres(&self) -> impl Iterator<Item = (f64, f64)> {
        let triangle = self.scheme == Scheme::Loop;
        let h = 1.0 / GRID as f64;
        (0..GRID * GRID * if triangle { 2 } else { 1 }).map(move |c| {
            let (sq, upper) = if triangle {
                (c / 2, c % 2 == 1)
            } else {
                (c, false)
            };
            let (i, j) = ((sq % GRID) as f64, (sq / GRID) as f64);
            match (triangle, upper) {
                (false, _) => ((i + 0.5) * h, (j + 0.5) * h),
                (true, false) => ((i + 1.0 / 3.0) * h, (j + 1.0 / 3.0) * h),
                (true, true) => ((i + 2.0 / 3.0) * h, (j + 2.0 / 3.0) * h),
            }
        })
    }

    /// The grid cell of a shortcut holding (u, v): square (i, j) of the [`GRID`] × [`GRID`]
    /// grid, each square halved along its anti-diagonal for Loop (lower triangle first).
    /// Parameters outside the domain go to the nearest cell of the square grid.
    #[inline]
    fn cell(&self, u: f64, v: f64) -> usize {
        let g = GRID as f64;
        let (x, y) = (u * g, v * g);
        // `as usize` saturates: negative and NaN give 0.
        let (i, j) = ((x as usize).min(GRID - 1), (y as usize).min(GRID - 1));
        let sq = j * GRID + i;
        if self.scheme == Scheme::Loop {
            let upper = (x - i as f64) + (y - j as f64) > 1.0;
            2 * sq + usize::from(upper)
        } else {
            sq
        }
    }

    /// Appends the tree node of `node` at `depth` to `tree` (its entry to `entries` if it ends
    /// there), whose local points are `acc` (`k_node × k`) times the root's and whose
    /// parameters are `map` of the root's, and its descendants; returns its index in `tree`.
    #[allow(clippy::too_many_arguments)]
    fn shortcut_cell(
        &self,
        node: u32,
        depth: usize,
        acc: Vec<f64>,
        map: ChildMap,
        k: usize,
        tree: &mut Vec<Tree>,
        entries: &mut Vec<Entry>,
    ) -> usize {
        let id = tree.len();
        match &self.nodes[node as usize] {
            Node::Regular { gather, .. } => {
                let cp = sparse_times_dense(gather, &acc, k);
                let mut mat = vec![0.0; self.power.len() * k];
                let rows = self.power.to_power.chunks_exact(self.power.points);
                for (m, row) in rows.enumerate() {
                    for (i, &w) in row.iter().enumerate().filter(|(_, &w)| w != 0.0) {
                        for (o, &x) in mat[m * k..(m + 1) * k].iter_mut().zip(&cp[i * k..]) {
                            *o += w * x;
                        }
                    }
                }
                let entry = match substitution(&self.power.exps, map.m) {
                    Some(t) => {
                        let n = self.power.len();
                        let mut rewritten = vec![0.0; n * k];
                        for r in 0..n {
                            for c in (0..n).filter(|&c| t[r * n + c] != 0.0) {
                                let (dst, src) = (r * k, c * k);
                                for j in 0..k {
                                    rewritten[dst + j] += t[r * n + c] * mat[src + j];
                                }
                            }
                        }
                        Entry::Leaf {
                            offset: 0,
                            origin: map.origin,
                            map: None,
                            mat: rewritten,
                        }
                    }
                    None => Entry::Leaf {
                        offset: 0,
                        origin: map.origin,
                        map: Some(map),
                        mat,
                    },
                };
                entries.push(entry);
                tree.push(Tree::End(entries.len() - 1));
            }
            Node::Split { children, .. } if depth < SHORTCUT_DEPTH => {
                tree.push(Tree::Split(Vec::new()));
                let mut links = Vec::with_capacity(children.len());
                for ch in children {
                    let next = sparse_times_dense(&ch.mat, &acc, k);
                    let inner = compose(&ch.map, &map);
                    let at = self.shortcut_cell(ch.node, depth + 1, next, inner, k, tree, entries);
                    links.push((at, ch.map));
                }
                tree[id] = Tree::Split(links);
            }
            _ => {
                entries.push(Entry::Deep {
                    offset: 0,
                    node,
                    kd: acc.len() / k.max(1),
                    map,
                    mat: acc,
                });
                tree.push(Tree::End(entries.len() - 1));
            }
        }
        id
    }

    /// Appends a patch's cached data for shortcut `id` given its local points `pts`.
    pub fn fill_shortcut(&self, id: u32, pts: &[Point3], out: &mut Vec<Vec3>) {
        for entry in &self.shortcuts[id as usize].entries {
            match entry {
                Entry::Leaf { mat, .. } | Entry::Deep { mat, .. } => {
                    rows_times_points(mat, pts, out)
                }
            }
        }
    }

    /// The entry of shortcut `id` whose sub-patch holds (u, v).
    #[inline]
    fn entry(&self, id: u32, u: f64, v: f64) -> Option<&Entry> {
        let sc = self.shortcuts.get(id as usize)?;
        let e = *sc.grid.get(self.cell(u, v))?;
        sc.entries.get(e as usize)
    }

    /// Where the data of the sub-patch of shortcut `id` holding (u, v) lies in a patch's cached
    /// data: its offset and length.
    #[inline]
    pub fn shortcut_span(&self, id: u32, u: f64, v: f64) -> Option<(usize, usize)> {
        match self.entry(id, u, v)? {
            Entry::Leaf { offset, .. } => Some((*offset, self.power.len())),
            Entry::Deep { offset, kd, .. } => Some((*offset, *kd)),
        }
    }

    /// Limit point and derivatives at (u, v) of a patch with shortcut `id` and cached data
    /// `cache` (from [`Graph::fill_shortcut`]).
    #[inline]
    pub fn eval_shortcut(&self, id: u32, cache: &[Vec3], u: f64, v: f64) -> LimitEval {
        match self.entry(id, u, v) {
            Some(Entry::Leaf {
                offset,
                origin,
                map: None,
                ..
            }) => self.power.eval(
                &cache[*offset..*offset + self.power.len()],
                u - origin[0],
                v - origin[1],
            ),
            Some(Entry::Leaf {
                offset,
                map: Some(map),
                ..
            }) => {
                let (lu, lv) = map.apply(u, v);
                let mut out = self
                    .power
                    .eval(&cache[*offset..*offset + self.power.len()], lu, lv);
                chain(&mut out, map.m);
                out
            }
            Some(Entry::Deep {
                offset,
                node,
                kd,
                map,
                ..
            }) => {
                let (lu, lv) = map.apply(u, v);
                let mut out = self.eval(*node, &cache[*offset..*offset + kd], lu, lv);
                chain(&mut out, map.m);
                out
            }
            None => LimitEval::default(),
        }
    }

    /// [`Graph::point`] through the shortcut `id`.
    pub fn point_shortcut(&self, id: u32, cache: &[Vec3], u: f64, v: f64) -> Point3 {
        match self.entry(id, u, v) {
            Some(Entry::Deep {
                offset,
                node,
                kd,
                map,
                ..
            }) => {
                let (lu, lv) = map.apply(u, v);
                self.point(*node, &cache[*offset..*offset + kd], lu, lv)
            }
            _ => self.eval_shortcut(id, cache, u, v).point,
        }
    }

    /// Weights of the patch's local points for the limit position at (u, v), through the
    /// shortcut `id`.
    pub fn stencil_shortcut(&self, id: u32, u: f64, v: f64, out: &mut Vec<f64>) {
        let k = self.shortcuts.get(id as usize).map_or(0, |s| s.k);
        out.clear();
        out.resize(k, 0.0);
        let add = |out: &mut Vec<f64>, mat: &[f64], weights: &[f64]| {
            for (row, &m) in mat.chunks_exact(k.max(1)).zip(weights) {
                for (o, &w) in out.iter_mut().zip(row) {
                    *o += m * w;
                }
            }
        };
        match self.entry(id, u, v) {
            Some(Entry::Leaf {
                origin, map, mat, ..
            }) => {
                let (lu, lv) = match map {
                    Some(map) => map.apply(u, v),
                    None => (u - origin[0], v - origin[1]),
                };
                let mut vals = [0.0; 16];
                self.power.values(lu, lv, &mut vals);
                add(out, mat, &vals);
            }
            Some(Entry::Deep { node, map, mat, .. }) => {
                let (lu, lv) = map.apply(u, v);
                let mut deep = Vec::new();
                self.stencil(*node, lu, lv, &mut deep);
                add(out, mat, &deep);
            }
            None => {}
        }
    }

    /// The node of a neighbourhood, building it and everything below it if new.
    pub fn add(&mut self, nb: Neighbourhood, patch: usize) -> Result<u32, SubdivError> {
        let id = self.intern(nb, patch)?;
        while let Some((node, topo, kind)) = self.pending.pop() {
            let built = if kind == Kind::DooSabinRoot {
                self.build_doo_sabin_root(&topo, patch)?
            } else {
                self.build(&topo, kind, patch)?
            };
            self.nodes[node as usize] = built;
        }
        Ok(id)
    }

    fn intern(&mut self, nb: Neighbourhood, patch: usize) -> Result<u32, SubdivError> {
        if let Some(&id) = self.index.get(&nb.key) {
            return Ok(id);
        }
        if nb.len() > MAX_LOCAL {
            return Err(SubdivError::NeighbourhoodTooLarge {
                patch,
                points: nb.len(),
                max: MAX_LOCAL,
            });
        }
        let id = self.nodes.len() as u32;
        self.nodes.push(Node::Pending);
        self.index.insert(nb.key.clone(), id);
        let (topo, kind) = nb.topo();
        self.pending.push((id, topo, kind));
        Ok(id)
    }

    /// The child matrix and node of the neighbourhood `nb` of refined points.
    fn child(
        &mut self,
        refined: &super::topo::Refined,
        nb: Neighbourhood,
        k: usize,
        map: ChildMap,
        patch: usize,
    ) -> Result<Child, SubdivError> {
        let kc = nb.len();
        let mut mat = vec![0.0; kc * k];
        for (row, &p) in nb.source.iter().enumerate() {
            let stencil = refined.points[p as usize]
                .as_ref()
                .ok_or(SubdivError::Unevaluable { patch })?;
            for &(j, w) in stencil {
                mat[row * k + j as usize] += w;
            }
        }
        let node = self.intern(nb, patch)?;
        Ok(Child {
            node,
            k: kc,
            mat: Sparse::from_dense(kc, k, &mat),
            map,
        })
    }

    /// The root of a Doo–Sabin patch: the fan of a control vertex, refined once; the patch is
    /// the new point of face 0's corner at the vertex, with the same parameters.
    fn build_doo_sabin_root(&mut self, topo: &Topo, patch: usize) -> Result<Node, SubdivError> {
        let refined = super::doo_sabin::refine(topo);
        // Face 0 starts at local vertex 0, so its corner point is new point 0, and the face
        // made from face 0 is new face 0.
        let nb = vertex_neighbourhood(&refined.topo, 0, 0, Kind::Vertex);
        let identity = ChildMap::new([0.0, 0.0], [1.0, 0.0], [0.0, 1.0]);
        let child = self.child(&refined, nb, topo.nv, identity, patch)?;
        Ok(Node::Split {
            k: topo.nv,
            children: vec![child],
            corner_masks: Vec::new(),
        })
    }

    fn build(&mut self, topo: &Topo, kind: Kind, patch: usize) -> Result<Node, SubdivError> {
        let k = topo.nv;
        if let Some(gather) = regular_gather(topo, self.scheme) {
            let rows = gather.len() / k.max(1);
            return Ok(Node::Regular {
                k,
                gather: Sparse::from_dense(rows, k, &gather),
            });
        }
        let refined = super::step::refine_step(topo, self.scheme);
        let maps = child_maps(self.scheme);
        let mut children = Vec::with_capacity(maps.len());
        for (ci, map) in maps.into_iter().enumerate() {
            let nb = if kind == Kind::Vertex {
                // Child ci is the new point of face ci's corner at vertex 0; its faces start
                // with the face made from face ci.
                let p = p_of(topo, ci, topo.face_starts[ci]);
                vertex_neighbourhood(&refined.topo, p, ci as u32, Kind::Vertex)
            } else {
                neighbourhood(&refined.topo, ci as u32)
            };
            children.push(self.child(&refined, nb, k, map, patch)?);
        }
        if kind == Kind::Vertex {
            // The limit at a patch corner is the centroid of the face there (Doo–Sabin keeps
            // face centroids).
            let corner_masks = (0..4u32)
                .map(|q| {
                    let f = topo.face(q);
                    f.iter()
                        .map(|&i| (i as u16, 1.0 / f.len() as f64))
                        .collect()
                })
                .collect();
            return Ok(Node::Split {
                k,
                children,
                corner_masks,
            });
        }
        let corner_masks = topo
            .face(0)
            .iter()
            .map(|&c| {
                let s: Stencil = topo
                    .limit_stencil(self.scheme, c)
                    .ok_or(SubdivError::Unevaluable { patch })?;
                Ok(s.into_iter().map(|(i, w)| (i as u16, w)).collect())
            })
            .collect::<Result<Vec<_>, SubdivError>>()?;
        Ok(Node::Split {
            k,
            children,
            corner_masks,
        })
    }

    /// For a regular node whose gather only picks points: the picked local indices in basis
    /// order.
    pub fn direct_picks(&self, node: u32) -> Option<Vec<u32>> {
        let Node::Regular { gather, .. } = &self.nodes[node as usize] else {
            return None;
        };
        (0..gather.rows())
            .map(|r| {
                let mut nz = gather.row(r);
                match (nz.next(), nz.next()) {
                    (Some((j, 1.0)), None) => Some(j as u32),
                    _ => None,
                }
            })
            .collect()
    }

    /// Follows the children that hold (u, v) down to a regular node.
    fn descend(&self, root: u32, u: f64, v: f64) -> Path {
        let mut path = Path {
            steps: [0; MAX_DEPTH + EXTRA_DEPTH],
            len: 0,
            leaf: root,
            u,
            v,
            g: [[1.0, 0.0], [0.0, 1.0]],
            cap: None,
        };
        let mut node = root;
        loop {
            match &self.nodes[node as usize] {
                Node::Split { children, .. } => {
                    if path.len == MAX_DEPTH && path.cap.is_none() {
                        path.cap = Some((path.len, nearest_corner(self.scheme, path.u, path.v)));
                        (path.u, path.v) = domain_centre(self.scheme);
                    }
                    if path.len == path.steps.len() {
                        path.leaf = node;
                        return path;
                    }
                    let ci = if children.len() == 1 {
                        0
                    } else {
                        pick_child(self.scheme, path.u, path.v)
                    };
                    let ch = &children[ci];
                    (path.u, path.v) = ch.map.apply(path.u, path.v);
                    path.g = mul2(ch.map.m, path.g);
                    path.steps[path.len] = ci as u8;
                    path.len += 1;
                    node = ch.node;
                }
                _ => {
                    path.leaf = node;
                    return path;
                }
            }
        }
    }

    /// Limit point at (u, v) of the patch `root` whose local points are `pts`. At a corner of
    /// the domain it is the corner's limit mask: [`Graph::eval`] would subdivide towards an
    /// extraordinary corner [`MAX_DEPTH`] + [`EXTRA_DEPTH`] times for derivatives a point does
    /// not need, and the surface → data measure samples every patch's first corner.
    pub fn point(&self, root: u32, pts: &[Point3], u: f64, v: f64) -> Point3 {
        if let Node::Split { corner_masks, .. } = &self.nodes[root as usize] {
            let corner = corner_params(self.scheme)
                .iter()
                .position(|c| c[0] == u && c[1] == v);
            if let Some(mask) = corner.and_then(|c| corner_masks.get(c)) {
                if let Some(p) = mask_point(mask, pts) {
                    return p;
                }
            }
        }
        self.eval(root, pts, u, v).point
    }

    /// Limit point and derivatives at (u, v) of the patch `root` whose local points are `pts`.
    pub fn eval(&self, root: u32, pts: &[Point3], u: f64, v: f64) -> LimitEval {
        let path = self.descend(root, u, v);
        let mut a = [Vec3::ZERO; MAX_LOCAL];
        let mut b = [Vec3::ZERO; MAX_LOCAL];
        let mut k = pts.len().min(MAX_LOCAL);
        // Points are kept relative to a moving origin (the first local point) so that deep
        // levels, whose points differ by 2^-depth, keep full relative precision and the
        // derivatives (scaled back up by 2^depth) do not suffer cancellation.
        let mut offset = pts.first().copied().unwrap_or_default();
        for (q, &p) in a.iter_mut().zip(&pts[..k]) {
            *q = p - offset;
        }
        let mut node = root;
        let mut capped = None;
        for d in 0..path.len {
            let Node::Split {
                children,
                corner_masks,
                ..
            } = &self.nodes[node as usize]
            else {
                break;
            };
            if let Some((cd, corner)) = path.cap {
                if cd == d {
                    let p: Vec3 = corner_masks[corner]
                        .iter()
                        .map(|&(i, w)| a[i as usize] * w)
                        .sum();
                    capped = Some(offset + p);
                }
            }
            let ch = &children[path.steps[d] as usize];
            ch.mat.apply(&a[..k], &mut b[..ch.k]);
            k = ch.k;
            node = ch.node;
            let c = b[0];
            offset += c;
            for (q, &p) in a[..k].iter_mut().zip(&b[..k]) {
                *q = p - c;
            }
        }
        let mut out = match &self.nodes[path.leaf as usize] {
            Node::Regular { gather, .. } => self.eval_regular(gather, &a[..k], path.u, path.v),
            _ => LimitEval {
                point: a[..k].iter().sum::<Vec3>() / k.max(1) as f64,
                ..LimitEval::default()
            },
        };
        out.point += offset;
        chain(&mut out, path.g);
        if let Some(p) = capped {
            out.point = p;
        }
        out
    }

    fn eval_regular(&self, gather: &Sparse, pts: &[Point3], u: f64, v: f64) -> LimitEval {
        let mut cp = [Vec3::ZERO; 16];
        gather.apply(pts, &mut cp);
        let mut coeffs = Vec::with_capacity(self.power.len());
        self.power
            .coefficients(&cp[..self.power.points], &mut coeffs);
        self.power.eval(&coeffs, u, v)
    }

    /// Weights of the patch's local points for the limit position at (u, v).
    pub fn stencil(&self, root: u32, u: f64, v: f64, out: &mut Vec<f64>) {
        let path = self.descend(root, u, v);
        let mut nodes = Vec::with_capacity(path.len + 1);
        let mut node = root;
        nodes.push(node);
        for d in 0..path.len {
            let Node::Split { children, .. } = &self.nodes[node as usize] else {
                break;
            };
            node = children[path.steps[d] as usize].node;
            nodes.push(node);
        }
        let mut w: Vec<f64> = match &self.nodes[path.leaf as usize] {
            Node::Regular { k, gather } => {
                let mut basis = [0.0; 16];
                self.power.point_weights(path.u, path.v, &mut basis);
                let mut w = vec![0.0; *k];
                gather.pull_back(&basis[..self.power.points], &mut w);
                w
            }
            Node::Split { k, .. } => vec![1.0 / (*k).max(1) as f64; *k],
            Node::Pending => Vec::new(),
        };
        for d in (0..path.len).rev() {
            let Node::Split {
                k,
                children,
                corner_masks,
            } = &self.nodes[nodes[d] as usize]
            else {
                continue;
            };
            let mut up = vec![0.0; *k];
            match path.cap {
                Some((cd, corner)) if cd == d => {
                    for &(i, m) in &corner_masks[corner] {
                        up[i as usize] += m;
                    }
                }
                _ => children[path.steps[d] as usize].mat.pull_back(&w, &mut up),
            }
            w = up;
        }
        out.clear();
        out.extend(w);
    }
}

/// A descent through the graph: which child at each level, and the leaf's parameters.
struct Path {
    steps: [u8; MAX_DEPTH + EXTRA_DEPTH],
    len: usize,
    leaf: u32,
    u: f64,
    v: f64,
    /// Jacobian of leaf parameters with respect to patch parameters.
    g: [[f64; 2]; 2],
    /// Depth and corner where the parameter was taken to be at a corner's limit point.
    cap: Option<(usize, usize)>,
}

fn nearest_corner(scheme: Scheme, u: f64, v: f64) -> usize {
    let c = corner_params(scheme);
    (0..c.len())
        .min_by(|&i, &j| {
            let d = |k: usize| (c[k][0] - u).powi(2) + (c[k][1] - v).powi(2);
            d(i).total_cmp(&d(j))
        })
        .unwrap_or(0)
}

/// The point a limit `mask` makes of `pts`, relative to the first (as [`Graph::eval`] keeps
/// them); `None` when the mask reaches past `pts`.
fn mask_point(mask: &[(u16, f64)], pts: &[Point3]) -> Option<Point3> {
    let origin = *pts.first()?;
    let mut sum = Vec3::ZERO;
    for &(i, w) in mask {
        sum += (*pts.get(i as usize)? - origin) * w;
    }
    Some(origin + sum)
}

fn mul2(a: [[f64; 2]; 2], b: [[f64; 2]; 2]) -> [[f64; 2]; 2] {
    let mut c = [[0.0; 2]; 2];
    for i in 0..2 {
        for j in 0..2 {
            c[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j];
        }
    }
    c
}

/// Turns derivatives with respect to leaf parameters into ones with respect to the patch's,
/// where leaf = g · patch + const.
pub(crate) fn chain(e: &mut LimitEval, g: [[f64; 2]; 2]) {
    let (du, dv) = (e.du, e.dv);
    e.du = du * g[0][0] + dv * g[1][0];
    e.dv = du * g[0][1] + dv * g[1][1];
    let h = [[e.duu, e.duv], [e.duv, e.dvv]];
    let second = |a: usize, b: usize| -> Vec3 {
        let mut s = Vec3::ZERO;
        for i in 0..2 {
            for j in 0..2 {
                s += h[i][j] * (g[i][a] * g[j][b]);
            }
        }
        s
    };
    e.duu = second(0, 0);
    e.duv = second(0, 1);
    e.dvv = second(1, 1);
}

/// The new point of local face `q`'s corner at vertex 0: Doo–Sabin numbers new points by face
/// corner, and local faces of a vertex neighbourhood start at vertex 0 (face 0) or not.
fn p_of(topo: &Topo, q: usize, first: u32) -> u32 {
    first + topo.corner_index(q as u32, 0).unwrap_or(0) as u32
}
