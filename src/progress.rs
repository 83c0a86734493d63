//! Progress of the long calls (reading a file, repair, reconstruction, QEM, a fit's set-up and
//! its iterations), for the page's progress bar and any caller that shows one.
//!
//! A caller that wants progress runs its call inside [`watch`]; the code of each phase reports
//! with [`report`]. Why a scoped sink rather than an argument: the phases sit deep inside
//! `FitSpec::build` (QEM's passes, the reconstruction's steps, the first foot points), and a
//! callback threaded through every signature on the way would be an argument a dozen functions
//! carry for no other use. [`report`] costs one thread-local read when nobody watches, and
//! hands the sink at most about a hundred reports per round of a phase (a new phase, a phase
//! that starts over, or one percent more of it), so a sink may do real work (the page posts a message per report). Reports from other
//! threads go nowhere: a phase reports from the thread that drives it.

use std::cell::RefCell;

/// A stage of the work, in the order a fit of bare points goes through them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    /// Parsing the file.
    Reading,
    /// Mending the mesh (non-manifold parts, degenerate and duplicate faces, orientation).
    Repair,
    /// Meshing bare points.
    Reconstruction,
    /// QEM down to the initial control mesh.
    Simplification,
    /// The fit's set-up after its initial control net: patches, foot points, first errors.
    Setup,
    /// One iteration of a fit.
    Iteration,
}

impl Phase {
    /// The phase's name as the JavaScript API spells it.
    pub fn name(self) -> &'static str {
        match self {
            Phase::Reading => "reading",
            Phase::Repair => "repair",
            Phase::Reconstruction => "reconstruction",
            Phase::Simplification => "simplification",
            Phase::Setup => "setup",
            Phase::Iteration => "iteration",
        }
    }
}

/// Receives `(phase, done)` with `done` in [0, 1].
pub type Sink = Box<dyn FnMut(Phase, f64)>;

/// Items (points, cells) a loop handles between two calls of [`report`]: the call is cheap,
/// but not free in loops of a few nanoseconds per item.
pub(crate) const BATCH: usize = 1 << 12;

/// The share of a phase that makes a new report worth sending.
const STEP: f64 = 0.01;

struct Watcher {
    sink: Sink,
    /// The last report handed to the sink.
    last: Option<(Phase, f64)>,
}

thread_local! {
    static WATCHER: RefCell<Option<Watcher>> = const { RefCell::new(None) };
}

/// Runs `f` with `sink` receiving the progress reports made on this thread, then restores
/// whatever watched before (calls may nest; the inner sink gets the inner call's reports).
pub fn watch<R>(sink: Sink, f: impl FnOnce() -> R) -> R {
    let outer = WATCHER.with(|w| w.replace(Some(Watcher { sink, last: None })));
    // Restored on unwinding too, so a panic inside `f` leaves no stale sink behind.
    struct Restore(Option<Option<Watcher>>);
    impl Drop for Restore {
        fn drop(&mut self) {
            let outer = self.0.take().flatten();
            WATCHER.with(|w| *w.borrow_mut() = outer);
        }
    }
    let _restore = Restore(Some(outer));
    f()
}

/// Reports that `done` (clamped to [0, 1]; NaN counts as 0) of `phase` is done. Passed on when
/// the phase changed or started over (less done than last reported), at its end, or when it
/// moved on by [`STEP`] since the last report.
pub(crate) fn report(phase: Phase, done: f64) {
    let done = if done.is_nan() {
        0.0
    } else {
        done.clamp(0.0, 1.0)
    };
    WATCHER.with(|w| {
        // A sink that reports from inside itself (it should not) is ignored, not a panic.
        let Ok(mut guard) = w.try_borrow_mut() else {
            return;
        };
        let Some(watcher) = guard.as_mut() else {
            return;
        };
        let due = match watcher.last {
            // A phase that starts over (the next iteration, a second QEM run) is a new round.
            Some((p, d)) if p == phase => done < d || done >= d + STEP || (done == 1.0 && d < 1.0),
            _ => true,
        };
        if due {
            watcher.last = Some((phase, done));
            (watcher.sink)(phase, done);
        }
    });
}

