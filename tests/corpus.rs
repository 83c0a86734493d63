//! Every mesh of ../shared/data and ../shared/data/corpus, and its vertices as a bare XYZ point
//! file, through `geofit fit` with the defaults for Loop, Catmull–Clark and Doo–Sabin (issue 15,
//! SPEC §6: a user presses Play without touching a setting): no error, no NaN in the report,
//! and the fit converged or ended with a status that says why (stalled, iteration cap).
//! Generated hostile meshes (non-manifold vertices and edges, duplicate and zero-area faces,
//! several components, inconsistent orientation, one triangle, one huge face among many tiny
//! ones) go through the same path, built with `FitSpec`.
//!
//! Every fitted surface is also measured against the surface its data came from (the "to
//! source" column): a mesh's own triangles, the mesh a bare copy was written from, and for
//! bun000.ply (a range scan in the frame of the bunny's final mesh) stanford-bunny.obj. For bare
//! points that is the one measure that does not rest on the points themselves: the fit's
//! E_back can read a surface beyond a scan's silhouette as farther from the data than it is
//! from the scanned object, and a surface across a large face with no point inside as over a
//! hole. It is reported, not asserted.
//!
//! The two 36K-point scans (the bunny, bun000) run with Loop only and not as bare points unless
//! `GEOFIT_CORPUS_FULL=1`: the rest of them adds about eight CPU minutes. Fits run on two threads; the table of all of them is
//! written to `target/tmp/corpus-report.md`.

mod common;

use common::shared_meshes;
use geofit::fit::{FitData, FitSpec, FitStatus, Scheme};
use geofit::geom::Point3;
use geofit::mesh::PolyMesh;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Mutex;

const SCHEMES: [&str; 3] = ["loop", "catmull-clark", "doo-sabin"];

/// Points above which a bare-point copy is left to the full run.
const LARGE: usize = 20_000;

/// One fit to run: a file and a scheme, and the mesh its data came from.
struct Job {
    file: PathBuf,
    scheme: &'static str,
    source: Option<PathBuf>,
}

/// The mesh `file`'s data came from: itself for a mesh, the mesh a bare copy in `dir` was
/// written from, stanford-bunny.obj for bun000.ply (same frame); `None` when it is not there.
fn source_of(file: &Path, dir: &Path, meshes: &[PathBuf]) -> Option<PathBuf> {
    let name = file.file_name()?.to_str()?;
    let stem = match name {
        "bun000.ply" => "stanford-bunny",
        _ if file.starts_with(dir) => name.strip_suffix("-points.xyz")?,
        _ => return Some(file.to_path_buf()),
    };
    meshes
        .iter()
        .find(|m| m.file_stem().and_then(|s| s.to_str()) == Some(stem))
        .cloned()
}

/// The largest distance from a vertex of `limit` to the surface of `source` (vertices over its
/// holes or beyond its outline left out), % of `source`'s bounding-box diagonal.
fn distance_to_source(limit: &Path, source: &Path) -> Option<f64> {
    let source = geofit::io::read_path(source).ok()?.mesh;
    let surface = geofit::fit::DataSurface::of_mesh(&source)?;
    let limit = geofit::io::read_path(limit).ok()?.mesh;
    let worst = surface
        .distances(limit.positions())
        .into_iter()
        .flatten()
        .fold(0.0f64, f64::max);
    Some(100.0 * worst / source.bbox()?.diagonal())
}

/// Writes the vertices of `mesh_file` as a bare XYZ file in `dir` and returns its path, or
/// `None` when the file is already bare points or too large for the quick run.
fn bare_copy(mesh_file: &Path, dir: &Path, full: bool) -> Option<PathBuf> {
    let loaded = geofit::io::read_path(mesh_file).expect("shared data reads");
    if loaded.mesh.is_point_cloud() || (!full && loaded.mesh.num_vertices() > LARGE) {
        return None;
    }
    let stem = mesh_file.file_stem()?.to_str()?;
    let out = dir.join(format!("{stem}-points.xyz"));
    let text: String = loaded
        .mesh
        .positions()
        .iter()
        .map(|p| format!("{} {} {}\n", p.x, p.y, p.z))
        .collect();
    std::fs::write(&out, text).expect("write xyz");
    Some(out)
}

/// Points of a file.
fn points_in(path: &Path) -> usize {
    geofit::io::read_path(path).map_or(0, |f| f.mesh.num_vertices())
}

/// Runs one fit with the defaults and returns its report, or the error text.
fn fit(job: &Job, dir: &Path, k: usize) -> Result<Value, String> {
    let json = dir.join(format!("report-{k}.json"));
    let limit = dir.join(format!("limit-{k}.obj"));
    let out = Command::new(env!("CARGO_BIN_EXE_geofit"))
        .arg("fit")
        .arg(&job.file)
        .args(["--scheme", job.scheme, "--quiet", "--json"])
        .arg(&json)
        .arg("--limit")
        .arg(&limit)
        .output()
        .map_err(|e| e.to_string())?;
    if !out.status.success() {
        return Err(String::from_utf8_lossy(&out.stderr).into_owned());
    }
    let text = std::fs::read_to_string(&json).map_err(|e| e.to_string())?;
    let mut report: Value = serde_json::from_str(&text).map_err(|e| e.to_string())?;
    let to_source = job
        .source
        .as_ref()
        .and_then(|source| distance_to_source(&limit, source));
    report["to_source_max_pct"] = to_source.into();
    Ok(report)
}

