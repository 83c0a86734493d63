//! [`SubdivSurface`]: the limit surface of a control mesh under one scheme, with everything
//! topological precomputed so evaluation after moving control points is only weighted sums.

use super::doo_sabin::limits_of;
use super::patch::{neighbourhood, vertex_neighbourhood, Graph, Kind};
use super::sites::DooSabinSites;
use super::topo::Topo;
use super::{LimitEval, LimitSurface, PatchDomain, Scheme, SubdivError, SurfaceParam};
use crate::geom::{prefetch_slice, Point3, Vec3};
use crate::mesh::{ControlMesh, NONE};

/// Where a patch's local points come from, and how to evaluate it.
#[derive(Clone, Copy, Debug)]
struct Patch {
    start: u32,
    len: u32,
    /// The patch is a plain box spline / B-spline over `ctrl[start..start + len]` in basis order.
    direct: bool,
    /// The shortcut of the patch's shape (unused when `direct`).
    shortcut: u32,
    /// Where the patch's data starts in [`SubdivSurface::cache`].
    cache: u32,
    /// The patch's shape in the graph (its root node), for the tests that evaluate it
    /// without the shortcut.
    #[cfg(test)]
    node: u32,
}

/// The limit surface of a Loop or Catmull–Clark control mesh.
pub struct SubdivSurface {
    scheme: Scheme,
    mesh: ControlMesh,
    graph: Graph,
    patches: Vec<Patch>,
    /// Face and vertex of each patch: the face itself for Loop and Catmull–Clark; for
    /// Doo–Sabin the face corner whose refined point the patch belongs to.
    sites: Vec<(u32, u32)>,
    /// Doo–Sabin's extended mesh and patch sites.
    doo_sabin: Option<Box<DooSabinSites>>,
    ctrl: Vec<u32>,
    /// Per patch, what evaluation needs from the current control points: power coefficients of
    /// direct patches, the shortcut data of the others. Refilled when control points move.
    cache: Vec<Vec3>,
    /// Limit stencil of every control vertex (limit masks), flattened.
    limit_starts: Vec<u32>,
    limit_weights: Vec<(u32, f64)>,
    /// Per patch, the patch of the surface this one was rebuilt from that it copies
    /// ([`SubdivSurface::kept_patch`]).
    kept: Vec<Option<u32>>,
}

/// The (face, first corner) of every patch of a primal scheme: one per face.
fn primal_sites(mesh: &ControlMesh) -> Vec<(u32, u32)> {
    (0..mesh.num_faces() as u32)
        .map(|f| (f, mesh.face_vertices(f).next().unwrap_or(0)))
        .collect()
}

impl SubdivSurface {
    /// The limit surface of `mesh` under `scheme` (Loop needs triangles, Catmull–Clark quads).
    pub fn try_new(scheme: Scheme, mesh: ControlMesh) -> Result<SubdivSurface, SubdivError> {
        let mut surface = SubdivSurface::with_graph(scheme, mesh, Graph::new(scheme), |_| None)?;
        surface.fill_cache_from(None);
        Ok(surface)
    }

    /// The limit surface of the same scheme over a new control mesh (after refinement): the
    /// patch shapes already analysed are reused, so only new shapes are subdivided, and a patch
    /// the new mesh leaves as it was (see [`SubdivSurface::kept_patch`]) is copied, not rebuilt.
    pub fn with_mesh(&self, mesh: ControlMesh) -> Result<SubdivSurface, SubdivError> {
        let kept = self.kept_patches(&mesh);
        let mut surface = SubdivSurface::with_graph(self.scheme, mesh, self.graph.clone(), |p| {
            let old = *self.patches.get(kept.get(p).copied().flatten()? as usize)?;
            Some((
                old,
                &self.ctrl[old.start as usize..(old.start + old.len) as usize],
            ))
        })?;
        surface.kept = kept;
        surface.fill_cache_from(Some(self));
        Ok(surface)
    }