/// Reports `done` of `total` steps of `phase` (nothing when `total` is 0).
pub(crate) fn report_count(phase: Phase, done: usize, total: usize) {
    if total > 0 {
        report(phase, done as f64 / total as f64);
    }
}

/// The share `from..to` of a phase that one step of it takes (the reconstruction's Delaunay
/// triangulation is 0.35..0.85 of the reconstruction): reports its own progress as the phase's.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Part {
    pub phase: Phase,
    pub from: f64,
    pub to: f64,
}

impl Part {
    /// Reports that `done` of `total` of this part is done.
    pub(crate) fn count(self, done: usize, total: usize) {
        if total > 0 {
            let t = done as f64 / total as f64;
            report(self.phase, self.from + (self.to - self.from) * t);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::rc::Rc;

    fn collect(f: impl FnOnce()) -> Vec<(Phase, f64)> {
        let seen = Rc::new(RefCell::new(Vec::new()));
        let sink = Rc::clone(&seen);
        watch(Box::new(move |p, d| sink.borrow_mut().push((p, d))), f);
        Rc::try_unwrap(seen)
            .map(RefCell::into_inner)
            .unwrap_or_default()
    }

    #[test]
    fn reports_are_thinned_to_steps_and_phase_changes() {
        let seen = collect(|| {
            for i in 0..=10_000 {
                report_count(Phase::Simplification, i, 10_000);
            }
            report(Phase::Setup, 0.0);
            report(Phase::Setup, 0.004);
            report(Phase::Setup, 1.0);
        });
        let qem: Vec<f64> = seen
            .iter()
            .filter(|(p, _)| *p == Phase::Simplification)
            .map(|s| s.1)
            .collect();
        assert_eq!(qem.len(), 101, "{qem:?}");
        assert_eq!((qem[0], qem[100]), (0.0, 1.0));
        assert!(qem.windows(2).all(|w| w[1] > w[0]));
        let setup: Vec<f64> = seen
            .iter()
            .filter(|(p, _)| *p == Phase::Setup)
            .map(|s| s.1)
            .collect();
        assert_eq!(setup, [0.0, 1.0]);
    }

    #[test]
    fn a_phase_that_starts_over_is_heard_again() {
        // Iterations in one watched call (`run`): every one is heard from its start to its end.
        let seen = collect(|| {
            for _ in 0..3 {
                report(Phase::Iteration, 0.0);
                report(Phase::Iteration, 0.6);
                report(Phase::Iteration, 1.0);
            }
        });
        let done: Vec<f64> = seen.iter().map(|s| s.1).collect();
        assert_eq!(done, [0.0, 0.6, 1.0, 0.0, 0.6, 1.0, 0.0, 0.6, 1.0]);
    }

    #[test]
    fn out_of_range_and_nan_are_clamped() {
        let seen = collect(|| {
            report(Phase::Reading, f64::NAN);
            report(Phase::Repair, 7.0);
            report(Phase::Iteration, -1.0);
        });
        assert_eq!(
            seen,
            [
                (Phase::Reading, 0.0),
                (Phase::Repair, 1.0),
                (Phase::Iteration, 0.0)
            ]
        );
    }

    #[test]
    fn nothing_reaches_a_sink_outside_its_call_and_nesting_restores_the_outer() {
        report(Phase::Reading, 0.5);
        let mut inner = Vec::new();
        let outer = collect(|| {
            report(Phase::Reading, 0.5);
            inner = collect(|| report(Phase::Repair, 0.5));
            report(Phase::Setup, 0.5);
        });
        assert_eq!(inner, [(Phase::Repair, 0.5)]);
        assert_eq!(outer, [(Phase::Reading, 0.5), (Phase::Setup, 0.5)]);
        report(Phase::Setup, 1.0);
    }

    #[test]
    fn a_panic_inside_leaves_no_sink_behind() {
        let hit = Rc::new(RefCell::new(0));
        let count = Rc::clone(&hit);
        let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            watch(Box::new(move |_, _| *count.borrow_mut() += 1), || {
                panic!("inside")
            })
        }));
        assert!(result.is_err());
        report(Phase::Reading, 1.0);
        assert_eq!(*hit.borrow(), 0);
    }
}
