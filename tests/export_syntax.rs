//! IGES and STEP export: the files are syntactically valid (IGES fixed columns, section counts,
//! directory ↔ parameter pointers; STEP entity references resolve), closed and rational curves
//! and surfaces included, and bad descriptions are refused with typed errors. Read-back by Open
//! CASCADE is checked in tests/interop/test_export_occ.py.

use geofit::export::iges::write_iges;
use geofit::export::step::write_step;
use geofit::export::{CurveDesc, ExportError, ExportModel, SurfaceDesc};
use geofit::geom::Point3;
use geofit::spline::BSplineCurve;
use std::collections::{HashMap, HashSet};

fn model() -> ExportModel {
    let pts: Vec<Point3> = (0..7)
        .map(|i| {
            let t = i as f64;
            Point3::new(t.cos() * 10.0, t.sin() * 8.0, 0.5 * t)
        })
        .collect();
    let open = BSplineCurve::try_clamped_uniform(3, pts.clone()).unwrap();
    let closed = BSplineCurve::try_periodic_uniform(3, pts.clone()).unwrap();
    let rational = BSplineCurve::try_periodic_uniform(2, pts.clone())
        .unwrap()
        .try_with_weights(vec![1.0, 0.5, 2.0, 1.0, 0.7, 1.3, 0.9])
        .unwrap();
    let grid: Vec<Point3> = (0..20)
        .map(|k| Point3::new((k / 5) as f64, (k % 5) as f64, ((k * 7) % 3) as f64))
        .collect();
    let surface = SurfaceDesc {
        degree_u: 2,
        degree_v: 3,
        knots_u: vec![0., 0., 0., 0.5, 1., 1., 1.],
        knots_v: vec![0., 0., 0., 0., 0.5, 1., 1., 1., 1.],
        num_u: 4,
        num_v: 5,
        control_points: grid,
        weights: Some((0..20).map(|k| 1.0 + (k % 3) as f64 * 0.25).collect()),
        trim: None,
    };
    ExportModel {
        curves: [open, closed, rational]
            .iter()
            .map(|c| CurveDesc::from_curve(c).unwrap())
            .collect(),
        surfaces: vec![surface],
    }
}

#[test]
fn iges_has_fixed_columns_and_consistent_sections() {
    let text = write_iges(&model(), "model.igs").unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let mut counts: HashMap<char, usize> = HashMap::new();
    let mut order = String::new();
    for l in &lines {
        assert_eq!(l.len(), 80, "not 80 columns: {l:?}");
        let letter = l.as_bytes()[72] as char;
        let seq: usize = l[73..].trim().parse().unwrap();
        let c = counts.entry(letter).or_default();
        *c += 1;
        assert_eq!(seq, *c, "sequence of {letter} lines: {l:?}");
        if !order.ends_with(letter) {
            order.push(letter);
        }
    }
    assert_eq!(order, "SGDPT");
    let t = lines.last().unwrap();
    let field = |k: char| -> usize {
        let at = t.find(k).unwrap();
        t[at + 1..at + 8].trim().parse().unwrap()
    };
    for k in ['S', 'G', 'D', 'P'] {
        assert_eq!(field(k), counts[&k], "terminate count of {k}");
    }
    // Directory entries point at their parameter lines, which point back.
    let d: Vec<&str> = lines
        .iter()
        .copied()
        .filter(|l| l.as_bytes()[72] == b'D')
        .collect();
    let p: Vec<&str> = lines
        .iter()
        .copied()
        .filter(|l| l.as_bytes()[72] == b'P')
        .collect();
    assert_eq!(d.len(), 8);
    for (k, pair) in d.chunks(2).enumerate() {
        let kind: usize = pair[0][..8].trim().parse().unwrap();
        let first: usize = pair[0][8..16].trim().parse().unwrap();
        let count: usize = pair[1][24..32].trim().parse().unwrap();
        assert_eq!(kind, if k < 3 { 126 } else { 128 });
        let params: String = p[first - 1..first - 1 + count]
            .iter()
            .map(|l| {
                let de: usize = l[65..72].trim().parse().unwrap();
                assert_eq!(de, 2 * k + 1, "back pointer of {l:?}");
                l[..64].trim_end()
            })
            .collect();
        assert!(params.starts_with(&format!("{kind},")) && params.ends_with(';'));
        let fields: Vec<&str> = params.trim_end_matches(';').split(',').collect();
        if kind == 126 {
            // 126: K, M, 4 flags, K+M+2 knots, K+1 weights, 3(K+1) coordinates, V0, V1, normal.
            let (kk, m): (usize, usize) = (fields[1].parse().unwrap(), fields[2].parse().unwrap());
            assert_eq!(
                fields.len(),
                7 + (kk + m + 2) + (kk + 1) + 3 * (kk + 1) + 2 + 3
            );
        }
    }
}

