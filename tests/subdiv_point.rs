//! `LimitSurface::point`, the limit position without derivatives, takes a corner of a patch
//! straight from its limit mask instead of subdividing towards it: it must be the point
//! `eval` gives, at corners (extraordinary, regular, on a boundary, on a crease) and inside.

mod common;

use common::meshes::{cube, icosahedron, octahedron, quad_grid, refine_flat, tri_grid};
use common::{perturbed, Rng};
use geofit::mesh::{detect_features, ControlMesh, FeatureOptions, PolyMesh};
use geofit::subdiv::adaptive::tag_creases;
use geofit::subdiv::{LimitSurface, Scheme, SubdivSurface, SurfaceParam};

const PARAMS: [(f64, f64); 7] = [
    (0.0, 0.0),
    (1.0, 0.0),
    (0.0, 1.0),
    (1.0, 1.0),
    (0.5, 0.0),
    (0.2, 0.3),
    (0.31, 0.011),
];

fn assert_points_match(scheme: Scheme, control: ControlMesh, what: &str) {
    let surface = SubdivSurface::try_new(scheme, control).expect("surface");
    let mut corners = 0;
    for patch in 0..surface.num_patches() as u32 {
        for (u, v) in PARAMS {
            if scheme == Scheme::Loop && u + v > 1.0 {
                continue;
            }
            let at = SurfaceParam { patch, u, v };
            let (fast, full) = (surface.point(at), surface.eval(at).point);
            assert!(
                (fast - full).length() <= 1e-12 * (1.0 + full.length()),
                "{what}, {scheme:?}, patch {patch} at ({u}, {v}): {fast} against {full}"
            );
            corners += usize::from(u.fract() == 0.0 && v.fract() == 0.0);
        }
    }
    assert!(corners > 0, "{what}: no corner was checked");
}

fn control(mesh: &PolyMesh) -> ControlMesh {
    ControlMesh::try_new(mesh).expect("control mesh")
}

#[test]
fn corner_points_from_limit_masks_are_the_evaluated_points() {
    let mut rng = Rng(7);
    // Valence 5 and 4 (extraordinary everywhere), a regular open grid, a cube's valence 3.
    for (name, mesh) in [
        ("icosahedron", perturbed(&icosahedron(), 0.05, &mut rng)),
        ("octahedron", octahedron()),
        ("triangle grid", tri_grid(4, |x, y| (x * y).sin())),
    ] {
        assert_points_match(Scheme::Loop, control(&mesh), name);
    }
    for (name, mesh) in [
        ("cube", perturbed(&cube(), 0.05, &mut rng)),
        ("quad grid", quad_grid(4, |x, y| (x - y).cos())),
    ] {
        assert_points_match(Scheme::CatmullClark, control(&mesh), name);
        assert_points_match(Scheme::DooSabin, control(&mesh), name);
    }
    // Sharp creases and corners: a cube's edges tagged.
    for (scheme, mesh) in [
        (Scheme::Loop, refine_flat(&cube(), 1)),
        (Scheme::CatmullClark, cube()),
    ] {
        let features = detect_features(&mesh, &FeatureOptions::default()).expect("features");
        let mut tagged = control(&mesh);
        tag_creases(&mut tagged, &features.edges);
        assert_points_match(scheme, tagged, "cube with creases");
    }
}
