//! Options of the subdivision-surface fitter: tolerances, iteration caps, the weighting of error
//! vectors, acceleration and refinement.

use crate::fit::{Acceleration, FitError, Tolerances};
use crate::geom::NewtonOptions;

/// How the error vectors of the foot points are turned into control-point moves.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Weighting {
    /// The patent's weights (SPEC §1.6): each control vertex collects the error vectors of the
    /// foot points on the control faces around it, weighted by the foot point's barycentric
    /// (triangle) or bilinear (quad) coordinate with respect to that vertex, normalised by the
    /// sum of weights. Local and easy to show; the demo teaches it.
    Patent,
    /// Each error vector goes to every control point whose basis function is non-zero at the
    /// foot point, weighted by that basis value (the limit stencil), normalised per control point
    /// (progressive-iterative approximation, LSPIA). Converges to the least-squares fit.
    #[default]
    Basis,
}

named_enum!(Weighting, "weights", { Patent => "patent", Basis => "basis" });

/// Everything that steers a subdivision-surface fit. Defaults in brackets on each field.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct SubdivFitOptions {
    /// Stop when these are met [E_avg 0.1 %, E_max 0.5 %: [`SubdivFitOptions::DEFAULT_TOLERANCES`]].
    pub tolerances: Tolerances,
    /// Iteration cap [200].
    pub max_iter: usize,
    /// Control-point budget for refinement [half the number of data points].
    pub max_control: Option<usize>,
    /// Whether faces are split where the tolerance is not met [true].
    pub refine: bool,
    /// Refine at the latest after this many iterations without meeting the tolerances [6].
    pub refine_interval: usize,
    /// One refinement adds at most this fraction of the current control points [3]. A high cap
    /// lets the out-of-tolerance faces decide how much to split: on the bunny (612 initial
    /// points, 7,049 budget) 0.5 took 32 iterations and ten refinements, 3 takes 21 and seven,
    /// with the same final control count.
    pub refine_growth: f64,
    /// Refine earlier when one iteration lowers E_rms by less than this fraction [0.05].
    pub stall_ratio: f64,
    /// Edge flips that lower the valence energy and remove thin triangles after each refinement
    /// (Loop only) [true].
    pub remesh: bool,
    /// Error-vector weighting [basis].
    pub weighting: Weighting,
    /// Acceleration [[`Acceleration::CG`], measured fastest on the bunny; with patent weights
    /// none, see [`SubdivFitOptions::default_acceleration`]].
    pub acceleration: Acceleration,
    /// Undo and halve a move that raises E_rms, and reset the acceleration [true].
    pub damping: bool,
    /// Foot-point search [12 iterations, steps up to 0.5 in patch parameters, `step_tol` 1e-10
    /// of the data's bounding-box diagonal].
    pub newton: NewtonOptions,
    /// Samples per patch edge of the tessellation behind the spatial index, at most [4]; fewer
    /// when there are many patches per data point.
    pub index_resolution: usize,
    /// With CG acceleration: weight of the tangential part of the error vectors relative to the
    /// normal part (1 = point-to-point distance, smaller = closer to point-to-plane) [0.1].
    pub tangent_weight: f64,
    /// With CG acceleration: weight of the control net's umbrella fairness, relative to the
    /// median data support of a control point; it holds the control points that few data points
    /// pull on (0: none) [0.01].
    pub fairness: f64,
}

impl SubdivFitOptions {
    /// The tolerances a fit stops at when none are given: E_avg 0.1 %, E_max 0.5 % of the
    /// diagonal. A default is what a user gets who presses Play on their own scan, so it is one
    /// the scans the fitter meets can reach within the default budget (half the data points):
    /// over `data/` and the corpus, 31 of 41 fits converge at these, 7 of 38 at the patent's
    /// Table 1 figures (E_avg 0.01 %, E_max 0.05 %, [`Tolerances::DEFAULT`]), which the
    /// benchmarks give explicitly.
    pub const DEFAULT_TOLERANCES: Tolerances = Tolerances {
        avg_pct: Some(0.1),
        max_pct: Some(0.5),
        rms_pct: None,
    };

