//! Shared helpers of the integration tests: the data directory, small meshes, and a
//! piecewise-linear `LimitSurface` the fitting engine can be checked against.
#![allow(dead_code)]

pub mod fuzz;
pub mod linear;
pub mod manifold;
pub mod meshes;
pub mod surface_checks;

use geofit::geom::Point3;
use geofit::mesh::PolyMesh;
use std::path::{Path, PathBuf};

/// `$GEOFIT_DATA`, else `<repo>/../shared/data`, else `/work/shared/data`.
pub fn data_dir() -> PathBuf {
    if let Ok(dir) = std::env::var("GEOFIT_DATA") {
        return PathBuf::from(dir);
    }
    let beside = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/data");
    if beside.exists() {
        return beside;
    }
    PathBuf::from("/work/shared/data")
}

/// A deterministic pseudo-random generator (SplitMix64) so tests need no seed handling.
pub struct Rng(pub u64);

impl Rng {
    /// Uniform in [0, 1).
    pub fn next_f64(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [-1, 1)³.
    pub fn vec(&mut self) -> Point3 {
        Point3::new(
            2.0 * self.next_f64() - 1.0,
            2.0 * self.next_f64() - 1.0,
            2.0 * self.next_f64() - 1.0,
        )
    }
}

/// An octahedron subdivided `levels` times (midpoints pushed onto the unit sphere): a closed,
/// consistently oriented triangle mesh with valence-4 and valence-6 vertices.
pub fn sphere_mesh(levels: usize) -> PolyMesh {
    let octahedron = meshes::octahedron();
    let mut pts = octahedron.positions().to_vec();
    let mut tris: Vec<[u32; 3]> = octahedron.triangles();
    for _ in 0..levels {
        let mut mid = std::collections::HashMap::new();
        let mut next = Vec::new();
        let mut m = |a: u32, b: u32, pts: &mut Vec<Point3>| {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                pts.push(((pts[a as usize] + pts[b as usize]) * 0.5).normalize());
                pts.len() as u32 - 1
            })
        };
        for [a, b, c] in tris {
            let (ab, bc, ca) = (m(a, b, &mut pts), m(b, c, &mut pts), m(c, a, &mut pts));
            next.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
        }
        tris = next;
    }
    PolyMesh::try_new(pts, tris).expect("valid sphere")
}

/// `n` points d · (1 + bump(d)) over directions d (`Rng(seed)` in the cube, normalised): a bumpy
/// sphere.
pub fn bumpy_sphere(seed: u64, n: usize, bump: impl Fn(Point3) -> f64) -> Vec<Point3> {
    let mut rng = Rng(seed);
    (0..n)
        .map(|_| {
            let d = rng.vec().normalize();
            d * (1.0 + bump(d))
        })
        .collect()
}

/// An open n × n grid of triangles over [0, 1]² with a bump of `height`: a surface with a
/// boundary.
pub fn bump_grid(n: usize, height: f64) -> PolyMesh {
    let mut pts = Vec::new();
    for i in 0..=n {
        for j in 0..=n {
            let (x, y) = (i as f64 / n as f64, j as f64 / n as f64);
            let z = height * (-8.0 * ((x - 0.5).powi(2) + (y - 0.4).powi(2))).exp();
            pts.push(Point3::new(x, y, z));
        }
    }
    let id = |i: usize, j: usize| (i * (n + 1) + j) as u32;
    let mut tris = Vec::new();
    for i in 0..n {
        for j in 0..n {
            tris.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            tris.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    PolyMesh::try_new(pts, tris).expect("valid grid")
}

/// The same mesh with every point moved by up to `amount` in each coordinate.
pub fn perturbed(mesh: &PolyMesh, amount: f64, rng: &mut Rng) -> PolyMesh {
    let pts = mesh
        .positions()
        .iter()
        .map(|p| *p + rng.vec() * amount)
        .collect();
    let faces: Vec<&[u32]> = mesh.faces().collect();
    PolyMesh::try_new(pts, faces).expect("same connectivity")
}

/// The same mesh with every point moved along z by up to `amount`.
pub fn perturbed_z(mesh: &PolyMesh, amount: f64, rng: &mut Rng) -> PolyMesh {
    let pts = mesh
        .positions()
        .iter()
        .map(|p| *p + Point3::Z * (rng.next_f64() * 2.0 - 1.0) * amount)
        .collect();
    let faces: Vec<&[u32]> = mesh.faces().collect();
    PolyMesh::try_new(pts, faces).expect("same connectivity")
}

/// A file in the shared scan directory.
pub fn data_file(name: &str) -> PathBuf {
    data_dir().join(name)
}

/// A file in the repository's own `tests/data` (small, often deliberately malformed samples).
pub fn test_file(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

/// The meshes and scans of the shared data and its corpus (`.obj`, `.ply`, `.stl`), sorted, or
/// `None` (with a message) where the shared data is absent.
pub fn shared_meshes() -> Option<Vec<PathBuf>> {
    let data = data_dir();
    if !data.is_dir() {
        eprintln!("skipped: no shared data at {}", data.display());
        return None;
    }
    let mut files = Vec::new();
    for dir in [data.clone(), data.join("corpus")] {
        for e in std::fs::read_dir(&dir).into_iter().flatten().flatten() {
            let p = e.path();
            let ext = p.extension().and_then(|x| x.to_str()).unwrap_or("");
            if ["obj", "ply", "stl"].contains(&ext) {
                files.push(p);
            }
        }
    }
    files.sort();
    Some(files)
}

/// A two-column section file of `tests/data` (made by scripts/make_sections.py) as points with
/// z = 0.
pub fn section(name: &str) -> Vec<Point3> {
    let text = std::fs::read_to_string(test_file(name)).expect("section file");
    text.lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            Point3::new(v[0], v[1], 0.0)
        })
        .collect()
}

/// Tolerances with only an E_max bound, in % of the diagonal.
pub fn max_only(pct: f64) -> geofit::fit::Tolerances {
    geofit::fit::Tolerances {
        avg_pct: None,
        max_pct: Some(pct),
        rms_pct: None,
    }
}

/// Runs `command` and returns its output, failing the test with its stderr when it fails.
pub fn run_ok(command: &mut std::process::Command) -> std::process::Output {
    let out = command.output().expect("the command starts");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// Runs the geofit binary with `args`.
pub fn geofit(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_geofit"))
        .args(args)
        .output()
        .expect("the geofit binary runs")
}

/// Runs the geofit binary with `args`, failing the test with its stdout and stderr when it
/// fails; returns its stdout.
pub fn geofit_ok(args: &[&str]) -> String {
    let out = geofit(args);
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    stdout
}

/// A JSON file (such as the report of `geofit fit --json`), parsed.
pub fn read_json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).expect("report")).expect("JSON")
}

/// The numbers every `geofit fit` JSON report holds: the errors and the timings.
pub const REPORT_NUMBERS: [&str; 6] = [
    "e_avg_pct",
    "e_max_pct",
    "e_rms_pct",
    "precompute_s",
    "fit_s",
    "total_s",
];
