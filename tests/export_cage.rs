//! The cage of a subdivision fit with its creases: the USD layer (`export::cage_usda`) and the
//! OBJ cage's JSON sidecar (`export::cage_creases_json`), from a fit that keeps a box's edges.

mod common;

use geofit::export::{cage_creases_json, cage_usda, INFINITE_SHARPNESS};
use geofit::fit::{FitData, FitSpec, Fitter, Scheme};
use geofit::mesh::PolyMesh;
use std::collections::HashSet;

/// A fit of a finely meshed unit cube with creases on, a few iterations.
fn cube_fit(scheme: Scheme) -> Box<dyn Fitter> {
    let mesh = common::meshes::refine_flat(&common::meshes::cube(), 3);
    let spec = FitSpec::new(scheme)
        .with_creases(true)
        .with_initial(Some(60))
        .with_max_iter(Some(3));
    let mut fit = spec.build(&FitData::points(&mesh)).expect("the fit starts");
    fit.run().expect("the fit runs");
    fit
}

/// The integers of the USDA attribute named `name` (`int[] name = [...]`).
fn ints(text: &str, name: &str) -> Vec<u32> {
    let line = text
        .lines()
        .find(|l| l.trim_start().starts_with(&format!("int[] {name} =")))
        .unwrap_or_else(|| panic!("no {name} in\n{text}"));
    let list = &line[line.find('=').unwrap()..];
    let inside = &list[list.find('[').unwrap() + 1..list.rfind(']').unwrap()];
    inside
        .split(',')
        .filter(|s| !s.trim().is_empty())
        .map(|s| s.trim().parse().expect("an integer"))
        .collect()
}

fn edges_of(mesh: &PolyMesh) -> HashSet<[u32; 2]> {
    mesh.faces()
        .flat_map(|f| (0..f.len()).map(move |k| (f[k], f[(k + 1) % f.len()])))
        .map(|(a, b)| [a.min(b), a.max(b)])
        .collect()
}

#[test]
fn the_usd_cage_carries_the_creases_of_the_fit() {
    for (scheme, token) in [
        (Scheme::Loop, "loop"),
        (Scheme::CatmullClark, "catmullClark"),
    ] {
        let fit = cube_fit(scheme);
        let control = fit
            .subdiv_surface()
            .expect("a subdivision fit")
            .control_mesh();
        let creases = control.creases();
        assert!(
            creases.len() >= 12,
            "{scheme:?}: {} crease edges",
            creases.len()
        );
        let cage = control.to_poly_mesh().expect("cage");
        let text = cage_usda(fit.as_ref()).expect("usda");
        assert!(text.starts_with("#usda 1.0"));
        assert!(
            text.contains(&format!("subdivisionScheme = \"{token}\"")),
            "{text}"
        );
        let counts = ints(&text, "faceVertexCounts");
        let indices = ints(&text, "faceVertexIndices");
        assert_eq!(counts.len(), cage.num_faces());
        assert_eq!(counts.iter().sum::<u32>() as usize, indices.len());
        // The crease pairs are edges of the cage, the same as the fit's, all infinitely sharp.
        let ends = ints(&text, "creaseIndices");
        let lengths = ints(&text, "creaseLengths");
        assert_eq!(ends.len(), 2 * creases.len());
        assert!(lengths.iter().all(|&l| l == 2) && lengths.len() == creases.len());
        let edges = edges_of(&cage);
        let written: Vec<[u32; 2]> = ends.chunks(2).map(|p| [p[0], p[1]]).collect();
        assert_eq!(written, creases);
        assert!(written.iter().all(|e| edges.contains(e)));
        let sharp = text
            .lines()
            .find(|l| l.contains("creaseSharpnesses"))
            .expect("sharpnesses");
        assert_eq!(
            sharp.matches(&format!("{INFINITE_SHARPNESS}")).count(),
            creases.len()
        );
        // The sidecar says the same for the OBJ cage.
        let sidecar: serde_json::Value =
            serde_json::from_str(&cage_creases_json(fit.as_ref()).expect("json")).expect("parses");
        assert_eq!(sidecar["vertices"], cage.num_vertices());
        assert_eq!(
            sidecar["creases"].as_array().map(Vec::len),
            Some(creases.len())
        );
        assert_eq!(sidecar["sharpness"], INFINITE_SHARPNESS);
    }
}

#[test]
fn usd_refuses_what_it_cannot_evaluate() {
    let fit = cube_fit(Scheme::DooSabin);
    let err = cage_usda(fit.as_ref()).expect_err("USD has no Doo–Sabin");
    assert!(err.to_string().contains("Loop and Catmull–Clark"), "{err}");
    // The sidecar is there for every subdivision scheme.
    assert!(cage_creases_json(fit.as_ref()).is_ok());
    let mesh = common::meshes::refine_flat(&common::meshes::cube(), 2);
    let mut spline = FitSpec::new(Scheme::BsplineSurface)
        .with_max_iter(Some(2))
        .build(&FitData::points(&mesh))
        .expect("starts");
    spline.run().expect("runs");
    let err = cage_creases_json(spline.as_ref()).expect_err("no cage with creases");
    assert!(err.to_string().contains("only subdivision fits"), "{err}");
}
