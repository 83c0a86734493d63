//! Local conforming refinement of Catmull–Clark control meshes (issue 4): the refined mesh is
//! all-quad, manifold and conforming, the limit surface does not move where nothing is split,
//! and a fit converges further with refinement than without.

mod common;

use common::meshes::{cube, quad_grid};
use common::{bumpy_sphere, sphere_mesh, Rng};
use geofit::fit::{surface_of, Fitter, SubdivFitOptions, SubdivFitter, Tolerances};
use geofit::geom::Point3;
use geofit::mesh::check_oriented_edges;
use geofit::mesh::PolyMesh;
use geofit::subdiv::adaptive::split_quads;
use geofit::subdiv::{LimitSurface, Scheme, SubdivSurface, SurfaceParam};
use proptest::prelude::*;
use std::collections::{BTreeMap, HashMap, HashSet};

/// Undirected edges with their face counts.
fn edge_counts(mesh: &PolyMesh) -> BTreeMap<(u32, u32), usize> {
    let mut count = BTreeMap::new();
    for f in mesh.faces() {
        for k in 0..f.len() {
            let (a, b) = (f[k], f[(k + 1) % f.len()]);
            *count.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    count
}

/// The checks every refinement must pass: all quads, an oriented manifold (every edge on one
/// or two faces), no T-junction (every boundary edge of the result lies on an old boundary
/// edge), finite points, and the marked quads are gone.
fn assert_conforming_refinement(old: &PolyMesh, new: &PolyMesh, marked: &[bool]) {
    assert!(new.faces().all(|f| f.len() == 4), "not all quads");
    check_oriented_edges(new).expect("oriented manifold");
    assert!(edge_counts(new).values().all(|&n| n <= 2));
    assert!(new.positions().iter().all(|p| p.is_finite()));
    let old_rim: Vec<(u32, u32)> = edge_counts(old)
        .into_iter()
        .filter(|&(_, n)| n == 1)
        .map(|(e, _)| e)
        .collect();
    // Old vertices at their old places (refinement may move them), new ones where they are.
    let nv = old.num_vertices();
    let at = |v: u32| {
        let v = v as usize;
        if v < nv {
            old.positions()[v]
        } else {
            new.positions()[v]
        }
    };
    for ((a, b), n) in edge_counts(new) {
        if n != 1 {
            continue;
        }
        // A new boundary edge must lie on an old boundary edge (collinear, within it).
        let on_rim = old_rim.iter().any(|&(c, d)| {
            let (pc, pd) = (at(c), at(d));
            let within = |x: Point3| {
                let t = (x - pc).dot(pd - pc) / (pd - pc).length_squared();
                (x - (pc + (pd - pc) * t)).length() < 1e-9 && (-1e-9..=1.0 + 1e-9).contains(&t)
            };
            within(at(a)) && within(at(b))
        });
        assert!(
            on_rim,
            "edge {a}–{b} is open but not on the old boundary (T-junction)"
        );
    }
    let faces: HashSet<Vec<u32>> = new.faces().map(canonical).collect();
    for (f, _) in marked.iter().enumerate().filter(|(_, &m)| m) {
        assert!(
            !faces.contains(&canonical(old.face(f))),
            "marked face {f} kept"
        );
    }
}

/// A face's corners rotated to start at the smallest index.
fn canonical(f: &[u32]) -> Vec<u32> {
    let s = (0..f.len()).min_by_key(|&i| f[i]).unwrap_or(0);
    (0..f.len()).map(|i| f[(s + i) % f.len()]).collect()
}

/// A closed quad mesh: the octahedral sphere, one Catmull–Clark step (valences 3, 4 and 6).
fn quad_sphere() -> PolyMesh {
    surface_of(Scheme::CatmullClark, &sphere_mesh(1), &[])
        .expect("quad sphere")
        .control_mesh()
        .to_poly_mesh()
        .expect("poly mesh")
}

fn marks(n: usize, seed: u64, density: f64) -> Vec<bool> {
    let mut rng = Rng(seed);
    (0..n).map(|_| rng.next_f64() < density).collect()
}

#[test]
fn refinement_is_conforming_on_open_and_closed_meshes() {
    let grid = quad_grid(8, |x, y| 0.1 * (x * y).sin());
    for mesh in [grid, quad_sphere(), cube()] {
        for seed in 0..6 {
            let marked = marks(mesh.num_faces(), seed, 0.15);
            let refined = split_quads(&mesh, &marked, &[]).expect("split");
            assert_conforming_refinement(&mesh, &refined, &marked);
            surface_of(Scheme::CatmullClark, &refined, &[]).expect("valid CC control mesh");
        }
    }
}

#[test]
fn refinement_stays_local() {
    let mesh = quad_grid(20, |_, _| 0.0);
    let mut marked = vec![false; 400];
    marked[10 * 20 + 10] = true;
    let refined = split_quads(&mesh, &marked, &[]).expect("split");
    // One quad 1→4 plus a closing ring: a handful of new points, not a whole strip.
    assert!(refined.num_vertices() - mesh.num_vertices() <= 16);
    let old: HashSet<Vec<u32>> = mesh.faces().map(canonical).collect();
    let kept = refined
        .faces()
        .filter(|f| old.contains(&canonical(f)))
        .count();
    assert!(kept >= 400 - 9, "only {kept} of 400 faces kept");
}

#[test]
fn limit_surface_is_unchanged_away_from_the_split_and_close_near_it() {
    let mesh = quad_grid(12, |x, y| 0.3 * (0.7 * x).sin() * (0.5 * y).cos());
    let mut marked = vec![false; 144];
    for f in [5 * 12 + 5, 5 * 12 + 6, 6 * 12 + 5] {
        marked[f] = true;
    }
    let refined = split_quads(&mesh, &marked, &[]).expect("split");
    let before = surface_of(Scheme::CatmullClark, &mesh, &[]).expect("before");
    let after = surface_of(Scheme::CatmullClark, &refined, &[]).expect("after");
    // Faces whose whole neighbourhood (every face at one of its corners) is unchanged.
    let old_faces: HashMap<Vec<u32>, usize> = mesh
        .faces()
        .enumerate()
        .map(|(i, f)| (f.to_vec(), i))
        .collect();
    let kept = |f: &[u32]| old_faces.contains_key(f);
    let mut compared = 0;
    for (g, f) in refined.faces().enumerate() {
        let Some(&old) = old_faces.get(f) else {
            continue;
        };
        let ring_kept = refined
            .faces()
            .filter(|h| h.iter().any(|v| f.contains(v)))
            .all(kept);
        let moved = f
            .iter()
            .any(|&v| mesh.positions()[v as usize] != refined.positions()[v as usize]);
        for (u, v) in [(0.1, 0.2), (0.5, 0.5), (0.9, 0.7)] {
            let a = before.eval(SurfaceParam {
                patch: old as u32,
                u,
                v,
            });
            let b = after.eval(SurfaceParam {
                patch: g as u32,
                u,
                v,
            });
            let d = (a.point - b.point).length();
            if ring_kept && !moved {
                assert!(d < 1e-12, "unchanged patch {old} moved by {d}");
                compared += 1;
            } else {
                // Transition templates are not Catmull–Clark steps: the surface moves a little
                // near them (the bump's amplitude is 0.3 over unit quads).
                assert!(d < 0.1, "patch {old} moved by {d}");
            }
        }
    }
    assert!(compared > 300);
}

/// Data on a bumpy sphere, fitted from the quad sphere with and without refinement.
fn bumpy_fit(refine: bool) -> SubdivFitter<SubdivSurface> {
    let data = bumpy_sphere(31, 4000, |d| 0.2 * (6.0 * d.x).sin() * (5.0 * d.y).cos());
    let options = SubdivFitOptions::default()
        .with_tolerances(Tolerances {
            avg_pct: None,
            max_pct: Some(0.01),
            rms_pct: None,
        })
        .with_max_iter(16)
        .with_max_control(Some(600))
        .with_refine(refine)
        .with_refine_interval(3);
    let mut fitter =
        SubdivFitter::<SubdivSurface>::try_new(&data, quad_sphere(), Scheme::CatmullClark, options)
            .expect("fitter");
    fitter.run().expect("run");
    fitter
}

#[test]
fn fit_converges_further_with_local_refinement() {
    let plain = bumpy_fit(false);
    let refined = bumpy_fit(true);
    assert!(refined.history().iter().any(|r| r.refined));
    assert!(refined.num_control_points() <= 600);
    assert!(refined.num_control_points() > plain.num_control_points());
    assert!(refined.point_errors().iter().all(|e| e.is_finite()));
    let (a, b) = (plain.stats(), refined.stats());
    assert!(
        b.e_max_pct < 0.8 * a.e_max_pct && b.e_rms_pct < 0.8 * a.e_rms_pct,
        "refined {b:?} vs plain {a:?}"
    );
    let mesh = refined.control_mesh();
    check_oriented_edges(&mesh).expect("manifold");
    assert!(mesh.faces().all(|f| f.len() == 4));
}

#[test]
fn refined_fit_is_deterministic() {
    let (a, b) = (bumpy_fit(true), bumpy_fit(true));
    assert_eq!(a.control_mesh().positions(), b.control_mesh().positions());
    assert_eq!(
        a.control_mesh().faces().collect::<Vec<_>>(),
        b.control_mesh().faces().collect::<Vec<_>>()
    );
    assert_eq!(a.point_errors(), b.point_errors());
}

#[test]
fn bad_input_is_an_error() {
    let grid = quad_grid(2, |_, _| 0.0);
    assert!(split_quads(&grid, &[true; 3], &[]).is_err());
    assert!(split_quads(&sphere_mesh(0), &[true; 8], &[]).is_err());
    // Inconsistent orientation: the second quad reuses the first one's edge in its direction.
    let p = (0..6).map(|i| Point3::new(i as f64, 0.0, 0.0)).collect();
    let flipped = PolyMesh::try_new(p, [[0u32, 1, 2, 3], [1, 2, 4, 5]]).expect("polygons");
    assert!(split_quads(&flipped, &[true, false], &[]).is_err());
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// Any set of marks on a jittered grid or the quad sphere gives a conforming refinement,
    /// and refining the result again works too.
    #[test]
    fn random_marks_give_conforming_quads(seed in 0u64..1000, density in 0.0f64..0.6, closed: bool) {
        let mesh = if closed {
            quad_sphere()
        } else {
            common::meshes::jitter(&quad_grid(7, |x, y| 0.2 * (x - y).sin()), 0.2, seed)
        };
        let marked = marks(mesh.num_faces(), seed, density);
        let once = split_quads(&mesh, &marked, &[]).expect("split");
        assert_conforming_refinement(&mesh, &once, &marked);
        let again = marks(once.num_faces(), seed + 1, density);
        let twice = split_quads(&once, &again, &[]).expect("split again");
        assert_conforming_refinement(&once, &twice, &again);
    }
}
