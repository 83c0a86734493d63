//! The simplifier's working mesh and its passes of edge collapses.
//!
//! No priority queue. Each pass costs every edge once and then collapses, in *waves*, the
//! edges that are the cheapest at both their ends among those still open; an end that took
//! part in a collapse is locked until the next pass. The waves of a pass take what a walk
//! through its edges in cost order would (meshoptimizer's scheme, which sorts instead), but a
//! wave's picks share no vertex and are tried in face order, which the spatial numbering of
//! the `locality` module makes an order through memory. Locking keeps the costs of a pass
//! exact (they depend only on the two ends' quadrics and positions), while the collapse test
//! always reads the mesh as it is now: the faces of each vertex are indexed once per pass, a
//! face changed by a collapse of this pass is read through `remap` (a merged vertex points at
//! the vertex it went into, never further, since that one is locked), and the face list is
//! compacted at the end of the pass.
//!
//! The waves run block by block: the open candidates of a block of [`WAVE_BLOCK`] (in face
//! order, so a spatial neighbourhood) go through all their waves before the next block's, so
//! the mesh data a block touches stays in the cache (a vertex whose candidates straddle two
//! blocks is the cheapest end of a candidate within its block); on a 4 M-triangle mesh every
//! wave swept the whole mesh through memory. Once most vertices have merged away, the
//! per-vertex arrays are renumbered densely, in the same order, so late passes do not skip
//! through mostly dead memory either.
//!
//! A pass takes only collapses up to 1.5 times the cost of the `n`-th cheapest edge, where
//! `n` is the number of collapses still needed (or up to the dearest collapse made so far):
//! cheap collapses come first across passes too. When that leaves it with too little, it takes
//! any valid collapse.

use super::check::{Corner, Limits, Ring};
use super::locality::Numbering;
use super::quadric::{placement, Quadric};
use super::rank::cost_at_rank;
use crate::geom::{prefetch, Point3, Vec3};
use crate::mesh::repair::clean::has_area;
use std::mem::take;

/// Below this share of the collapses still needed, a pass does not stop for cost (passes on
/// meshes of odd topology, where most collapses are refused, still make progress).
const MIN_PASS_SHARE: usize = 6;

/// How much dearer than the pass's cost goal a collapse may be (see the module docs).
const GOAL_FACTOR: f64 = 1.5;

/// Waves of a pass: most of what a pass can take comes in the first few; the rest is left to
/// the next pass, which costs its edges anew.
const MAX_WAVES: usize = 8;

/// A wave that tries fewer than one in this many open candidates ends the pass's waves.
const MIN_WAVE_SHARE: usize = 1000;

/// The working index of an input vertex that has been dropped (see
/// [`Engine::drop_dead_vertices`]).
const DROPPED: u32 = u32::MAX;

/// Vertices are renumbered once fewer than one in this many are left with faces.
const DENSE_SHARE: usize = 2;

/// Candidates whose waves run together before the next ones' (a few megabytes of mesh data).
/// On the 4 M-triangle bunny (one thread, the VM's noise ±5 %), blocks of 2 K–64 K candidates
/// took 4.0–4.5 s, one block (no blocking) 5.2 s; the deviation of the result moves with the
/// block size as with any change of order (max 0.65–0.86 %, rms 0.103–0.109 %). This size gave
/// the lowest there and leaves the bunny (whose passes fit in one block) as it was.
const WAVE_BLOCK: usize = 1 << 16;

/// A collapse of edge `a`–`b` (`a < b`) at its cost; NaN once refused.
#[derive(Clone, Copy, Debug)]
struct Candidate {
    a: u32,
    b: u32,
    cost: f64,
}

/// A triangle of the working mesh with the area-weighted normal of the input it stands for:
/// its own input triangle's, plus shares of the faces that collapses removed next to it. A
/// face may never turn against it, which catches fold-overs built up by many small rotations
/// and faces that end up facing away from the surface they replace. One record, as the
/// collapse test reads both for every face around an edge.
#[derive(Clone, Copy, Debug)]
struct Face {
    v: [u32; 3],
    /// The normal in units of [`Engine::normal_unit`], stored compactly: only its direction
    /// is ever tested, against a loose angle.
    normal: [f32; 3],
}

/// The mesh being simplified: an oriented manifold triangle mesh with boundary.
pub(super) struct Engine {
    pos: Vec<Point3>,
    quadric: Vec<Quadric>,

