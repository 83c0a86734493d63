//! The subdivision-surface fitter (SPEC §1): foot points by Newton on the limit surface, error
//! vectors, weighted control-point moves, acceleration with damping, and local refinement.

mod control;
mod feet;
mod frozen;
mod index;
mod options;
mod setup;

pub use control::surface_of;
pub use feet::{FootPointBench, FootPointTiming};
pub use options::{SubdivFitOptions, Weighting};
pub(crate) use setup::build_subdiv_fitter;
pub(crate) use setup::find_creases;
pub use setup::{default_initial_count, initial_control, CreaseReport, ReconstructionReport};

use super::accel::Accelerator;
use super::parallel;
use super::stall::{stalled, STALL_WINDOW};
use super::{
    Acceleration, DataSurface, ErrorStats, FitError, FitLog, FitState, FitStatus, Fitter, Method,
    PhaseTimes, Scheme, Shape, BACK_TOLERANCE_FACTOR,
};
use crate::geom::{ClosestPoint, Nearest, NewtonOptions, Point3, Vec3};
use crate::mesh::PolyMesh;
use crate::progress::{self, Part, Phase};
use crate::subdiv::{
    grid_params, tessellate, LimitSurface, PatchDomain, SubdivError, SurfaceParam,
};
use frozen::{Fairness, PointFrame, Stencils};
use index::SurfaceIndex;
use std::collections::HashSet;
use web_time::Instant;

/// A refinement after which E_rms is more than this many times what it was is undone: Loop's
/// and Catmull–Clark's splits change the surface little (not at all away from the split
/// faces), so such a jump means a broken split, not a worse fit. (One seen: 7 faces of
/// fandisk's Catmull–Clark cage beside its creases, E_rms 3.7 × after the split; kept, the fit
/// stalled at E_back 0.19 % where undoing it converged.)
const REFINE_WORSE_FACTOR: f64 = 2.0;

/// [`REFINE_WORSE_FACTOR`] for Doo–Sabin, whose split is no Doo–Sabin step and moves the
/// surface: a sound split raised rocker-arm's E_rms 2.3 × at E_max 0.05 %, and undoing every
/// such split left that fit at its initial control points (E_max 0.70 % to the end). The
/// broken splits the guard is for sent E_avg to 19 % (alligator) and 7e9 % (fandisk's points).
const DOO_SABIN_WORSE_FACTOR: f64 = 5.0;

/// Where the set-up's progress stands when the spatial index and patches are built (before
/// them: the data's reference surface for E_back, made by `build_subdiv_fitter`).
const SETUP_INDEX: f64 = 0.4;

/// The set-up's share for its foot points (the surface → data distances come after).
const SETUP_FEET: Part = Part {
    phase: Phase::Setup,
    from: 0.5,
    to: 0.95,
};

/// Progress of an iteration: moving the control points (foot points and the solve) takes
/// most of it, then the surface → data distances and, when due, a refinement, whose new foot
/// points report in the refinement's share.
const ITERATION_MOVED: f64 = 0.6;
const ITERATION_MEASURED: f64 = 0.75;
const REFINE_FEET: Part = Part {
    phase: Phase::Iteration,
    from: 0.8,
    to: 0.95,
};

/// A refinement that adds less than this share of the control points (or a budget with less
/// room than that) no longer changes a fit's course: it does not restart the stall window.
const MIN_GROWTH: f64 = 0.01;

/// Below this share of the option's weight a control point's fairness is switched off.
const FAIRNESS_FLOOR: f64 = 1e-6;

/// The most a control point's fairness grows to, in multiples of the option's weight.
const FAIRNESS_CAP: f64 = 16.0;

/// A control point whose weight in a straying sample's stencil is below this does not shape
/// the surface there enough to be held for it.
const STRAY_STENCIL_WEIGHT: f64 = 0.01;
/// The weight of a surface → data row in the moves, per data point a sample stands for.
const PULL_BACK: f64 = 1.0;
/// The least share of [`PULL_BACK`] that [`SubdivFitter::ease_pull`] eases it to.
const MIN_PULL_SCALE: f64 = 1.0 / 64.0;

/// A point farther than this share of the E_max tolerance from the surface gains weight while
/// E_max is missed ([`SubdivFitter::adapt_point_weights`]).
const PULL_FROM: f64 = 0.9;

/// The most weight a pulled point gets, relative to the others.
const PULL_CAP: f64 = 64.0;

/// While points are pulled, a move that raises E_max past its tolerance by more than this
/// factor is damped like one that raises the objective ([`SubdivFitter::max_jumped`]).
const MAX_JUMP: f64 = 1.25;

/// The longest move of a weakly supported control point in one iteration, in mean lengths
/// of its control edges ([`SubdivFitter::move_reach`]). Why: where the data barely reaches
/// a control point, a CG solve can swing it by several times its spacing while the data
/// errors still fall, and the damping, which judges the data errors, lets it through:
/// suzanne's 507 vertices as bare points with Catmull–Clark (1,067 control points) stalled
/// with a sheet 30.8 % of the diagonal from suzanne's mesh.
const MOVE_REACH: f64 = 1.0;

/// The control points whose move [`MOVE_REACH`] limits: data support Σ_i B_ij² below this
/// share of the median. Where the data is dense enough, large moves are the data's own: with
/// every point limited the bunny at Table 1 model C ended at E_max 0.10 % instead of 0.056 %;
/// with a quarter of the median instead of a tenth, Catmull–Clark's E_max there rose by 18 %
/// on average over six rotated copies.
const WEAK_REACH_SUPPORT: f64 = 0.1;

/// `moves` with every move longer than its point's `reach` shortened to it.
fn capped(mut moves: Vec<Vec3>, reach: &[f64]) -> Vec<Vec3> {
    for (m, &r) in moves.iter_mut().zip(reach) {
        let l = m.length();
        if l > r {
            *m *= r / l;
        }
    }
    moves
}

/// How far E_back may rise in one move past its bound before the move is shortened
/// ([`SubdivFitter::damp_back_jump`]), as a factor of E_back before it.
const BACK_JUMP: f64 = 1.5;

/// The surface → data check that a fit must pass to converge samples each patch at the centres
/// of this many × this many cells (of its square, or of its triangle split into this many
/// squared small triangles), besides the two samples per patch measured every iteration; see
/// [`SubdivFitter::passes_dense_check`].
const DENSE_CELLS: u32 = 4;

/// Patches that the dense check finds within half the surface → data bound are sampled again
/// on a lattice of this many segments per patch edge (the vertices of a 16-segment display
/// tessellation): the distance to a scan changes fast near its outline and its holes, faster
/// than cell centres a quarter of a patch apart follow.
const SUSPECT_LATTICE: usize = 16;

/// Patches per chunk of [`SubdivFitter::measure_back_samples`].
const BACK_CHUNK: usize = 4096;

/// What a surface → data measure keeps of its samples, chunk by chunk, in sample order.
struct BackTally {
    limit: f64,
    tol: f64,
    pull: bool,
    /// Every sample's distance (`None` over a hole of the data).
    distances: Vec<Option<f64>>,
    /// The samples beyond `limit` with the data point nearest to each, when `pull`.
    pulls: Vec<(SurfaceParam, Point3)>,
    /// The samples beyond `tol`.
    strays: Vec<SurfaceParam>,
    /// The patches with a sample beyond half of `tol`, and beyond `limit`.
    beyond_half: HashSet<u32>,
    beyond_limit: HashSet<u32>,
}