    /// The patch of the surface this one was made from ([`SubdivSurface::with_mesh`]) that
    /// `patch` is an exact copy of: same face corners in the same order, same neighbourhood,
    /// same control points. Foot points on such a patch are still foot points.
    pub fn kept_patch(&self, patch: u32) -> Option<u32> {
        self.kept.get(patch as usize).copied().flatten()
    }

    /// For every patch over `mesh`, the patch of `self` it copies, if any. A primal patch
    /// depends on the faces around its corners, so it is kept when every face around every
    /// corner is a face of `self` (same corners, same order) and its control points have not
    /// moved; a refinement changes a few regions and leaves the rest of the mesh alone.
    /// Doo–Sabin patches (not one per face) are always rebuilt: the list is empty.
    fn kept_patches(&self, mesh: &ControlMesh) -> Vec<Option<u32>> {
        let n = mesh.num_faces();
        if self.doo_sabin.is_some() {
            return Vec::new();
        }
        let corners = |m: &ControlMesh, f: u32| {
            let mut key = [u32::MAX; 4];
            for (k, v) in key.iter_mut().zip(m.face_vertices(f)) {
                *k = v;
            }
            key
        };
        let old: std::collections::HashMap<[u32; 4], u32> = (0..self.mesh.num_faces() as u32)
            .map(|f| (corners(&self.mesh, f), f))
            .collect();
        let same: Vec<Option<u32>> = (0..n as u32)
            .map(|f| old.get(&corners(mesh, f)).copied())
            .collect();
        let mut touched = vec![false; mesh.num_vertices()];
        for f in (0..n as u32).filter(|&f| same[f as usize].is_none()) {
            for v in mesh.face_vertices(f) {
                touched[v as usize] = true;
            }
        }
        let (old_pts, new_pts) = (self.mesh.positions(), mesh.positions());
        let unmoved = |i: u32| old_pts.get(i as usize) == new_pts.get(i as usize);
        (0..n as u32)
            .map(|f| {
                let old_f = same[f as usize]?;
                let p = self.patches.get(old_f as usize)?;
                let local = self
                    .ctrl
                    .get(p.start as usize..(p.start + p.len) as usize)?;
                let clean = mesh.face_vertices(f).all(|v| !touched[v as usize]);
                (clean && local.iter().all(|&i| unmoved(i))).then_some(old_f)
            })
            .collect()
    }

