//! Trimmed B-spline surfaces: the outline of (u, v) parameters ([`TrimRegion::outline`]), its
//! `contains` test, degenerate parameters refused with typed errors, and the STEP / IGES trim
//! entities. Read-back by Open CASCADE (face valid, area) is in tests/interop/test_trim_occ.py.

use geofit::export::iges::write_iges;
use geofit::export::step::write_step;
use geofit::export::{ExportError, ExportModel, SurfaceDesc};
use geofit::geom::Point3;
use geofit::spline::{TrimError, TrimOptions, TrimRegion};

/// A 51 × 51 grid of [0, 1]² at spacing 0.02 without the points strictly inside
/// (0.4, 0.6)²: region area 1 − 0.2² exactly.
fn grid_with_hole() -> Vec<[f64; 2]> {
    let mut p = Vec::new();
    for i in 0..=50 {
        for j in 0..=50 {
            let (u, v) = (i as f64 / 50.0, j as f64 / 50.0);
            let inside = |x: f64| x > 0.4 + 1e-9 && x < 0.6 - 1e-9;
            if !(inside(u) && inside(v)) {
                p.push([u, v]);
            }
        }
    }
    p
}

#[test]
fn outline_of_a_grid_with_a_hole() {
    let o = TrimRegion::outline(&grid_with_hole(), &TrimOptions::default()).unwrap();
    assert!((o.spacing - 0.02).abs() < 1e-9, "spacing {}", o.spacing);
    assert_eq!(o.region.holes().len(), 1);
    // The alpha shape keeps the short-edged triangles across the hole's corners (legs up to
    // 4 spacings), so the hole is the 0.2 square with its corners cut: area in (0.03, 0.04].
    let hole = 1.0 - o.region.area();
    assert!(hole > 0.03 && hole <= 0.04 + 1e-12, "hole area {hole}");
    // Douglas–Peucker leaves the corners of the outer square, and at most the 8 of the cut one.
    assert_eq!(o.region.outer().len(), 4, "{:?}", o.region.outer());
    assert!(o.region.holes()[0].len() <= 8, "{:?}", o.region.holes());
    assert!(o.region.contains(0.1, 0.1));
    assert!(o.region.contains(0.39, 0.5));
    assert!(!o.region.contains(0.5, 0.5));
    assert!(!o.region.contains(1.2, 0.5));
    assert!(!o.region.contains(-0.01, 0.5));
    // The kept Delaunay triangles (half cells, or corner cuts across the hole) cover the
    // square less the cut hole, as the region does.
    let p = grid_with_hole();
    let tri_area: f64 = o
        .triangles
        .iter()
        .map(|t| {
            let (a, b, c) = (p[t[0]], p[t[1]], p[t[2]]);
            ((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1])) / 2.0
        })
        .sum();
    assert!(tri_area > 0.96 && tri_area < 0.97, "{tri_area}");
}

#[test]
fn small_gaps_are_not_holes() {
    // A hole one spacing wide (a single missing point) is data, not a hole.
    let p: Vec<[f64; 2]> = grid_with_hole()
        .into_iter()
        .chain((0..=50).flat_map(|i| {
            (0..=50).filter_map(move |j| {
                let (u, v) = (i as f64 / 50.0, j as f64 / 50.0);
                let inside = |x: f64| x > 0.4 + 1e-9 && x < 0.6 - 1e-9;
                (inside(u) && inside(v) && !(i == 25 && j == 25)).then_some([u, v])
            })
        }))
        .collect();
    let o = TrimRegion::outline(&p, &TrimOptions::default()).unwrap();
    assert!(o.region.holes().is_empty(), "{:?}", o.region.holes());
    assert!((o.region.area() - 1.0).abs() < 1e-9);
}