/// Every problem with a report: a missing or non-finite figure (NaN is written as `null`), a
/// status other than converged, stalled or the iteration cap.
fn problems(report: &Value) -> Vec<String> {
    let mut found = Vec::new();
    for key in ["e_avg_pct", "e_max_pct", "e_rms_pct", "total_s"] {
        if !report[key].as_f64().is_some_and(f64::is_finite) {
            found.push(format!("{key} is {}", report[key]));
        }
    }
    for (i, r) in report["history"]
        .as_array()
        .into_iter()
        .flatten()
        .enumerate()
    {
        for key in ["e_avg_pct", "e_max_pct", "e_rms_pct"] {
            if !r[key].as_f64().is_some_and(f64::is_finite) {
                found.push(format!("history[{i}].{key} is {}", r[key]));
            }
        }
    }
    // Converged means both ways: the surface → data distance was measured and is finite.
    if report["status"] == "converged"
        && !report["e_back_max_pct"]
            .as_f64()
            .is_some_and(f64::is_finite)
    {
        found.push(format!(
            "converged with E_back {}",
            report["e_back_max_pct"]
        ));
    }
    // A fit that ends with its mean error a tenth of the object has broken down (a bad split
    // once took Doo–Sabin on fandisk's points to E_avg 7e9 %).
    if report["e_avg_pct"].as_f64().is_some_and(|e| e > 10.0) {
        found.push(format!("E_avg {} % of the diagonal", report["e_avg_pct"]));
    }
    let status = report["status"].as_str().unwrap_or("");
    if !["converged", "stalled", "max_iterations"].contains(&status) {
        found.push(format!("status {status:?}"));
    }
    found
}