impl BackTally {
    fn new(limit: f64, tol: f64, pull: bool) -> BackTally {
        BackTally {
            limit,
            tol,
            pull,
            distances: Vec::new(),
            pulls: Vec::new(),
            strays: Vec::new(),
            beyond_half: HashSet::new(),
            beyond_limit: HashSet::new(),
        }
    }

    /// Takes the samples at `params`, with their nearest data `closest`.
    fn add(&mut self, params: &[SurfaceParam], closest: &[Option<(f64, Point3)>]) {
        for (&at, &c) in params.iter().zip(closest) {
            self.distances.push(c.map(|(d, _)| d));
            let Some((d, q)) = c else { continue };
            if d > 0.5 * self.tol {
                self.beyond_half.insert(at.patch);
            }
            if d > self.limit {
                self.beyond_limit.insert(at.patch);
                if self.pull {
                    self.pulls.push((at, q));
                }
            }
            if d > self.tol {
                self.strays.push(at);
            }
        }
    }
}

/// A data point's foot point on the limit surface.
type FootPoint = Nearest<SurfaceParam>;

/// A limit surface the fitter can rebuild from a control mesh, so that refinement (which changes
/// the connectivity) can continue with the same scheme.
pub trait ControlSurface: LimitSurface + ClosestPoint<Param = SurfaceParam> + Sized + Sync {
    /// The subdivision scheme.
    fn scheme(&self) -> crate::subdiv::Scheme;

    /// The control mesh: polygons and current control points. Face `i` holds patch `i`'s
    /// foot points as far as [`ControlSurface::patch_face`] says.
    fn control_polygons(&self) -> PolyMesh;

    /// The surface of the same scheme over `control` (new connectivity).
    fn rebuild(&self, control: &PolyMesh) -> Result<Self, FitError>;

    /// The face of [`ControlSurface::control_polygons`] that `patch` belongs to; an index past
    /// the last face means "no single face" (such patches are never refined).
    fn patch_face(&self, patch: u32) -> usize;

    /// Splits the `marked` faces of `control` (one flag per face) and what conformity needs
    /// around them, placing new points so that the limit surface changes as little as possible.
    fn refine_control(&self, control: &PolyMesh, marked: &[bool]) -> Result<PolyMesh, FitError>;

    /// The patch of the surface this one was rebuilt from ([`ControlSurface::rebuild`]) that
    /// `patch` is an exact copy of, if any: foot points there carry over without a search. The
    /// default knows of none.
    fn kept_patch(&self, patch: u32) -> Option<u32> {
        let _ = patch;
        None
    }

    /// The surface as a [`SubdivSurface`](crate::subdiv::SubdivSurface), when it is one (for
    /// the FEM mesh); the default is none.
    fn as_subdiv(&self) -> Option<&crate::subdiv::SubdivSurface> {
        None
    }

    /// Local remeshing after a refinement (edge flips for triangle schemes) of `control`, the
    /// result of [`ControlSurface::refine_control`] on this surface's mesh (its vertices past
    /// this surface's control points are the new ones). Returns the number of changes; the
    /// default makes none.
    fn remesh_control(&self, control: &mut PolyMesh) -> Result<usize, FitError> {
        let _ = control;
        Ok(0)
    }
}

/// Fits the limit surface of a subdivision scheme `S` to data points by geometric iteration.
///
/// Build it with [`SubdivFitter::try_new`], then drive it through [`Fitter`]. Everything before
/// the first iteration (surface set-up, spatial index, first foot points) is the precompute
/// phase, timed in its [`FitLog`].
pub struct SubdivFitter<S: ControlSurface> {
    state: FitState,
    surface: S,
    feet: Vec<FootPoint>,
    options: SubdivFitOptions,
    /// `options.newton` with its step tolerance in model units.
    newton: NewtonOptions,
    since_refine: usize,
    /// Iterations since a refinement last added [`MIN_GROWTH`] of the control points: the
    /// stall window (a few points added near the budget do not change a fit's course).
    since_growth: usize,
    /// Whether the last refinement that was due added nothing (the budget left is smaller
    /// than any split, or nothing was worth splitting).
    refine_exhausted: bool,
    /// Whether the last refinement that was due added less than [`MIN_GROWTH`] of the control
    /// points: such refinements do not change the fit's course, so they do not keep the stall
    /// rule from stopping it. Refining by a handful of points every other iteration had kept
    /// fandisk (with creases, at E_avg 0.01 % / E_max 0.05 %) running for 160 iterations
    /// with nothing changing.
    refine_futile: bool,
    /// The fairness weight of every control point's umbrella in the next move, relative to
    /// the median data support (see [`SubdivFitter::adapt_fairness`]).
    fairness: Vec<f64>,
    /// The part of [`SubdivFitter::fairness`] that holds every control point.
    global_fairness: f64,
    /// The part of [`SubdivFitter::fairness`] that holds the surface where it strays.
    local_fairness: Vec<f64>,
    /// The surface samples of the last [`SubdivFitter::measure_back`] that keep the fit from
    /// converging: farther from the data than [`BACK_TOLERANCE_FACTOR`] E_max tolerances.
    strays: Vec<SurfaceParam>,
    /// The surface samples of the last [`SubdivFitter::measure_back`] farther from the data
    /// than the E_max tolerance, each with the nearest data point, and the weight of each in
    /// the moves (see [`SubdivFitter::back_rows`]).
    pulls: Vec<(SurfaceParam, Point3)>,
    pull_weight: f64,
    /// A factor on [`PULL_BACK`]: halved after every move that the damping of
    /// [`SubdivFitter::move_control_points`] undid while samples were pulled, doubled back (up
    /// to 1) after every move kept ([`SubdivFitter::ease_pull`]).
    pull_scale: f64,
    /// Surface samples a move threw off the data, held since at the data point nearest to
    /// where they were before it ([`SubdivFitter::damp_back_jump`]), until a refinement
    /// renumbers the patches. They make the moves remember where the surface swung.
    holds: Vec<(SurfaceParam, Point3)>,
    /// Whether the last surface → data measure sampled every patch densely
    /// ([`SubdivFitter::passes_dense_check`]).
    back_dense: bool,
    /// Patches sampled densely in every measure: those where the dense check last found the
    /// surface beyond the E_max tolerance, until a refinement renumbers the patches. Their
    /// samples are pulled every iteration, so a fit that failed the check works on what the
    /// check found rather than on what two samples per patch see.
    dense_patches: HashSet<u32>,
    /// Every data point's weight in the moves (see [`SubdivFitter::adapt_point_weights`]).
    point_weights: Vec<f64>,
    accel: Accelerator,
    index: SurfaceIndex,
    scratch: Vec<(u32, f64)>,
    /// Where the iteration under way spends its time.
    phases: PhaseTimes,
    /// The best iteration since the last refinement ([`SubdivFitter::go_back_to_best`]).
    best: Option<Best>,
}