    /// Builds the patches of `mesh`, without their cached data; `copy(patch)` gives a patch of
    /// the previous surface and its control indices to take as they are.
    fn with_graph<'a>(
        scheme: Scheme,
        mesh: ControlMesh,
        mut graph: Graph,
        copy: impl Fn(usize) -> Option<(Patch, &'a [u32])>,
    ) -> Result<SubdivSurface, SubdivError> {
        let needed = match scheme {
            Scheme::Loop => 3,
            Scheme::CatmullClark => 4,
            Scheme::DooSabin => 0,
        };
        if mesh.num_faces() == 0 {
            return Err(SubdivError::NoFaces);
        }
        for f in 0..mesh.num_faces() as u32 {
            let len = mesh.face_len(f);
            if needed != 0 && len != needed {
                return Err(SubdivError::WrongFaceSize {
                    face: f as usize,
                    len,
                    scheme,
                });
            }
        }
        let topo = Topo::of_control_mesh(&mesh);
        let mut patches = Vec::with_capacity(mesh.num_faces());
        let mut ctrl = Vec::new();
        let doo_sabin = (scheme == Scheme::DooSabin).then(|| Box::new(DooSabinSites::new(&topo)));
        let sites = match &doo_sabin {
            Some(ds) => ds.control_sites(),
            None => primal_sites(&mesh),
        };
        let mut cache_len = 0;
        for patch in 0..sites.len() {
            if let Some((old, local)) = copy(patch) {
                patches.push(Patch {
                    start: ctrl.len() as u32,
                    cache: cache_len as u32,
                    ..old
                });
                ctrl.extend_from_slice(local);
                cache_len += graph.cache_len(old.direct, old.shortcut);
                continue;
            }
            let (nb, source) = match &doo_sabin {
                Some(ds) => {
                    let (f, v) = ds.sites[patch];
                    let nb = vertex_neighbourhood(&ds.ext.topo, v, f, Kind::DooSabinRoot);
                    let source: Vec<u32> = nb
                        .source
                        .iter()
                        .map(|&i| ds.ext.owner[i as usize])
                        .collect();
                    (nb, source)
                }
                None => {
                    let nb = neighbourhood(&topo, sites[patch].0);
                    let source = nb.source.clone();
                    (nb, source)
                }
            };
            let node = graph.add(nb, patch)?;
            let start = ctrl.len() as u32;
            let (picks, direct, shortcut) = match graph.direct_picks(node) {
                Some(picks) => (picks, true, 0),
                None => (
                    (0..source.len() as u32).collect(),
                    false,
                    graph.shortcut(node),
                ),
            };
            ctrl.extend(picks.iter().map(|&p| source[p as usize]));
            patches.push(Patch {
                start,
                len: picks.len() as u32,
                direct,
                shortcut,
                cache: cache_len as u32,
                #[cfg(test)]
                node,
            });
            cache_len += graph.cache_len(direct, shortcut);
        }
        let mut limit_starts = vec![0u32];
        let mut limit_weights = Vec::new();
        let ds_limits = doo_sabin
            .as_ref()
            .map(|ds| limits_of(&ds.ext, mesh.num_vertices()));
        let stencils = topo.limit_stencils(scheme, mesh.num_vertices(), ds_limits);
        for s in stencils {
            limit_weights.extend(s.ok_or(SubdivError::Unevaluable { patch: 0 })?);
            limit_starts.push(limit_weights.len() as u32);
        }
        let surface = SubdivSurface {
            scheme,
            mesh,
            graph,
            patches,
            sites,
            doo_sabin,
            ctrl,
            cache: Vec::with_capacity(cache_len),
            limit_starts,
            limit_weights,
            kept: Vec::new(),
        };
        Ok(surface)
    }

    /// Fills every patch's cached data: copied from `previous` for the patches kept from it
    /// (their control points are the same), computed from the current control points for the
    /// others (all of them with `None`, as after moving control points).
    fn fill_cache_from(&mut self, previous: Option<&SubdivSurface>) {
        self.cache.clear();
        let pts = self.mesh.positions();
        let mut local = Vec::with_capacity(super::patch::MAX_LOCAL);
        for (i, p) in self.patches.iter().enumerate() {
            let kept = previous.zip(self.kept.get(i).copied().flatten());
            if let Some((old, k)) = kept {
                let start = old.patches[k as usize].cache as usize;
                let len = self.graph.cache_len(p.direct, p.shortcut);
                self.cache.extend_from_slice(&old.cache[start..start + len]);
                continue;
            }
            local.clear();
            let idx = &self.ctrl[p.start as usize..(p.start + p.len) as usize];
            local.extend(idx.iter().map(|&i| pts[i as usize]));
            if p.direct {
                self.graph.power().coefficients(&local, &mut self.cache);
            } else {
                self.graph
                    .fill_shortcut(p.shortcut, &local, &mut self.cache);
            }
        }
    }

    /// The control face and vertex of `patch`: for Loop and Catmull–Clark the face (and its
    /// first corner); for Doo–Sabin the face corner at the vertex whose region the patch covers
    /// (parameter (0, 0) is at the face's centroid, (1, 1) at the vertex's limit point). Doo–Sabin
    /// patches between a face and a boundary or crease curve (two or three per vertex there) sit
    /// on ghost faces (see [`refine`](super::refine)) and report the control face on that side.
    pub fn patch_site(&self, patch: u32) -> Option<(u32, u32)> {
        self.sites.get(patch as usize).copied()
    }

    /// The scheme.
    pub fn scheme(&self) -> Scheme {
        self.scheme
    }

    /// The control mesh (connectivity and current control points).
    pub fn control_mesh(&self) -> &ControlMesh {
        &self.mesh
    }

