//! Sharp features of a triangle mesh: crease edges, the lines they form, the corners where three
//! or more lines meet and the dart ends where a line stops inside a face region.
//!
//! A crease is where the surface turns by more than an angle across an edge. The two triangles
//! at an edge are a poor witness on a scan: noise of a fraction of the edge length turns
//! neighbouring facets by several degrees, and a long thin triangle can fold by more than the
//! crease threshold on a smooth part. So the face normals are first smoothed by a few rounds of
//! bilateral normal filtering (Zheng et al., "Bilateral normal filtering for mesh denoising",
//! 2011): each normal becomes the area-, distance- and similarity-weighted mean of the normals
//! of the faces around it. The similarity weight keeps a crease — normals on the other side of
//! it differ too much to count — while noise on either side averages out. The dihedral angle
//! is then taken between the filtered normals.
//!
//! Edges turning by more than the angle are crease edges; edges turning by more than
//! [`FeatureOptions::WEAK_FRACTION`] of it are kept where they continue a crease (hysteresis,
//! as in Canny's edge detector), which bridges the gaps noise opens in a line. Short spurs and
//! short isolated lines are removed, dart ends a few edges apart are joined, and what is left is
//! traced into lines between nodes (corners and ends) or closed loops.
//!
//! ```
//! use geofit::mesh::{detect_features, FeatureOptions, PolyMesh};
//! use geofit::geom::Point3;
//!
//! // A unit cube, two triangles per side: 12 crease edges, 8 corners.
//! let p = |x: f64, y: f64, z: f64| Point3::new(x, y, z);
//! let positions = vec![
//!     p(0., 0., 0.), p(1., 0., 0.), p(1., 1., 0.), p(0., 1., 0.),
//!     p(0., 0., 1.), p(1., 0., 1.), p(1., 1., 1.), p(0., 1., 1.),
//! ];
//! let quads = [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]];
//! let faces: Vec<[u32; 3]> = quads.iter().flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]).collect();
//! let mesh = PolyMesh::try_new(positions, faces)?;
//! let features = detect_features(&mesh, &FeatureOptions::default())?;
//! assert_eq!(features.edges.len(), 12);
//! assert_eq!(features.corners.len(), 8);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use super::{MeshError, PolyMesh};
use crate::geom::{Point3, Vec3};
use serde::Serialize;
use std::collections::{HashMap, VecDeque};

/// How [`detect_features`] decides what is sharp.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FeatureOptions {
    /// Dihedral angle (degrees, between filtered normals) above which an edge is a crease.
    pub angle_deg: f64,
    /// Rounds of bilateral normal filtering before the angles are taken (0: raw normals).
    pub smoothing: usize,
    /// Lines and spurs of fewer edges than this are dropped as noise.
    pub min_line_edges: usize,
}

impl FeatureOptions {
    /// The default crease angle, degrees (chosen on fandisk, rocker-arm, the bunny and the
    /// corpus: see docs/features.md).
    pub const DEFAULT_ANGLE_DEG: f64 = 40.0;
    /// Weak edges (above this fraction of the angle) continue a crease line.
    pub const WEAK_FRACTION: f64 = 0.6;
    /// The width of the similarity weight of the normal filter: normals further apart than
    /// about this (radians, chord length) hardly average.
    const SIGMA_NORMAL: f64 = 0.35;
    /// A line between two dart ends shorter than this fraction of the bounding-box diagonal is
    /// dropped: facets of a coarse or noisy mesh that turn sharply form short chains; a
    /// crease of a part runs a good way.
    const MIN_LINE_FRACTION: f64 = 0.02;
    /// A line whose direction turns by more than this on average (radians, between chords of
    /// `TURN_STRIDE` vertices) is dropped: noise meanders, a crease of a part runs smooth.
    const MAX_MEAN_TURN: f64 = 0.5;
    /// Vertices between the chords whose angle `MAX_MEAN_TURN` bounds.
    const TURN_STRIDE: usize = 3;
    /// Dart ends at most this many mesh edges apart are joined.
    const BRIDGE_EDGES: usize = 2;