/// The state before a move, to shorten or undo it.
struct Before {
    points: Vec<Point3>,
    feet: Vec<FootPoint>,
    signed: Vec<f64>,
    stats: ErrorStats,
    objective: f64,
    /// E_back before the move (% of the diagonal), when measured.
    back_max_pct: Option<f64>,
}

/// An iteration a fit may go back to: its [`FitState::shortfall`], number, control points
/// and foot points.
struct Best {
    shortfall: f64,
    iteration: usize,
    points: Vec<Point3>,
    feet: Vec<FootPoint>,
}

impl<S: ControlSurface> SubdivFitter<S> {
    /// A fitter of `data_points` starting from the limit surface `surface` (its control mesh is
    /// the initial one). Data points need no connectivity.
    pub fn with_surface(
        data_points: &[Point3],
        surface: S,
        options: SubdivFitOptions,
    ) -> Result<Self, FitError> {
        let start = Instant::now();
        progress::report(Phase::Setup, SETUP_INDEX);
        options.validate()?;
        crate::geom::check_coordinates(data_points)?;
        if data_points.is_empty() {
            return Err(FitError::TooFewPoints {
                found: 0,
                needed: 1,
            });
        }
        let control = surface.control_polygons();
        if control.num_faces() == 0 || surface.num_patches() == 0 {
            return Err(FitError::EmptyControlMesh);
        }
        let index = SurfaceIndex::build(&surface, options.index_resolution);
        let state = FitState::new(
            (Scheme::from(surface.scheme()), Method::Geometric),
            options.tolerances,
            data_points.to_vec(),
            control.num_vertices(),
            start,
        );
        let diagonal = state.diagonal();
        let mut fitter = SubdivFitter {
            state,
            surface,
            feet: Vec::new(),
            newton: options
                .newton
                .with_step_tol(options.newton.step_tol * diagonal),
            options,
            since_refine: 0,
            since_growth: 0,
            refine_exhausted: false,
            refine_futile: false,
            fairness: Vec::new(),
            global_fairness: 0.0,
            local_fairness: Vec::new(),
            strays: Vec::new(),
            holds: Vec::new(),
            pulls: Vec::new(),
            pull_weight: 0.0,
            pull_scale: 1.0,
            back_dense: false,
            dense_patches: HashSet::new(),
            point_weights: vec![1.0; data_points.len()],
            accel: Accelerator::new(options.acceleration),
            index,
            scratch: Vec::new(),
            phases: PhaseTimes::default(),
            best: None,
        };
        progress::report(Phase::Setup, SETUP_FEET.from);
        fitter.search_all_feet(SETUP_FEET)?;
        fitter.measure_back();
        progress::report(Phase::Setup, 1.0);
        let n = fitter.log().initial_control_points();
        *fitter.state.log_mut() = FitLog::new(n, start);
        Ok(fitter)
    }

    /// The current limit surface.
    pub fn surface(&self) -> &S {
        &self.surface
    }

    /// The current control mesh (connectivity and control points).
    pub fn control_mesh(&self) -> PolyMesh {
        self.surface.control_polygons()
    }

    /// Current foot point of every data point, in data order.
    pub fn foot_points(&self) -> &[FootPoint] {
        &self.feet
    }

    /// Error vector e_i = p_i − S(t_i) of every data point.
    pub fn error_vectors(&self) -> Vec<Vec3> {
        self.state
            .data()
            .iter()
            .zip(&self.feet)
            .map(|(p, f)| *p - f.point)
            .collect()
    }

    /// The options in force.
    pub fn options(&self) -> &SubdivFitOptions {
        &self.options
    }

    /// The limit surface tessellated with `resolution` segments per patch edge (clamped to
    /// 1..=64), for display and export (patches are not welded to each other).
    pub fn limit_mesh(&self, resolution: usize) -> PolyMesh {
        let t = tessellate(&self.surface, resolution.clamp(1, 64));
        PolyMesh::try_new(t.positions, t.triangles).unwrap_or_default()
    }

    /// The control-point budget: the option, or half the number of data points.
    fn budget(&self) -> usize {
        self.options
            .max_control
            .unwrap_or(self.state.data().len() / 2)
            .max(self.state.log().initial_control_points())
    }

    /// The E_max tolerance in model units (it is given in % of the diagonal), if there is one.
    fn max_tolerance(&self) -> Option<f64> {
        self.state
            .tolerances()
            .max_pct
            .map(|t| t / 100.0 * self.state.diagonal())
    }

    /// Global search: every foot point from the spatial index, then Newton.
    fn search_all_feet(&mut self, part: Part) -> Result<(), FitError> {
        let opts = self.newton;
        self.feet = feet::cold_feet(&self.surface, &self.index, self.state.data(), &opts, part)
            .map_err(|point| FitError::NoSurfaceNear { point })?;
        self.update_errors();
        Ok(())
    }

    /// Warm-started Newton from the previous foot points; a point whose result is suspect (not
    /// converged, or much farther than before) is searched again from the spatial index, and
    /// the better of the two results is kept.
    fn update_feet(&mut self, previous: &[FootPoint]) {
        let started = Instant::now();
        let opts = self.newton;
        let slack = feet::WARM_SLACK * self.state.diagonal();
        feet::warm_feet(
            &self.surface,
            &self.index,
            self.state.data(),
            previous,
            &opts,
            slack,
            &mut self.feet,
        );
        self.update_errors();
        self.phases.add(|p| &mut p.feet_ms, started);
    }

    /// Signed distances and statistics from the current foot points.
    fn update_errors(&mut self) {
        let signed = self
            .state
            .data()
            .iter()
            .zip(&self.feet)
            .map(|(p, f)| {
                let d = f.dist_sq.sqrt();
                let s = if (*p - f.point).dot(f.direction) < 0.0 {
                    -d
                } else {
                    d
                };
                if s.is_finite() {
                    s
                } else {
                    f64::MAX
                }
            })
            .collect();
        self.state.set_errors(signed);
    }

    /// The move of every control point: the normalised weighted sum of the error vectors
    /// (patent or basis weights).
    fn moves(&mut self) -> Vec<Vec3> {
        let n = self.num_control_points();
        let mut sum = vec![Vec3::ZERO; n];
        let mut weight = vec![0.0; n];
        for ((p, f), &omega) in self
            .state
            .data()
            .iter()
            .zip(&self.feet)
            .zip(&self.point_weights)
        {
            let e = *p - f.point;
            self.scratch.clear();
            match self.options.weighting {
                Weighting::Patent => self.surface.corner_weights(f.param, &mut self.scratch),
                Weighting::Basis => self.surface.stencil(f.param, &mut self.scratch),
            }
            for &(j, w) in &self.scratch {
                let w = w * omega;
                if let (Some(s), Some(t)) = (sum.get_mut(j as usize), weight.get_mut(j as usize)) {
                    *s += e * w;
                    *t += w;
                }
            }
        }
        sum.iter()
            .zip(&weight)
            .map(|(s, &w)| if w > 1e-12 { *s / w } else { Vec3::ZERO })
            .collect()
    }

