//! Refinement against independent implementations: reference outputs made by MeshLab (Loop)
//! and Blender/OpenSubdiv (Catmull–Clark) with `tests/data/subdiv/make_refs.py`, compared vertex
//! by vertex after nearest-vertex matching.

use geofit::geom::Point3;
use geofit::mesh::{ControlMesh, PolyMesh};
use geofit::subdiv::{refine_levels, Scheme};
use std::path::PathBuf;

fn load(name: &str) -> Option<PolyMesh> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/subdiv")
        .join(name);
    if !path.exists() {
        return None;
    }
    Some(
        geofit::io::read_path(&path)
            .expect("reference file parses")
            .mesh,
    )
}

/// Largest distance from a vertex of `ours` to the nearest vertex of `reference`, relative to
/// the largest coordinate magnitude (the scale of float32 rounding in the references), after
/// checking both have the same counts.
fn compare(ours: &PolyMesh, reference: &PolyMesh) -> f64 {
    assert_eq!(
        ours.num_vertices(),
        reference.num_vertices(),
        "vertex count"
    );
    assert_eq!(ours.num_faces(), reference.num_faces(), "face count");
    let b = reference.bbox().expect("non-empty");
    let diag = b.min.abs().max(b.max.abs()).max_element();
    let refs: Vec<Point3> = reference.positions().to_vec();
    let mut used = vec![false; refs.len()];
    let mut worst = 0.0f64;
    for p in ours.positions() {
        let (j, d) = refs
            .iter()
            .enumerate()
            .map(|(j, q)| (j, (*q - *p).length()))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .expect("non-empty");
        assert!(
            !used[j] || d / diag > 1e-6,
            "two vertices matched the same reference vertex"
        );
        used[j] = true;
        worst = worst.max(d / diag);
    }
    worst
}

fn check(input: &str, output: &str, scheme: Scheme, levels: usize, tol: f64) {
    let (Some(input), Some(reference)) = (load(input), load(output)) else {
        panic!("reference data missing: run tests/data/subdiv/make_refs.py");
    };
    let control = ControlMesh::try_new(&input).expect("manifold input");
    let ours = refine_levels(scheme, &control, levels)
        .expect("refines")
        .to_poly_mesh()
        .expect("valid");
    let worst = compare(&ours, &reference);
    println!("{output}: worst vertex deviation {worst:e} of the coordinate scale");
    assert!(worst < tol, "{output}: deviation {worst:e}");
}

#[test]
fn loop_matches_meshlab_on_an_open_bunny_patch() {
    check(
        "bunny_patch.obj",
        "bunny_patch_loop2.obj",
        Scheme::Loop,
        2,
        1e-12,
    );
}

#[test]
fn loop_matches_meshlab_on_a_closed_coarse_spot() {
    check(
        "spot_coarse.obj",
        "spot_coarse_loop2.obj",
        Scheme::Loop,
        2,
        1e-12,
    );
}

// Blender keeps float32 coordinates: agreement to a few float32 ulps is all it can show.
#[test]
fn catmull_clark_matches_opensubdiv_on_a_closed_quad_dominant_spot() {
    check(
        "spot_quads.obj",
        "spot_quads_cc2.obj",
        Scheme::CatmullClark,
        2,
        1e-6,
    );
}

#[test]
fn catmull_clark_matches_opensubdiv_on_an_open_quad_dominant_bunny_patch() {
    check(
        "bunny_quads.obj",
        "bunny_quads_cc2.obj",
        Scheme::CatmullClark,
        2,
        1e-6,
    );
}