#[test]
fn step_references_resolve() {
    let text = write_step(&model(), "model.stp").unwrap();
    assert!(text.starts_with("ISO-10303-21;\nHEADER;"));
    assert!(text.trim_end().ends_with("END-ISO-10303-21;"));
    assert!(text.contains("FILE_SCHEMA(('AUTOMOTIVE_DESIGN"));
    let data = &text[text.find("DATA;").unwrap()..];
    let mut defined = HashSet::new();
    let mut used = Vec::new();
    for line in data.lines().filter(|l| l.starts_with('#')) {
        let eq = line.find('=').unwrap();
        assert!(defined.insert(line[1..eq].to_string()), "duplicate {line}");
        assert!(line.ends_with(';'));
        let body = &line[eq + 1..];
        assert_eq!(
            body.matches('(').count(),
            body.matches(')').count(),
            "{line}"
        );
        let mut rest = body;
        while let Some(at) = rest.find('#') {
            let digits: String = rest[at + 1..]
                .chars()
                .take_while(char::is_ascii_digit)
                .collect();
            used.push(digits.clone());
            rest = &rest[at + 1 + digits.len()..];
        }
    }
    for u in used {
        assert!(defined.contains(&u), "#{u} is referenced but not defined");
    }
    assert_eq!(data.matches("B_SPLINE_CURVE_WITH_KNOTS").count(), 3);
    assert_eq!(data.matches("RATIONAL_B_SPLINE_CURVE(").count(), 1);
    assert_eq!(data.matches("RATIONAL_B_SPLINE_SURFACE(").count(), 1);
}

#[test]
fn closed_curves_export_as_their_clamped_equivalent() {
    let m = model();
    let c = &m.curves[1];
    assert!(c.closed);
    let p = c.degree;
    assert!(c.knots[..=p].iter().all(|&k| k == c.knots[0]));
    let first = c.control_points[0];
    let last = *c.control_points.last().unwrap();
    assert!((first - last).length() < 1e-12, "the clamped ends meet");
}

#[test]
fn bad_descriptions_are_refused() {
    let mut m = model();
    m.curves[0].knots.pop();
    assert!(matches!(
        write_iges(&m, "x"),
        Err(ExportError::Count { .. })
    ));
    let mut m = model();
    m.curves[2].weights.as_mut().unwrap()[1] = -1.0;
    assert!(matches!(
        write_step(&m, "x"),
        Err(ExportError::Invalid { .. })
    ));
    let mut m = model();
    m.surfaces[0].control_points[3].z = f64::NAN;
    assert!(matches!(
        write_step(&m, "x"),
        Err(ExportError::Invalid { .. })
    ));
    let mut m = model();
    m.surfaces[0].knots_v.swap(4, 6);
    assert!(matches!(
        write_iges(&m, "x"),
        Err(ExportError::Invalid { .. })
    ));
    let mut m = model();
    m.surfaces[0].num_v = 4;
    assert!(write_iges(&m, "x").is_err());
}
