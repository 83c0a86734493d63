//! Foot-point rate on the Stanford bunny's final surface (issue 17, item 2: at least 3 M foot
//! points per second per core). For each scheme (Loop, Catmull–Clark, Doo–Sabin) the bunny
//! (35,947 points) is fitted with the Table 1 model C settings (612 initial control points,
//! E_avg 0.01 %, E_max 0.05 %, at most 7049 control points) to the end; then every data point's
//! foot point on the final limit surface is timed
//! - cold: from the spatial index, as the fit's first iteration finds them;
//! - warm: from the foot points on the control points before the fit's last move, as every
//!   later iteration finds them.
//!
//! Run: `cargo bench --bench foot_points [-- SCHEME...]` (schemes: loop, catmull-clark,
//! doo-sabin; all three by default). The data directory is `GEOFIT_DATA`, else
//! `../shared/data` beside the repository, else `/work/shared/data`. Each figure is the best
//! of `REPEATS` passes, in thread CPU time where the system gives it (so a busy machine does not
//! lower it), and wall time otherwise. A plain timing loop (no criterion) keeps the
//! dev-dependencies and the build small.

use geofit::fit::{FitData, FitSpec, FootPointBench, FootPointTiming, Scheme};
use std::path::PathBuf;
use std::time::Instant;

/// Timed passes of each kind; the best counts.
const REPEATS: usize = 7;

/// CPU time of this thread in seconds (`CLOCK_THREAD_CPUTIME_ID`: nanoseconds, unlike the
/// scheduler's tick-granular counters in /proc), `None` where there is none.
#[cfg(unix)]
fn thread_cpu_seconds() -> Option<f64> {
    let mut t = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `t` is a valid timespec for clock_gettime to write.
    let ok = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut t) } == 0;
    ok.then_some(t.tv_sec as f64 + t.tv_nsec as f64 * 1e-9)
}

#[cfg(not(unix))]
fn thread_cpu_seconds() -> Option<f64> {
    None
}

fn data_dir() -> PathBuf {
    if let Some(d) = std::env::var_os("GEOFIT_DATA") {
        return PathBuf::from(d);
    }
    let beside = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/data");
    if beside.is_dir() {
        beside
    } else {
        PathBuf::from("/work/shared/data")
    }
}

/// The best of [`REPEATS`] runs of `pass`, timed in thread CPU time where available (a pass
/// takes tens of milliseconds, so each is repeated until it has run 0.2 s of CPU).
fn best(pass: impl Fn() -> FootPointTiming) -> (FootPointTiming, f64) {
    let first = pass();
    let mut best_rate = 0.0f64;
    for _ in 0..REPEATS {
        let (cpu0, wall0) = (thread_cpu_seconds(), Instant::now());
        let mut points = 0;
        while wall0.elapsed().as_secs_f64() < 0.2 {
            let t = pass();
            assert_eq!(
                t.distance_sum.to_bits(),
                first.distance_sum.to_bits(),
                "passes differ"
            );
            points += t.points;
        }
        let wall = wall0.elapsed().as_secs_f64();
        let cpu = cpu0
            .and_then(|c| Some(thread_cpu_seconds()? - c))
            .filter(|&c| c > 0.0);
        best_rate = best_rate.max(points as f64 / cpu.unwrap_or(wall));
    }
    (first, best_rate)
}

fn main() {
    // One thread: the figure is per core, and thread CPU time counts only this thread.
    geofit::fit::set_max_threads(1);
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with('-'))
        .collect();
    let path = data_dir().join("stanford-bunny.obj");
    let loaded = match geofit::io::read_path(&path) {
        Ok(l) => l,
        Err(e) => {
            eprintln!("cannot read {}: {e}", path.display());
            return;
        }
    };
    let data = FitData::from(&loaded);
    for (name, scheme) in [
        ("loop", Scheme::Loop),
        ("catmull-clark", Scheme::CatmullClark),
        ("doo-sabin", Scheme::DooSabin),
    ] {
        if !args.is_empty() && !args.iter().any(|a| a == name) {
            continue;
        }
        let mut spec = FitSpec::new(scheme);
        spec.initial = Some(612);
        spec.tol_avg = Some(0.01);
        spec.tol_max = Some(0.05);
        spec.max_control = Some(7049);
        let t0 = Instant::now();
        let bench = match FootPointBench::from_fit(&spec, &data) {
            Ok(b) => b,
            Err(e) => {
                eprintln!("{name}: {e}");
                continue;
            }
        };
        let (iters, status) = bench.fit_outcome();
        println!(
            "{name}: fit {iters} iterations ({status:?}), {} control points, {} points, set-up {:.1} s, last move up to {:.2e}",
            bench.num_control_points(),
            bench.num_points(),
            t0.elapsed().as_secs_f64(),
            bench.largest_move(),
        );
        for (kind, pass) in [
            ("cold", &(|| bench.cold()) as &dyn Fn() -> FootPointTiming),
            ("warm", &|| bench.warm()),
        ] {
            let (t, rate) = best(pass);
            println!(
                "  {kind}: {:.3} M foot points/s per core ({:.0} ns each); {:.2} Newton iterations per point, {} not converged, distance sum {:.9e}  [{}]",
                rate / 1e6,
                1e9 / rate,
                t.iterations as f64 / t.points.max(1) as f64,
                t.unconverged,
                t.distance_sum,
                if t.distance_sum.is_finite() { "ok" } else { "non-finite!" }
            );
        }
    }
}
