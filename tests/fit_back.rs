//! A subdivision fit converges only when its surface lies on the data both ways: the surface →
//! data bound (2 × the E_max tolerance) holds at every vertex of the 16-segment tessellation of
//! its limit surface, not only at the two samples per patch that every iteration measures.

mod common;

use geofit::fit::{FitData, FitReport, FitSpec, FitStatus, Scheme, Shape, BACK_TOLERANCE_FACTOR};
use geofit::io::read_path;

/// Fits `file` (of the repository's data) with `scheme` at the defaults and returns the report,
/// the surface → data bound and the largest distance of the 16 × 16 tessellation's vertices to
/// the data, both % of the diagonal; `None` when the data is not there.
fn fit_and_measure(file: &str, scheme: Scheme) -> Option<(FitReport, f64, f64)> {
    let path = common::data_file(file);
    if !path.exists() {
        eprintln!("skipped: no {}", path.display());
        return None;
    }
    let mesh = read_path(&path).expect("the file reads").mesh;
    let mut fit = FitSpec::new(scheme)
        .build(&FitData::points(&mesh))
        .expect("the fit starts");
    fit.run().expect("the fit runs");
    let Shape::Mesh(limit) = fit.limit_shape(16) else {
        panic!("a subdivision fit has a limit mesh");
    };
    let distances = fit
        .distances_to_data(limit.positions())
        .expect("a mesh fit measures the surface against its triangles");
    let worst = distances.into_iter().flatten().fold(0.0, f64::max);
    let bound = BACK_TOLERANCE_FACTOR * fit.tolerances().max_pct.expect("an E_max tolerance");
    Some((
        FitReport::of(fit.as_ref()),
        bound,
        100.0 * worst / fit.diagonal(),
    ))
}

#[test]
fn a_converged_fit_lies_on_the_data_at_every_tessellation_vertex() {
    // With two samples per patch as the only check, both fits "converged" at the defaults
    // while their tessellations reached 1.54 % (cow, Catmull–Clark) and 1.20 % (beetle, Loop)
    // from the data, for a bound of 1 %.
    for (file, scheme) in [
        ("corpus/cow.obj", Scheme::CatmullClark),
        ("corpus/beetle.obj", Scheme::Loop),
    ] {
        let Some((report, bound, worst)) = fit_and_measure(file, scheme) else {
            continue;
        };
        let back = report.e_back_max_pct.expect("E_back measured");
        let last = report.history.last().expect("iterations ran");
        println!(
            "{file} {scheme:?}: {:?} after {} iterations, E_back {back:.3} %, tessellation {worst:.3} %",
            report.status, report.iterations
        );
        assert_eq!(report.status, FitStatus::Converged, "{file} {scheme:?}");
        assert!(worst <= bound, "{file} {scheme:?}: {worst} % > {bound} %");
        assert!(back <= bound);
        // The final row carries the dense figure the fit ended with.
        assert_eq!(last.e_back_max_pct, Some(back), "{file} {scheme:?}");
    }
}

/// A fit that stops unconverged ends at its best iteration since the last refinement, and
/// while it pulls its worst points in no move throws others off: the bunny at Table 1 model C
/// (Loop) stalled with E_max 0.43 %, one iteration after 0.047 %, when the heavy points of the
/// pull dragged their neighbours off in a move the weighted objective accepted.
#[test]
fn a_fit_that_stalls_ends_at_its_best_iteration() {
    let path = common::data_file("stanford-bunny.obj");
    if !path.exists() {
        eprintln!("skipped: no {}", path.display());
        return;
    }
    let mesh = read_path(&path).expect("the file reads").mesh;
    let mut spec = FitSpec::new(Scheme::Loop);
    (spec.initial, spec.tol_avg, spec.tol_max) = (Some(612), Some(0.01), Some(0.05));
    (spec.max_control, spec.max_iter) = (Some(7049), Some(60));
    let mut fit = spec.build(&FitData::points(&mesh)).expect("the fit starts");
    fit.run().expect("the fit runs");
    let report = FitReport::of(fit.as_ref());
    let k = report
        .ended_at_iteration
        .expect("this fit is known to stop past its best iteration");
    println!(
        "{:?} after {} iterations, back to iteration {k}: E_max {:.4} %",
        report.status, report.iterations, report.e_max_pct
    );
    assert_ne!(report.status, FitStatus::Converged);
    let history = &report.history;
    let last_refined = history.iter().rposition(|r| r.refined).map_or(0, |i| i + 1);
    assert!(
        k >= last_refined && k < report.iterations,
        "{k} {last_refined}"
    );
    // The same control points give the same figures (foot points found again).
    let best = &history[k - 1];
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-3 * b;
    assert!(
        close(report.e_max_pct, best.e_max_pct),
        "{} {}",
        report.e_max_pct,
        best.e_max_pct
    );
    assert!(close(report.e_avg_pct, best.e_avg_pct));
    // The last record is the state the fit ends in, and no worse on E_max than its best.
    let last = history.last().expect("iterations ran");
    assert_eq!(last.e_max_pct, report.e_max_pct);
    assert_eq!(last.e_back_max_pct, report.e_back_max_pct);
    let worst_tail = history[last_refined..]
        .iter()
        .map(|r| r.e_max_pct)
        .fold(0.0, f64::max);
    assert!(report.e_max_pct <= worst_tail);
    // The fit's time is its records' time, the closing work (going back, the dense measure)
    // included in the last one.
    let ms: f64 = history.iter().map(|r| r.ms).sum();
    assert!(
        (report.fit_s * 1e3 - ms).abs() <= 1e-6 * ms,
        "{} {ms}",
        report.fit_s
    );
    assert!(
        worst_tail <= 2.0 * 0.05,
        "E_max jumped to {worst_tail} % after the last refinement"
    );
}

/// Doo–Sabin's split moves the surface (its new points are not those of a Doo–Sabin step), so
/// E_rms rises right after one; on rocker-arm at E_avg 0.01 % / E_max 0.05 % it rose 2.3 ×,
/// and the guard against broken splits (then: undo past 2 ×) undid every refinement: the fit
/// sat at its 1,200 initial control points with E_max 0.70 % until it stalled. The guard now
/// undoes a Doo–Sabin split only past 5 × (the broken splits it is for sent E_avg to 19 % and
/// 7e9 %).
#[test]
fn a_doo_sabin_split_that_moves_the_surface_is_kept() {
    let file = read_path(&common::data_file("rocker-arm.obj")).expect("rocker-arm.obj");
    let spec = FitSpec::new(Scheme::DooSabin)
        .with_tol_avg(Some(0.01))
        .with_tol_max(Some(0.05));
    let mut fit = spec.build(&FitData::from(&file)).expect("the fit starts");
    fit.run().expect("the fit runs");
    let r = FitReport::of(fit.as_ref());
    println!(
        "rocker-arm Doo-Sabin at 0.01 / 0.05: {:?}, {} -> {} control points, E_max {:.4} %",
        r.status, r.initial_control_points, r.final_control_points, r.e_max_pct
    );
    assert!(
        r.final_control_points > 2 * r.initial_control_points,
        "{} -> {} control points",
        r.initial_control_points,
        r.final_control_points
    );
    assert!(r.e_max_pct < 0.2, "E_max {:.4} %", r.e_max_pct);
}