    /// Checks the options.
    pub fn validate(&self) -> Result<(), MeshError> {
        if !(self.angle_deg.is_finite() && self.angle_deg > 0.0 && self.angle_deg < 180.0) {
            return Err(MeshError::InvalidOption {
                name: "crease angle",
                reason: format!("{} is not in (0, 180) degrees", self.angle_deg),
            });
        }
        if self.smoothing > 100 {
            return Err(MeshError::InvalidOption {
                name: "crease smoothing",
                reason: format!("{} rounds; at most 100", self.smoothing),
            });
        }
        Ok(())
    }
}

impl Default for FeatureOptions {
    fn default() -> Self {
        FeatureOptions {
            angle_deg: Self::DEFAULT_ANGLE_DEG,
            smoothing: 3,
            min_line_edges: 3,
        }
    }
}

/// One crease line: a chain of crease edges between two nodes, or a closed loop.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FeatureLine {
    /// Its vertices in order (a closed loop does not repeat the first).
    pub vertices: Vec<u32>,
    /// Whether it is a closed loop.
    pub closed: bool,
    /// Its length in model units.
    pub length: f64,
}

/// What [`detect_features`] found.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Features {
    /// The crease edges (vertex pairs, smaller index first, sorted).
    pub edges: Vec<[u32; 2]>,
    /// The crease lines the edges form.
    pub lines: Vec<FeatureLine>,
    /// Vertices where three or more crease edges meet.
    pub corners: Vec<u32>,
    /// Vertices where a crease line ends inside the surface (one crease edge).
    pub darts: Vec<u32>,
    /// Total length of the crease edges, model units.
    pub total_length: f64,
}

impl Features {
    /// A one-line account for people: "12 crease edges in 3 lines (4.00 long), 8 corners, 0 dart ends".
    pub fn summary(&self) -> String {
        format!(
            "{} crease edges in {} lines ({:.4} long), {} corners, {} dart ends",
            self.edges.len(),
            self.lines.len(),
            self.total_length,
            self.corners.len(),
            self.darts.len()
        )
    }
}

/// Finds the crease edges, lines, corners and dart ends of `mesh`'s triangles (polygons are
/// triangulated; points in no face are ignored). Faces should be consistently oriented, as
/// [`crate::mesh::repair`] leaves them; an edge whose two faces disagree is measured with one
/// normal flipped. Boundary edges and edges of three or more faces are never creases.
pub fn detect_features(mesh: &PolyMesh, options: &FeatureOptions) -> Result<Features, MeshError> {
    options.validate()?;
    let positions = mesh.positions();
    let triangles = mesh.triangles();
    let raw = face_normals(positions, &triangles);
    let normals = filter_normals(positions, &triangles, &raw, options.smoothing);
    let edges = interior_edges(&triangles);
    let threshold = options.angle_deg.to_radians();
    let weak = threshold * FeatureOptions::WEAK_FRACTION;
    let mut strong = Vec::new();
    let mut candidates = Vec::new();
    for e in &edges {
        let (n1, n2) = (normals[e.faces[0] as usize], normals[e.faces[1] as usize]);
        let n2 = if e.agree { n2 } else { -n2 };
        let angle = libm::acos(n1.dot(n2).clamp(-1.0, 1.0));
        if angle > weak {
            candidates.push(e.ends);
            strong.push(angle > threshold);
        }
    }
    let mut graph = CreaseGraph::new(positions.len());
    for ends in hysteresis(&candidates, &strong, positions.len()) {
        graph.insert(ends);
    }
    graph.bridge_darts(&triangles, positions.len());
    let diagonal = mesh.bbox().map_or(0.0, |b| b.diagonal());
    loop {
        graph.prune(options.min_line_edges);
        if !graph.drop_ragged_lines(positions, diagonal * FeatureOptions::MIN_LINE_FRACTION) {
            break;
        }
    }
    Ok(graph.features(positions))
}

