//! Options of the subdivision-surface fitter: tolerances, iteration caps, the weighting of error
//! vectors, acceleration and refinement.

use super::{FitError, Tolerances};
use serde::{Deserialize, Serialize};

/// How the error vectors of the foot points are turned into control-point moves.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
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

/// How successive moves are combined to converge in fewer iterations.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Acceleration {
    /// Plain geometric iteration: P ← P + d.
    None,
    /// Constant over-relaxation P ← P + ω d (the constant step of LSPIA). With per-point
    /// normalised weights the iteration matrix has eigenvalues in (0, 1], so 1 < ω < 2 speeds up
    /// the slow (smooth) error modes.
    Relax {
        /// Step factor ω, in (0, 2).
        omega: f64,
    },
    /// Anderson acceleration of the fixed-point map P ↦ P + d(P) over the last `depth` moves:
    /// a small least-squares problem per iteration, no matrix of the size of the mesh.
    Anderson {
        /// How many previous iterates are combined (1..=20).
        depth: usize,
    },
    /// Conjugate gradients on frozen foot parameters: with the foot points of this iteration
    /// fixed, the surface is linear in the control points (S(t_i) = Σ_j B_j(t_i) P_j, the cached
    /// limit stencils), so `inner` Jacobi-preconditioned CG steps on that least-squares problem
    /// cost only sums over the stencils, no surface evaluation; then the foot points are
    /// recomputed. Each CG step moves the control points by basis-weighted error vectors, like
    /// the plain iteration, with optimal step lengths and directions. Needs basis weights.
    Cg {
        /// CG steps per iteration (1..=100).
        inner: usize,
    },
}

impl Acceleration {
    /// CG with the default number of steps per iteration, 12: on the bunny (612 initial
    /// control points, 7,049 budget) 8 steps took 21 iterations, 12 take 18 with fewer control
    /// points (6,908) and about 20 % less time; 5 steps took 97 iterations, 16–24 no fewer
    /// than 12.
    pub const fn cg() -> Acceleration {
        Acceleration::Cg { inner: 12 }
    }
}

impl Default for Acceleration {
    fn default() -> Self {
        Acceleration::cg()
    }
}

/// Newton foot-point search settings (SPEC §1.4).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct NewtonOptions {
    /// Iteration cap per point and search. Default 12.
    pub max_iter: usize,
    /// Converged when the parameter step moves the surface point by less than this fraction of
    /// the data's bounding-box diagonal. Default 1e-10.
    pub step_tol: f64,
    /// Largest parameter step per Newton iteration (trust region, in patch-parameter units).
    /// Default 0.5.
    pub max_step: f64,
}

impl Default for NewtonOptions {
    fn default() -> Self {
        NewtonOptions {
            max_iter: 12,
            step_tol: 1e-10,
            max_step: 0.5,
        }
    }
}

/// Everything that steers a subdivision-surface fit. Defaults in brackets on each field.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct SubdivFitOptions {
    /// Stop when these are met [E_avg 0.01 %, E_max 0.05 %].
    pub tolerances: Tolerances,
    /// Iteration cap [200].
    pub max_iter: usize,
    /// Control-point budget for refinement [no cap beyond 4× the initial count].
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
    /// Acceleration [CG, 12 steps per iteration; measured fastest on the bunny].
    pub acceleration: Acceleration,
    /// Undo and halve a move that raises E_rms, and reset the acceleration [true].
    pub damping: bool,
    /// Foot-point search.
    pub newton: NewtonOptions,
    /// Samples per patch edge of the tessellation behind the spatial index, at most [4]; fewer
    /// when there are many patches per data point.
    pub index_resolution: usize,
    /// With CG acceleration: weight of the tangential part of the error vectors relative to the
    /// normal part (1 = point-to-point distance, smaller = closer to point-to-plane) [0.1].
    pub tangent_weight: f64,
}

impl Default for SubdivFitOptions {
    fn default() -> Self {
        SubdivFitOptions {
            tolerances: Tolerances::default(),
            max_iter: 200,
            max_control: None,
            refine: true,
            refine_interval: 6,
            refine_growth: 3.0,
            stall_ratio: 0.05,
            remesh: true,
            weighting: Weighting::default(),
            acceleration: Acceleration::default(),
            damping: true,
            newton: NewtonOptions::default(),
            index_resolution: 4,
            tangent_weight: 0.1,
        }
    }
}