#[test]
fn degenerate_parameters_give_typed_errors() {
    let opts = TrimOptions::default();
    assert_eq!(
        TrimRegion::outline(&[[0.0, 0.0], [1.0, 1.0]], &opts),
        Err(TrimError::TooFewPoints { found: 2 })
    );
    let line: Vec<[f64; 2]> = (0..20).map(|k| [k as f64 * 0.1, k as f64 * 0.05]).collect();
    assert_eq!(
        TrimRegion::outline(&line, &opts),
        Err(TrimError::Degenerate { points: 20 })
    );
    let same = vec![[0.3, 0.3]; 10];
    assert!(TrimRegion::outline(&same, &opts).is_err());
    let mut nan = grid_with_hole();
    nan[7] = [f64::NAN, 0.5];
    assert_eq!(
        TrimRegion::outline(&nan, &opts),
        Err(TrimError::NotFinite { index: 7 })
    );
    let three = TrimRegion::outline(&[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]], &opts).unwrap();
    assert!((three.region.area() - 0.5).abs() < 1e-12);
    assert!(TrimRegion::try_new(vec![[0.0, 0.0], [1.0, 0.0]], vec![]).is_err());
}

#[test]
fn try_new_orients_loops() {
    let cw = vec![[0.0, 0.0], [0.0, 1.0], [1.0, 1.0], [1.0, 0.0]];
    let hole_ccw = vec![[0.4, 0.4], [0.6, 0.4], [0.6, 0.6], [0.4, 0.6]];
    let r = TrimRegion::try_new(cw, vec![hole_ccw]).unwrap();
    assert!((r.area() - 0.96).abs() < 1e-12);
    assert!(!r.contains(0.5, 0.5) && r.contains(0.2, 0.5));
}

fn trimmed_patch(trim: Option<TrimRegion>) -> ExportModel {
    let grid: Vec<Point3> = (0..16)
        .map(|k| Point3::new((k / 4) as f64, (k % 4) as f64, ((k * 7) % 3) as f64 * 0.2))
        .collect();
    let s = SurfaceDesc {
        degree_u: 3,
        degree_v: 3,
        knots_u: vec![0., 0., 0., 0., 1., 1., 1., 1.],
        knots_v: vec![0., 0., 0., 0., 1., 1., 1., 1.],
        num_u: 4,
        num_v: 4,
        control_points: grid,
        weights: None,
        trim,
    };
    ExportModel {
        curves: vec![],
        surfaces: vec![s],
    }
}

#[test]
fn step_and_iges_carry_the_trim() {
    let o = TrimRegion::outline(&grid_with_hole(), &TrimOptions::default()).unwrap();
    let model = trimmed_patch(Some(o.region));
    let step = write_step(&model, "trim").unwrap();
    for e in [
        "ADVANCED_FACE(",
        "FACE_OUTER_BOUND(",
        "FACE_BOUND(",
        "PCURVE(",
        "SURFACE_CURVE(",
        "EDGE_LOOP(",
        "OPEN_SHELL(",
        "MANIFOLD_SURFACE_SHAPE_REPRESENTATION(",
    ] {
        assert!(step.contains(e), "STEP lacks {e}");
    }
    assert!(!step.contains("GEOMETRIC_SET("));
    let iges = write_iges(&model, "trim").unwrap();
    let kinds: Vec<&str> = iges
        .lines()
        .filter(|l| l.as_bytes().get(72) == Some(&b'D'))
        .step_by(2)
        .map(|l| l[..8].trim())
        .collect();
    // 128, then per loop a (u, v) 126, a 3D 126 and a 142, then the 144.
    assert_eq!(
        kinds,
        ["128", "126", "126", "142", "126", "126", "142", "144"]
    );
    assert!(iges.lines().all(|l| l.len() == 80));
    // Untrimmed: the bare surface as before.
    let plain = write_step(&trimmed_patch(None), "plain").unwrap();
    assert!(plain.contains("GEOMETRIC_SET(") && !plain.contains("ADVANCED_FACE("));
}

#[test]
fn trim_outside_the_domain_is_refused() {
    let r = TrimRegion::try_new(vec![[0.0, 0.0], [1.5, 0.0], [0.0, 1.0]], vec![]).unwrap();
    let err = write_step(&trimmed_patch(Some(r)), "x").unwrap_err();
    assert!(matches!(err, ExportError::Invalid { .. }), "{err}");
}