    /// The weighted sum of squared distances that the moves lower (E_rms² times the number of
    /// points while every weight is 1).
    fn objective(&self) -> f64 {
        let data: f64 = self
            .state
            .errors()
            .iter()
            .zip(&self.point_weights)
            .map(|(d, w)| w * d * d)
            .sum();
        let back: f64 = self.back_rows().0.iter().map(|e| e.length_squared()).sum();
        data + self.pull_weight * back
    }

    /// The surface → data rows of the moves: from every sample in [`SubdivFitter::pulls`] to
    /// its data point, with the direction of each. Data → surface distances alone never pull a
    /// sheet that no data point is nearest to (a web across the gap between two legs); these
    /// rows do, to the data the sheet should lie on.
    fn back_rows(&self) -> (Vec<Vec3>, Vec<Vec3>) {
        let pulls = self.pulls.iter().map(|&(at, q)| {
            let e = q - self.surface.eval(at).point;
            (e, e.normalize_or_zero())
        });
        let holds = self.holds.iter().map(|&(at, q)| {
            let s = self.surface.eval(at);
            (q - s.point, s.du.cross(s.dv).normalize_or_zero())
        });
        pulls.chain(holds).unzip()
    }

    /// The control mesh's crease edges (none for a surface that is no [`SubdivSurface`]).
    ///
    /// [`SubdivSurface`]: crate::subdiv::SubdivSurface
    fn creases(&self) -> Vec<[u32; 2]> {
        self.surface
            .as_subdiv()
            .map(|s| s.control_mesh().creases())
            .unwrap_or_default()
    }

    /// One move of the control points with damping: a move that raises the weighted squared
    /// error ([`SubdivFitter::objective`]) is halved (twice at most) and otherwise undone.
    /// Returns whether a move was kept.
    fn move_control_points(&mut self) -> Option<Before> {
        let before = Before {
            points: self.surface.control_points().to_vec(),
            feet: self.feet.clone(),
            signed: self.state.errors().to_vec(),
            stats: self.state.stats(),
            objective: self.objective(),
            back_max_pct: self.state.back().map(|b| b.max_pct),
        };
        let (old_points, old_feet) = (&before.points, &before.feet);
        let (old_stats, old_objective) = (before.stats, before.objective);
        let started = Instant::now();
        let mut weak = Vec::new();
        let d = match self.options.acceleration {
            Acceleration::Cg { inner } => {
                let pulls = self.pulls.iter().chain(&self.holds).map(|&(at, _)| at);
                let stencils = Stencils::build(
                    &self.surface,
                    self.feet.iter().map(|f| f.param).chain(pulls),
                );
                weak = stencils.weakly_supported(WEAK_REACH_SUPPORT);
                let (back_errors, back_normals) = self.back_rows();
                let mut errors = self.error_vectors();
                errors.extend(back_errors);
                let mut normals: Vec<Vec3> = self.feet.iter().map(|f| f.direction).collect();
                normals.extend(back_normals);
                let mut weights = self.point_weights.clone();
                weights.resize(errors.len(), self.pull_weight);
                let fairness = self
                    .fairness
                    .iter()
                    .any(|&w| w > 0.0)
                    .then(|| Fairness::of(&self.surface.control_polygons(), &self.creases()));
                let fair = fairness
                    .as_ref()
                    .map(|f| (f, old_points.as_slice(), self.fairness.as_slice()));
                let frame = PointFrame {
                    normals: &normals,
                    tangent_weight: self.options.tangent_weight,
                    weights: &weights,
                };
                stencils.cg(&errors, frame, inner, fair)
            }
            _ => self.moves(),
        };
        self.phases.add(|p| &mut p.moves_ms, started);
        let reach = self.move_reach(old_points, &weak);
        let d = capped(d, &reach);
        let proposal = self.accel.propose(old_points, &d);
        let steps = proposal
            .iter()
            .zip(old_points)
            .map(|(p, o)| *p - *o)
            .collect();
        let proposal: Vec<Point3> = old_points
            .iter()
            .zip(capped(steps, &reach))
            .map(|(o, v)| *o + v)
            .collect();
        self.set_points(&proposal);
        self.update_feet(old_feet);
        if !self.options.damping
            || (self.objective() <= old_objective * (1.0 + 1e-12) && !self.max_jumped(&old_stats))
        {
            return Some(before);
        }
        self.accel.reset();
        for t in [0.5, 0.25] {
            let damped: Vec<Point3> = old_points
                .iter()
                .zip(&d)
                .map(|(p, v)| *p + *v * t)
                .collect();
            self.set_points(&damped);
            self.update_feet(old_feet);
            if self.objective() <= old_objective && !self.max_jumped(&old_stats) {
                return Some(before);
            }
        }
        self.undo(before);
        None
    }

    /// The longest move each control point may make in one iteration: [`MOVE_REACH`] times the
    /// mean length of its control edges where `weak` flags the point, no limit elsewhere.
    fn move_reach(&self, points: &[Point3], weak: &[bool]) -> Vec<f64> {
        if !weak.contains(&true) {
            return vec![f64::INFINITY; points.len()];
        }
        let mut sum = vec![0.0; points.len()];
        let mut count = vec![0u32; points.len()];
        for f in self.surface.control_polygons().faces() {
            for k in 0..f.len() {
                let (a, b) = (f[k] as usize, f[(k + 1) % f.len()] as usize);
                let (Some(&pa), Some(&pb)) = (points.get(a), points.get(b)) else {
                    continue;
                };
                let l = (pa - pb).length();
                for v in [a, b] {
                    sum[v] += l;
                    count[v] += 1;
                }
            }
        }
        sum.iter()
            .zip(&count)
            .enumerate()
            .map(|(j, (&s, &c))| {
                if c > 0 && weak.get(j) == Some(&true) {
                    MOVE_REACH * s / f64::from(c)
                } else {
                    f64::INFINITY
                }
            })
            .collect()
    }

    /// Puts the control points, foot points and errors of `before` back.
    fn undo(&mut self, before: Before) {
        self.set_points(&before.points);
        self.feet = before.feet;
        self.state.restore(before.signed, before.stats);
    }

    /// Shortens a kept move whose surface → data distance (just measured) jumped: beyond the
    /// bound and more than [`BACK_JUMP`] times what it was before the move. The move is
    /// halved (twice at most, each time judged again by the objective, E_max and E_back) and
    /// otherwise undone, with the distance measured again. Returns whether a move is kept.
    /// Why: the damping judges the data → surface errors only, and where control points are
    /// packed closer than the data points a move that lowers them can throw a sheet off the
    /// data (cheburashka with Catmull–Clark at the defaults: E_back 1.05 → 4.29 → 1.68 →
    /// 6.47 % in successive moves, so the fit stalled above the bound it had nearly met).
    fn damp_back_jump(&mut self, before: Before) -> bool {
        if !self.options.damping || !self.back_jumped(before.back_max_pct) {
            return true;
        }
        self.accel.reset();
        let moved = self.surface.control_points().to_vec();
        for t in [0.5, 0.25] {
            let damped: Vec<Point3> = before
                .points
                .iter()
                .zip(&moved)
                .map(|(&p, &q)| p + (q - p) * t)
                .collect();
            self.set_points(&damped);
            self.update_feet(&before.feet);
            if self.objective() <= before.objective && !self.max_jumped(&before.stats) {
                self.measure_back();
                if !self.back_jumped(before.back_max_pct) {
                    return true;
                }
            }
        }
        let mut jumped: Vec<SurfaceParam> = self.pulls.iter().map(|&(at, _)| at).collect();
        jumped.extend(&self.strays);
        self.undo(before);
        self.hold(jumped);
        self.measure_back();
        false
    }

