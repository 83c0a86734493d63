//! QEM simplification: the initial control mesh of a fit (Garland & Heckbert 1997).
//!
//! Edges are collapsed cheapest first, where the cost of a collapse is the quadric error — the
//! sum of squared distances of the new vertex to the planes of the faces its two ends have
//! absorbed — at the position that minimises it. On top of the textbook method, every collapse
//! must keep the surface a manifold of unchanged topology (no closed holes, no pinched
//! vertices, no duplicate faces), may not rotate a face normal by more than a set angle (no
//! fold-overs) and may not create needles; open boundaries are held in place by penalty planes
//! perpendicular to their faces, so the holes of a scan keep their outline.
//!
//! ```
//! use geofit::geom::Point3;
//! use geofit::mesh::{simplify, PolyMesh};
//!
//! // A 5×5 grid of a curved sheet, simplified to 9 vertices.
//! let n = 5u32;
//! let pos = (0..n * n)
//!     .map(|k| {
//!         let (x, y) = ((k % n) as f64, (k / n) as f64);
//!         Point3::new(x, y, 0.1 * x * x)
//!     })
//!     .collect();
//! let mut faces = Vec::new();
//! for j in 0..n - 1 {
//!     for i in 0..n - 1 {
//!         let a = j * n + i;
//!         faces.push([a, a + 1, a + n + 1]);
//!         faces.push([a, a + n + 1, a + n]);
//!     }
//! }
//! let mesh = PolyMesh::try_new(pos, faces)?;
//! let coarse = simplify(&mesh, 9)?;
//! assert_eq!(coarse.num_vertices(), 9);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod collapse;
mod deviation;
mod error;
mod incidence;
mod locality;
mod quadric;
mod queue;

pub use deviation::{deviation, Deviation};
pub use error::SimplifyError;

use crate::geom::Point3;
use crate::mesh::PolyMesh;
use collapse::{Limits, Work};
use incidence::{Incidence, InputEdge};
use locality::Numbering;
use quadric::Quadric;
use queue::{Candidate, Queue};

/// Settings of [`simplify_with`]. Build with `SimplifyOptions::default()` and the `with_*`
/// setters.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct SimplifyOptions {
    /// Weight of the boundary penalty planes relative to the face planes (which are weighted by
    /// face area): the penalty plane of a boundary edge is weighted by this times the edge's
    /// squared length, so 10 (the default) makes it about twenty times as stiff as the face
    /// beside it. Open boundaries keep their outline; much larger values pin boundary vertices
    /// in place and spend the vertex budget on the outline (on the bunny → 612, 1000 raises the
    /// rms deviation by a quarter and the max by 40 %); 0 lets boundaries move freely.
    pub boundary_weight: f64,
    /// Largest rotation of any face normal, in degrees, that one collapse may cause. Default 60.
    /// Collapses beyond it would fold the surface over (or come close to it).
    pub max_normal_change_deg: f64,
    /// Smallest triangle quality (4√3·area / Σ edge², 1 = equilateral) a collapse may create,
    /// unless its neighbourhood already had a worse triangle. Default 0.1: no needles.
    pub min_triangle_quality: f64,
}

impl Default for SimplifyOptions {
    fn default() -> SimplifyOptions {
        SimplifyOptions {
            boundary_weight: 10.0,
            max_normal_change_deg: 60.0,
            min_triangle_quality: 0.1,
        }
    }
}

impl SimplifyOptions {
    /// Sets [`SimplifyOptions::boundary_weight`].
    pub fn with_boundary_weight(mut self, weight: f64) -> SimplifyOptions {
        self.boundary_weight = weight;
        self
    }

    /// Sets [`SimplifyOptions::max_normal_change_deg`].
    pub fn with_max_normal_change_deg(mut self, degrees: f64) -> SimplifyOptions {
        self.max_normal_change_deg = degrees;
        self
    }

    /// Sets [`SimplifyOptions::min_triangle_quality`].
    pub fn with_min_triangle_quality(mut self, quality: f64) -> SimplifyOptions {
        self.min_triangle_quality = quality;
        self
    }

    fn validate(&self) -> Result<(), SimplifyError> {
        let check = |name, value: f64, ok: bool, expected| {
            if ok {
                Ok(())
            } else {
                Err(SimplifyError::InvalidOption {
                    name,
                    value,
                    expected,
                })
            }
        };
        let w = self.boundary_weight;
        check(
            "boundary_weight",
            w,
            w.is_finite() && w >= 0.0,
            "finite and >= 0",
        )?;
        let a = self.max_normal_change_deg;
        check(
            "max_normal_change_deg",
            a,
            a > 0.0 && a <= 90.0,
            "in (0, 90]",
        )?;
        let q = self.min_triangle_quality;
        check(
            "min_triangle_quality",
            q,
            (0.0..1.0).contains(&q),
            "in [0, 1)",
        )
    }