/// Unit normal of every triangle (zero for a degenerate one).
fn face_normals(positions: &[Point3], triangles: &[[u32; 3]]) -> Vec<Vec3> {
    triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| positions[i as usize]);
            (b - a).cross(c - a).normalize_or_zero()
        })
        .collect()
}

/// `rounds` of bilateral filtering of the face normals over the faces sharing a vertex.
fn filter_normals(
    positions: &[Point3],
    triangles: &[[u32; 3]],
    raw: &[Vec3],
    rounds: usize,
) -> Vec<Vec3> {
    if rounds == 0 || triangles.is_empty() {
        return raw.to_vec();
    }
    let (starts, faces_of) = vertex_faces(positions.len(), triangles);
    let centroid: Vec<Point3> = triangles
        .iter()
        .map(|t| t.iter().map(|&i| positions[i as usize]).sum::<Point3>() / 3.0)
        .collect();
    let area: Vec<f64> = triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| positions[i as usize]);
            0.5 * (b - a).cross(c - a).length()
        })
        .collect();
    let sigma_c = mean_neighbour_distance(triangles, &centroid, &starts, &faces_of);
    let inv_c = if sigma_c > 0.0 {
        1.0 / (2.0 * sigma_c * sigma_c)
    } else {
        0.0
    };
    let inv_n = 1.0 / (2.0 * FeatureOptions::SIGMA_NORMAL * FeatureOptions::SIGMA_NORMAL);
    let mut normals = raw.to_vec();
    let mut seen = vec![u32::MAX; triangles.len()];
    for _ in 0..rounds {
        let mut next = vec![Vec3::ZERO; triangles.len()];
        for (i, t) in triangles.iter().enumerate() {
            let ni = normals[i];
            let mut sum = Vec3::ZERO;
            for &v in t {
                let v = v as usize;
                for &j in &faces_of[starts[v]..starts[v + 1]] {
                    let j = j as usize;
                    if seen[j] == i as u32 {
                        continue;
                    }
                    seen[j] = i as u32;
                    let dc = centroid[i].distance_squared(centroid[j]);
                    let dn = ni.distance_squared(normals[j]);
                    sum += normals[j] * (area[j] * libm::exp(-dc * inv_c - dn * inv_n));
                }
            }
            next[i] = sum.try_normalize().unwrap_or(ni);
        }
        seen.fill(u32::MAX);
        normals = next;
    }
    normals
}

/// The faces of every vertex, as a compressed list: `faces[starts[v]..starts[v + 1]]`.
pub(crate) fn vertex_faces(num_vertices: usize, triangles: &[[u32; 3]]) -> (Vec<usize>, Vec<u32>) {
    let mut starts = vec![0usize; num_vertices + 1];
    for t in triangles {
        for &v in t {
            starts[v as usize + 1] += 1;
        }
    }
    for v in 0..num_vertices {
        starts[v + 1] += starts[v];
    }
    let mut fill = starts.clone();
    let mut faces = vec![0u32; starts[num_vertices]];
    for (f, t) in triangles.iter().enumerate() {
        for &v in t {
            faces[fill[v as usize]] = f as u32;
            fill[v as usize] += 1;
        }
    }
    (starts, faces)
}

/// Mean distance between the centroids of faces sharing a vertex: the filter's spatial scale.
fn mean_neighbour_distance(
    triangles: &[[u32; 3]],
    centroid: &[Point3],
    starts: &[usize],
    faces_of: &[u32],
) -> f64 {
    let (mut sum, mut count) = (0.0, 0usize);
    for (i, t) in triangles.iter().enumerate() {
        let v = t[0] as usize;
        for &j in &faces_of[starts[v]..starts[v + 1]] {
            if j as usize != i {
                sum += centroid[i].distance(centroid[j as usize]);
                count += 1;
            }
        }
    }
    if count == 0 {
        0.0
    } else {
        sum / count as f64
    }
}