impl SubdivFitOptions {
    /// Sets the stopping tolerances.
    pub fn with_tolerances(mut self, tolerances: Tolerances) -> Self {
        self.tolerances = tolerances;
        self
    }
    /// Sets the iteration cap.
    pub fn with_max_iter(mut self, max_iter: usize) -> Self {
        self.max_iter = max_iter;
        self
    }
    /// Sets the control-point budget.
    pub fn with_max_control(mut self, max_control: Option<usize>) -> Self {
        self.max_control = max_control;
        self
    }
    /// Turns refinement on or off.
    pub fn with_refine(mut self, refine: bool) -> Self {
        self.refine = refine;
        self
    }
    /// Sets the weighting of error vectors.
    pub fn with_weighting(mut self, weighting: Weighting) -> Self {
        self.weighting = weighting;
        self
    }
    /// Sets the acceleration.
    pub fn with_acceleration(mut self, acceleration: Acceleration) -> Self {
        self.acceleration = acceleration;
        self
    }
    /// Turns damping on or off.
    pub fn with_damping(mut self, damping: bool) -> Self {
        self.damping = damping;
        self
    }
    /// Sets the refinement interval.
    pub fn with_refine_interval(mut self, iterations: usize) -> Self {
        self.refine_interval = iterations;
        self
    }
    /// Sets the tangential weight of the CG acceleration.
    pub fn with_tangent_weight(mut self, weight: f64) -> Self {
        self.tangent_weight = weight;
        self
    }
    /// Turns the remeshing flips on or off.
    pub fn with_remesh(mut self, remesh: bool) -> Self {
        self.remesh = remesh;
        self
    }

    /// Checks every option's range; the message names the option as the CLI spells it.
    pub fn validate(&self) -> Result<(), FitError> {
        let bad =
            |name: &'static str, reason: String| Err(FitError::InvalidOption { name, reason });
        let t = &self.tolerances;
        for (name, tol) in [
            ("tol-avg", t.avg_pct),
            ("tol-max", t.max_pct),
            ("tol-rms", t.rms_pct),
        ] {
            if let Some(v) = tol {
                if !(v.is_finite() && v >= 0.0) {
                    return bad(name, format!("{v} is not a finite percentage >= 0"));
                }
            }
        }
        if self.max_iter == 0 {
            return bad("max-iter", "must be at least 1".into());
        }
        if self.refine_interval == 0 {
            return bad("refine-interval", "must be at least 1".into());
        }
        if !(self.refine_growth.is_finite() && self.refine_growth > 0.0) {
            return bad(
                "refine-growth",
                format!("{} is not > 0", self.refine_growth),
            );
        }
        if !(self.stall_ratio.is_finite() && (0.0..1.0).contains(&self.stall_ratio)) {
            return bad(
                "stall-ratio",
                format!("{} is not in [0, 1)", self.stall_ratio),
            );
        }
        match self.acceleration {
            Acceleration::Relax { omega } if !(omega > 0.0 && omega < 2.0) => {
                return bad(
                    "accel",
                    format!("relaxation factor {omega} is not in (0, 2)"),
                );
            }
            Acceleration::Anderson { depth } if !(1..=20).contains(&depth) => {
                return bad("accel", format!("Anderson depth {depth} is not in 1..=20"));
            }
            Acceleration::Cg { inner } if !(1..=100).contains(&inner) => {
                return bad("accel", format!("CG steps {inner} not in 1..=100"));
            }
            Acceleration::Cg { .. } if self.weighting == Weighting::Patent => {
                return bad(
                    "accel",
                    "CG solves the basis-weighted least-squares problem; use it with basis weights"
                        .into(),
                );
            }
            _ => {}
        }
        let n = &self.newton;
        if n.max_iter == 0 || !(n.step_tol.is_finite() && n.step_tol > 0.0) {
            return bad(
                "newton",
                "needs max_iter >= 1 and a finite step_tol > 0".into(),
            );
        }
        if !(n.max_step.is_finite() && n.max_step > 0.0) {
            return bad("newton", format!("max_step {} is not > 0", n.max_step));
        }
        if !(self.tangent_weight.is_finite()
            && self.tangent_weight > 0.0
            && self.tangent_weight <= 1.0)
        {
            return bad(
                "tangent-weight",
                format!("{} is not in (0, 1]", self.tangent_weight),
            );
        }
        if !(1..=32).contains(&self.index_resolution) {
            return bad(
                "index-resolution",
                format!("{} is not in 1..=32", self.index_resolution),
            );
        }
        Ok(())
    }
}
