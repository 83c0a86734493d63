//! QEM simplification: the initial control mesh of a fit (Garland & Heckbert 1997).
//!
//! Edges are collapsed cheapest first, where the cost of a collapse is the quadric error — the
//! sum of squared distances of the new vertex to the planes of the faces its two ends have
//! absorbed — at the position that minimises it. On top of the textbook method, every collapse
//! must keep the surface a manifold of unchanged topology (no closed holes, no pinched
//! vertices, no duplicate faces), may not rotate a face normal by more than a set angle nor
//! turn a face against its input normal (no fold-overs), may not create needles and may not
//! give a vertex more neighbours than subdivision evaluates well; open boundaries are held in
//! place by penalty planes perpendicular to their faces, so the holes of a scan keep their
//! outline.
//!
//! The input is repaired first ([`crate::mesh::repair`]) and its polygons fan-triangulated, so
//! any mesh goes in. When the shape guards leave no valid collapse above the target they are
//! relaxed step by step (recorded in [`SimplifyReport::relaxations`]); the only floor is the
//! topology (a closed component keeps at least 4 vertices, a boundary loop at least 3), and a
//! target below it gives the floor, with [`SimplifyReport::floor_note`] saying so.
//!
//! Collapses are made in passes rather than from a priority queue (see the `engine` module).
//! Measured on one core of a quiet 2-core VM (`bash scripts/bench_qem.sh`, figures in
//! docs/subdivision.md): the Stanford bunny (69,451 triangles) to 612 vertices in 0.048 s cold,
//! 1.45 M triangles per second (0.040 s warm); the bunny Loop-subdivided three times (4.4 M
//! triangles) in 3.4–3.5 s, 1.3 M triangles per second, the whole process peaking at 175 bytes
//! per input triangle.
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

mod check;
mod deviation;
mod engine;
mod error;
mod locality;
mod quadric;
mod rank;
mod verify;

pub use deviation::{deviation, foldovers, Deviation, Foldovers};
pub use error::SimplifyError;

use crate::geom::Point3;
use crate::mesh::repair::{repair, RepairReport};
use crate::mesh::PolyMesh;
use crate::progress::{self, Phase};
use check::Limits;
use engine::Engine;
use serde::Serialize;

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
    /// Largest valence (number of neighbours) a collapse may give a vertex, unless one of the
    /// edge's ends already had more: subdivision evaluates a patch from at most 64 control
    /// points, which three corners of valence about 20 already need. Default 16 (never more
    /// than 3 above the largest valence an input ends with; see the QEM figures in docs/subdivision.md).
    pub max_valence: usize,
}

impl Default for SimplifyOptions {
    fn default() -> SimplifyOptions {
        SimplifyOptions {
            boundary_weight: 10.0,
            max_normal_change_deg: 60.0,
            min_triangle_quality: 0.1,
            max_valence: 16,
        }
    }
}

setters!(SimplifyOptions {
    /// Sets [`SimplifyOptions::boundary_weight`].
    with_boundary_weight(weight: f64) => |s| s.boundary_weight;
    /// Sets [`SimplifyOptions::max_normal_change_deg`].
    with_max_normal_change_deg(degrees: f64) => |s| s.max_normal_change_deg;
    /// Sets [`SimplifyOptions::min_triangle_quality`].
    with_min_triangle_quality(quality: f64) => |s| s.min_triangle_quality;
    /// Sets [`SimplifyOptions::max_valence`].
    with_max_valence(valence: usize) => |s| s.max_valence;
});

impl SimplifyOptions {
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
        )?;
        let v = self.max_valence;
        check("max_valence", v as f64, v >= MIN_VALENCE_CAP, ">= 6")
    }

    /// The limits of the configured options, then the relaxed ones, loosest last.
    fn stages(&self) -> Vec<Limits> {
        let first = Limits {
            min_normal_cos: libm::cos(self.max_normal_change_deg.to_radians()),
            min_quality: self.min_triangle_quality,
            max_valence: self.max_valence,
            min_reference_cos: REFERENCE_COS,
        };
        let mut stages = vec![first];
        for (degrees, quality) in RELAXED {
            let next = Limits {
                min_normal_cos: first.min_normal_cos.min(libm::cos(degrees.to_radians())),
                min_quality: first.min_quality.min(quality),
                min_reference_cos: 0.0,
                ..first
            };
            if stages.last() != Some(&next) {
                stages.push(next);
            }
        }
        stages
    }
}