/// An edge with exactly two faces.
struct InteriorEdge {
    ends: [u32; 2],
    faces: [u32; 2],
    /// Whether the two faces run the edge in opposite directions (consistent orientation).
    agree: bool,
}

/// The edges of exactly two faces, in a deterministic order (sorted by their ends).
fn interior_edges(triangles: &[[u32; 3]]) -> Vec<InteriorEdge> {
    let mut uses: HashMap<[u32; 2], Vec<(u32, bool)>> = HashMap::new();
    for (f, t) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if a == b {
                continue;
            }
            let key = [a.min(b), a.max(b)];
            uses.entry(key).or_default().push((f as u32, a < b));
        }
    }
    let mut edges: Vec<InteriorEdge> = uses
        .into_iter()
        .filter_map(|(ends, faces)| match faces.as_slice() {
            [(f1, d1), (f2, d2)] => Some(InteriorEdge {
                ends,
                faces: [*f1, *f2],
                agree: d1 != d2,
            }),
            _ => None,
        })
        .collect();
    edges.sort_unstable_by_key(|e| e.ends);
    edges
}

/// The candidate edges that are strong, or weak and connected through weak edges to a strong
/// one.
fn hysteresis(candidates: &[[u32; 2]], strong: &[bool], num_vertices: usize) -> Vec<[u32; 2]> {
    let mut at: Vec<Vec<usize>> = vec![Vec::new(); num_vertices];
    for (k, e) in candidates.iter().enumerate() {
        at[e[0] as usize].push(k);
        at[e[1] as usize].push(k);
    }
    let mut keep = strong.to_vec();
    let mut queue: VecDeque<usize> = (0..candidates.len()).filter(|&k| strong[k]).collect();
    while let Some(k) = queue.pop_front() {
        for &v in &candidates[k] {
            for &k2 in &at[v as usize] {
                if !keep[k2] {
                    keep[k2] = true;
                    queue.push_back(k2);
                }
            }
        }
    }
    candidates
        .iter()
        .zip(keep)
        .filter_map(|(e, k)| k.then_some(*e))
        .collect()
}

/// The crease edges as a graph on the mesh's vertices.
struct CreaseGraph {
    adjacent: Vec<Vec<u32>>,
}

impl CreaseGraph {
    fn new(num_vertices: usize) -> CreaseGraph {
        CreaseGraph {
            adjacent: vec![Vec::new(); num_vertices],
        }
    }

    fn insert(&mut self, [a, b]: [u32; 2]) {
        if !self.adjacent[a as usize].contains(&b) {
            self.adjacent[a as usize].push(b);
            self.adjacent[b as usize].push(a);
        }
    }

    fn remove(&mut self, a: u32, b: u32) {
        self.adjacent[a as usize].retain(|&x| x != b);
        self.adjacent[b as usize].retain(|&x| x != a);
    }

    fn degree(&self, v: u32) -> usize {
        self.adjacent[v as usize].len()
    }

    /// Joins every dart end to the nearest other crease vertex at most `BRIDGE_EDGES` mesh
    /// edges away that is not on its own line's last few edges (a gap noise opened in a line).
    fn bridge_darts(&mut self, triangles: &[[u32; 3]], num_vertices: usize) {
        let darts: Vec<u32> = (0..num_vertices as u32)
            .filter(|&v| self.degree(v) == 1)
            .collect();
        if darts.is_empty() {
            return;
        }
        let mesh_adjacent = mesh_neighbours(triangles, num_vertices);
        for d in darts {
            if self.degree(d) != 1 {
                continue;
            }
            let own = self.line_near(d, FeatureOptions::BRIDGE_EDGES + 1);
            if let Some(path) = self.path_to_crease(d, &own, &mesh_adjacent) {
                for w in path.windows(2) {
                    self.insert([w[0], w[1]]);
                }
            }
        }
    }