    /// Live triangles, in spatial order.
    tris: Vec<Face>,
    /// Whether every input face had three distinct corners and an area.
    sound: bool,
    /// Whether each vertex has an edge with one face.
    boundary: Vec<bool>,
    /// Faces of vertex `v` at the start of the pass: `faces[start[v]..start[v + 1]]`.
    start: Vec<u32>,
    faces: Vec<u32>,
    /// Faces each vertex has now.
    face_count: Vec<u32>,
    /// The vertex each vertex was merged into in this pass (itself if none).
    remap: Vec<u32>,
    /// Whether each vertex took part in a collapse in this pass.
    locked: Vec<bool>,
    /// Vertices with at least one face.
    live: usize,
    /// Largest cost of any collapse made.
    worst: f64,
    /// The wave under way (see [`Engine::waves`]), counted over all passes.
    wave: u64,
    /// The cheapest candidate of each vertex in a wave: the wave in the high 32 bits, the
    /// candidate's index in the low ones; and its cost, kept beside it so that marking reads
    /// no other candidate.
    cheapest: Vec<(u64, f64)>,
    ring: Ring,
    /// The buffers of a pass, kept from pass to pass: fresh ones of this size would each be
    /// mapped and zeroed by the system anew, which on a large mesh took a fifth of the time.
    dear: Vec<Candidate>,
    open: Vec<Candidate>,
    histogram: Vec<u32>,
    turn: Vec<u32>,
    /// The candidates a wave tries, in order (see [`Engine::block_waves`]).
    picks: Vec<usize>,
    /// How working indices relate to the input's.
    numbering: Numbering,
    /// Whether vertices without faces are dropped from the arrays once they are the majority
    /// (see [`Engine::drop_dead_vertices`]; off only to test that it changes nothing).
    renumber: bool,
    /// Whether ties between equal costs go by a scrambled index rather than the index (see
    /// [`Engine::scramble_ties`]).
    scramble_ties: bool,
    /// The crease neighbours of every vertex (the other ends of its crease edges); empty, with
    /// no entry per vertex, when the mesh has no creases (see [`Engine::crease_plan`]).
    crease: Vec<Vec<u32>>,
}

/// How a collapse respects the crease lines: which end survives, which goes, and where the
/// survivor goes (`None`: the quadric's best place).
#[derive(Clone, Copy, Debug)]
struct Plan {
    survivor: u32,
    removed: u32,
    at: Option<Point3>,
}

impl Engine {
    /// The working mesh of `pos` and the triangles `tris` (an oriented manifold with
    /// boundary; both are copied into working order), with `boundary_weight` for the penalty
    /// planes along open edges and crease edges. `creases` (vertex pairs of `pos`) are kept as
    /// edge chains; pairs that are no edge of `tris` are ignored.
    pub(super) fn new(
        pos: &[Point3],
        tris: &[u32],
        creases: &[[u32; 2]],
        boundary_weight: f64,
    ) -> Engine {
        let n = pos.len();
        let numbering = Numbering::spatial(pos);
        let (pos, tris) = numbering.apply(pos, tris, |v| Face {
            v,
            normal: [0.0; 3],
        });
        let mut e = Engine {
            quadric: Vec::new(),
            pos,
            tris,
            sound: true,
            boundary: vec![false; n],
            start: Vec::new(),
            faces: Vec::new(),
            face_count: vec![0; n],
            remap: (0..n as u32).collect(),
            locked: vec![false; n],
            live: 0,
            worst: 0.0,
            wave: 0,
            cheapest: vec![(0, 0.0); n],
            ring: Ring::default(),
            dear: Vec::new(),
            open: Vec::new(),
            histogram: Vec::new(),
            turn: Vec::new(),
            picks: Vec::new(),
            numbering,
            scramble_ties: false,
            renumber: true,
            crease: Vec::new(),
        };
        e.index_faces();
        e.set_creases(creases);
        e.live = e.face_count.iter().filter(|&&c| c > 0).count();
        e.set_planes(boundary_weight);
        e
    }

    /// Records the crease edges `creases` (input numbering) that are edges of the mesh.
    fn set_creases(&mut self, creases: &[[u32; 2]]) {
        if creases.is_empty() {
            return;
        }
        let mut crease = vec![Vec::new(); self.pos.len()];
        let work = &self.numbering.work;
        for &[x, y] in creases {
            let (Some(&a), Some(&b)) = (work.get(x as usize), work.get(y as usize)) else {
                continue;
            };
            let is_edge = a != b && (self.has_side(a, b) || self.has_side(b, a));
            let list: &mut Vec<u32> = &mut crease[a as usize];
            if is_edge && !list.contains(&b) {
                list.push(b);
                crease[b as usize].push(a);
            }
        }
        self.crease = crease;
    }