/// Cosine of the largest angle (about 75°) between a face and the input it stands for under
/// the configured limits; the relaxed ones allow up to a right angle, never more.
const REFERENCE_COS: f64 = 0.25;

/// The smallest valence cap accepted: a regular interior vertex has 6 neighbours.
const MIN_VALENCE_CAP: usize = 6;

/// The relaxation steps (largest normal rotation in degrees, smallest triangle quality) used
/// in turn once the previous limits leave no valid collapse. Even the last refuses faces that
/// turn by a right angle or more, or against their input normal, and near-degenerate slivers.
const RELAXED: [(f64, f64); 3] = [(75.0, 0.05), (85.0, 0.01), (89.0, 1e-3)];

/// A relaxation of the shape guards during a simplification.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[non_exhaustive]
pub struct Relaxation {
    /// Vertices left when the previous limits blocked every collapse.
    pub at_vertices: usize,
    /// The new largest normal rotation per collapse, in degrees.
    pub max_normal_change_deg: f64,
    /// The new smallest triangle quality.
    pub min_triangle_quality: f64,
}

/// What a simplification did.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[non_exhaustive]
pub struct SimplifyReport {
    /// The vertex count asked for.
    pub target: usize,
    /// The vertex count reached: `target`, unless the mesh allows no fewer (see
    /// [`SimplifyReport::floor_note`]) or has fewer.
    pub vertices: usize,
    /// Triangles of the result.
    pub triangles: usize,
    /// Passes of collapses made.
    pub passes: usize,
    /// The shape guards relaxed on the way, in order.
    pub relaxations: Vec<Relaxation>,
    /// Why the result has more vertices than `target`, when it has.
    pub floor_note: Option<String>,
    /// The largest valence of the result.
    pub max_valence: usize,
    /// What repairing the (triangulated) input changed.
    pub repair: RepairReport,
    /// Crease edges given ([`simplify_with_creases`]) and crease edges of the result.
    pub creases: CreaseCount,
}

/// Crease edges before and after a simplification.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
#[non_exhaustive]
pub struct CreaseCount {
    /// Crease edges of the input that are edges of its faces.
    pub input: usize,
    /// Crease edges of the result.
    pub output: usize,
}

/// A simplified mesh and its report.
#[derive(Clone, Debug, PartialEq)]
pub struct Simplified {
    /// The simplified triangle mesh.
    pub mesh: PolyMesh,
    /// Its crease edges (vertex pairs, smaller first, sorted): the chains the input's crease
    /// lines became (empty without [`simplify_with_creases`]).
    pub creases: Vec<[u32; 2]>,
    /// What was done.
    pub report: SimplifyReport,
}

/// Simplifies `mesh` to `target` vertices, with default options. See [`simplify_with_report`].
pub fn simplify(mesh: &PolyMesh, target: usize) -> Result<PolyMesh, SimplifyError> {
    simplify_with(mesh, target, &SimplifyOptions::default())
}

/// Simplifies `mesh` to `target` vertices. See [`simplify_with_report`].
pub fn simplify_with(
    mesh: &PolyMesh,
    target: usize,
    options: &SimplifyOptions,
) -> Result<PolyMesh, SimplifyError> {
    Ok(simplify_with_report(mesh, target, options)?.mesh)
}

/// Simplifies `mesh` to a triangle mesh with `target` vertices, and reports how.
///
/// The mesh is fan-triangulated and repaired first ([`crate::mesh::repair`]); vertices in no
/// face are left out of the result, so `target` counts only vertices of faces. The result is an
/// oriented manifold with the topology of the repaired input (Euler characteristic, boundary
/// loops), keeps the input's vertex order among the survivors and its face orientation, and is
/// deterministic. It has exactly `target` vertices unless the topology allows no fewer (then it
/// has the fewest it allows, and the report's `floor_note` says why) or the faces have fewer
/// vertices than `target` (then it has them all).
pub fn simplify_with_report(
    mesh: &PolyMesh,
    target: usize,
    options: &SimplifyOptions,
) -> Result<Simplified, SimplifyError> {
    simplify_with_creases(mesh, target, options, &[])
}

