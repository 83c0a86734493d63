//! Sharp-feature detection (`mesh::detect_features`): synthetic meshes with known creases, with
//! and without noise; the real parts of ../shared/data and smooth scans; bad options.

mod common;

use common::{data_file, sphere_mesh, Rng};
use geofit::geom::Point3;
use geofit::mesh::{detect_features, repair, FeatureOptions, Features, MeshError, PolyMesh};
use std::collections::HashSet;

/// A unit cube of 6 · 2 · 4^levels triangles.
fn fine_box(levels: usize) -> PolyMesh {
    common::meshes::refine_flat(&common::meshes::cube(), levels)
}

/// A closed cylinder (radius 1, height 2, `n` segments around, `rows` rows), its caps fans around
/// a centre vertex.
fn cylinder(n: usize, rows: usize) -> PolyMesh {
    let mut p = Vec::new();
    for r in 0..=rows {
        let z = 2.0 * r as f64 / rows as f64;
        for i in 0..n {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            p.push(Point3::new(a.cos(), a.sin(), z));
        }
    }
    let at = |r: usize, i: usize| (r * n + i % n) as u32;
    let mut t = Vec::new();
    for r in 0..rows {
        for i in 0..n {
            t.push([at(r, i), at(r, i + 1), at(r + 1, i + 1)]);
            t.push([at(r, i), at(r + 1, i + 1), at(r + 1, i)]);
        }
    }
    let (bottom, top) = (p.len() as u32, p.len() as u32 + 1);
    p.push(Point3::new(0.0, 0.0, 0.0));
    p.push(Point3::new(0.0, 0.0, 2.0));
    for i in 0..n {
        t.push([bottom, at(0, i + 1), at(0, i)]);
        t.push([top, at(rows, i), at(rows, i + 1)]);
    }
    PolyMesh::try_new(p, t).expect("cylinder")
}

/// `mesh` with every vertex moved by uniform noise of up to `amount` per coordinate.
fn noisy(mesh: &PolyMesh, amount: f64, seed: u64) -> PolyMesh {
    let mut rng = Rng(seed);
    let p = mesh
        .positions()
        .iter()
        .map(|&x| x + rng.vec() * amount)
        .collect();
    PolyMesh::try_new(p, mesh.triangles()).expect("noisy mesh")
}

fn detect(mesh: &PolyMesh) -> Features {
    detect_features(mesh, &FeatureOptions::default()).expect("detection")
}

/// Length of the crease edges of `a` that `b` has too, over the length of all of `a`'s.
fn kept_share(mesh: &PolyMesh, a: &Features, b: &Features) -> f64 {
    let in_b: HashSet<[u32; 2]> = b.edges.iter().copied().collect();
    let len =
        |e: &[u32; 2]| mesh.positions()[e[0] as usize].distance(mesh.positions()[e[1] as usize]);
    let kept: f64 = a.edges.iter().filter(|e| in_b.contains(*e)).map(len).sum();
    kept / a.edges.iter().map(len).sum::<f64>()
}

#[test]
fn a_fine_box_has_its_twelve_edges_and_eight_corners() {
    let mesh = fine_box(3);
    let f = detect(&mesh);
    assert_eq!(f.corners.len(), 8, "{}", f.summary());
    assert!(f.darts.is_empty(), "{}", f.summary());
    assert_eq!(f.lines.len(), 12, "{}", f.summary());
    assert!((f.total_length - 12.0).abs() < 1e-9, "{}", f.summary());
    for line in &f.lines {
        assert!((line.length - 1.0).abs() < 1e-9 && !line.closed);
    }
}

#[test]
fn a_cylinder_has_its_two_rims_as_closed_loops() {
    let mesh = cylinder(48, 12);
    let f = detect(&mesh);
    assert_eq!(f.lines.len(), 2, "{}", f.summary());
    assert!(
        f.lines.iter().all(|l| l.closed && l.vertices.len() == 48),
        "{}",
        f.summary()
    );
    assert!(
        f.corners.is_empty() && f.darts.is_empty(),
        "{}",
        f.summary()
    );
    let rim = 48.0 * 2.0 * (std::f64::consts::PI / 48.0).sin();
    assert!((f.total_length - 2.0 * rim).abs() < 1e-9, "{}", f.summary());
}

#[test]
fn a_sphere_has_no_crease() {
    let f = detect(&sphere_mesh(4));
    assert!(f.edges.is_empty(), "{}", f.summary());
}

#[test]
fn noise_keeps_the_box_and_cylinder_creases() {
    for (name, mesh) in [("box", fine_box(3)), ("cylinder", cylinder(48, 12))] {
        let clean = detect(&mesh);
        let diagonal = mesh.bbox().expect("bbox").diagonal();
        for pct in [0.05, 0.2] {
            let shaken = noisy(&mesh, diagonal * pct / 100.0, 7);
            let f = detect(&shaken);
            let share = kept_share(&mesh, &clean, &f);
            assert!(
                share >= 0.9,
                "{name} at {pct} %: {share:.3} of the crease length kept; {}",
                f.summary()
            );
            assert!(
                f.edges.len() <= clean.edges.len() * 11 / 10,
                "{name} at {pct} %: {}",
                f.summary()
            );
        }
    }
}