    /// Breaks ties between equal costs by a scrambled index from now on, and returns whether
    /// that is new. Ties by index are the better order while they work (their spatial
    /// coherence gave fandisk an initial mesh whose fit converged where the scrambled one's
    /// stalled), but among many equal costs (a flat region, where every collapse costs 0) they
    /// chain: each vertex's pick is its neighbour's second choice, a wave takes one collapse
    /// where it could take a matching, and a finely meshed cube stopped at 1,525 of its 1,538
    /// vertices. So the simplifier scrambles ties only once a pass makes no collapse.
    pub(super) fn scramble_ties(&mut self) -> bool {
        !std::mem::replace(&mut self.scramble_ties, true)
    }

    /// Number of crease edges.
    pub(super) fn num_creases(&self) -> usize {
        self.crease.iter().map(Vec::len).sum::<usize>() / 2
    }

    /// The crease neighbours of `v`.
    fn crease_of(&self, v: u32) -> &[u32] {
        self.crease.get(v as usize).map_or(&[], |c| c.as_slice())
    }

    /// Whether `x`–`y` is a crease edge.
    fn is_crease(&self, x: u32, y: u32) -> bool {
        self.crease_of(x).contains(&y)
    }

    /// How `a`–`b` may collapse so that the crease lines keep their course and their nodes:
    /// a vertex off the creases goes into one on them, which stays where it is; two crease
    /// vertices merge only along a crease edge, and only a vertex inside a line (two crease
    /// edges) goes, into its neighbour on the line (the cheaper of the two places when both
    /// are inside the line): crease vertices stay on the data's lines. Corners (three or more crease edges) and dart ends (one) never
    /// go. `None` when no collapse keeps them, or one would close a line into a triangle of
    /// two edges.
    fn crease_plan(&self, a: u32, b: u32) -> Option<Plan> {
        let (ca, cb) = (self.crease_of(a), self.crease_of(b));
        let plan = |survivor, removed, at| {
            Some(Plan {
                survivor,
                removed,
                at,
            })
        };
        match (ca.len(), cb.len()) {
            (0, 0) => plan(a, b, None),
            (_, 0) => plan(a, b, Some(self.pos(a))),
            (0, _) => plan(b, a, Some(self.pos(b))),
            _ if !ca.contains(&b) || ca.iter().any(|c| cb.contains(c)) => None,
            (2, 2) => {
                let q = self.quadric[a as usize] + self.quadric[b as usize];
                if q.eval(self.pos(b)) < q.eval(self.pos(a)) {
                    plan(b, a, Some(self.pos(b)))
                } else {
                    plan(a, b, Some(self.pos(a)))
                }
            }
            (_, 2) => plan(a, b, Some(self.pos(a))),
            (2, _) => plan(b, a, Some(self.pos(b))),
            _ => None,
        }
    }

    /// Vertices with at least one face.
    pub(super) fn live(&self) -> usize {
        self.live
    }

    /// Position of `v`.
    pub(super) fn pos(&self, v: u32) -> Point3 {
        self.pos[v as usize]
    }

    /// Faces `v` has now.
    pub(super) fn face_count(&self, v: u32) -> u32 {
        self.face_count[v as usize]
    }

    /// Whether `v` is on an open boundary.
    pub(super) fn is_boundary(&self, v: u32) -> bool {
        self.boundary[v as usize]
    }

    /// Number of vertices, with or without faces.
    pub(super) fn num_vertices(&self) -> usize {
        self.pos.len()
    }

    /// The corners of face `f`.
    pub(super) fn face(&self, f: usize) -> [u32; 3] {
        self.tris[f].v
    }

    /// The area-weighted normal of the input face `f` stands for (see [`Face`]), in units of
    /// the engine's own choosing: only its direction means anything.
    pub(super) fn reference_normal(&self, f: u32) -> Vec3 {
        let [x, y, z] = self.tris[f as usize].normal;
        Vec3::new(f64::from(x), f64::from(y), f64::from(z))
    }

