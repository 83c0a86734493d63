//! Foot points of the data on the current limit surface, as every iteration of the fitter finds
//! them: cold (from the spatial index) and warm (from the previous iteration's parameters), and
//! [`FootPointBench`], which times both on a finished fit the way the fit runs them.

use super::index::SurfaceIndex;
use super::{FootPoint, SubdivFitOptions};
use crate::fit::{parallel, FitData, FitError, FitSpec, FitStatus, Fitter};
use crate::geom::{ClosestPoint, NewtonOptions, Point3};
use crate::progress::{self, Part, Phase};
use crate::subdiv::{LimitSurface, SubdivSurface, SurfaceParam};
use web_time::Instant;

/// A warm foot point farther than twice the previous distance plus this share of the data's
/// diagonal is searched again from the spatial index (Newton may have slid into another valley).
pub(crate) const WARM_SLACK: f64 = 1e-3;

/// The foot point of `p` found from the spatial index (the global search).
pub(crate) fn cold_foot<S: ClosestPoint<Param = SurfaceParam>>(
    surface: &S,
    index: &SurfaceIndex,
    p: Point3,
    opts: &NewtonOptions,
) -> Option<FootPoint> {
    let start = index.nearest(p)?;
    Some(surface.closest_point_from(p, start, opts))
}

/// The foot point of `p` by Newton from the previous one, `prev`; a result that is suspect (not
/// converged, or more than twice as far as before plus `slack`) is searched again from the
/// spatial index, and the nearer of the two is kept.
pub(crate) fn warm_foot<S: ClosestPoint<Param = SurfaceParam>>(
    surface: &S,
    index: &SurfaceIndex,
    p: Point3,
    prev: &FootPoint,
    opts: &NewtonOptions,
    slack: f64,
) -> FootPoint {
    let mut foot = surface.closest_point_from(p, prev.param, opts);
    let grew = foot.dist_sq.sqrt() > 2.0 * prev.dist_sq.sqrt() + slack;
    if !foot.converged || grew {
        if let Some(other) = cold_foot(surface, index, p, opts) {
            if other.dist_sq < foot.dist_sq {
                foot = other;
            }
        }
    }
    foot
}

/// Every point's foot point from the spatial index ([`cold_foot`]). `Err(i)` names the first
/// point the index has nothing near. Reports its progress as `part`, block by block; the
/// points of a block are searched on several threads ([`crate::fit::max_threads`]; the same
/// result on any number).
///
/// Points are visited in data order: scans list their points in a spatially coherent order, so
/// consecutive searches mostly share patches. (Visiting them grouped by patch was measured
/// slower: the scattered reads and writes of the points cost more than the patch data they
/// share.)
pub(crate) fn cold_feet<S: ClosestPoint<Param = SurfaceParam> + Sync>(
    surface: &S,
    index: &SurfaceIndex,
    data: &[Point3],
    opts: &NewtonOptions,
    part: Part,
) -> Result<Vec<FootPoint>, usize> {
    let block = progress::BATCH * crate::fit::max_threads();
    let mut feet = Vec::with_capacity(data.len());
    for (b, points) in data.chunks(block).enumerate() {
        part.count(b * block, data.len());
        let found = parallel::map(points, |&p| cold_foot(surface, index, p, opts));
        for (k, foot) in found.into_iter().enumerate() {
            feet.push(foot.ok_or(b * block + k)?);
        }
    }
    Ok(feet)
}

/// How many points ahead [`warm_feet`] asks for the patch data at the previous foot point
/// ([`ClosestPoint::prefetch`]). Points come in data order, which visits patches in no order
/// the hardware can foresee, and an irregular patch's data (about 3 KB) is mostly not in
/// cache: on the bunny's final Loop surface the first evaluation of a warm foot point waited on
/// its first load for about 40 % of its time (perf). Asking 4 points ahead (2, 4 and 8 measured
/// the same) took the warm pass from 1.45–1.58 to 1.78–1.83 M foot points/s (best pass, one
/// thread); results are the same bits.
const PREFETCH_AHEAD: usize = 4;