    /// The limit curves of the crease edges as line segments (both ends of each, `segments`
    /// per crease edge): where the surface is sharp, for drawing. Loop and Catmull–Clark
    /// patches are the control faces, so a crease edge's curve is a side of the patch of
    /// either face on it; Doo–Sabin patches sit elsewhere, and it draws none.
    pub fn crease_curves(&self, segments: usize) -> Vec<Point3> {
        if self.scheme == Scheme::DooSabin {
            return Vec::new();
        }
        let segments = segments.max(1);
        let domain = self.domain();
        let mut out = Vec::new();
        for [a, b] in self.mesh.creases() {
            let Some(h) = self.mesh.find_half_edge(a, b) else {
                continue;
            };
            let f = self.mesh.face_of(h);
            let Some(k) = self.mesh.face_half_edges(f).position(|x| x == h) else {
                continue;
            };
            let at = |i: usize| {
                let (u, v) = side_param(domain, k, i as f64 / segments as f64);
                self.eval(SurfaceParam { patch: f, u, v }).point
            };
            for i in 0..segments {
                out.extend([at(i), at(i + 1)]);
            }
        }
        out
    }

    /// Exact limit positions of the control vertices (limit masks).
    pub fn limit_positions(&self) -> Vec<Point3> {
        let p = self.mesh.positions();
        (0..self.mesh.num_vertices())
            .map(|v| {
                let s = &self.limit_weights
                    [self.limit_starts[v] as usize..self.limit_starts[v + 1] as usize];
                s.iter().map(|&(i, w)| p[i as usize] * w).sum()
            })
            .collect()
    }

    /// Unit limit normals of the control vertices (zero for vertices in no face), from the
    /// limit tangent plane of a patch at that corner.
    pub fn limit_normals(&self) -> Vec<Vec3> {
        if self.scheme == Scheme::DooSabin {
            let mut normals = vec![Vec3::ZERO; self.mesh.num_vertices()];
            for (patch, &(_, v)) in self.sites.iter().enumerate() {
                let e = self.eval(SurfaceParam {
                    patch: patch as u32,
                    u: 1.0,
                    v: 1.0,
                });
                normals[v as usize] = e.du.cross(e.dv).normalize_or_zero();
            }
            return normals;
        }
        (0..self.mesh.num_vertices() as u32)
            .map(|v| {
                let h = self.mesh.vertex_half_edge(v);
                if h == NONE {
                    return Vec3::ZERO;
                }
                let f = self.mesh.face_of(h);
                let corner = self.mesh.face_vertices(f).position(|x| x == v).unwrap_or(0);
                let (u, w) = corner_uv(self.scheme, corner);
                let e = self.eval(SurfaceParam { patch: f, u, v: w });
                e.du.cross(e.dv).normalize_or_zero()
            })
            .collect()
    }

    /// Asks the processor to load the cached data that evaluation at `at` reads (a hint: the
    /// next foot point's patch is known one or more points ahead, and its data is otherwise a
    /// cache miss, as patches are visited in the data's order).
    pub(crate) fn prefetch_patch(&self, at: SurfaceParam) {
        let Some((p, u, v)) = self.patch(at) else {
            return;
        };
        let span = if p.direct {
            Some((0, self.graph.power().len()))
        } else {
            self.graph.shortcut_span(p.shortcut, u, v)
        };
        if let Some(data) = span.and_then(|(offset, len)| {
            let start = p.cache as usize + offset;
            self.cache.get(start..start + len)
        }) {
            prefetch_slice(data);
        }
    }

    fn patch(&self, at: SurfaceParam) -> Option<(&Patch, f64, f64)> {
        let p = self.patches.get(at.patch as usize)?;
        let clean = |x: f64| if x.is_finite() { x } else { 0.0 };
        Some((p, clean(at.u), clean(at.v)))
    }
}

/// Parameters of corner `i` of a patch.
fn corner_uv(scheme: Scheme, i: usize) -> (f64, f64) {
    match (scheme, i) {
        (_, 0) => (0.0, 0.0),
        (_, 1) => (1.0, 0.0),
        (Scheme::Loop, _) => (0.0, 1.0),
        (_, 2) => (1.0, 1.0),
        _ => (0.0, 1.0),
    }
}