    fn limits(&self) -> Limits {
        Limits {
            min_normal_cos: self.max_normal_change_deg.to_radians().cos(),
            min_quality: self.min_triangle_quality,
        }
    }
}

/// The limits used once the configured ones leave no valid collapse: normals may turn up to
/// this many degrees (still no flip), and only degenerate slivers are refused.
const RELAXED_NORMAL_CHANGE_DEG: f64 = 85.0;
const RELAXED_MIN_QUALITY: f64 = 1e-3;

/// The smallest target: a tetrahedron is the smallest closed triangle mesh.
const MIN_TARGET: usize = 4;

/// Simplifies `mesh` to a triangle mesh with exactly `target` vertices, with default options.
/// See [`simplify_with`].
pub fn simplify(mesh: &PolyMesh, target: usize) -> Result<PolyMesh, SimplifyError> {
    simplify_with(mesh, target, &SimplifyOptions::default())
}

/// Simplifies `mesh` to a triangle mesh with exactly `target` vertices.
///
/// Polygons are fan-triangulated; degenerate and duplicate faces are dropped, and vertices in
/// no face are left out of the result (so `target` counts only vertices used by faces). The
/// output keeps the input's vertex order among the survivors and its face orientation, and is
/// deterministic. A manifold input gives a manifold output with the same Euler characteristic
/// and boundary loops; non-manifold places of an input are left as they are.
///
/// If the configured limits leave no valid collapse before `target`, they are relaxed once
/// (normals may turn up to 85°, only degenerate slivers are refused) before giving up with
/// [`SimplifyError::TargetUnreachable`].
pub fn simplify_with(
    mesh: &PolyMesh,
    target: usize,
    options: &SimplifyOptions,
) -> Result<PolyMesh, SimplifyError> {
    options.validate()?;
    if let Some(vertex) = mesh.positions().iter().position(|p| !p.is_finite()) {
        return Err(SimplifyError::NonFiniteVertex { vertex });
    }
    if mesh.is_point_cloud() {
        return Err(SimplifyError::NoFaces);
    }
    if target < MIN_TARGET {
        return Err(SimplifyError::TargetTooSmall {
            target,
            min: MIN_TARGET,
        });
    }
    let pos = mesh.positions();
    let tris = clean_triangles(mesh);
    let incidence = Incidence::new(pos.len(), &tris);
    let available = incidence.used_vertices();
    if target > available {
        return Err(SimplifyError::TargetTooLarge { target, available });
    }
    let edges = incidence.edges(&tris);
    let quadric = quadrics(pos, &tris, &edges, options.boundary_weight);
    let numbering = Numbering::spatial(pos, &tris);
    let mut work = Work::new(pos, &tris, &incidence, &edges, &quadric, numbering);
    reduce(&mut work, target, options)?;
    output(&work)
}

/// The mesh's triangles without degenerate (repeated-index) or duplicate faces, in input order.
fn clean_triangles(mesh: &PolyMesh) -> Vec<[u32; 3]> {
    let tris: Vec<[u32; 3]> = mesh
        .triangles()
        .into_iter()
        .filter(|t| t[0] != t[1] && t[1] != t[2] && t[2] != t[0])
        .collect();
    let mut keyed: Vec<([u32; 3], usize)> = tris
        .iter()
        .enumerate()
        .map(|(i, t)| {
            let mut k = *t;
            k.sort_unstable();
            (k, i)
        })
        .collect();
    keyed.sort_unstable();
    let mut keep = vec![true; tris.len()];
    for w in keyed.windows(2) {
        if w[0].0 == w[1].0 {
            keep[w[1].1] = false;
        }
    }
    tris.into_iter()
        .zip(keep)
        .filter_map(|(t, k)| k.then_some(t))
        .collect()
}

