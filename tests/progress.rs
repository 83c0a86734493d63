//! Progress reports of a whole fit of bare points: every phase the page's progress bar names
//! is heard, in order, each rising from its start to its end.

use geofit::fit::{FitData, FitSpec, Scheme};
use geofit::io::read_bytes;
use geofit::progress::{watch, Phase};
use std::cell::RefCell;
use std::fmt::Write;
use std::rc::Rc;

/// A wavy open sheet of `n` × `n` points as XYZ text, rows jittered so that no four points
/// are cocircular (the Delaunay triangulation of an exact grid is a degenerate case).
fn sheet(n: usize) -> Vec<u8> {
    let mut text = String::new();
    for i in 0..n {
        for j in 0..n {
            let x = (j as f64 + 0.25 * ((i * 7 + j * 13) % 5) as f64 / 5.0) / n as f64;
            let y = i as f64 / n as f64;
            let z = 0.05 * (7.0 * x).sin() * (5.0 * y).cos();
            writeln!(text, "{x:.6} {y:.6} {z:.6}").unwrap();
        }
    }
    text.into_bytes()
}

/// What `f` reports, in order.
fn heard(f: impl FnOnce()) -> Vec<(Phase, f64)> {
    let seen = Rc::new(RefCell::new(Vec::new()));
    let sink = Rc::clone(&seen);
    watch(Box::new(move |p, d| sink.borrow_mut().push((p, d))), f);
    let seen = seen.borrow().clone();
    seen
}

/// The phases in the order first heard, and for each whether its reports rose from 0 to 1.
fn phases(reports: &[(Phase, f64)]) -> Vec<Phase> {
    let mut order: Vec<Phase> = Vec::new();
    for &(p, _) in reports {
        if order.last() != Some(&p) {
            order.push(p);
        }
    }
    order
}

#[test]
fn a_fit_of_bare_points_reports_every_phase_in_order() {
    let bytes = sheet(120);
    let mut file = None;
    let reading = heard(|| file = Some(read_bytes(&bytes, Some("sheet.xyz")).unwrap()));
    let file = file.unwrap();
    assert_eq!(phases(&reading), [Phase::Reading]);
    let fractions: Vec<f64> = reading.iter().map(|r| r.1).collect();
    assert_eq!((fractions[0], *fractions.last().unwrap()), (0.0, 1.0));
    assert!(
        fractions.len() >= 3,
        "14,400 lines report on the way: {fractions:?}"
    );
    assert!(fractions.windows(2).all(|w| w[1] > w[0]), "{fractions:?}");

    let spec = FitSpec::new(Scheme::Loop);
    let mut fit = None;
    let setup = heard(|| fit = Some(spec.build(&FitData::from(&file)).unwrap()));
    let order = phases(&setup);
    // The reconstruction's mesh is clean: QEM's intake check skips the repair.
    assert_eq!(
        order,
        [Phase::Reconstruction, Phase::Simplification, Phase::Setup],
        "{setup:?}"
    );
    for phase in order {
        let d: Vec<f64> = setup.iter().filter(|r| r.0 == phase).map(|r| r.1).collect();
        assert_eq!((d[0], *d.last().unwrap()), (0.0, 1.0), "{phase:?}: {d:?}");
        assert!(d.windows(2).all(|w| w[1] > w[0]), "{phase:?}: {d:?}");
    }
    let reconstruction = setup
        .iter()
        .filter(|r| r.0 == Phase::Reconstruction)
        .count();
    assert!(
        reconstruction >= 10,
        "the meshing reports on the way: {reconstruction}"
    );

    let mut fit = fit.unwrap();
    let iteration = heard(|| {
        fit.step().unwrap();
    });
    assert_eq!(phases(&iteration), [Phase::Iteration]);
    let d: Vec<f64> = iteration.iter().map(|r| r.1).collect();
    assert_eq!((d[0], *d.last().unwrap()), (0.0, 1.0), "{d:?}");
    assert!(d.len() >= 3, "{d:?}");
    // Several iterations in one watched call (the wasm `run`): each is heard from its start.
    let iterations = heard(|| {
        for _ in 0..2 {
            fit.step().unwrap();
        }
    });
    let starts = iterations.iter().filter(|r| r.1 == 0.0).count();
    let ends = iterations.iter().filter(|r| r.1 == 1.0).count();
    assert_eq!((starts, ends), (2, 2), "{iterations:?}");
}

#[test]
fn progress_changes_no_result() {
    let bytes = sheet(60);
    let file = read_bytes(&bytes, Some("sheet.xyz")).unwrap();
    let spec = FitSpec::new(Scheme::Loop);
    let run = || {
        let mut fit = spec.build(&FitData::from(&file)).unwrap();
        fit.step().unwrap();
        (
            fit.num_control_points(),
            fit.stats().e_max_pct,
            fit.stats().e_rms_pct,
        )
    };
    let quiet = run();
    let mut watched = None;
    let reports = heard(|| watched = Some(run()));
    assert!(!reports.is_empty());
    assert_eq!(watched, Some(quiet));
}

#[test]
fn a_mesh_that_needs_repair_reports_it_before_qem() {
    // Two tetrahedra sharing a vertex (a non-manifold vertex), one face given twice.
    let obj = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv -1 0 0\nv 0 -1 0\nv 0 0 -1\n\
                f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\nf 2 3 4\n\
                f 1 5 6\nf 1 6 7\nf 1 7 5\nf 5 7 6\n";
    let file = read_bytes(obj, Some("pair.obj")).unwrap();
    let spec = FitSpec::new(Scheme::Loop).with_initial(Some(7));
    let reports = heard(|| {
        spec.build(&FitData::from(&file)).unwrap();
    });
    assert_eq!(
        phases(&reports),
        [Phase::Repair, Phase::Simplification, Phase::Setup],
        "{reports:?}"
    );
    let repair: Vec<f64> = reports
        .iter()
        .filter(|r| r.0 == Phase::Repair)
        .map(|r| r.1)
        .collect();
    assert_eq!(
        (repair[0], *repair.last().unwrap()),
        (0.0, 1.0),
        "{repair:?}"
    );
}