    /// Adds to [`SubdivFitter::holds`] those of `thrown` (samples a move threw off the data)
    /// that lie within the E_max tolerance of the data now and are not held yet. Samples that
    /// were off the data before are the pulls' business: held too, the bunny at Table 1 model
    /// C had its E_max jump from 0.049 to 0.40 % in one move.
    fn hold(&mut self, mut thrown: Vec<SurfaceParam>) {
        let key = |at: &SurfaceParam| (at.patch, at.u.to_bits(), at.v.to_bits());
        let held: HashSet<_> = self.holds.iter().map(|(at, _)| key(at)).collect();
        thrown.retain(|at| !held.contains(&key(at)));
        let limit = self.max_tolerance().unwrap_or(f64::INFINITY);
        let closest = self.closest_at(&thrown);
        let near = thrown
            .into_iter()
            .zip(closest)
            .filter_map(|(at, c)| c.filter(|&(d, _)| d <= limit).map(|(_, q)| (at, q)));
        self.holds.extend(near);
    }

    /// Whether the surface → data distance just measured is beyond the bound and more than
    /// [`BACK_JUMP`] times `before` (% of the diagonal).
    fn back_jumped(&self, before: Option<f64>) -> bool {
        let (Some(now), Some(before)) = (self.state.back(), before) else {
            return false;
        };
        !self.state.back_met() && now.max_pct > BACK_JUMP * before
    }

    /// Sets the control points (the surface refills its patch data), timed.
    fn set_points(&mut self, points: &[Point3]) {
        let started = Instant::now();
        self.surface.set_control_points(points);
        self.phases.add(|p| &mut p.refill_ms, started);
    }

    /// Pulls more gently after a move the damping of [`SubdivFitter::move_control_points`]
    /// undid while samples were pulled, and back to full strength as moves are kept. A pull
    /// towards the data can drag the surface off other data (E_max past its tolerance), and
    /// then every move is undone: the teapot with
    /// creases at the defaults had E_avg and E_max met and a sheet 1.85 % off the data, and
    /// each move halved the objective but threw E_max from 0.50 to 0.79–0.97 %, nine times in
    /// a row, until the fit stalled in place.
    fn ease_pull(&mut self, moved: bool) {
        self.pull_scale = if moved {
            (self.pull_scale * 2.0).min(1.0)
        } else if !self.pulls.is_empty() {
            (self.pull_scale * 0.5).max(MIN_PULL_SCALE)
        } else {
            self.pull_scale
        };
    }

    /// Whether E_max rose by more than [`MAX_JUMP`] from `before` past its tolerance while
    /// points are pulled ([`SubdivFitter::adapt_point_weights`]) or surface samples are
    /// ([`SubdivFitter::pulls`], [`SubdivFitter::holds`]): the weighted objective the damping
    /// judges can fall while the heavy points drag their neighbours off (the bunny at Table 1
    /// model C went from E_max 0.050 to 0.41 % in one such move), or while the samples pulled
    /// towards the data drag the surface off other data (the same fit, E_max 0.049 → 0.40 %
    /// with E_back 0.36 → 0.14 %), which defeats what the pull is for.
    fn max_jumped(&self, before: &ErrorStats) -> bool {
        let pulling = self.point_weights.iter().any(|&w| w > 1.0)
            || !self.pulls.is_empty()
            || !self.holds.is_empty();
        let now = self.state.stats().e_max_pct;
        pulling
            && self.state.tolerances().max_pct.is_some_and(|t| now > t)
            && now > MAX_JUMP * before.e_max_pct
    }

    /// Faces to split, in order: first those holding a point beyond the E_max tolerance (largest
    /// distance first); then, while E_avg or E_rms misses its tolerance, the faces whose points
    /// add most to it. As many as the budget and the growth cap of one refinement allow.
    fn faces_to_split(&self) -> Vec<usize> {
        let control = self.control_mesh();
        let nf = control.num_faces();
        let (mut max, mut sum, mut sum_sq) = (vec![0.0f64; nf], vec![0.0; nf], vec![0.0; nf]);
        for (f, d) in self.feet.iter().zip(self.state.errors()) {
            let face = self.surface.patch_face(f.param.patch);
            if face < nf {
                max[face] = max[face].max(d.abs());
                sum[face] += d.abs();
                sum_sq[face] += d * d;
            }
        }
        let t = self.options.tolerances;
        let tmax = self.max_tolerance();
        let by = |key: &[f64], keep: &dyn Fn(usize) -> bool| {
            let mut faces: Vec<usize> = (0..nf).filter(|&f| keep(f)).collect();
            faces.sort_by(|&a, &b| key[b].total_cmp(&key[a]).then(a.cmp(&b)));
            faces
        };
        let mut order = by(&max, &|f| tmax.is_some_and(|t| max[f] > t));
        let s = &self.state.stats();
        let avg_missed = t.avg_pct.is_some_and(|v| s.e_avg_pct > v);
        let rms_missed = t.rms_pct.is_some_and(|v| s.e_rms_pct > v);
        if avg_missed || rms_missed {
            let key = if avg_missed { &sum } else { &sum_sq };
            let first: HashSet<usize> = order.iter().copied().collect();
            order.extend(by(key, &|f| key[f] > 0.0 && !first.contains(&f)));
        }
        let current = self.num_control_points();
        let growth = ((current as f64 * self.options.refine_growth).ceil() as usize).max(32);
        let room = self.budget().saturating_sub(current).min(growth);
        let mut edges = HashSet::new();
        let mut chosen = Vec::new();
        for f in order {
            let face = control.face(f);
            for k in 0..face.len() {
                let (a, b) = (face[k], face[(k + 1) % face.len()]);
                edges.insert((a.min(b), a.max(b)));
            }
            if edges.len() > room {
                break;
            }
            chosen.push(f);
        }
        chosen
    }

    /// Samples per patch edge for the spatial index: about one sample per data point in all, at
    /// most the option (two per point made the bunny fit 6 % slower for the same result: the
    /// index only seeds Newton, which walks across patches from there).
    fn index_resolution(&self) -> usize {
        let per_patch = self.state.data().len() as f64 / self.surface.num_patches().max(1) as f64;
        (per_patch.sqrt().ceil() as usize).clamp(1, self.options.index_resolution)
    }

