//! Every mesh of the shared data and corpus (issue 15): repaired, simplified to 200 and to 50
//! vertices (or the topological floor, with a note), the result a manifold that the control
//! mesh accepts, of the repaired input's topology, without fold-overs, with the deviation
//! reported. bun000.ply has no faces: its range grid is meshed first, as a fit does.

mod common;

use common::manifold::{assert_manifold, boundary_loops, euler_characteristic};
use common::shared_meshes;
use geofit::cloud::{reconstruct, ReconstructOptions};
use geofit::mesh::{deviation, foldovers};
use geofit::mesh::{repair, simplify_with_report, ControlMesh, PolyMesh, SimplifyOptions};
use std::path::Path;

/// The file's mesh; a bare point file is meshed first.
fn surface(path: &Path) -> PolyMesh {
    let loaded = geofit::io::read_path(path).unwrap();
    if !loaded.mesh.is_point_cloud() {
        return loaded.mesh;
    }
    let options = ReconstructOptions::default();
    reconstruct(
        loaded.mesh.positions(),
        loaded.range_grid.as_ref(),
        &options,
    )
    .unwrap()
    .mesh
}

#[test]
fn every_shared_mesh_simplifies_to_200_and_50() {
    let Some(files) = shared_meshes() else {
        return;
    };
    let mut lines = Vec::new();
    for path in files {
        let mesh = surface(&path);
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        // The topology to keep is that of the repaired triangulation simplify works on (fan
        // triangles of suzanne's quads meet along edges of their own).
        let triangles = PolyMesh::try_new(mesh.positions().to_vec(), mesh.triangles()).unwrap();
        let repaired = repair(&triangles).unwrap().mesh;
        let diag = mesh.bbox().unwrap().diagonal();
        for target in [200, 50] {
            let out = simplify_with_report(&mesh, target, &SimplifyOptions::default()).unwrap();
            let (coarse, r) = (&out.mesh, &out.report);
            assert_manifold(coarse);
            ControlMesh::try_new(coarse).unwrap_or_else(|e| panic!("{name} -> {target}: {e}"));
            assert_eq!(coarse.num_vertices(), r.vertices);
            if r.vertices != target {
                assert!(
                    r.vertices > target && r.floor_note.is_some(),
                    "{name}: {r:?}"
                );
            }
            assert_eq!(boundary_loops(coarse), boundary_loops(&repaired), "{name}");
            assert_eq!(
                euler_characteristic(coarse),
                euler_characteristic(&repaired),
                "{name}"
            );
            assert!(
                r.max_valence <= SimplifyOptions::default().max_valence,
                "{name}"
            );
            let dev = deviation(mesh.positions(), coarse)
                .unwrap()
                .percent_of(diag);
            let folds = foldovers(&mesh, coarse);
            lines.push(format!(
                "{name} -> {target}: {} vertices, deviation max {:.3} % rms {:.3} %, \
                 {} fold-overs (worst cos {:.2}), {} relaxations",
                r.vertices,
                dev.max,
                dev.rms,
                folds.count,
                folds.worst_cos,
                r.relaxations.len()
            ));
            assert!(dev.max.is_finite() && dev.rms <= dev.max);
            // At 50 vertices two corpus meshes keep one face each that faces more than 120°
            // from the input nearest to it (cow, beetle: see the QEM figures in docs/subdivision.md); at 200
            // none does.
            let allowed = if target == 50 { 1 } else { 0 };
            assert!(folds.count <= allowed, "{name} -> {target}: {folds:?}");
        }
    }
    println!("{}", lines.join("\n"));
}