impl LimitSurface for SubdivSurface {
    fn domain(&self) -> PatchDomain {
        match self.scheme {
            Scheme::Loop => PatchDomain::Triangle,
            _ => PatchDomain::Square,
        }
    }

    fn num_patches(&self) -> usize {
        self.patches.len()
    }

    fn control_points(&self) -> &[Point3] {
        self.mesh.positions()
    }

    fn set_control_points(&mut self, points: &[Point3]) {
        self.mesh.set_positions(points);
        self.fill_cache_from(None);
    }

    fn eval(&self, at: SurfaceParam) -> LimitEval {
        let Some((p, u, v)) = self.patch(at) else {
            return LimitEval::default();
        };
        let cache = &self.cache[p.cache as usize..];
        if p.direct {
            self.graph.power().eval(cache, u, v)
        } else {
            self.graph.eval_shortcut(p.shortcut, cache, u, v)
        }
    }

    fn point(&self, at: SurfaceParam) -> Point3 {
        let Some((p, u, v)) = self.patch(at) else {
            return Point3::ZERO;
        };
        let cache = &self.cache[p.cache as usize..];
        if p.direct {
            self.graph.power().eval(cache, u, v).point
        } else {
            self.graph.point_shortcut(p.shortcut, cache, u, v)
        }
    }

    fn stencil(&self, at: SurfaceParam, out: &mut Vec<(u32, f64)>) {
        let Some((p, u, v)) = self.patch(at) else {
            return;
        };
        let idx = &self.ctrl[p.start as usize..(p.start + p.len) as usize];
        let mut weights = [0.0; super::patch::MAX_LOCAL];
        if p.direct {
            self.graph.power().point_weights(u, v, &mut weights);
        } else {
            let mut w = Vec::with_capacity(idx.len());
            self.graph.stencil_shortcut(p.shortcut, u, v, &mut w);
            weights[..w.len().min(idx.len())].copy_from_slice(&w[..w.len().min(idx.len())]);
        }
        let start = out.len();
        for (&i, &w) in idx.iter().zip(&weights) {
            if w != 0.0 {
                match out[start..].iter_mut().find(|(j, _)| *j == i) {
                    Some(e) => e.1 += w,
                    None => out.push((i, w)),
                }
            }
        }
    }

    fn corner_weights(&self, at: SurfaceParam, out: &mut Vec<(u32, f64)>) {
        let Some((_, u, v)) = self.patch(at) else {
            return;
        };
        let (face, vertex) = self.sites[at.patch as usize];
        let corners: Vec<u32> = self.mesh.face_vertices(face).collect();
        let (u, v) = (u.clamp(0.0, 1.0), v.clamp(0.0, 1.0));
        match self.scheme {
            Scheme::DooSabin => {
                // The patch spans from the face centroid (u = v = 0) to the vertex (u = v = 1):
                // the vertex's share grows bilinearly, the rest is spread over the face.
                let own = u * v + 0.5 * (u * (1.0 - v) + (1.0 - u) * v);
                let spread = (1.0 - own) / corners.len() as f64;
                for &c in &corners {
                    out.push((c, spread + if c == vertex { own } else { 0.0 }));
                }
            }
            Scheme::Loop => {
                let s = u + v;
                let (u, v) = if s > 1.0 { (u / s, v / s) } else { (u, v) };
                out.extend([(corners[0], 1.0 - u - v), (corners[1], u), (corners[2], v)]);
            }
            _ => out.extend([
                (corners[0], (1.0 - u) * (1.0 - v)),
                (corners[1], u * (1.0 - v)),
                (corners[2], u * v),
                (corners[3], (1.0 - u) * v),
            ]),
        }
    }

    fn relocate(&self, patch: u32, u: f64, v: f64) -> SurfaceParam {
        match &self.doo_sabin {
            Some(ds) => super::walk::walk_doo_sabin(ds, patch, u, v),
            None => super::walk::relocate(&self.mesh, self.scheme, patch, u, v),
        }
    }
}