    /// Splits the worst faces within the budget and rebuilds the surface. Returns whether the
    /// control mesh changed.
    fn refine(&mut self) -> Result<bool, FitError> {
        let mut chosen = self.faces_to_split();
        let control = self.control_mesh();
        let mut last_size = None;
        while !chosen.is_empty() {
            let mut marked = vec![false; control.num_faces()];
            for &f in &chosen {
                marked[f] = true;
            }
            let mut refined = self.surface.refine_control(&control, &marked)?;
            if refined.num_vertices() <= self.budget() {
                if self.options.remesh {
                    self.surface.remesh_control(&mut refined)?;
                }
                let old_faces = self.patch_faces_now(&control);
                let before = self.state.stats().e_rms;
                let refined_surface = match self.surface.rebuild(&refined) {
                    Ok(surface) => surface,
                    // The split gave a face more neighbours than a patch can depend on (seen
                    // with Doo–Sabin, whose split faces hand extra corners to their
                    // neighbours): fewer splits, or none.
                    Err(FitError::Subdiv(SubdivError::NeighbourhoodTooLarge { .. })) => {
                        chosen.truncate(chosen.len() / 2);
                        continue;
                    }
                    Err(e) => return Err(e),
                };
                let previous = std::mem::replace(&mut self.surface, refined_surface);
                self.index = SurfaceIndex::build(&self.surface, self.index_resolution());
                self.accel.reset();
                self.carry_feet_over(&old_faces, &refined)?;
                let after = self.state.stats().e_rms;
                let worse = match self.surface.scheme() {
                    crate::subdiv::Scheme::DooSabin => DOO_SABIN_WORSE_FACTOR,
                    _ => REFINE_WORSE_FACTOR,
                };
                if after.is_nan() || after > worse * before {
                    // A split that breaks the surface (seen with Doo–Sabin on open meshes): back
                    // to the control mesh before it, and no more refinement.
                    self.surface = previous;
                    self.index = SurfaceIndex::build(&self.surface, self.index_resolution());
                    self.search_all_feet(REFINE_FEET)?;
                    return Ok(false);
                }
                return Ok(true);
            }
            if last_size == Some(refined.num_vertices()) {
                break; // the scheme refines globally: fewer marks do not make it smaller
            }
            last_size = Some(refined.num_vertices());
            chosen.truncate(chosen.len() / 2);
        }
        Ok(false)
    }

    /// The corners of the control face of every patch, before a refinement.
    fn patch_faces_now(&self, control: &PolyMesh) -> Vec<Vec<u32>> {
        (0..self.surface.num_patches() as u32)
            .map(|p| {
                let f = self.surface.patch_face(p);
                if f < control.num_faces() {
                    control.face(f).to_vec()
                } else {
                    Vec::new()
                }
            })
            .collect()
    }

    /// Foot points after a refinement: a point on a patch the rebuild kept as it was keeps its
    /// foot point; a point whose patch lies on a face the refinement left as it was (same
    /// corners, same order) starts Newton from its old parameters on that face; the others are
    /// searched from the spatial index.
    fn carry_feet_over(&mut self, old: &[Vec<u32>], refined: &PolyMesh) -> Result<(), FitError> {
        let mut copy_of = vec![u32::MAX; old.len()];
        for p in 0..self.surface.num_patches() as u32 {
            if let Some(slot) = self
                .surface
                .kept_patch(p)
                .and_then(|k| copy_of.get_mut(k as usize))
            {
                *slot = p;
            }
        }
        let mut face_patch = std::collections::HashMap::new();
        for p in (0..self.surface.num_patches() as u32).rev() {
            let f = self.surface.patch_face(p);
            if f < refined.num_faces() {
                face_patch.insert(refined.face(f).to_vec(), p);
            }
        }
        let opts = self.newton;
        for i in 0..self.feet.len() {
            let (p, prev) = (self.state.data()[i], self.feet[i].param);
            if let Some(&patch) = copy_of.get(prev.patch as usize).filter(|&&c| c != u32::MAX) {
                self.feet[i].param.patch = patch;
                continue;
            }
            let kept = old
                .get(prev.patch as usize)
                .and_then(|corners| face_patch.get(corners));
            let warm = kept.map(|&patch| {
                self.surface
                    .closest_point_from(p, SurfaceParam { patch, ..prev }, &opts)
            });
            self.feet[i] = match warm {
                Some(foot) if foot.converged => foot,
                _ => {
                    let start = self
                        .index
                        .nearest(p)
                        .ok_or(FitError::NoSurfaceNear { point: i })?;
                    self.surface.closest_point_from(p, start, &opts)
                }
            };
        }
        self.update_errors();
        Ok(())
    }

    /// Measures how far the limit surface strays from the data (when a reference is set): at
    /// every patch's centre, where a sheet between control points bulges most, and at its first
    /// corner (a control vertex for Loop and Catmull–Clark), where a spike at a control point
    /// shows; densely ([`DENSE_CELLS`]) in the patches of
    /// [`SubdivFitter::dense_patches`].
    fn measure_back(&mut self) {
        self.measure_back_at(false);
    }

    /// [`SubdivFitter::measure_back`] with every patch sampled densely; the patches where the
    /// surface is beyond the E_max tolerance are sampled densely from now on.
    fn measure_back_densely(&mut self) {
        self.measure_back_at(true);
    }

    /// The surface → data samples of `patch`: the centre and the first corner, and with
    /// `dense` the centres of [`DENSE_CELLS`]² cells.
    fn back_params(&self, patch: u32, dense: bool, out: &mut Vec<SurfaceParam>) {
        let centre = match self.surface.domain() {
            PatchDomain::Triangle => 1.0 / 3.0,
            PatchDomain::Square => 0.5,
        };
        out.push(SurfaceParam {
            patch,
            u: centre,
            v: centre,
        });
        out.push(SurfaceParam {
            patch,
            u: 0.0,
            v: 0.0,
        });
        if dense {
            self.cell_centres(patch, DENSE_CELLS, out);
        }
    }

    /// The centres of the `n`² cells of `patch`: of an `n` × `n` grid of its square, or of its
    /// triangle split into `n`² small triangles (pointing up where i + j < n, down where
    /// i + j < n − 1).
    fn cell_centres(&self, patch: u32, n: u32, out: &mut Vec<SurfaceParam>) {
        let h = 1.0 / f64::from(n);
        let triangle = self.surface.domain() == PatchDomain::Triangle;
        let mut push = |u: f64, v: f64| out.push(SurfaceParam { patch, u, v });
        for i in 0..n {
            for j in 0..n {
                let (u, v) = (f64::from(i) * h, f64::from(j) * h);
                if !triangle {
                    push(u + 0.5 * h, v + 0.5 * h);
                    continue;
                }
                if i + j < n {
                    push(u + h / 3.0, v + h / 3.0);
                }
                if i + j + 1 < n {
                    push(u + 2.0 * h / 3.0, v + 2.0 * h / 3.0);
                }
            }
        }
    }

    /// The distance to the data of the surface at `params`, with the nearest data point.
    fn closest_at(&self, params: &[SurfaceParam]) -> Vec<Option<(f64, Point3)>> {
        let samples = parallel::map(params, |&at| self.surface.point(at));
        self.state.closest_data(&samples)
    }

    /// Measures the surface → data distance at the samples of every patch (densely where
    /// `dense`, or in [`SubdivFitter::dense_patches`]) and sets the pulls and strays from it.
    /// A dense measure also samples the [`SUSPECT_LATTICE`] of every patch with a sample
    /// beyond half the bound, and adds the patches beyond the E_max tolerance to the ones
    /// sampled densely from now on.
    fn measure_back_at(&mut self, dense: bool) {
        let started = Instant::now();
        self.measure_back_samples(dense);
        self.phases.add(|p| &mut p.back_ms, started);
    }