/// Area-weighted face-plane quadrics at every vertex, plus penalty planes along the edges
/// with one face (in input order: the sums, and so the result, do not depend on the working
/// numbering).
fn quadrics(
    pos: &[Point3],
    tris: &[[u32; 3]],
    edges: &[InputEdge],
    boundary_weight: f64,
) -> Vec<Quadric> {
    let mut quadric = vec![Quadric::default(); pos.len()];
    for t in tris {
        let p = t.map(|i| pos[i as usize]);
        let n = (p[1] - p[0]).cross(p[2] - p[0]);
        let q = Quadric::plane(n.normalize_or_zero(), p[0], 0.5 * n.length());
        for &v in t {
            quadric[v as usize] += q;
        }
    }
    if boundary_weight == 0.0 {
        return quadric;
    }
    for &InputEdge { a, b, face, .. } in edges.iter().filter(|e| e.faces == 1) {
        let t = tris[face as usize].map(|v| pos[v as usize]);
        let face_normal = (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero();
        let (pa, pb) = (pos[a as usize], pos[b as usize]);
        let normal = (pb - pa).cross(face_normal).normalize_or_zero();
        let q = Quadric::plane(normal, pa, boundary_weight * pa.distance_squared(pb));
        quadric[a as usize] += q;
        quadric[b as usize] += q;
    }
    quadric
}

/// How far (in edge lengths from the edge midpoint) the quadric's optimum may lie before it is
/// distrusted as the product of a nearly singular system.
const MAX_OPTIMUM_OFFSET: f64 = 2.0;

/// The best position for the vertex that replaces edge `u`–`v`, and its quadric error: the
/// optimum of the summed quadric when it is well defined, else the best of the end points, the
/// midpoint and the optimum along the edge.
fn placement(work: &Work, u: u32, v: u32) -> (Point3, f64) {
    let q = work.quadric[u as usize] + work.quadric[v as usize];
    let (pu, pv) = (work.pos[u as usize], work.pos[v as usize]);
    let mid = (pu + pv) * 0.5;
    let optimum = q
        .minimizer()
        .filter(|x| x.distance(mid) <= MAX_OPTIMUM_OFFSET * pu.distance(pv));
    let target = optimum.unwrap_or_else(|| {
        let on_segment = q.minimizer_on_segment(pu, pv);
        [pu, pv, mid, on_segment]
            .into_iter()
            .min_by(|a, b| q.eval(*a).total_cmp(&q.eval(*b)))
            .unwrap_or(mid)
    });
    (target, q.eval(target))
}

/// Edge `edge` as a queue entry (ordered by input indices); its collapse position goes to
/// `targets`.
fn candidate(work: &Work, edge: u32, targets: &mut [Point3]) -> Candidate {
    let (u, v) = work.edge_ends(edge);
    let (target, cost) = placement(work, u, v);
    targets[edge as usize] = target;
    let input = &work.numbering.vertex_input;
    Candidate {
        cost,
        u: input[u as usize],
        v: input[v as usize],
        edge,
    }
}

/// Every edge of the current mesh, queued.
fn all_candidates(work: &Work, targets: &mut [Point3]) -> Queue {
    let mut items = Vec::new();
    for (v, links) in work.adj.iter().enumerate() {
        for l in links.iter().filter(|l| l.nbr > v as u32) {
            items.push(candidate(work, l.edge, targets));
        }
    }
    Queue::new(work.ends.len(), items)
}

/// Collapses edges until `target` vertices are left.
fn reduce(work: &mut Work, target: usize, options: &SimplifyOptions) -> Result<(), SimplifyError> {
    let mut limits = options.limits();
    let mut relaxed = false;
    // Where each edge would collapse to, for its queued cost.
    let mut targets = vec![Point3::ZERO; work.ends.len()];
    let mut heap = all_candidates(work, &mut targets);
    let mut removed = Vec::new();
    let mut progress_since_rebuild = false;
    while work.live > target {
        let Some(c) = heap.pop() else {
            if !progress_since_rebuild {
                if relaxed {
                    return Err(SimplifyError::TargetUnreachable {
                        target,
                        reached: work.live,
                    });
                }
                relaxed = true;
                limits = Limits {
                    min_normal_cos: RELAXED_NORMAL_CHANGE_DEG.to_radians().cos(),
                    min_quality: RELAXED_MIN_QUALITY.min(limits.min_quality),
                };
            }
            // Collapses refused earlier may have become valid as their neighbourhood changed.
            heap = all_candidates(work, &mut targets);
            progress_since_rebuild = false;
            continue;
        };
        // A refused edge stays out of the queue until a collapse at one of its ends re-costs it.
        let p = targets[c.edge as usize];
        let (u, v) = work.edge_ends(c.edge);
        if !work.allows(u, v, p, &limits) {
            continue;
        }
        removed.clear();
        work.collapse(u, v, p, &mut removed);
        progress_since_rebuild = true;
        for &e in &removed {
            heap.remove(e);
        }
        for l in &work.adj[u as usize] {
            heap.set(candidate(work, l.edge, &mut targets));
        }
    }
    Ok(())
}

/// The surviving vertices and faces, in input order, as a [`PolyMesh`].
fn output(work: &Work) -> Result<PolyMesh, SimplifyError> {
    let numbering = &work.numbering;
    let mut remap = vec![u32::MAX; work.pos.len()];
    let mut positions = Vec::with_capacity(work.live);
    for &v in &numbering.vertex_work {
        if !work.vfaces[v as usize].is_empty() {
            remap[v as usize] = positions.len() as u32;
            positions.push(work.pos[v as usize]);
        }
    }
    let faces: Vec<[u32; 3]> = numbering
        .face_work
        .iter()
        .filter(|&&f| work.tri_alive[f as usize])
        .map(|&f| work.faces[f as usize].corners.map(|v| remap[v as usize]))
        .collect();
    Ok(PolyMesh::try_new(positions, faces)?)
}