#[test]
fn fandisk_creases_survive_scan_noise() {
    let file = geofit::io::read_path(&data_file("fandisk.obj")).expect("fandisk.obj");
    let mesh = repair(&file.mesh).expect("repair").mesh;
    let clean = detect(&mesh);
    let diagonal = mesh.bbox().expect("bbox").diagonal();
    println!(
        "fandisk: {}, {:.2} diagonals",
        clean.summary(),
        clean.total_length / diagonal
    );
    assert!(clean.total_length > 5.0 * diagonal, "{}", clean.summary());
    assert!(clean.corners.len() >= 10, "{}", clean.summary());
    // Gaussian-like noise of 0.05 % of the diagonal (the sum of three uniforms, σ = that).
    let sigma = diagonal * 0.05 / 100.0;
    let mut rng = Rng(3);
    let p = mesh
        .positions()
        .iter()
        .map(|&x| x + (rng.vec() + rng.vec() + rng.vec()) * sigma)
        .collect();
    let shaken = PolyMesh::try_new(p, mesh.triangles()).expect("noisy fandisk");
    let f = detect(&shaken);
    let share = kept_share(&mesh, &clean, &f);
    println!(
        "fandisk + noise σ 0.05 %: {}, {:.3} of the clean length kept",
        f.summary(),
        share
    );
    assert!(share >= 0.9, "{share:.3} kept: {}", f.summary());
}

#[test]
fn detection_is_deterministic_and_measured_on_every_mesh() {
    let mut rows = Vec::new();
    for dir in [common::data_dir(), common::data_dir().join("corpus")] {
        let mut files: Vec<_> = std::fs::read_dir(&dir)
            .expect("data dir")
            .map(|e| e.expect("entry").path())
            .filter(|p| p.extension().is_some_and(|e| e == "obj"))
            .collect();
        files.sort();
        for path in files {
            let file = geofit::io::read_path(&path).expect("readable");
            let mesh = repair(&file.mesh).expect("repair").mesh;
            let (a, b) = (detect(&mesh), detect(&mesh));
            assert_eq!(a, b, "{}: two runs differ", path.display());
            let diagonal = mesh.bbox().expect("bbox").diagonal();
            rows.push(format!(
                "| {} | {} | {} | {:.2} | {} |",
                path.file_name().expect("name").to_string_lossy(),
                a.edges.len(),
                a.lines.len(),
                a.total_length / diagonal,
                a.corners.len()
            ));
        }
    }
    println!(
        "| mesh | crease edges | lines | length (diagonals) | corners |\n|---|---|---|---|---|"
    );
    println!("{}", rows.join("\n"));
}

#[test]
fn point_clouds_and_empty_meshes_have_no_features() {
    let cloud = PolyMesh::from_points(vec![Point3::ZERO, Point3::X, Point3::Y]).expect("points");
    assert_eq!(detect(&cloud), Features::default());
    let one = PolyMesh::try_new(vec![Point3::ZERO, Point3::X, Point3::Y], vec![[0u32, 1, 2]])
        .expect("one face");
    assert!(detect(&one).edges.is_empty());
    // A degenerate sliver beside a face: no NaN angle, no panic.
    let sliver = PolyMesh::try_new(
        vec![
            Point3::ZERO,
            Point3::X,
            Point3::Y,
            Point3::new(2.0, 0.0, 0.0),
        ],
        vec![[0u32, 1, 2], [1, 0, 3]],
    )
    .expect("sliver");
    assert!(detect(&sliver).edges.is_empty());
}

#[test]
fn bad_options_are_typed_errors() {
    let mesh = fine_box(1);
    for angle in [0.0, -5.0, 180.0, f64::NAN, f64::INFINITY] {
        let o = FeatureOptions {
            angle_deg: angle,
            ..Default::default()
        };
        assert!(
            matches!(
                detect_features(&mesh, &o),
                Err(MeshError::InvalidOption { .. })
            ),
            "{angle}"
        );
    }
    let o = FeatureOptions {
        smoothing: 1000,
        ..Default::default()
    };
    assert!(matches!(
        detect_features(&mesh, &o),
        Err(MeshError::InvalidOption { .. })
    ));
}

#[test]
fn inconsistent_orientation_does_not_make_creases() {
    // The sphere with every other face flipped: each edge is measured with one normal turned.
    let sphere = sphere_mesh(3);
    let flipped: Vec<[u32; 3]> = sphere
        .triangles()
        .into_iter()
        .enumerate()
        .map(|(i, [a, b, c])| if i % 2 == 0 { [a, c, b] } else { [a, b, c] })
        .collect();
    let mesh = PolyMesh::try_new(sphere.positions().to_vec(), flipped).expect("flipped");
    let f = detect_features(
        &mesh,
        &FeatureOptions {
            smoothing: 0,
            ..Default::default()
        },
    )
    .expect("detect");
    assert!(f.edges.is_empty(), "{}", f.summary());
}