/// Simplifies `mesh` as [`simplify_with_report`] does, keeping the crease edges `creases`
/// (vertex pairs of `mesh`, such as [`crate::mesh::detect_features`] finds) as chains of edges
/// of the result, returned in [`Simplified::creases`].
///
/// Crease edges get penalty planes like open boundaries, and collapses keep the lines' course
/// and nodes: a vertex off the creases may go into one on them, which stays in place; along a
/// line only a vertex with two crease edges goes, into its neighbour on the line; corners
/// (three or more crease edges) and dart ends (one) stay, and no line shrinks below three
/// edges when it is closed. Pairs that are no edge of `mesh` are ignored. With no creases the
/// result is exactly [`simplify_with_report`]'s.
pub fn simplify_with_creases(
    mesh: &PolyMesh,
    target: usize,
    options: &SimplifyOptions,
    creases: &[[u32; 2]],
) -> Result<Simplified, SimplifyError> {
    options.validate()?;
    if mesh.is_point_cloud() {
        return Err(SimplifyError::NoFaces);
    }
    // Quadrics hold squared plane offsets: far from the origin (a scan in survey coordinates)
    // their costs cancel catastrophically, so such a mesh is simplified around its bbox
    // centre. Near the origin nothing is gained and the shift's rounding would change results.
    let origin = mesh
        .bbox()
        .filter(|b| b.center().length() > b.diagonal())
        .map_or(Point3::ZERO, |b| b.center());
    let (mut engine, repair) = working_mesh(mesh, origin, creases, options.boundary_weight)?;
    let input_creases = engine.num_creases();
    let (passes, relaxations) = reduce(&mut engine, target, &options.stages());
    let max_valence = engine.max_valence();
    let live = engine.live();
    let (mut positions, tris, creases) = engine.into_parts();
    positions.iter_mut().for_each(|p| *p += origin);
    let starts = (0..=tris.len() as u32 / 3).map(|f| 3 * f).collect();
    let mesh = PolyMesh::from_parts_unchecked(positions, starts, tris);
    let report = SimplifyReport {
        target,
        vertices: live,
        triangles: mesh.num_faces(),
        passes,
        relaxations,
        floor_note: floor_note(&mesh, target),
        max_valence,
        repair,
        creases: CreaseCount {
            input: input_creases,
            output: creases.len(),
        },
    };
    Ok(Simplified {
        mesh,
        creases,
        report,
    })
}

/// The working mesh of `mesh` (fan-triangulated, and repaired unless it is clean already),
/// with positions relative to `origin` and the crease edges `creases`, and the repair's report.
fn working_mesh(
    mesh: &PolyMesh,
    origin: Point3,
    creases: &[[u32; 2]],
    boundary_weight: f64,
) -> Result<(Engine, RepairReport), SimplifyError> {
    let triangles = triangulated(mesh);
    let (_, idx) = triangles.raw_faces();
    let engine = Engine::new(
        &relative(triangles.positions(), origin),
        idx,
        creases,
        boundary_weight,
    );
    if let Some(report) = verify::clean_report(&engine) {
        return Ok((engine, report));
    }
    drop(engine);
    let repaired = repair(&triangles)?;
    let creases = split_creases(
        creases,
        &repaired.vertex_origin,
        repaired.mesh.raw_faces().1,
    );
    let (pos, _, tris) = repaired.mesh.into_parts();
    if tris.is_empty() {
        return Err(SimplifyError::NoFaces);
    }
    Ok((
        Engine::new(&relative(&pos, origin), &tris, &creases, boundary_weight),
        repaired.report,
    ))
}

/// The crease edges of a repaired mesh (triangles `tris`, vertex `v` a copy of input vertex
/// `origin[v]`): the sides whose ends are copies of the ends of an input crease edge.
fn split_creases(creases: &[[u32; 2]], origin: &[u32], tris: &[u32]) -> Vec<[u32; 2]> {
    if creases.is_empty() {
        return Vec::new();
    }
    let key = |x: u32, y: u32| (x.min(y), x.max(y));
    let wanted: std::collections::HashSet<(u32, u32)> =
        creases.iter().map(|&[x, y]| key(x, y)).collect();
    let mut out: Vec<[u32; 2]> = tris
        .chunks_exact(3)
        .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
        .filter(|&(x, y)| wanted.contains(&key(origin[x as usize], origin[y as usize])))
        .map(|(x, y)| [x.min(y), x.max(y)])
        .collect();
    out.sort_unstable();
    out.dedup();
    out
}

/// `pos` relative to `origin` (borrowed when that is the origin itself: no copy).
fn relative(pos: &[Point3], origin: Point3) -> std::borrow::Cow<'_, [Point3]> {
    if origin == Point3::ZERO {
        return std::borrow::Cow::Borrowed(pos);
    }
    std::borrow::Cow::Owned(pos.iter().map(|&p| p - origin).collect())
}