    /// Input indices of the vertices in no face, in order.
    pub(super) fn unreferenced_inputs(&self) -> impl Iterator<Item = usize> + '_ {
        let work = &self.numbering.work;
        (0..work.len()).filter(move |&v| !self.has_faces(work[v]))
    }

    /// The faces `v` had at the start of the pass.
    pub(super) fn faces_of(&self, v: u32) -> &[u32] {
        let v = v as usize;
        &self.faces[self.start[v] as usize..self.start[v + 1] as usize]
    }

    /// Appends the faces of `v` (an unlocked vertex) as they are now, seen from `v`, with
    /// merged corners renamed; faces that a collapse in this pass removed are left out.
    pub(super) fn live_corners(&self, v: u32, out: &mut Vec<Corner>) {
        for &f in self.faces_of(v) {
            let t = self.tris[f as usize].v;
            let k = if t[0] == v {
                0
            } else if t[1] == v {
                1
            } else {
                2
            };
            let next = self.remap[t[(k + 1) % 3] as usize];
            let prev = self.remap[t[(k + 2) % 3] as usize];
            if next != prev {
                out.push(Corner {
                    face: f,
                    next,
                    prev,
                });
            }
        }
    }

    /// Indexes the faces of every vertex, finds the boundary vertices and resets the pass
    /// state (merges, locks).
    ///
    /// Around a vertex of a manifold the faces form one fan, in which each face's next corner
    /// is the following face's previous one; so the sum of next minus previous corners over
    /// the vertex's faces is 0 for a closed fan and the difference of the two (distinct)
    /// boundary neighbours for an open one: an exact boundary test with no sorting (exact in
    /// wrapping `u32` arithmetic too, as two distinct indices differ modulo 2³²).
    fn index_faces(&mut self) {
        let n = self.pos.len();
        self.start.clear();
        self.start.resize(n + 1, 0);
        let mut turn = take(&mut self.turn);
        turn.clear();
        turn.resize(n, 0);
        for f in &self.tris {
            let t = f.v;
            for k in 0..3 {
                let (v, next, prev) = (t[k] as usize, t[(k + 1) % 3], t[(k + 2) % 3]);
                self.start[v + 1] += 1;
                turn[v] = turn[v].wrapping_add(next.wrapping_sub(prev));
            }
        }
        for (b, &s) in self.boundary.iter_mut().zip(&turn) {
            *b = s != 0;
        }
        self.turn = turn;
        for v in 0..n {
            self.face_count[v] = self.start[v + 1];
            self.start[v + 1] += self.start[v];
        }
        self.faces.resize(3 * self.tris.len(), 0);
        let mut fill = std::mem::take(&mut self.remap);
        fill.copy_from_slice(&self.start[..n]);
        for (k, f) in self.tris.iter().enumerate() {
            for &v in &f.v {
                self.faces[fill[v as usize] as usize] = k as u32;
                fill[v as usize] += 1;
            }
        }
        for (v, r) in fill.iter_mut().enumerate() {
            *r = v as u32;
        }
        self.remap = fill;
        self.locked.fill(false);
    }

    /// Whether side `x`→`y` of a face is on an open boundary: no face has `y`→`x`. Only
    /// sides between two boundary vertices can be.
    fn is_open_side(&self, x: u32, y: u32) -> bool {
        self.boundary[x as usize] && self.boundary[y as usize] && !self.has_side(y, x)
    }

    /// Whether a face has the side running from `x` to `y`.
    fn has_side(&self, x: u32, y: u32) -> bool {
        self.faces_of(x).iter().any(|&f| {
            let t = self.tris[f as usize].v;
            (0..3).any(|k| t[k] == x && t[(k + 1) % 3] == y)
        })
    }

    /// Sets the faces' reference normals, whether every face is sound (three distinct corners
    /// and an area), and the area-weighted face-plane quadrics at every vertex, plus a penalty
    /// plane along each open edge, perpendicular to its face and weighted by `boundary_weight`
    /// times its squared length (so open boundaries keep their outline), and one for each face
    /// along a crease edge (so the faces on either side keep the crease's course). One sweep
    /// over the faces, as they are many.
    fn set_planes(&mut self, boundary_weight: f64) {
        let unit = 0.5 / normal_unit(&self.pos);
        let mut quadric = vec![Quadric::default(); self.pos.len()];
        let mut sound = true;
        for k in 0..self.tris.len() {
            self.prefetch_corners(k + PREFETCH_AHEAD, &quadric);
            let t = self.tris[k].v;
            let [a, b, c] = t.map(|v| self.pos(v));
            let n = (b - a).cross(c - a);
            self.tris[k].normal = compact(n * unit);
            let sides =
                (b - a).length_squared() + (c - b).length_squared() + (a - c).length_squared();
            sound &= t[0] != t[1] && t[1] != t[2] && t[2] != t[0] && has_area(n.length(), sides);
            let q = Quadric::plane(n.normalize_or_zero(), a, 0.5 * n.length());
            for v in t {
                quadric[v as usize] += q;
            }
            if boundary_weight == 0.0 {
                continue;
            }
            for k in 0..3 {
                let (x, y) = (t[k], t[(k + 1) % 3]);
                if self.is_open_side(x, y) || self.is_crease(x, y) {
                    let (px, py) = (self.pos(x), self.pos(y));
                    let side = (py - px).cross(n).normalize_or_zero();
                    let q = Quadric::plane(side, px, boundary_weight * px.distance_squared(py));
                    quadric[x as usize] += q;
                    quadric[y as usize] += q;
                }
            }
        }
        self.quadric = quadric;
        self.sound = sound;
    }

    /// Asks the processor to load the positions and the `quadric` entries of face `f`'s
    /// corners (nothing when there is no face `f`): see [`PREFETCH_AHEAD`].
    #[inline]
    fn prefetch_corners(&self, f: usize, quadric: &[Quadric]) {
        if let Some(face) = self.tris.get(f) {
            for v in face.v {
                prefetch(&quadric[v as usize]);
                prefetch(&self.pos[v as usize]);
            }
        }
    }

    /// Whether every face of the input had three distinct corners and an area.
    pub(super) fn faces_are_sound(&self) -> bool {
        self.sound
    }

    /// One pass of collapses towards `target` within `limits`; returns how many were made
    /// (none only when no edge could be collapsed).
    pub(super) fn pass(&mut self, target: usize, limits: &Limits) -> usize {
        let (mut dear, mut open) = (take(&mut self.dear), take(&mut self.open));
        let mut histogram = take(&mut self.histogram);
        self.candidates(&mut dear);
        open.clear();
        open.reserve(dear.len());
        let needed = self.live.saturating_sub(target);
        let enough = needed / MIN_PASS_SHARE;
        let goal = GOAL_FACTOR * cost_at_rank(dear.iter().map(|c| c.cost), needed, &mut histogram);
        let mut threshold = goal.max(self.worst);
        let mut done = 0;
        loop {
            // The waves see the candidates up to the threshold; the dearer ones wait.
            dear.retain(|&c| {
                let ends_open = !self.locked[c.a as usize] && !self.locked[c.b as usize];
                if ends_open && c.cost <= threshold {
                    open.push(c);
                }
                ends_open && c.cost > threshold
            });
            done += self.waves(&mut open, target, limits);
            if done > enough || self.live <= target || dear.is_empty() {
                break;
            }
            // Too little within the goal (most collapses refused): admit about as many more
            // candidates as the pass still lacks, cheapest first.
            let lacking = enough + 1 - done;
            let rank = lacking.min(dear.len() - 1);
            threshold = cost_at_rank(dear.iter().map(|c| c.cost), rank, &mut histogram);
        }
        (self.dear, self.open, self.histogram) = (dear, open, histogram);
        self.compact();
        if self.renumber && self.live * DENSE_SHARE < self.pos.len() {
            self.drop_dead_vertices();
        }
        self.index_faces();
        done
    }

    /// Every edge once, costed: from the face side that runs from its lower end, or from its
    /// only side on a boundary.
    fn candidates(&self, out: &mut Vec<Candidate>) {
        out.clear();
        out.reserve(3 * self.tris.len() / 2 + 1);
        for (k, f) in self.tris.iter().enumerate() {
            self.prefetch_corners(k + PREFETCH_AHEAD, &self.quadric);
            let t = f.v;
            for k in 0..3 {
                let (x, y) = (t[k], t[(k + 1) % 3]);
                if x < y || self.is_open_side(x, y) {
                    let (a, b) = (x.min(y), x.max(y));
                    if let Some((_, _, cost)) = self.placed(a, b) {
                        out.push(Candidate { a, b, cost });
                    }
                }
            }
        }
    }

    /// Collapses, in waves, the candidates that are the cheapest at both their ends among
    /// those still open (ends unlocked, not refused). A wave's picks share no vertex and are
    /// tried in face order; a refused candidate gets a NaN cost and is out of the pass.
    /// Returns the collapses made.
    fn waves(&mut self, cands: &mut Vec<Candidate>, target: usize, limits: &Limits) -> usize {
        let mut ring = std::mem::take(&mut self.ring);
        let (mut done, mut kept, mut start) = (0, 0, 0);
        let len = cands.len();
        while start < len {
            let end = (start + WAVE_BLOCK).min(len);
            let (made, left) = self.block_waves(&mut ring, &mut cands[start..end], limits, target);
            done += made;
            cands.copy_within(start..start + left, kept);
            kept += left;
            start = end;
            if self.live <= target {
                cands.copy_within(start..len, kept);
                kept += len - start;
                break;
            }
        }
        cands.truncate(kept);
        self.ring = ring;
        done
    }

    /// The waves of one block of candidates; returns the collapses made and how many
    /// candidates are left open, moved to the front of the block.
    fn block_waves(
        &mut self,
        ring: &mut Ring,
        cands: &mut [Candidate],
        limits: &Limits,
        target: usize,
    ) -> (usize, usize) {
        let mut done = 0;
        let mut len = cands.len();
        let mut picks = take(&mut self.picks);
        for _ in 0..MAX_WAVES {
            len = self.mark_cheapest(&mut cands[..len]);
            let stamp = self.wave << 32;
            let mine = |i: usize, end: u32| self.cheapest[end as usize].0 == stamp | i as u64;
            picks.clear();
            picks.extend((0..len).filter(|&i| mine(i, cands[i].a) && mine(i, cands[i].b)));
            let tried = picks.len();
            for (j, &i) in picks.iter().enumerate() {
                // Two stages: the faces of a later pick, then (now in the cache) the corners
                // of a nearer one.
                if let Some(&ahead) = picks.get(j + 2 * PICKS_AHEAD) {
                    self.prefetch_faces(cands[ahead]);
                }
                if let Some(&ahead) = picks.get(j + PICKS_AHEAD) {
                    self.prefetch_corners_around(cands[ahead]);
                }
                let c = cands[i];
                if !self.try_collapse(ring, c.a, c.b, limits) {
                    cands[i].cost = f64::NAN;
                    continue;
                }
                done += 1;
                self.worst = self.worst.max(c.cost);
                if self.live <= target {
                    self.picks = picks;
                    return (done, len);
                }
            }
            // A wave that finds little to take leaves the rest to the next pass.
            if tried * MIN_WAVE_SHARE < len || tried == 0 {
                break;
            }
        }
        self.picks = picks;
        (done, len)
    }

    /// Asks the processor to load the quadrics of the ends of `c` and the positions of the
    /// corners of their faces (see [`PREFETCH_AHEAD`]), which the collapse test reads next to the
    /// faces themselves; reads the faces, which [`Engine::prefetch_faces`] should have
    /// brought into the cache.
    fn prefetch_corners_around(&self, c: Candidate) {
        for v in [c.a, c.b] {
            prefetch(&self.quadric[v as usize]);
            for &f in self.faces_of(v) {
                for w in self.tris[f as usize].v {
                    prefetch(&self.pos[w as usize]);
                }
            }
        }
    }

    /// Asks the processor to load the faces around the ends of `c` (see [`PREFETCH_AHEAD`]): the
    /// collapse test reads them in an order that hardware prefetching cannot foresee.
    fn prefetch_faces(&self, c: Candidate) {
        for v in [c.a, c.b] {
            for &f in self.faces_of(v) {
                prefetch(&self.tris[f as usize]);
            }
        }
    }

    /// Starts a wave: drops the candidates that are out of the pass (refused, or an end
    /// locked) and marks in `cheapest` the cheapest candidate at each vertex, stamped with the
    /// wave. Ties go to the lower index, or by a scrambled index once
    /// [`Engine::scramble_ties`] is set.
    fn mark_cheapest(&mut self, cands: &mut [Candidate]) -> usize {
        self.wave += 1;
        let scramble_ties = self.scramble_ties;
        let stamp = self.wave << 32;
        let mut kept = 0;
        for i in 0..cands.len() {
            let c = cands[i];
            if c.cost.is_nan() || self.locked[c.a as usize] || self.locked[c.b as usize] {
                continue;
            }
            cands[kept] = c;
            for end in [c.a, c.b] {
                let slot = &mut self.cheapest[end as usize];
                let cheaper = slot.0 >> 32 != self.wave
                    || slot.1 > c.cost
                    || (scramble_ties
                        && slot.1 == c.cost
                        && scramble(kept as u32) < scramble(slot.0 as u32));
                if cheaper {
                    *slot = (stamp | kept as u64, c.cost);
                }
            }
            kept += 1;
        }
        kept
    }

    /// The collapse of `x`–`y` the crease rules allow ([`Engine::crease_plan`]): the
    /// surviving end, the vertex it absorbs, and the survivor's place with its quadric error.
    #[inline]
    fn placed(&self, x: u32, y: u32) -> Option<(Plan, Point3, f64)> {
        let plan = if self.crease.is_empty() {
            Plan {
                survivor: x,
                removed: y,
                at: None,
            }
        } else {
            self.crease_plan(x, y)?
        };
        let q = self.quadric[x as usize] + self.quadric[y as usize];
        let (p, cost) = match plan.at {
            Some(p) => (p, q.eval(p)),
            None => placement(&q, self.pos(x), self.pos(y)),
        };
        Some((plan, p, cost))
    }

    /// Collapses `x`–`y` if the crease rules and the collapse test allow it.
    fn try_collapse(&mut self, ring: &mut Ring, x: u32, y: u32, limits: &Limits) -> bool {
        let Some((plan, p, _)) = self.placed(x, y) else {
            return false;
        };
        let (a, b) = (plan.survivor, plan.removed);
        ring.gather(self, a, b);
        if !ring.topology_allows(self, a, b) || !ring.valence_allows(limits.max_valence) {
            return false;
        }
        if !ring.geometry_allows(self, a, b, p, limits) {
            return false;
        }
        let q = self.quadric[a as usize] + self.quadric[b as usize];
        self.merge(ring, a, b, p, q);
        true
    }

    /// Hands `b`'s crease edges to `a` (which `b` merges into).
    fn merge_creases(&mut self, a: u32, b: u32) {
        if self.crease.is_empty() {
            return;
        }
        let moved = take(&mut self.crease[b as usize]);
        for c in moved.into_iter().filter(|&c| c != a) {
            for w in self.crease[c as usize].iter_mut().filter(|w| **w == b) {
                *w = a;
            }
            self.crease[a as usize].push(c);
        }
        self.crease[a as usize].retain(|&w| w != b);
    }

    /// Merges `b` into `a`, which moves to `p` and takes the summed quadric `q`.
    fn merge(&mut self, ring: &Ring, a: u32, b: u32, p: Point3, q: Quadric) {
        let (ai, bi) = (a as usize, b as usize);
        self.remap[bi] = a;
        self.merge_creases(a, b);
        self.pos[ai] = p;
        self.quadric[ai] = q;
        self.boundary[ai] |= self.boundary[bi];
        self.locked[ai] = true;
        self.locked[bi] = true;
        self.face_count[ai] = ring.surviving_faces() as u32;
        self.face_count[bi] = 0;
        for &w in ring.opposite() {
            self.face_count[w as usize] -= 1;
        }
        for (face, heirs) in ring.removed_faces(a, b) {
            let share = self.reference_normal(face) / heirs.iter().flatten().count().max(1) as f64;
            for g in heirs.into_iter().flatten() {
                let normal = compact(self.reference_normal(g) + share);
                self.tris[g as usize].normal = normal;
            }
        }
        self.live -= 1;
    }

    /// Renames merged corners and drops the faces the pass removed (order kept).
    fn compact(&mut self) {
        let remap = &self.remap;
        self.tris.retain_mut(|f| {
            f.v = f.v.map(|w| remap[w as usize]);
            f.v[0] != f.v[1] && f.v[1] != f.v[2] && f.v[2] != f.v[0]
        });
    }

    /// Whether working vertex `w` (or [`DROPPED`]) has faces.
    fn has_faces(&self, w: u32) -> bool {
        self.face_count.get(w as usize).is_some_and(|&c| c > 0)
    }

    /// Drops the vertices without faces from the per-vertex arrays, keeping the others in
    /// order, so that late passes, which have most of the input's vertices behind them, read
    /// dense arrays. Every comparison of indices, and with it every result, stays as it was.
    fn drop_dead_vertices(&mut self) {
        let n = self.pos.len();
        let mut used = vec![false; n];
        for f in &self.tris {
            f.v.iter().for_each(|&w| used[w as usize] = true);
        }
        let mut new = vec![DROPPED; n];
        let mut k = 0;
        for (v, _) in used.iter().enumerate().filter(|(_, &u)| u) {
            new[v] = k;
            k += 1;
        }
        let k = k as usize;
        keep_used(&mut self.pos, &used);
        keep_used(&mut self.quadric, &used);
        keep_used(&mut self.boundary, &used);
        if !self.crease.is_empty() {
            keep_used(&mut self.crease, &used);
            for list in &mut self.crease {
                list.iter_mut().for_each(|w| *w = new[*w as usize]);
            }
        }
        for f in &mut self.tris {
            f.v = f.v.map(|w| new[w as usize]);
        }
        for w in &mut self.numbering.work {
            *w = new.get(*w as usize).copied().unwrap_or(DROPPED);
        }
        self.face_count.truncate(k);
        self.remap.truncate(k);
        self.locked.truncate(k);
        self.cheapest.clear();
        self.cheapest.resize(k, (0, 0.0));
    }

    /// The largest valence of any vertex.
    pub(super) fn max_valence(&self) -> usize {
        let mut around = Vec::new();
        (0..self.pos.len() as u32)
            .map(|v| {
                around.clear();
                for &f in self.faces_of(v) {
                    around.extend(self.tris[f as usize].v.into_iter().filter(|&w| w != v));
                }
                around.sort_unstable();
                around.dedup();
                around.len()
            })
            .max()
            .unwrap_or(0)
    }

    /// The used vertices (in input order), the faces and the crease edges (smaller end first,
    /// sorted), renumbered to them.
    pub(super) fn into_parts(self) -> (Vec<Point3>, Vec<u32>, Vec<[u32; 2]>) {
        let mut new = vec![u32::MAX; self.pos.len()];
        let mut positions = Vec::with_capacity(self.live);
        for &w in &self.numbering.work {
            if self.has_faces(w) {
                new[w as usize] = positions.len() as u32;
                positions.push(self.pos[w as usize]);
            }
        }
        let tris = self
            .tris
            .iter()
            .flat_map(|f| f.v.map(|v| new[v as usize]))
            .collect();
        let mut creases: Vec<[u32; 2]> = (0..self.crease.len())
            .filter(|&v| self.face_count[v] > 0)
            .flat_map(|v| self.crease[v].iter().map(move |&w| (v, w as usize)))
            .map(|(v, w)| [new[v], new[w]])
            .filter(|&[x, y]| x < y && y != u32::MAX)
            .collect();
        creases.sort_unstable();
        (positions, tris, creases)
    }
}

