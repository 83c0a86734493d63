//! QEM that keeps sharp features (`mesh::simplify_with_creases`): the crease lines detected on
//! the input come out as chains of edges of the simplified mesh, on their course, with their
//! corners in place; without creases nothing changes.

mod common;

use common::data_file;
use common::manifold::assert_manifold;
use common::meshes::{crease_degrees, on_unit_cube_edge};
use geofit::geom::Point3;
use geofit::mesh::{
    detect_features, repair, simplify_with_creases, simplify_with_report, FeatureOptions, PolyMesh,
    Simplified, SimplifyOptions,
};

fn simplify_keeping_features(mesh: &PolyMesh, target: usize) -> (Simplified, usize) {
    let features = detect_features(mesh, &FeatureOptions::default()).expect("features");
    let done = simplify_with_creases(mesh, target, &SimplifyOptions::default(), &features.edges)
        .expect("simplify");
    (done, features.edges.len())
}

#[test]
fn a_fine_cube_keeps_its_edges_and_corners() {
    let mesh = common::meshes::refine_flat(&common::meshes::cube(), 4);
    let (done, input) = simplify_keeping_features(&mesh, 40);
    let out = &done.mesh;
    println!(
        "cube {} -> {} vertices, {} -> {} crease edges",
        mesh.num_vertices(),
        out.num_vertices(),
        input,
        done.creases.len()
    );
    assert_manifold(out);
    assert_eq!(done.report.creases.input, input);
    assert_eq!(done.report.creases.output, done.creases.len());
    // Every crease edge of the result runs along an edge of the cube, and the twelve edges
    // are all there: the crease graph has the 8 corners of degree 3 and the rest of degree 2.
    let pos = out.positions();
    for &[a, b] in &done.creases {
        let (pa, pb) = (pos[a as usize], pos[b as usize]);
        assert!(
            on_unit_cube_edge(pa, 1e-12) && on_unit_cube_edge(pb, 1e-12),
            "{pa:?}-{pb:?}"
        );
        let same = [pa.x == pb.x, pa.y == pb.y, pa.z == pb.z];
        assert_eq!(same.iter().filter(|&&s| s).count(), 2, "{pa:?}-{pb:?}");
    }
    let degree = crease_degrees(&done.creases);
    let corners: Vec<Point3> = degree
        .iter()
        .filter(|(_, &d)| d == 3)
        .map(|(&v, _)| pos[v as usize])
        .collect();
    assert_eq!(corners.len(), 8, "corners {corners:?}");
    for c in corners {
        assert!(
            [c.x, c.y, c.z].iter().all(|&x| x == 0.0 || x == 1.0),
            "{c:?}"
        );
    }
    assert!(degree.values().all(|&d| d == 2 || d == 3));
    let length: f64 = done
        .creases
        .iter()
        .map(|&[a, b]| pos[a as usize].distance(pos[b as usize]))
        .sum();
    assert!((length - 12.0).abs() < 1e-9, "crease length {length}");
    // Far fewer vertices than the fine mesh, near the target (corners and lines cost some).
    assert!(out.num_vertices() <= 60, "{} vertices", out.num_vertices());
}

#[test]
fn without_creases_the_result_is_unchanged() {
    let file = geofit::io::read_path(&data_file("fandisk.obj")).expect("fandisk.obj");
    let options = SimplifyOptions::default();
    let plain = simplify_with_report(&file.mesh, 300, &options).expect("simplify");
    let none = simplify_with_creases(&file.mesh, 300, &options, &[]).expect("simplify");
    assert_eq!(plain.mesh, none.mesh);
    assert!(none.creases.is_empty());
    // Pairs that are no edge are ignored.
    let bogus = simplify_with_creases(&file.mesh, 300, &options, &[[0, 0], [0, u32::MAX]])
        .expect("simplify");
    assert_eq!(plain.mesh, bogus.mesh);
}

#[test]
fn fandisk_keeps_its_crease_lines_through_qem() {
    let file = geofit::io::read_path(&data_file("fandisk.obj")).expect("fandisk.obj");
    let mesh = repair(&file.mesh).expect("repair").mesh;
    let features = detect_features(&mesh, &FeatureOptions::default()).expect("features");
    let (done, _) = simplify_keeping_features(&mesh, 200);
    let out = &done.mesh;
    assert_manifold(out);
    let input_length = features.total_length;
    let pos = out.positions();
    let length: f64 = done
        .creases
        .iter()
        .map(|&[a, b]| pos[a as usize].distance(pos[b as usize]))
        .sum();
    let kept_corners = crease_degrees(&done.creases)
        .values()
        .filter(|&&d| d >= 3)
        .count();
    println!(
        "fandisk {} -> {} vertices: crease length {:.4} -> {:.4}, corners {} -> {}",
        mesh.num_vertices(),
        out.num_vertices(),
        input_length,
        length,
        features.corners.len(),
        kept_corners
    );
    // Chains of chords of the lines: a little shorter where a line curves, never longer.
    assert!(length <= input_length * (1.0 + 1e-9));
    assert!(length >= 0.97 * input_length, "{length} of {input_length}");
    assert_eq!(kept_corners, features.corners.len());
    // Every crease vertex of the result is a vertex of a detected line, where it was (up to the
    // rounding of the shift to the bounding-box centre the simplifier works around).
    let diagonal = mesh.bbox().expect("bbox").diagonal();
    let on_line: Vec<Point3> = features
        .lines
        .iter()
        .flat_map(|l| l.vertices.iter().map(|&v| mesh.positions()[v as usize]))
        .collect();
    for &[a, b] in &done.creases {
        for v in [a, b] {
            let p = pos[v as usize];
            let near = on_line
                .iter()
                .map(|q| q.distance(p))
                .fold(f64::INFINITY, f64::min);
            assert!(
                near < 1e-12 * diagonal,
                "crease vertex {v} at {p:?} left its line by {near}"
            );
        }
    }
}

#[test]
fn the_command_line_keeps_creases_on_request() {
    let run = |extra: &[&str]| {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_geofit"))
            .args([
                "simplify",
                data_file("fandisk.obj").to_str().expect("utf-8 path"),
            ])
            .args(["--target", "300", "--json"])
            .args(extra)
            .output()
            .expect("geofit runs");
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let report: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json");
        (
            report["creases"]["input"].as_u64(),
            report["creases"]["output"].as_u64(),
        )
    };
    assert_eq!(run(&[]), (Some(0), Some(0)));
    let (input, output) = run(&["--creases"]);
    assert_eq!(input, Some(709), "fandisk's detected crease edges");
    assert!(
        output.is_some_and(|n| n >= 150),
        "{output:?} crease edges kept"
    );
    // A sharper angle finds fewer.
    let (sharper, _) = run(&["--creases", "--crease-angle", "80"]);
    assert!(sharper < input, "{sharper:?}");
}