    /// The defaults, as each field documents them.
    pub const DEFAULT: SubdivFitOptions = SubdivFitOptions {
        tolerances: SubdivFitOptions::DEFAULT_TOLERANCES,
        max_iter: 200,
        max_control: None,
        refine: true,
        refine_interval: 6,
        refine_growth: 3.0,
        stall_ratio: 0.05,
        remesh: true,
        weighting: Weighting::Basis,
        acceleration: Acceleration::CG,
        damping: true,
        newton: NewtonOptions {
            max_iter: 12,
            step_tol: 1e-10,
            max_step: 0.5,
        },
        index_resolution: 4,
        tangent_weight: 0.1,
        fairness: 0.01,
    };

    /// The acceleration that goes with a weighting when none is chosen: CG solves the
    /// basis-weighted problem, so the patent's weights iterate plainly.
    pub const fn default_acceleration(weighting: Weighting) -> Acceleration {
        match weighting {
            Weighting::Basis => Acceleration::CG,
            Weighting::Patent => Acceleration::None,
        }
    }

    /// Checks every option's range; the message names the option as the CLI spells it.
    pub fn validate(&self) -> Result<(), FitError> {
        let bad =
            |name: &'static str, reason: String| Err(FitError::InvalidOption { name, reason });
        self.tolerances.validate()?;
        if self.max_iter == 0 {
            return bad("maxIter", "must be at least 1".into());
        }
        if self.refine_interval == 0 {
            return bad("refine_interval", "must be at least 1".into());
        }
        if !(self.refine_growth.is_finite() && self.refine_growth > 0.0) {
            return bad("refineGrowth", format!("{} is not > 0", self.refine_growth));
        }
        if !(self.stall_ratio.is_finite() && (0.0..1.0).contains(&self.stall_ratio)) {
            return bad(
                "stall_ratio",
                format!("{} is not in [0, 1)", self.stall_ratio),
            );
        }
        self.acceleration.validate()?;
        if matches!(self.acceleration, Acceleration::Cg { .. })
            && self.weighting == Weighting::Patent
        {
            return bad(
                "acceleration",
                "CG solves the basis-weighted least-squares problem; use it with basis weights"
                    .into(),
            );
        }
        if !(self.newton.is_valid() && self.newton.max_step.is_finite()) {
            return bad(
                "newton",
                "needs max_iter >= 1, a finite step_tol > 0 and a finite max_step > 0".into(),
            );
        }
        if !(self.tangent_weight.is_finite()
            && self.tangent_weight > 0.0
            && self.tangent_weight <= 1.0)
        {
            return bad(
                "tangentWeight",
                format!("{} is not in (0, 1]", self.tangent_weight),
            );
        }
        if !(self.fairness.is_finite() && self.fairness >= 0.0) {
            return bad(
                "fairness",
                format!("{} is not a finite weight >= 0", self.fairness),
            );
        }
        if !(1..=32).contains(&self.index_resolution) {
            return bad(
                "index_resolution",
                format!("{} is not in 1..=32", self.index_resolution),
            );
        }
        Ok(())
    }
}

default_is_const!(SubdivFitOptions);

setters!(SubdivFitOptions {
    /// Sets the stopping tolerances.
    with_tolerances(tolerances: Tolerances) => |s| s.tolerances;
    /// Sets the iteration cap.
    with_max_iter(max_iter: usize) => |s| s.max_iter;
    /// Sets the control-point budget.
    with_max_control(max_control: Option<usize>) => |s| s.max_control;
    /// Turns refinement on or off.
    with_refine(refine: bool) => |s| s.refine;
    /// Sets the weighting of error vectors.
    with_weighting(weighting: Weighting) => |s| s.weighting;
    /// Sets the acceleration.
    with_acceleration(acceleration: Acceleration) => |s| s.acceleration;
    /// Turns damping on or off.
    with_damping(damping: bool) => |s| s.damping;
    /// Sets the refinement interval.
    with_refine_interval(refine_interval: usize) => |s| s.refine_interval;
    /// Sets the growth cap of one refinement.
    with_refine_growth(refine_growth: f64) => |s| s.refine_growth;
    /// Sets the tangential weight of the CG acceleration.
    with_tangent_weight(tangent_weight: f64) => |s| s.tangent_weight;
    /// Turns the remeshing flips on or off.
    with_remesh(remesh: bool) => |s| s.remesh;
    /// Sets the weight of the control net's fairness.
    with_fairness(fairness: f64) => |s| s.fairness;
});