#[test]
fn every_shared_mesh_and_its_points_fit_with_the_defaults() {
    let files = shared_meshes().expect("the shared data beside the repository");
    let full = std::env::var_os("GEOFIT_CORPUS_FULL").is_some();
    let dir = std::env::temp_dir().join(format!("geofit-corpus-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let mut inputs = files.clone();
    inputs.extend(files.iter().filter_map(|f| bare_copy(f, &dir, full)));
    let sources: Vec<Option<PathBuf>> = inputs.iter().map(|f| source_of(f, &dir, &files)).collect();
    let large: Vec<bool> = inputs.iter().map(|f| points_in(f) > LARGE).collect();
    let jobs: Vec<Job> = inputs
        .iter()
        .zip(&large)
        .zip(&sources)
        .flat_map(|((file, &large), source)| {
            SCHEMES
                .map(|scheme| Job {
                    file: file.clone(),
                    scheme,
                    source: source.clone(),
                })
                .into_iter()
                .filter(move |job| full || !large || job.scheme == "loop")
        })
        .collect();
    let next = Mutex::new(0usize);
    let results = Mutex::new(Vec::new());
    std::thread::scope(|s| {
        for _ in 0..2 {
            s.spawn(|| loop {
                let k = {
                    let mut n = next.lock().expect("lock");
                    *n += 1;
                    *n - 1
                };
                let Some(job) = jobs.get(k) else { break };
                let result = fit(job, &dir, k);
                results.lock().expect("lock").push((k, result));
            });
        }
    });
    let mut results = results.into_inner().expect("lock");
    results.sort_by_key(|(k, _)| *k);
    let mut failures = Vec::new();
    let mut table = String::new();
    for (k, result) in &results {
        let job = &jobs[*k];
        let name = format!(
            "{} {}",
            job.file.file_name().unwrap_or_default().to_string_lossy(),
            job.scheme
        );
        match result {
            Ok(report) => {
                table += &format!(
                    "| {name} | {} | {} | {} → {} | {:.4} | {:.4} | {} | {} | {:.1} |\n",
                    report["status"].as_str().unwrap_or("?"),
                    report["iterations"],
                    report["initial_control_points"],
                    report["final_control_points"],
                    report["e_avg_pct"].as_f64().unwrap_or(f64::NAN),
                    report["e_max_pct"].as_f64().unwrap_or(f64::NAN),
                    report["e_back_max_pct"]
                        .as_f64()
                        .map_or("—".to_string(), |b| format!("{b:.4}")),
                    report["to_source_max_pct"]
                        .as_f64()
                        .map_or("—".to_string(), |b| format!("{b:.2}")),
                    report["total_s"].as_f64().unwrap_or(f64::NAN),
                );
                let p = problems(report);
                if !p.is_empty() {
                    failures.push(format!("{name}: {}", p.join(", ")));
                }
            }
            Err(e) => failures.push(format!("{name}: {e}")),
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    // The table of every fit, for docs/subdivision.md and the issue notes.
    let out = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("corpus-report.md");
    let header = "| file scheme | status | iterations | control points | E_avg % | E_max % | E_back % | to source % | total s |\n|---|---|---|---|---|---|---|---|---|\n";
    std::fs::write(&out, format!("{header}{table}")).expect("write the table");
    eprintln!("{header}{table}");
    assert_eq!(results.len(), jobs.len());
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// A closed octahedron-like cone pair and more: the hostile shapes, each as a `PolyMesh`.
fn hostile_meshes() -> Vec<(&'static str, PolyMesh)> {
    let sphere = common::sphere_mesh(3);
    let (pos, faces) = (sphere.positions().to_vec(), triangles(&sphere));
    let shifted: Vec<Point3> = pos
        .iter()
        .map(|&p| p + glam::DVec3::new(3.0, 0.0, 0.0))
        .collect();
    let n = pos.len() as u32;
    let mut two = pos.clone();
    two.extend(&shifted);
    let mut two_faces = faces.clone();
    two_faces.extend(faces.iter().map(|t| t.map(|v| v + n)));
    // The second sphere touches the first at one vertex: a non-manifold vertex.
    let mut touching = two.clone();
    let far = (0..pos.len())
        .max_by(|&a, &b| pos[a].x.total_cmp(&pos[b].x))
        .unwrap_or(0);
    let near = (0..pos.len())
        .min_by(|&a, &b| pos[a].x.total_cmp(&pos[b].x))
        .unwrap_or(0);
    let offset = pos[far] - (pos[near] + glam::DVec3::new(3.0, 0.0, 0.0));
    for p in &mut touching[pos.len()..] {
        *p += offset;
    }
    let touching_faces: Vec<[u32; 3]> = two_faces
        .iter()
        .map(|t| t.map(|v| if v == near as u32 + n { far as u32 } else { v }))
        .collect();
    let mut duplicated = faces.clone();
    duplicated.extend(faces.iter().take(20).copied());
    duplicated.push([0, 0, 1]);
    duplicated.push([faces[0][0], faces[0][1], faces[0][1]]);
    let mut flipped = faces.clone();
    for t in flipped.iter_mut().step_by(3) {
        t.swap(1, 2);
    }
    // A third face on some edges (a book).
    let mut book_pos = pos.clone();
    let mut book = faces.clone();
    for t in faces.iter().take(10) {
        let tip = (pos[t[0] as usize] + pos[t[1] as usize]) * 0.5 * 1.5;
        book_pos.push(tip);
        book.push([t[1], t[0], book_pos.len() as u32 - 1]);
    }
    let mesh =
        |p: &[Point3], f: &[[u32; 3]]| PolyMesh::try_new(p.to_vec(), f.to_vec()).expect("valid");
    let mut grid = common::meshes::tri_grid(40, |x, y| 0.1 * (x * 3.0).sin() * y);
    let big = grid.num_vertices() as u32;
    let mut gp = grid.positions().to_vec();
    let mut gf = triangles(&grid);
    gp.extend([
        Point3::new(-5.0, -5.0, -1.0),
        Point3::new(6.0, -5.0, -1.0),
        Point3::new(0.5, 6.0, -1.0),
    ]);
    gf.push([big, big + 1, big + 2]);
    grid = mesh(&gp, &gf);
    vec![
        ("two components", mesh(&two, &two_faces)),
        ("touching at a vertex", mesh(&touching, &touching_faces)),
        ("duplicate and degenerate faces", mesh(&pos, &duplicated)),
        ("inconsistent orientation", mesh(&pos, &flipped)),
        ("non-manifold edges", mesh(&book_pos, &book)),
        (
            "a single triangle",
            mesh(&[Point3::ZERO, Point3::X, Point3::Y], &[[0, 1, 2]]),
        ),
        ("one huge face under many tiny ones", grid),
    ]
}

fn triangles(mesh: &PolyMesh) -> Vec<[u32; 3]> {
    mesh.triangles()
}

#[test]
fn hostile_meshes_fit_with_the_defaults_or_fail_with_a_typed_error() {
    for (name, mesh) in hostile_meshes() {
        for scheme in [Scheme::Loop, Scheme::CatmullClark, Scheme::DooSabin] {
            let mut spec = FitSpec::new(scheme);
            spec.max_iter = Some(30);
            match spec.build(&FitData::points(&mesh)) {
                Ok(mut fitter) => {
                    let status = fitter
                        .run()
                        .unwrap_or_else(|e| panic!("{name} {scheme:?}: {e}"));
                    let s = fitter.stats();
                    assert!(
                        [s.e_avg_pct, s.e_max_pct, s.e_rms_pct]
                            .iter()
                            .all(|v| v.is_finite()),
                        "{name} {scheme:?}: {s:?}"
                    );
                    assert_ne!(status, FitStatus::Running, "{name} {scheme:?}");
                    eprintln!(
                        "{name} {scheme:?}: {status:?}, {:.4} % E_max, E_back {:?}",
                        s.e_max_pct,
                        fitter.back_stats()
                    );
                }
                // Only a mesh too small for the scheme may be refused, and it says so.
                Err(e) => {
                    assert_eq!(name, "a single triangle", "{name} {scheme:?}: {e}");
                    assert!(!e.to_string().is_empty());
                }
            }
        }
    }
}