/// Every point's foot point from its previous one ([`warm_foot`]) into `out`, on several
/// threads (the same result on any number).
pub(crate) fn warm_feet<S: ClosestPoint<Param = SurfaceParam> + Sync>(
    surface: &S,
    index: &SurfaceIndex,
    data: &[Point3],
    previous: &[FootPoint],
    opts: &NewtonOptions,
    slack: f64,
    out: &mut [FootPoint],
) {
    parallel::fill(out, |i| {
        if let Some(ahead) = previous.get(i + PREFETCH_AHEAD) {
            surface.prefetch(&ahead.param);
        }
        warm_foot(surface, index, data[i], &previous[i], opts, slack)
    });
}

/// The benchmark's searches report as a whole set-up.
const BENCH_PART: Part = Part {
    phase: Phase::Setup,
    from: 0.0,
    to: 1.0,
};

/// What one timed pass of [`FootPointBench`] did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FootPointTiming {
    /// Foot points found (one per data point).
    pub points: usize,
    /// Wall-clock seconds of the pass (one thread).
    pub seconds: f64,
    /// Newton iterations, summed over the points.
    pub iterations: u64,
    /// Points whose search did not converge.
    pub unconverged: usize,
    /// Sum of the distances to the foot points (a checksum: equal passes give equal sums).
    pub distance_sum: f64,
}

impl FootPointTiming {
    /// Foot points per second.
    pub fn rate(&self) -> f64 {
        self.points as f64 / self.seconds.max(1e-12)
    }
}

/// A finished subdivision fit set up to time its foot points: the final limit surface, the
/// data, and the control points of the last iteration that moved them (or, if none did, the
/// final ones shifted by a small deterministic perturbation).
///
/// [`FootPointBench::cold`] finds every data point's foot point from the spatial index, as the
/// fit's first iteration does; [`FootPointBench::warm`] finds them from the foot points on the
/// previous control points, as every later iteration does. Used by `benches/foot_points.rs`
/// and by the browser benchmark (`scripts/bench_wasm.mjs`).
pub struct FootPointBench {
    surface: SubdivSurface,
    index: SurfaceIndex,
    data: Vec<Point3>,
    newton: NewtonOptions,
    slack: f64,
    /// Control points before and after the last move.
    before: Vec<Point3>,
    after: Vec<Point3>,
    /// Foot points on the surface over `before` (the warm starts).
    previous: Vec<FootPoint>,
    iterations: usize,
    status: FitStatus,
}

impl FootPointBench {
    /// Runs the fit of `spec` (a subdivision scheme) on `data` to its end and prepares the
    /// timing passes.
    pub fn from_fit(spec: &FitSpec, data: &FitData) -> Result<FootPointBench, FitError> {
        let options = spec.subdiv_options();
        let mut fitter = spec.build(data)?;
        let ctrl = |f: &dyn Fitter| {
            f.subdiv_surface()
                .map(|s| s.control_points().to_vec())
                .unwrap_or_default()
        };
        let mut history = vec![ctrl(fitter.as_ref())];
        let mut status = fitter.status();
        while status == FitStatus::Running {
            status = fitter.step()?;
            history.push(ctrl(fitter.as_ref()));
        }
        let Some(last) = fitter.subdiv_surface() else {
            return Err(FitError::InvalidOption {
                name: "scheme",
                reason: "the foot-point benchmark needs a subdivision scheme".into(),
            });
        };
        let after = last.control_points().to_vec();
        let diagonal = fitter.state().diagonal();
        // The last move: the latest pair of consecutive control nets with the same count that
        // differ.
        let moved = history
            .windows(2)
            .rev()
            .find(|w| w[0].len() == after.len() && w[1] == after && w[0] != w[1])
            .map(|w| w[0].clone());
        let before = moved.unwrap_or_else(|| perturbed(&after, 1e-5 * diagonal));
        let surface = SubdivSurface::try_new(last.scheme(), last.control_mesh().clone())?;
        let mut bench = FootPointBench::with_surface(
            surface,
            &before,
            fitter.state().data().to_vec(),
            diagonal,
            &options,
        )?;
        (bench.iterations, bench.status) = (fitter.log().history().len(), status);
        Ok(bench)
    }

