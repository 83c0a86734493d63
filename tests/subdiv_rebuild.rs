//! Rebuilding a limit surface over a locally refined control mesh
//! ([`SubdivSurface::with_mesh`]) copies the patches the refinement left alone instead of
//! rebuilding them: the result must be the surface a fresh build gives, patch by patch.

mod common;

use common::{bump_grid, perturbed, sphere_mesh, Rng};
use geofit::mesh::{ControlMesh, PolyMesh};
use geofit::subdiv::adaptive::split_quads;
use geofit::subdiv::adaptive::{improve_by_flips, split_triangles, SplitRule};
use geofit::subdiv::{quadrangulate, LimitSurface, Scheme, SubdivSurface, SurfaceParam};

/// Parameters inside a patch, on its edges and at its corners (for triangles, u + v ≤ 1).
const PARAMS: [(f64, f64); 7] = [
    (0.0, 0.0),
    (1.0, 0.0),
    (0.0, 1.0),
    (0.5, 0.0),
    (0.2, 0.3),
    (0.05, 0.9),
    (0.31, 0.011),
];

/// Asserts that `a` and `b` have the same patches and evaluate alike on each.
fn assert_same_surface(a: &SubdivSurface, b: &SubdivSurface) {
    assert_eq!(a.num_patches(), b.num_patches());
    for patch in 0..a.num_patches() as u32 {
        for (u, v) in PARAMS {
            let at = SurfaceParam { patch, u, v };
            let (ea, eb) = (a.eval(at), b.eval(at));
            for (x, y) in [(ea.point, eb.point), (ea.du, eb.du), (ea.dvv, eb.dvv)] {
                assert!(
                    (x - y).length() <= 1e-12 * (1.0 + y.length()),
                    "patch {patch} at ({u}, {v}): {x} against {y}"
                );
            }
        }
    }
}

/// Rebuilds `old` over `refined` both ways and checks them against each other, and that every
/// kept patch evaluates exactly as the old patch it copies. Returns how many were kept.
fn check_rebuild(old: &SubdivSurface, refined: ControlMesh) -> usize {
    let fresh = SubdivSurface::try_new(old.scheme(), refined.clone()).expect("fresh build");
    let rebuilt = old.with_mesh(refined).expect("rebuild");
    assert_same_surface(&rebuilt, &fresh);
    let mut kept = 0;
    for patch in 0..rebuilt.num_patches() as u32 {
        let Some(from) = rebuilt.kept_patch(patch) else {
            continue;
        };
        kept += 1;
        for (u, v) in PARAMS {
            let (a, b) = (
                rebuilt.eval(SurfaceParam { patch, u, v }).point,
                old.eval(SurfaceParam { patch: from, u, v }).point,
            );
            assert_eq!(a, b, "kept patch {patch} (was {from}) at ({u}, {v})");
        }
    }
    assert_eq!(fresh.kept_patch(0), None, "a fresh build keeps nothing");
    kept
}

fn marked_every(mesh: &PolyMesh, k: usize) -> Vec<bool> {
    (0..mesh.num_faces()).map(|f| f % k == 0).collect()
}

#[test]
fn loop_rebuild_after_a_local_split_and_flips_equals_a_fresh_build() {
    for control in [
        perturbed(&sphere_mesh(2), 0.05, &mut Rng(3)),
        bump_grid(8, 0.3),
    ] {
        let old = SubdivSurface::try_new(Scheme::Loop, ControlMesh::try_new(&control).unwrap())
            .expect("surface");
        let mut marked = vec![false; control.num_faces()];
        marked[control.num_faces() / 2] = true;
        marked[1] = true;
        let mut refined = split_triangles(&control, &marked, SplitRule::Loop, &[]).expect("split");
        improve_by_flips(&mut refined, 3, control.num_vertices() as u32, &[]).expect("flips");
        let kept = check_rebuild(&old, ControlMesh::try_new(&refined).unwrap());
        assert!(
            kept * 2 > control.num_faces(),
            "only {kept} of {} patches kept after splitting two faces",
            control.num_faces()
        );
    }
}

#[test]
fn loop_rebuild_after_splitting_everything_keeps_nothing() {
    let control = perturbed(&sphere_mesh(1), 0.05, &mut Rng(5));
    let old = SubdivSurface::try_new(Scheme::Loop, ControlMesh::try_new(&control).unwrap())
        .expect("surface");
    let refined = split_triangles(
        &control,
        &vec![true; control.num_faces()],
        SplitRule::Loop,
        &[],
    )
    .expect("split");
    assert_eq!(
        check_rebuild(&old, ControlMesh::try_new(&refined).unwrap()),
        0
    );
}

#[test]
fn catmull_clark_rebuild_after_a_local_split_equals_a_fresh_build() {
    let tri = perturbed(&sphere_mesh(1), 0.05, &mut Rng(9));
    let quads = quadrangulate(&ControlMesh::try_new(&tri).unwrap()).expect("quads");
    let control = quads.to_poly_mesh().expect("poly");
    let old = SubdivSurface::try_new(Scheme::CatmullClark, quads).expect("surface");
    let refined = split_quads(&control, &marked_every(&control, 17), &[]).expect("split");
    let kept = check_rebuild(&old, ControlMesh::try_new(&refined).unwrap());
    assert!(kept > 0, "no patch kept");
}

#[test]
fn doo_sabin_rebuild_rebuilds_every_patch() {
    let tri = perturbed(&sphere_mesh(1), 0.05, &mut Rng(11));
    let quads = quadrangulate(&ControlMesh::try_new(&tri).unwrap()).expect("quads");
    let old = SubdivSurface::try_new(Scheme::DooSabin, quads.clone()).expect("surface");
    assert_eq!(check_rebuild(&old, quads), 0);
}