    /// [`SubdivFitter::measure_back_at`] without its timing.
    ///
    /// The samples go through in chunks of [`BACK_CHUNK`] patches, and only each sample's
    /// distance is kept (and the few beyond the bounds): a dense measure of a 20,000-point
    /// Loop cage has 700,000 samples, whose parameters, points and nearest data points held at
    /// once were about 63 MB, at the peak of a 2-million-point fit in the browser.
    fn measure_back_samples(&mut self, dense: bool) {
        self.back_dense = dense;
        if !self.state.has_reference() {
            return;
        }
        let limit = self.max_tolerance().unwrap_or(f64::INFINITY);
        let tol = BACK_TOLERANCE_FACTOR * limit;
        // Pull (the CG moves take the rows) only once the data → surface errors meet E_max:
        // before, refinement and the data shape the surface, and a pull against the data's own
        // (a sharp rim) costs E_max.
        let pull = matches!(self.options.acceleration, Acceleration::Cg { .. })
            && self
                .state
                .tolerances()
                .max_pct
                .is_none_or(|t| self.state.stats().e_max_pct <= t);
        let mut tally = BackTally::new(limit, tol, pull);
        // The even samples first (they alone make the percentile), then the finer ones.
        let n = self.surface.num_patches() as u32;
        let mut params = Vec::new();
        for first in (0..n).step_by(BACK_CHUNK) {
            params.clear();
            for patch in first..n.min(first + BACK_CHUNK as u32) {
                self.back_params(patch, dense, &mut params);
            }
            tally.add(&params, &self.closest_at(&params));
        }
        let uniform = tally.distances.len();
        let mut finer: Vec<u32> = if dense {
            // Every patch with a sample beyond half the bound, on the suspect lattice.
            tally.beyond_half.iter().copied().collect()
        } else {
            let sticky = self.dense_patches.iter().copied();
            sticky.filter(|&p| p < n).collect()
        };
        finer.sort_unstable();
        for chunk in finer.chunks(BACK_CHUNK) {
            params.clear();
            for &patch in chunk {
                if dense {
                    grid_params(self.surface.domain(), patch, SUSPECT_LATTICE, &mut params);
                } else {
                    self.cell_centres(patch, DENSE_CELLS, &mut params);
                }
            }
            tally.add(&params, &self.closest_at(&params));
        }
        if dense {
            self.dense_patches
                .extend(tally.beyond_limit.iter().copied());
        }
        self.state.set_back_distances(&tally.distances, uniform);
        self.pull_weight = PULL_BACK * self.pull_scale * self.state.data().len() as f64
            / tally.distances.len().max(1) as f64;
        self.pulls = tally.pulls;
        self.strays = tally.strays;
    }

    /// Whether the tolerances are met, with the surface → data bound checked densely: the
    /// two samples per patch of every iteration miss sheets and bulges between them, so a fit
    /// they pass is measured again at [`DENSE_CELLS`]² cells per patch, and on the
    /// [`SUSPECT_LATTICE`] where that comes within half the bound, before it converges. With
    /// two samples alone, 13 of the 36 mesh fits of the data and the corpus that converged at
    /// the defaults had tessellation vertices (16 per patch edge) beyond the bound, up to
    /// 1.54 % for a bound of 1 % (the cow with Catmull–Clark); with this check none has.
    fn passes_dense_check(&mut self) -> bool {
        if !self.state.met() {
            return false;
        }
        if self.state.has_reference() && !self.back_dense {
            self.measure_back_densely();
        }
        self.state.met()
    }

    /// Measures the surface → data distance against `reference`, and the moves pull straying
    /// samples towards it ([`SubdivFitter::back_rows`]). For bare points the reference is the
    /// points' own discs ([`DataSurface::of_points`]), not the mesh reconstructed from them:
    /// that mesh lies off the points, and pulled towards it cheburashka's points with Loop went
    /// from stalled at E_back 2.05 % to stalled at 11.6 % after 111 iterations.
    pub fn with_reference(mut self, reference: Option<DataSurface>) -> Self {
        self.state.set_reference(reference);
        self.measure_back();
        self
    }

    /// Fairness holds the control points few data points pull on, but it also pulls the
    /// surface off the data it could reach (a fit of the fitter's own limit surface would never
    /// end exactly). So it is a means to the surface → data bound, not a prior, in two parts:
    /// - everywhere, the option's weight while any sample of the surface is farther from the
    ///   data than the E_max tolerance (it holds, too, the control points over holes, where
    ///   E_back is not measured), halving every iteration once none is;
    /// - on top of it, at the control points under a sample that keeps the fit from converging
    ///   ([`SubdivFitter::strays`]), a weight that starts at
    ///   the option's and doubles every iteration the surface there keeps straying (up to
    ///   [`FAIRNESS_CAP`] times), halving once it is back.
    ///
    /// A weight below [`FAIRNESS_FLOOR`] of the option's is 0.
    fn adapt_fairness(&mut self) {
        let base = self.options.fairness;
        let decay = |w: f64| {
            if w > base * FAIRNESS_FLOOR {
                w * 0.5
            } else {
                0.0
            }
        };
        let strays = match (self.state.back(), self.state.tolerances().max_pct) {
            (Some(b), Some(tol)) => b.max_pct > tol,
            _ => false,
        };
        self.global_fairness = if strays {
            base
        } else {
            decay(self.global_fairness)
        };
        let n = self.num_control_points();
        self.local_fairness.resize(n, 0.0);
        let mut straying = vec![false; n];
        for &at in &self.strays {
            self.scratch.clear();
            self.surface.stencil(at, &mut self.scratch);
            for &(j, w) in &self.scratch {
                if w > STRAY_STENCIL_WEIGHT {
                    if let Some(s) = straying.get_mut(j as usize) {
                        *s = true;
                    }
                }
            }
        }
        for (w, strays) in self.local_fairness.iter_mut().zip(straying) {
            *w = if strays {
                (*w * 2.0).clamp(base, base * FAIRNESS_CAP)
            } else {
                decay(*w)
            };
        }
        self.fairness = self
            .local_fairness
            .iter()
            .map(|w| w + self.global_fairness)
            .collect();
    }

    /// Pulls the worst points in (a Lawson-style reweighting towards the L∞ fit): once no
    /// refinement is left and while E_max misses its tolerance, a point beyond [`PULL_FROM`]
    /// of it doubles its weight every iteration (up to [`PULL_CAP`]); a point back under half
    /// that halves it (down to 1), and so does every weight after a move the damping undid.
    /// The least-squares moves spread the error evenly, so the few points past a tight E_max
    /// would otherwise need faces split for them, which the budget no longer allows. Earlier,
    /// refinement is the better cure: pulling from the first iteration also met E_max on the
    /// bunny at Table 1 model C, but it moved fits that converged (fandisk with creases at
    /// the page defaults went from converged with 378 control points to stalled on E_back, its
    /// pulled points overshooting next to the creases).
    fn adapt_point_weights(&mut self, moved: bool) {
        let (Some(tmax), Some(limit)) = (self.state.tolerances().max_pct, self.max_tolerance())
        else {
            return;
        };
        let pull = moved && !self.can_refine() && self.state.stats().e_max_pct > tmax;
        for (w, d) in self.point_weights.iter_mut().zip(self.state.errors()) {
            let r = d.abs() / limit;
            if pull && r > PULL_FROM {
                *w = (*w * 2.0).min(PULL_CAP);
            } else if !moved || r < PULL_FROM / 2.0 {
                *w = (*w * 0.5).max(1.0);
            }
        }
    }