    /// Timing passes on `surface` (whose control points are the final ones) for `data`, the
    /// warm pass starting from the foot points on the control points `before`; `diagonal` is
    /// the data's bounding-box diagonal and `options` the fit's (index resolution, Newton).
    pub fn with_surface(
        mut surface: SubdivSurface,
        before: &[Point3],
        data: Vec<Point3>,
        diagonal: f64,
        options: &SubdivFitOptions,
    ) -> Result<FootPointBench, FitError> {
        let after = surface.control_points().to_vec();
        if before.len() != after.len() {
            return Err(FitError::InvalidOption {
                name: "before",
                reason: format!("{} control points for {}", before.len(), after.len()),
            });
        }
        let per_patch = data.len() as f64 / surface.num_patches().max(1) as f64;
        let resolution = (per_patch.sqrt().ceil() as usize).clamp(1, options.index_resolution);
        let newton = options
            .newton
            .with_step_tol(options.newton.step_tol * diagonal);
        surface.set_control_points(before);
        let index = SurfaceIndex::build(&surface, resolution);
        let previous = cold_feet(&surface, &index, &data, &newton, BENCH_PART)
            .map_err(|point| FitError::NoSurfaceNear { point })?;
        surface.set_control_points(&after);
        let index = SurfaceIndex::build(&surface, resolution);
        Ok(FootPointBench {
            surface,
            index,
            data,
            newton,
            slack: WARM_SLACK * diagonal,
            before: before.to_vec(),
            after,
            previous,
            iterations: 0,
            status: FitStatus::Running,
        })
    }

    /// The final surface.
    pub fn surface(&self) -> &SubdivSurface {
        &self.surface
    }

    /// The control points before the last move (the warm pass starts from their foot points).
    pub fn control_points_before(&self) -> &[Point3] {
        &self.before
    }

    /// The data points.
    pub fn data(&self) -> &[Point3] {
        &self.data
    }

    /// Number of data points (foot points per pass).
    pub fn num_points(&self) -> usize {
        self.data.len()
    }

    /// Number of control points of the final surface.
    pub fn num_control_points(&self) -> usize {
        self.after.len()
    }

    /// Iterations the fit ran, and how it ended.
    pub fn fit_outcome(&self) -> (usize, FitStatus) {
        (self.iterations, self.status)
    }

    /// Largest control-point move of the warm pass (model units).
    pub fn largest_move(&self) -> f64 {
        self.before
            .iter()
            .zip(&self.after)
            .map(|(a, b)| (*a - *b).length())
            .fold(0.0, f64::max)
    }

    /// One pass of cold foot points: every data point from the spatial index.
    pub fn cold(&self) -> FootPointTiming {
        let start = Instant::now();
        let feet = cold_feet(
            &self.surface,
            &self.index,
            &self.data,
            &self.newton,
            BENCH_PART,
        );
        let seconds = start.elapsed().as_secs_f64();
        summary(feet.as_deref().unwrap_or(&[]), seconds)
    }

    /// One pass of warm foot points: every data point from its foot point on the previous
    /// control points.
    pub fn warm(&self) -> FootPointTiming {
        let mut feet = self.previous.clone();
        let start = Instant::now();
        warm_feet(
            &self.surface,
            &self.index,
            &self.data,
            &self.previous,
            &self.newton,
            self.slack,
            &mut feet,
        );
        let seconds = start.elapsed().as_secs_f64();
        summary(&feet, seconds)
    }
}

fn summary(feet: &[FootPoint], seconds: f64) -> FootPointTiming {
    let mut t = FootPointTiming {
        points: 0,
        seconds,
        iterations: 0,
        unconverged: 0,
        distance_sum: 0.0,
    };
    for f in feet {
        tally(&mut t, f);
    }
    t
}

fn tally(t: &mut FootPointTiming, f: &FootPoint) {
    t.points += 1;
    t.iterations += u64::from(f.iterations);
    t.unconverged += usize::from(!f.converged);
    t.distance_sum += f.dist_sq.sqrt();
}

/// `points` each moved by a deterministic pseudo-random vector of length at most `size`.
fn perturbed(points: &[Point3], size: f64) -> Vec<Point3> {
    let mut s: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut next = || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    points
        .iter()
        .map(|&p| p + Point3::new(next(), next(), next()) * (size / 3f64.sqrt()))
        .collect()
}