    /// The vertices on the crease line from `v` within `steps` edges (to exclude them as targets).
    fn line_near(&self, v: u32, steps: usize) -> Vec<u32> {
        let mut out = vec![v];
        let (mut prev, mut cur) = (u32::MAX, v);
        for _ in 0..steps {
            let Some(&next) = self.adjacent[cur as usize].iter().find(|&&x| x != prev) else {
                break;
            };
            out.push(next);
            (prev, cur) = (cur, next);
        }
        out
    }

    /// The shortest mesh path (at most `BRIDGE_EDGES` edges) from `from` to a crease vertex not
    /// in `own`, breadth first in vertex order (deterministic).
    fn path_to_crease(&self, from: u32, own: &[u32], mesh: &[Vec<u32>]) -> Option<Vec<u32>> {
        let mut frontier = vec![vec![from]];
        for _ in 0..FeatureOptions::BRIDGE_EDGES {
            let mut next = Vec::new();
            for path in &frontier {
                let last = *path.last().expect("paths are not empty");
                for &n in &mesh[last as usize] {
                    if path.contains(&n) || own.contains(&n) {
                        continue;
                    }
                    let mut p = path.clone();
                    p.push(n);
                    if self.degree(n) > 0 {
                        return Some(p);
                    }
                    next.push(p);
                }
            }
            frontier = next;
        }
        None
    }

    /// Removes spurs (a chain from a dart end to a corner) and isolated open lines of fewer
    /// than `min_edges` edges, until none is left.
    fn prune(&mut self, min_edges: usize) {
        loop {
            let mut removed = false;
            for v in 0..self.adjacent.len() as u32 {
                if self.degree(v) != 1 {
                    continue;
                }
                let chain = self.chain_from(v);
                if chain.len() - 1 < min_edges {
                    for w in chain.windows(2) {
                        self.remove(w[0], w[1]);
                    }
                    removed = true;
                }
            }
            if !removed {
                return;
            }
        }
    }

    /// Removes the lines that zig-zag (mean turn per vertex above `MAX_MEAN_TURN`) and the
    /// open lines between two dart ends shorter than `min_length`; whether any was removed.
    fn drop_ragged_lines(&mut self, positions: &[Point3], min_length: f64) -> bool {
        let mut removed = false;
        for line in self.lines(positions) {
            let isolated = !line.closed
                && line.vertices.first().is_some_and(|&v| self.degree(v) == 1)
                && line.vertices.last().is_some_and(|&v| self.degree(v) == 1);
            let short = isolated && line.length < min_length;
            if short || mean_turn(positions, &line) > FeatureOptions::MAX_MEAN_TURN {
                let v = &line.vertices;
                for w in v.windows(2) {
                    self.remove(w[0], w[1]);
                }
                if line.closed {
                    if let (Some(&a), Some(&b)) = (v.first(), v.last()) {
                        self.remove(a, b);
                    }
                }
                removed = true;
            }
        }
        removed
    }

    /// The chain of vertices from the dart end `v` to the next vertex of degree other than 2.
    fn chain_from(&self, v: u32) -> Vec<u32> {
        let mut chain = vec![v];
        let (mut prev, mut cur) = (u32::MAX, v);
        loop {
            let Some(&next) = self.adjacent[cur as usize].iter().find(|&&x| x != prev) else {
                return chain;
            };
            chain.push(next);
            if self.degree(next) != 2 || next == v {
                return chain;
            }
            (prev, cur) = (cur, next);
        }
    }

    /// Edges, lines, corners and dart ends of the graph.
    fn features(&self, positions: &[Point3]) -> Features {
        let mut f = Features::default();
        for (a, adj) in self.adjacent.iter().enumerate() {
            let a = a as u32;
            for &b in adj {
                if a < b {
                    f.edges.push([a, b]);
                    f.total_length += positions[a as usize].distance(positions[b as usize]);
                }
            }
            match adj.len() {
                1 => f.darts.push(a),
                n if n >= 3 => f.corners.push(a),
                _ => {}
            }
        }
        f.edges.sort_unstable();
        f.lines = self.lines(positions);
        f
    }