/// The unit of the stored reference normals of `pos`: the square of its bounding box's largest
/// side (1 for a single point), so that a face's stored normal is at most about 1.
fn normal_unit(pos: &[Point3]) -> f64 {
    let lo = pos.iter().fold(Point3::INFINITY, |a, &p| a.min(p));
    let hi = pos.iter().fold(Point3::NEG_INFINITY, |a, &p| a.max(p));
    let side = (hi - lo).max_element();
    if side > 0.0 && side.is_finite() {
        side * side
    } else {
        1.0
    }
}

/// `values` without the entries whose `used` flag is false, in order.
fn keep_used<T>(values: &mut Vec<T>, used: &[bool]) {
    let mut flags = used.iter();
    values.retain(|_| flags.next().copied().unwrap_or(false));
}

/// A bijection of `u32` that scatters neighbouring indices (the finaliser of MurmurHash3).
fn scramble(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x85eb_ca6b);
    x ^= x >> 13;
    x = x.wrapping_mul(0xc2b2_ae35);
    x ^ (x >> 16)
}

/// How many picks of a wave ahead of the collapse under test [`Engine::block_waves`]
/// prefetches the corners of (and twice as many ahead, the faces).
const PICKS_AHEAD: usize = 2;

/// How many faces ahead the sweeps over all faces ([`Engine::candidates`],
/// [`Engine::set_planes`]) prefetch their corners' data.
///
/// Why prefetch at all: the sweeps read each corner's quadric and position, which on a large
/// mesh sit far apart in memory (Morton order keeps most neighbours close, not all), so they
/// stalled on the loads: the costing of edges waited on its quadrics about 40 % of its time
/// (perf, 4.4 M triangles); so did the collapse test on the faces and positions around an edge.
/// Prefetching took about 5 % (the sweeps) and 9 % (the waves) off the whole simplification of
/// the 4.4 M mesh, 9 % off the bunny's in a warm process, with identical results (interleaved
/// runs, see docs/subdivision.md).
const PREFETCH_AHEAD: usize = 16;