/// `mesh` with its polygons fan-triangulated (the mesh itself when it has only triangles).
fn triangulated(mesh: &PolyMesh) -> std::borrow::Cow<'_, PolyMesh> {
    if mesh.faces().all(|f| f.len() == 3) {
        return std::borrow::Cow::Borrowed(mesh);
    }
    let tris = mesh.triangles();
    let starts = (0..=tris.len() as u32).map(|f| 3 * f).collect();
    let idx = tris.into_iter().flatten().collect();
    std::borrow::Cow::Owned(PolyMesh::from_parts_unchecked(
        mesh.positions().to_vec(),
        starts,
        idx,
    ))
}

/// Passes of collapses until `target` vertices are left or the loosest of `stages` leaves no
/// valid collapse (with ties scrambled: [`Engine::scramble_ties`]); returns the number of
/// passes and the relaxations made.
fn reduce(engine: &mut Engine, target: usize, stages: &[Limits]) -> (usize, Vec<Relaxation>) {
    let mut stage = 0;
    let mut passes = 0;
    let mut relaxations = Vec::new();
    let first = engine.live();
    let progress = |live: usize| {
        let to_go = first.saturating_sub(target);
        progress::report_count(Phase::Simplification, first - live.max(target), to_go);
    };
    progress(first);
    while engine.live() > target {
        progress(engine.live());
        passes += 1;
        if engine.pass(target, &stages[stage]) > 0 || engine.scramble_ties() {
            continue;
        }
        stage += 1;
        let Some(limits) = stages.get(stage) else {
            break;
        };
        relaxations.push(Relaxation {
            at_vertices: engine.live(),
            max_normal_change_deg: libm::acos(limits.min_normal_cos.clamp(-1.0, 1.0)).to_degrees(),
            min_triangle_quality: limits.min_quality,
        });
    }
    progress::report(Phase::Simplification, 1.0);
    (passes, relaxations)
}

/// Why `mesh` has more vertices than `target`, if it has.
fn floor_note(mesh: &PolyMesh, target: usize) -> Option<String> {
    let v = mesh.num_vertices();
    if v <= target {
        return None;
    }
    let t = topology(mesh);
    Some(format!(
        "target {target} is below what this mesh allows: stopped at {v} vertices, where no \
         collapse keeps its topology ({} components, Euler characteristic {}, {} boundary \
         loops) without folding the surface",
        t.components, t.euler, t.boundary_loops
    ))
}

/// Components, Euler characteristic and boundary loops of a small manifold triangle mesh.
struct Topology {
    components: usize,
    euler: i64,
    boundary_loops: usize,
}

fn topology(mesh: &PolyMesh) -> Topology {
    let n = mesh.num_vertices();
    let mut parent: Vec<usize> = (0..n).collect();
    fn root(parent: &mut [usize], mut v: usize) -> usize {
        while parent[v] != v {
            parent[v] = parent[parent[v]];
            v = parent[v];
        }
        v
    }
    let mut edges = std::collections::BTreeMap::new();
    for f in mesh.faces() {
        for k in 0..f.len() {
            let (a, b) = (f[k], f[(k + 1) % f.len()]);
            *edges.entry((a.min(b), a.max(b))).or_insert(0usize) += 1;
            let (ra, rb) = (root(&mut parent, a as usize), root(&mut parent, b as usize));
            parent[ra] = rb;
        }
    }
    let components = (0..n).filter(|&v| root(&mut parent, v) == v).count();
    // Boundary loops: components of the graph of boundary edges (each boundary vertex of a
    // manifold has two boundary edges, so each component is one loop).
    let mut loop_parent: Vec<usize> = (0..n).collect();
    let mut on_boundary = vec![false; n];
    for (&(a, b), _) in edges.iter().filter(|(_, &c)| c == 1) {
        on_boundary[a as usize] = true;
        on_boundary[b as usize] = true;
        let (ra, rb) = (
            root(&mut loop_parent, a as usize),
            root(&mut loop_parent, b as usize),
        );
        loop_parent[ra] = rb;
    }
    let boundary_loops = (0..n)
        .filter(|&v| on_boundary[v] && root(&mut loop_parent, v) == v)
        .count();
    Topology {
        components,
        euler: n as i64 - edges.len() as i64 + mesh.num_faces() as i64,
        boundary_loops,
    }
}
