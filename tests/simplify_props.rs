//! Property tests of QEM simplification: arbitrary small meshes never make it panic, and
//! jittered manifold meshes simplify to manifold meshes of the same topology and exact size.

mod common;

use common::manifold::{assert_manifold, boundary_loops, euler_characteristic};
use common::{bump_grid, perturbed, sphere_mesh, Rng};
use geofit::geom::Point3;
use geofit::mesh::{simplify, simplify_with_report, PolyMesh, SimplifyError, SimplifyOptions};
use proptest::prelude::*;

/// Any triangle soup over up to 12 points (repeated, flipped and non-manifold faces included).
fn soup() -> impl Strategy<Value = PolyMesh> {
    (4usize..12).prop_flat_map(|n| {
        (
            prop::collection::vec(
                (-10i32..10, -10i32..10, -10i32..10)
                    .prop_map(|(x, y, z)| Point3::new(x as f64, y as f64, z as f64 * 0.5)),
                n,
            ),
            prop::collection::vec(prop::array::uniform3(0u32..n as u32), 1..30),
        )
            .prop_map(|(pos, faces)| PolyMesh::try_new(pos, faces).expect("indices in range"))
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    // Whatever the soup, the result is an oriented manifold: exactly `target` vertices, or
    // the floor (with a note) above it, or every vertex when there are fewer.
    #[test]
    fn any_soup_simplifies_to_a_manifold(mesh in soup(), target in 0usize..14, angle in 1.0f64..90.0) {
        let options = SimplifyOptions::default().with_max_normal_change_deg(angle);
        match simplify_with_report(&mesh, target, &options) {
            Ok(out) => {
                let v = out.mesh.num_vertices();
                prop_assert_eq!(v, out.report.vertices);
                prop_assert!(v == target || (v > target) == out.report.floor_note.is_some());
                prop_assert!(out.mesh.positions().iter().all(|p| p.is_finite()));
                assert_manifold(&out.mesh);
            }
            Err(SimplifyError::NoFaces) => {}
            Err(e) => prop_assert!(false, "unexpected error {e}"),
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    #[test]
    fn jittered_sphere_stays_a_closed_sphere(seed in any::<u64>(), target in 4usize..120) {
        let mesh = perturbed(&sphere_mesh(3), 0.02, &mut Rng(seed));
        let out = simplify(&mesh, target).unwrap();
        prop_assert_eq!(out.num_vertices(), target);
        assert_manifold(&out);
        prop_assert_eq!(euler_characteristic(&out), 2);
        prop_assert_eq!(boundary_loops(&out), 0);
    }

    #[test]
    fn jittered_grid_stays_a_disc(seed in any::<u64>(), target in 6usize..150) {
        let mesh = perturbed(&bump_grid(14, 0.3), 0.01, &mut Rng(seed));
        let out = simplify(&mesh, target).unwrap();
        prop_assert_eq!(out.num_vertices(), target);
        assert_manifold(&out);
        prop_assert_eq!(euler_characteristic(&out), 1);
        prop_assert_eq!(boundary_loops(&out), 1);
    }
}