/// The parameters of the point a fraction `t` along side `k` of a Loop or Catmull–Clark patch
/// (side `k` runs from corner `k` to corner `k + 1` of its face, as the face's half-edges do).
pub fn side_param(domain: PatchDomain, k: usize, t: f64) -> (f64, f64) {
    match (domain, k) {
        (_, 0) => (t, 0.0),
        (PatchDomain::Triangle, 1) => (1.0 - t, t),
        (PatchDomain::Triangle, _) => (0.0, 1.0 - t),
        (PatchDomain::Square, 1) => (1.0, t),
        (PatchDomain::Square, 2) => (1.0 - t, 1.0),
        (PatchDomain::Square, _) => (0.0, 1.0 - t),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::PolyMesh;

    fn bunny() -> PolyMesh {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/tests/data/subdiv/bunny_coarse.obj"
        );
        crate::io::read_path(std::path::Path::new(path))
            .expect("bunny_coarse.obj")
            .mesh
    }

    /// The flattened shortcut (a grid lookup and one polynomial in the patch's parameters)
    /// against the plain descent through the patch graph, at parameters all over every
    /// patch that is not a plain spline, dyadic cell edges included.
    #[test]
    fn shortcut_evaluation_matches_the_descent() {
        let mesh = bunny();
        for scheme in [Scheme::Loop, Scheme::CatmullClark, Scheme::DooSabin] {
            let control = ControlMesh::try_new(&mesh).expect("control mesh");
            let control = if scheme == Scheme::CatmullClark {
                super::super::quadrangulate(&control).expect("quads")
            } else {
                control
            };
            let s = SubdivSurface::try_new(scheme, control).expect("surface");
            let pts = s.mesh.positions();
            let mut checked = 0;
            for (i, p) in s.patches.iter().enumerate().filter(|(_, p)| !p.direct) {
                let local: Vec<Point3> = s.ctrl[p.start as usize..(p.start + p.len) as usize]
                    .iter()
                    .map(|&j| pts[j as usize])
                    .collect();
                let params =
                    (0..=16).flat_map(|a| [a as f64 / 16.0, a as f64 / 16.0 * 0.999 + 3e-4]);
                let params: Vec<f64> = params.collect();
                for &u in &params {
                    for &v in &params {
                        if scheme == Scheme::Loop && u + v > 1.0 {
                            continue;
                        }
                        let got = s.eval(SurfaceParam {
                            patch: i as u32,
                            u,
                            v,
                        });
                        let want = s.graph.eval(p.node, &local, u, v);
                        let pairs = [
                            (got.point, want.point, 1e-12),
                            (got.du, want.du, 1e-10),
                            (got.dv, want.dv, 1e-10),
                            (got.duu, want.duu, 1e-8),
                            (got.duv, want.duv, 1e-8),
                            (got.dvv, want.dvv, 1e-8),
                        ];
                        // At a corner (an extraordinary vertex) the derivatives are singular: only
                        // the point is defined. On an edge between the shortcut's sub-patches
                        // (dyadic parameters) the second derivatives may jump (Doo–Sabin is C1,
                        // and so are the others at boundaries and creases): the lookup and the
                        // descent may take different sides.
                        let on = |x: f64| x == 0.0;
                        let corner = [u, v, 1.0 - u - v, 1.0 - u, 1.0 - v]
                            .into_iter()
                            .filter(|&x| on(x))
                            .count()
                            >= 2;
                        let dyadic = |x: f64| (x * 16.0).fract() == 0.0;
                        let outputs = match (corner, dyadic(u) || dyadic(v)) {
                            (true, _) => 1,
                            (false, true) => 3,
                            (false, false) => pairs.len(),
                        };
                        for (k, (g, w, tol)) in pairs.into_iter().take(outputs).enumerate() {
                            assert!(
                                (g - w).length() <= tol * (1.0 + w.length()),
                                "{scheme:?} patch {i} ({u}, {v}) output {k}: {g} vs {w}"
                            );
                        }
                        checked += 1;
                    }
                }
            }
            assert!(checked > 1000, "{scheme:?}: only {checked} samples");
        }
    }
}