    /// Traces the lines: from every node (degree ≠ 2) along each of its edges to the next
    /// node, then the closed loops left (every vertex of degree 2).
    fn lines(&self, positions: &[Point3]) -> Vec<FeatureLine> {
        let mut used: HashMap<[u32; 2], ()> = HashMap::new();
        let mut lines = Vec::new();
        let key = |a: u32, b: u32| [a.min(b), a.max(b)];
        let starts = (0..self.adjacent.len() as u32)
            .filter(|&v| self.degree(v) != 2)
            .chain((0..self.adjacent.len() as u32).filter(|&v| self.degree(v) == 2));
        for start in starts {
            for &first in &self.adjacent[start as usize] {
                if used.contains_key(&key(start, first)) {
                    continue;
                }
                let mut vertices = vec![start];
                let (mut prev, mut cur) = (start, first);
                used.insert(key(prev, cur), ());
                let closed = loop {
                    if cur == start {
                        break true;
                    }
                    vertices.push(cur);
                    if self.degree(cur) != 2 {
                        break false;
                    }
                    let next = *self.adjacent[cur as usize]
                        .iter()
                        .find(|&&x| x != prev)
                        .expect("a vertex of degree 2 has another neighbour");
                    used.insert(key(cur, next), ());
                    (prev, cur) = (cur, next);
                };
                let length = polyline_length(positions, &vertices, closed);
                lines.push(FeatureLine {
                    vertices,
                    closed,
                    length,
                });
            }
        }
        lines
    }
}

/// Mean angle (radians) by which `line` turns per vertex, measured between chords
/// `TURN_STRIDE` vertices long (a line with fewer vertices: between its edges). The chords make
/// a straight crease that zig-zags over an irregular triangulation count as straight, while a
/// chain that meanders through noise still turns.
fn mean_turn(positions: &[Point3], line: &FeatureLine) -> f64 {
    let mut v: Vec<Point3> = line
        .vertices
        .iter()
        .map(|&i| positions[i as usize])
        .collect();
    let stride = if v.len() > 2 * FeatureOptions::TURN_STRIDE {
        FeatureOptions::TURN_STRIDE
    } else {
        1
    };
    if line.closed {
        v.extend_from_within(..(2 * stride).min(v.len()));
    }
    let turns: Vec<f64> = (stride..v.len().saturating_sub(stride))
        .filter_map(|i| {
            let d1 = (v[i] - v[i - stride]).try_normalize()?;
            let d2 = (v[i + stride] - v[i]).try_normalize()?;
            Some(libm::acos(d1.dot(d2).clamp(-1.0, 1.0)))
        })
        .collect();
    if turns.is_empty() {
        0.0
    } else {
        turns.iter().sum::<f64>() / turns.len() as f64
    }
}

/// Length of the polyline through `vertices` (back to the first when `closed`).
fn polyline_length(positions: &[Point3], vertices: &[u32], closed: bool) -> f64 {
    let p = |i: u32| positions[i as usize];
    let open: f64 = vertices.windows(2).map(|w| p(w[0]).distance(p(w[1]))).sum();
    match (closed, vertices.first(), vertices.last()) {
        (true, Some(&a), Some(&b)) => open + p(a).distance(p(b)),
        _ => open,
    }
}

/// The mesh's vertex neighbours (sorted, deduplicated).
fn mesh_neighbours(triangles: &[[u32; 3]], num_vertices: usize) -> Vec<Vec<u32>> {
    let mut adjacent = vec![Vec::new(); num_vertices];
    for t in triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if a != b {
                adjacent[a as usize].push(b);
                adjacent[b as usize].push(a);
            }
        }
    }
    for adj in &mut adjacent {
        adj.sort_unstable();
        adj.dedup();
    }
    adjacent
}