    /// Whether a refinement can still change the fit's course: refinement is on, the budget
    /// has room for [`MIN_GROWTH`] more control points, and the last refinement due added some.
    fn can_refine(&self) -> bool {
        let n = self.num_control_points();
        self.options.refine
            && self.budget().saturating_sub(n) as f64 >= n as f64 * MIN_GROWTH
            && !self.refine_exhausted
    }

    /// Whether the fit cannot refine any more, or its refinements add too little to matter,
    /// and its errors stopped falling (see [`stalled`]).
    fn is_stalled(&self) -> bool {
        let history = self.state.log().history();
        (!self.can_refine() || self.refine_futile)
            && self.since_growth >= STALL_WINDOW
            && stalled(
                history,
                &self.state.tolerances(),
                self.options.max_iter.saturating_sub(history.len()),
            )
    }

    /// Remembers the control points when this iteration is the best since the last
    /// refinement (a refinement starts over: the control mesh changed).
    fn keep_if_best(&mut self, refined: bool) {
        let shortfall = self.state.shortfall();
        if refined || self.best.as_ref().is_none_or(|b| shortfall < b.shortfall) {
            self.best = Some(Best {
                shortfall,
                iteration: self.state.log().iterations(),
                points: self.surface.control_points().to_vec(),
                feet: self.feet.clone(),
            });
        }
    }

    /// Puts back the control points and foot points of the best iteration since the last
    /// refinement when the current ones are worse. Returns whether it did. (Foot points are
    /// kept, not found again: warm Newton from the last iteration's left some on the wrong
    /// side of a bumpy sphere's fold, E_max 1.87 % where the iteration had 0.31 %.)
    /// Why: near the end of a tight fit, the fairness that holds straying parts of the surface
    /// and the pull on the worst points take turns, and an iteration can trade E_back for
    /// E_max: the bunny at Table 1 model C stalled at E_max 0.43 % one iteration after 0.047 %.
    /// A fit that stops without converging should end at the best it reached.
    fn go_back_to_best(&mut self) -> bool {
        let Some(best) = self.best.take() else {
            return false;
        };
        if best.shortfall >= self.state.shortfall()
            || best.points.len() != self.num_control_points()
        {
            return false;
        }
        self.surface.set_control_points(&best.points);
        self.feet = best.feet;
        self.update_errors();
        self.state.log_mut().set_went_back_to(best.iteration);
        true
    }

    fn due_for_refinement(&self, improvement: f64) -> bool {
        self.options.refine
            && self.num_control_points() < self.budget()
            && (self.since_refine >= self.options.refine_interval
                || (self.since_refine >= 2 && improvement < self.options.stall_ratio))
    }
}

impl<S: ControlSurface> Fitter for SubdivFitter<S> {
    fn step(&mut self) -> Result<FitStatus, FitError> {
        if self.status() != FitStatus::Running {
            return Ok(self.status());
        }
        // The dense check belongs to the fit's time: in this iteration's record when it fails,
        // in the last one when it passes (or the fit's alone before any iteration: a 2.2 M-point
        // scan met its tolerances at the start and reported 0 s for a 0.8 s check).
        let start = Instant::now();
        self.phases = PhaseTimes::default();
        if self.passes_dense_check() {
            self.state.amend_time(start);
            return Ok(self.state.log_mut().stop(FitStatus::Converged));
        }
        progress::report(Phase::Iteration, 0.0);
        let before = self.state.stats().e_rms;
        let before_move = self.move_control_points();
        let mut moved = before_move.is_some();
        progress::report(Phase::Iteration, ITERATION_MOVED);
        self.ease_pull(moved);
        self.since_refine += 1;
        self.since_growth += 1;
        let improvement = if before > 0.0 && moved {
            (before - self.state.stats().e_rms) / before
        } else {
            0.0
        };
        // A refinement is certain when the data → surface errors miss a tolerance and one is
        // due: the surface is about to be replaced, so only the refined one is measured (a
        // measure is about 40 % of an iteration on the bunny).
        let refining = !self.state.tolerances().met_by(&self.state.stats())
            && self.due_for_refinement(improvement);
        if !refining {
            self.measure_back();
            if let Some(b) = before_move {
                moved = self.damp_back_jump(b);
            }
        }
        progress::report(Phase::Iteration, ITERATION_MEASURED);
        self.adapt_fairness();
        self.adapt_point_weights(moved);
        let before_count = self.num_control_points();
        let mut refined = false;
        let mut met = !refining && self.passes_dense_check();
        if refining || (!met && self.due_for_refinement(improvement)) {
            let started = Instant::now();
            refined = self.refine()?;
            self.phases.add(|p| &mut p.refine_ms, started);
            self.refine_exhausted = !refined;
            let grew = self.num_control_points() as f64 >= before_count as f64 * (1.0 + MIN_GROWTH);
            self.refine_futile = !grew;
            if grew {
                self.since_growth = 0;
            }
            if refined {
                self.since_refine = 0;
                self.dense_patches.clear();
                self.holds.clear();
            }
            if refined || refining {
                self.measure_back();
                met = self.passes_dense_check();
            }
        }
        progress::report(Phase::Iteration, 1.0);
        let mut status = self.state.status_after(met, self.options.max_iter);
        let n = self.num_control_points();
        self.state.record(start, n, refined, status);
        self.state.log_mut().set_phases(self.phases);
        self.keep_if_best(refined);
        if status == FitStatus::Running && self.is_stalled() {
            status = self.state.log_mut().stop(FitStatus::Stalled);
        }
        let closing = Instant::now();
        if matches!(status, FitStatus::Stalled | FitStatus::MaxIterations) && self.go_back_to_best()
        {
            self.back_dense = false;
            self.state.amend_stats();
        }
        if status != FitStatus::Running && !self.back_dense {
            // A fit ends with the dense figure, converged or not.
            self.measure_back_densely();
            self.state.amend_back();
        }
        if status != FitStatus::Running {
            self.state.amend_time(closing);
        }
        Ok(status)
    }

    fn state(&self) -> &FitState {
        &self.state
    }

    fn state_mut(&mut self) -> &mut FitState {
        &mut self.state
    }

    fn foot_points(&self) -> Vec<Point3> {
        self.feet.iter().map(|f| f.point).collect()
    }

    fn num_control_points(&self) -> usize {
        self.surface.control_points().len()
    }

    fn control_shape(&self) -> Shape {
        Shape::Mesh(self.control_mesh())
    }

    fn limit_shape(&self, resolution: usize) -> Shape {
        Shape::Mesh(self.limit_mesh(resolution))
    }

    fn subdiv_surface(&self) -> Option<&crate::subdiv::SubdivSurface> {
        self.surface.as_subdiv()
    }
}