/// `n` in compact storage.
fn compact(n: Vec3) -> [f32; 3] {
    [n.x as f32, n.y as f32, n.z as f32]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A closed, bumpy sphere of `n` × `n` quads per cube side, split into triangles.
    fn bumpy_sphere(n: u32) -> (Vec<Point3>, Vec<u32>) {
        let mut pos = Vec::new();
        let mut tris = Vec::new();
        let mut index = std::collections::HashMap::new();
        let mut vertex = |p: [i64; 3], pos: &mut Vec<Point3>| {
            *index.entry(p).or_insert_with(|| {
                let v = Vec3::new(p[0] as f64, p[1] as f64, p[2] as f64).normalize();
                let bump = 1.0 + 0.05 * (7.0 * v.x).sin() * (5.0 * v.y).cos();
                pos.push(v * bump);
                pos.len() as u32 - 1
            })
        };
        let h = i64::from(n);
        for axis in 0..3 {
            for sign in [-1i64, 1] {
                for i in 0..h {
                    for j in 0..h {
                        let corner = |a: i64, b: i64| {
                            let mut p = [0i64; 3];
                            p[axis] = sign * h;
                            p[(axis + 1) % 3] = 2 * a - h;
                            p[(axis + 2) % 3] = 2 * b - h;
                            p
                        };
                        let q = [
                            corner(i, j),
                            corner(i + 1, j),
                            corner(i + 1, j + 1),
                            corner(i, j + 1),
                        ]
                        .map(|p| vertex(p, &mut pos));
                        let q = if sign > 0 {
                            q
                        } else {
                            [q[0], q[3], q[2], q[1]]
                        };
                        tris.extend([q[0], q[1], q[2], q[0], q[2], q[3]]);
                    }
                }
            }
        }
        (pos, tris)
    }

    #[test]
    fn dropping_dead_vertices_changes_no_result() {
        let (pos, tris) = bumpy_sphere(24);
        let limits = Limits {
            min_normal_cos: 0.5,
            min_quality: 0.1,
            max_valence: 16,
            min_reference_cos: 0.25,
        };
        let run = |renumber: bool| {
            let mut e = Engine::new(&pos, &tris, &[], 10.0);
            e.renumber = renumber;
            let mut dropped = false;
            while e.live() > 40 && e.pass(40, &limits) > 0 {
                dropped |= e.pos.len() < pos.len();
            }
            (dropped, e.into_parts())
        };
        let (dropped, renumbered) = run(true);
        let (kept, plain) = run(false);
        assert!(dropped && !kept);
        assert_eq!(renumbered, plain);
    }
}
