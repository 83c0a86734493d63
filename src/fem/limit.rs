//! The FEM mesh of a Catmull–Clark limit surface: a k_u × k_v grid per control quad (patch),
//! nodes shared along control edges and at control vertices, counts chosen per strip of quads.

use super::grading::{elements_along, intervals, max_curvature, resolve_size};
use super::{FemError, FemMesh, FemOptions};
use crate::geom::{Aabb, Point3, Vec3};
use crate::subdiv::{LimitSurface, Scheme, SubdivSurface, SurfaceParam};
use std::collections::HashMap;

/// Sample segments per patch edge for the size estimate.
const SAMPLES: usize = 4;

/// The FEM quad mesh of a Catmull–Clark limit `surface` (see the [module](super) docs).
/// Loop and Doo–Sabin surfaces are refused: their patches are triangles, or corners of faces
/// that do not tile the control quads.
pub fn mesh_limit(surface: &SubdivSurface, options: &FemOptions) -> Result<FemMesh, FemError> {
    options.validate()?;
    if surface.scheme() != Scheme::CatmullClark {
        return Err(FemError::Unsupported {
            what: format!(
                "a FEM quad mesh of a {:?} surface is not made; fit Catmull–Clark or a B-spline \
                 surface",
                surface.scheme()
            ),
        });
    }
    let strips = Strips::of(surface)?;
    let samples: Vec<PatchSamples> = (0..strips.corners.len())
        .map(|p| PatchSamples::of(surface, p as u32))
        .collect();
    let scale = Aabb::from_points(surface.control_points()).map_or(1.0, |b| b.diagonal());
    let scale = if scale > 0.0 { scale } else { 1.0 };
    let g = options.grading;
    let counts = |l: f64| strips.counts(&samples, l, g);
    let l = resolve_size(options.size, scale, |l| strips.total(&counts(l)) as f64)?;
    let counts = counts(l);
    Nodes::build(surface, &strips, &counts)
}

/// The control quads' corners and the strip (class of edges linked through opposite sides of
/// quads) of each quad's u and v edges.
struct Strips {
    corners: Vec<[u32; 4]>,
    /// Per patch, the strip of its u edges (corner 0 → 1, 3 → 2) and of its v edges (1 → 2,
    /// 0 → 3).
    strip: Vec<[usize; 2]>,
    num_strips: usize,
}

impl Strips {
    fn of(surface: &SubdivSurface) -> Result<Strips, FemError> {
        let mesh = surface.control_mesh();
        let mut edges: HashMap<(u32, u32), usize> = HashMap::new();
        let mut edge = |a: u32, b: u32| {
            let n = edges.len();
            *edges.entry((a.min(b), a.max(b))).or_insert(n)
        };
        let mut corners = Vec::with_capacity(surface.num_patches());
        let mut pairs = Vec::new();
        for p in 0..surface.num_patches() as u32 {
            let face = surface.patch_site(p).map_or(p, |s| s.0);
            let c: Vec<u32> = mesh.face_vertices(face).collect();
            let c: [u32; 4] = c.as_slice().try_into().map_err(|_| FemError::NotQuad {
                face,
                sides: c.len(),
            })?;
            pairs.push([
                (edge(c[0], c[1]), edge(c[3], c[2])),
                (edge(c[1], c[2]), edge(c[0], c[3])),
            ]);
            corners.push(c);
        }
        let mut parent: Vec<usize> = (0..edges.len()).collect();
        fn root(parent: &mut [usize], mut e: usize) -> usize {
            while parent[e] != e {
                parent[e] = parent[parent[e]];
                e = parent[e];
            }
            e
        }
        for &(a, b) in pairs.iter().flatten() {
            let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
            parent[ra.max(rb)] = ra.min(rb);
        }
        let mut class = vec![usize::MAX; edges.len()];
        let mut num_strips = 0;
        for e in 0..edges.len() {
            let r = root(&mut parent, e);
            if class[r] == usize::MAX {
                class[r] = num_strips;
                num_strips += 1;
            }
            class[e] = class[r];
        }
        let strip = pairs
            .iter()
            .map(|[u, v]| [class[u.0], class[v.0]])
            .collect();
        Ok(Strips {
            corners,
            strip,
            num_strips,
        })
    }

    /// Intervals per strip at size `l`: the most any of its patches asks for.
    fn counts(&self, samples: &[PatchSamples], l: f64, g: f64) -> Vec<usize> {
        let mut counts = vec![1; self.num_strips];
        for (s, [cu, cv]) in samples.iter().zip(&self.strip) {
            let [eu, ev] = s.elements(l, g);
            counts[*cu] = counts[*cu].max(intervals(eu));
            counts[*cv] = counts[*cv].max(intervals(ev));
        }
        counts
    }

    /// Elements at these strip counts.
    fn total(&self, counts: &[usize]) -> usize {
        self.strip
            .iter()
            .map(|&[u, v]| counts[u].saturating_mul(counts[v]))
            .fold(0, usize::saturating_add)
    }
}

/// A patch sampled on a (SAMPLES + 1)² grid: per segment along u (rows of constant v) and along
/// v, its chord length and mean curvature at its ends.
struct PatchSamples {
    along_u: [[(f64, f64); SAMPLES]; SAMPLES + 1],
    along_v: [[(f64, f64); SAMPLES]; SAMPLES + 1],
}

impl PatchSamples {
    fn of(surface: &SubdivSurface, patch: u32) -> PatchSamples {
        let h = 1.0 / SAMPLES as f64;
        let mut pt = [[(Point3::ZERO, 0.0); SAMPLES + 1]; SAMPLES + 1];
        for (i, row) in pt.iter_mut().enumerate() {
            for (j, x) in row.iter_mut().enumerate() {
                let (u, v) = (i as f64 * h, j as f64 * h);
                let e = surface.eval(SurfaceParam { patch, u, v });
                *x = (e.point, max_curvature(e.du, e.dv, e.duu, e.duv, e.dvv));
            }
        }
        let seg = |a: (Point3, f64), b: (Point3, f64)| {
            let ds = a.0.distance(b.0);
            (if ds.is_finite() { ds } else { 0.0 }, 0.5 * (a.1 + b.1))
        };
        let mut s = PatchSamples {
            along_u: [[(0.0, 0.0); SAMPLES]; SAMPLES + 1],
            along_v: [[(0.0, 0.0); SAMPLES]; SAMPLES + 1],
        };
        for a in 0..=SAMPLES {
            for b in 0..SAMPLES {
                s.along_u[a][b] = seg(pt[b][a], pt[b + 1][a]);
                s.along_v[a][b] = seg(pt[a][b], pt[a][b + 1]);
            }
        }
        s
    }

    /// ∫ ds / h along u and along v, the largest over the sampled lines.
    fn elements(&self, l: f64, g: f64) -> [f64; 2] {
        let along = |lines: &[[(f64, f64); SAMPLES]; SAMPLES + 1]| {
            lines
                .iter()
                .map(|line| elements_along(line, l, g))
                .fold(0.0, f64::max)
        };
        [along(&self.along_u), along(&self.along_v)]
    }
}

/// The shared nodes being built: one per control vertex, k − 1 per control edge (in order
/// from the edge's lower vertex index), the rest inside patches.
struct Nodes {
    points: Vec<Point3>,
    normals: Vec<Vec3>,
    done: Vec<bool>,
    vertex: Vec<u32>,
    edge: HashMap<(u32, u32), u32>,
}

impl Nodes {
    fn build(
        surface: &SubdivSurface,
        strips: &Strips,
        counts: &[usize],
    ) -> Result<FemMesh, FemError> {
        let mut n = Nodes {
            points: Vec::new(),
            normals: Vec::new(),
            done: Vec::new(),
            vertex: vec![u32::MAX; surface.control_points().len()],
            edge: HashMap::new(),
        };
        let mut quads = Vec::with_capacity(strips.total(counts));
        let mut ids = Vec::new();
        for (p, (c, s)) in strips.corners.iter().zip(&strips.strip).enumerate() {
            let (ku, kv) = (counts[s[0]], counts[s[1]]);
            ids.clear();
            let interior = n.alloc((ku - 1) * (kv - 1));
            for i in 0..=ku {
                for j in 0..=kv {
                    let id = n.id(c, (i, j), (ku, kv), interior);
                    if !n.done[id as usize] {
                        let at = SurfaceParam {
                            patch: p as u32,
                            u: i as f64 / ku as f64,
                            v: j as f64 / kv as f64,
                        };
                        n.set(id, surface.eval(at));
                    }
                    ids.push(id);
                }
            }
            let at = |i: usize, j: usize| ids[i * (kv + 1) + j];
            for i in 0..ku {
                for j in 0..kv {
                    quads.push([at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]);
                }
            }
        }
        FemMesh::assemble(n.points, n.normals, quads)
    }

    /// `count` new nodes, not yet evaluated; the first's id.
    fn alloc(&mut self, count: usize) -> u32 {
        let first = self.points.len() as u32;
        self.points.resize(self.points.len() + count, Point3::ZERO);
        self.normals.resize(self.points.len(), Vec3::ZERO);
        self.done.resize(self.points.len(), false);
        first
    }

    fn set(&mut self, id: u32, e: crate::subdiv::LimitEval) {
        let i = id as usize;
        self.points[i] = e.point;
        self.normals[i] = e.du.cross(e.dv).normalize_or_zero();
        self.done[i] = true;
    }

    /// The node at grid point (i, j) of a patch with corners `c` and (ku, kv) intervals. The
    /// patch's corners 0, 1, 2, 3 sit at (u, v) = (0, 0), (1, 0), (1, 1), (0, 1); its interior
    /// nodes are the block from `interior`, row-major in u.
    fn id(
        &mut self,
        c: &[u32; 4],
        (i, j): (usize, usize),
        (ku, kv): (usize, usize),
        interior: u32,
    ) -> u32 {
        let (u_end, v_end) = (i == 0 || i == ku, j == 0 || j == kv);
        match (u_end, v_end) {
            (true, true) => {
                let corner = match (i == 0, j == 0) {
                    (true, true) => c[0],
                    (false, true) => c[1],
                    (false, false) => c[2],
                    (true, false) => c[3],
                };
                if self.vertex[corner as usize] == u32::MAX {
                    self.vertex[corner as usize] = self.alloc(1);
                }
                self.vertex[corner as usize]
            }
            (false, true) if j == 0 => self.edge_node(c[0], c[1], ku, i),
            (false, true) => self.edge_node(c[3], c[2], ku, i),
            (true, false) if i == 0 => self.edge_node(c[0], c[3], kv, j),
            (true, false) => self.edge_node(c[1], c[2], kv, j),
            (false, false) => interior + ((i - 1) * (kv - 1) + (j - 1)) as u32,
        }
    }

    /// Node `t` (1..k) of the edge a → b with k intervals.
    fn edge_node(&mut self, a: u32, b: u32, k: usize, t: usize) -> u32 {
        let key = (a.min(b), a.max(b));
        let first = match self.edge.get(&key) {
            Some(&f) => f,
            None => {
                let f = self.alloc(k - 1);
                self.edge.insert(key, f);
                f
            }
        };
        let from_low = if a < b { t } else { k - t };
        first + (from_low - 1) as u32
    }
}
