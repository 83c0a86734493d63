//! `geofit fit` end to end on a small shared scan (spot.obj, 2,930 points): progress lines, the
//! JSON report's fields, the cage and limit OBJ files, and clear errors for bad options.

mod common;

use common::{data_file, geofit, geofit_ok, read_json, REPORT_NUMBERS};

#[test]
fn fit_writes_report_cage_and_limit() {
    let dir = std::env::temp_dir().join(format!("geofit-fit-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let (json, cage, limit) = (
        dir.join("r.json"),
        dir.join("cage.obj"),
        dir.join("limit.obj"),
    );
    let spot = data_file("spot.obj");
    let stdout = geofit_ok(&[
        "fit",
        spot.to_str().expect("utf-8 path"),
        "--scheme",
        "loop",
        "--initial",
        "150",
        "--tol-avg",
        "0.2",
        "--max-iter",
        "8",
        "--max-control",
        "400",
        "--json",
        json.to_str().expect("utf-8"),
        "--cage",
        cage.to_str().expect("utf-8"),
        "--limit",
        limit.to_str().expect("utf-8"),
    ]);
    assert!(
        stdout.lines().any(|l| l.starts_with("iter   1")),
        "{stdout}"
    );
    let report = read_json(&json);
    let counts = [
        "scheme",
        "points",
        "initial_control_points",
        "final_control_points",
        "iterations",
    ];
    for key in counts.into_iter().chain(REPORT_NUMBERS).chain(["history"]) {
        assert!(report.get(key).is_some(), "missing {key}");
    }
    assert_eq!(report["scheme"], "loop");
    assert_eq!(report["points"], 2930);
    let history = report["history"].as_array().expect("history");
    assert_eq!(
        history.len() as u64,
        report["iterations"].as_u64().expect("count")
    );
    for key in [
        "iter",
        "control_points",
        "e_avg_pct",
        "e_max_pct",
        "e_rms_pct",
        "ms",
    ] {
        assert!(history[0].get(key).is_some(), "history lacks {key}");
    }
    let first = history[0]["e_avg_pct"].as_f64().expect("number");
    assert!(report["e_avg_pct"].as_f64().expect("number") <= first);
    let cage_mesh = geofit::io::read_path(&cage).expect("cage OBJ").mesh;
    assert_eq!(
        cage_mesh.num_vertices() as u64,
        report["final_control_points"].as_u64().expect("count")
    );
    assert!(
        geofit::io::read_path(&limit)
            .expect("limit OBJ")
            .mesh
            .num_faces()
            > 0
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bad_options_fail_with_a_message() {
    let spot = data_file("spot.obj");
    let spot = spot.to_str().expect("utf-8");
    for args in [
        vec!["fit", spot, "--tol-max=-1"],
        vec!["fit", spot, "--weights", "patent", "--accel", "cg"],
        vec!["fit", "/nonexistent/file.obj"],
    ] {
        let out = geofit(&args);
        assert!(!out.status.success(), "{args:?} succeeded");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.starts_with("geofit: "), "{args:?}: {err}");
    }
}

/// The page's first sample with the defaults (its preset sets only the scheme,
/// www/samples/samples.json) converges both ways in every subdivision scheme: data → surface
/// within the tolerances and no surface sample farther from the data than the surface → data
/// bound (a blister between the sample's sparse points once made Loop and Doo–Sabin stall,
/// and the page's Play never reach "converged").
#[test]
fn the_page_sample_converges_both_ways_with_the_defaults() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("www/samples");
    let samples: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(root.join("samples.json")).expect("list"))
            .expect("JSON");
    let first = &samples["samples"][0];
    let preset = first["preset"].as_object().expect("preset");
    assert_eq!(preset.keys().collect::<Vec<_>>(), ["scheme"]);
    let file = root.join(first["file"].as_str().expect("file name"));
    let json = std::env::temp_dir().join(format!("geofit-sample-{}.json", std::process::id()));
    for scheme in ["loop", "catmull-clark", "doo-sabin"] {
        let report = fit_with_defaults(&file, scheme, &json);
        let last = report["history"]
            .as_array()
            .and_then(|h| h.last())
            .expect("iterations");
        let back = last["e_back_max_pct"].as_f64().expect("E_back measured");
        assert_converged_both_ways(&report, back, scheme);
    }
    std::fs::remove_file(&json).ok();
}

/// `geofit fit FILE --scheme SCHEME` with every other setting at its default, its report
/// written to `json` and read back.
fn fit_with_defaults(
    file: &std::path::Path,
    scheme: &str,
    json: &std::path::Path,
) -> serde_json::Value {
    geofit_ok(&[
        "fit",
        file.to_str().expect("utf-8"),
        "--scheme",
        scheme,
        "-q",
        "--json",
        json.to_str().expect("utf-8"),
    ]);
    read_json(json)
}

/// A fit at the default tolerances converged both ways: status, E_max within its tolerance and
/// `back` (E_back max %) within the surface → data bound.
fn assert_converged_both_ways(report: &serde_json::Value, back: f64, scheme: &str) {
    let tol_max = geofit::fit::SubdivFitOptions::DEFAULT_TOLERANCES
        .max_pct
        .expect("an E_max tolerance");
    assert_eq!(report["status"], "converged", "{scheme}: E_back {back} %");
    assert!(
        back <= geofit::fit::BACK_TOLERANCE_FACTOR * tol_max,
        "{scheme}: E_back {back} %"
    );
    assert!(report["e_max_pct"].as_f64().expect("E_max") <= tol_max);
}

/// `--fem` writes the FEM quad mesh (MSH, or OBJ quads for `.obj`) and prints its quality; the
/// FEM flags are refused where they do not apply (issue 18).
#[test]
fn fem_flags_write_the_quad_mesh_or_fail_with_a_message() {
    let dir = std::env::temp_dir().join(format!("geofit-fem-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let spot = data_file("spot.obj");
    let spot = spot.to_str().expect("utf-8");
    let (msh, obj) = (dir.join("spot.msh"), dir.join("spot.obj"));
    for (out, size) in [
        (&msh, ["--fem-count", "3000"]),
        (&obj, ["--fem-size", "0.05"]),
    ] {
        let out_s = out.to_str().expect("utf-8");
        let stdout = geofit_ok(&[
            "fit",
            spot,
            "--scheme",
            "catmull-clark",
            "-q",
            "--fem",
            out_s,
            size[0],
            size[1],
        ]);
        let line = stdout
            .lines()
            .find(|l| l.starts_with("FEM mesh: "))
            .expect("quality line");
        let quads: usize = line["FEM mesh: ".len()..]
            .split(' ')
            .next()
            .unwrap()
            .parse()
            .unwrap();
        assert!(line.contains(" 0 inverted"), "{line}");
        let text = std::fs::read_to_string(out).expect("written");
        if out == &msh {
            assert!(text.starts_with("$MeshFormat\n4.1 0 8\n"));
            assert!(text.contains(&format!("\n2 1 3 {quads}\n")), "{line}");
            assert!((quads as f64 / 3000.0 - 1.0).abs() < 0.25, "{line}");
        } else {
            assert_eq!(text.lines().filter(|l| l.starts_with("f ")).count(), quads);
            assert!(text
                .lines()
                .filter(|l| l.starts_with("f "))
                .all(|l| l.split(' ').count() == 5));
        }
    }
    let msh_s = msh.to_str().expect("utf-8");
    for (args, message) in [
        (
            vec!["fit", spot, "--scheme", "loop", "--fem", msh_s],
            "--fem does not apply to --scheme loop",
        ),
        (vec!["fit", spot, "--fem-size", "1"], "need --fem FILE"),
        (
            vec![
                "fit",
                spot,
                "--scheme",
                "catmull-clark",
                "--max-iter",
                "1",
                "--fem",
                msh_s,
                "--fem-size",
                "0",
            ],
            "FEM element size must be a positive finite length, got 0",
        ),
    ] {
        let out = geofit(&args);
        assert!(!out.status.success(), "{args:?} succeeded");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(message), "{args:?}: {err}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// A smooth surface over a concave gap of the data (the cow's hind legs) bridges it with a web
/// that no data point is nearest to, so data → surface distances never pull it in: at the
/// defaults Loop and Doo–Sabin met E_max on the cow and stalled with E_back 1.46 % and 1.16 %
/// (the bound is 1 %). The moves now pull the surface samples beyond the E_max tolerance
/// towards their nearest data points, and both fits converge both ways.
#[test]
fn a_web_across_a_gap_of_the_data_is_pulled_onto_it() {
    let cow = common::data_file("corpus/cow.obj");
    if !cow.exists() {
        eprintln!("skipped: no {}", cow.display());
        return;
    }
    let json = std::env::temp_dir().join(format!("geofit-cow-{}.json", std::process::id()));
    for scheme in ["loop", "doo-sabin"] {
        let report = fit_with_defaults(&cow, scheme, &json);
        let back = report["e_back_max_pct"].as_f64().expect("E_back measured");
        assert_converged_both_ways(&report, back, scheme);
    }
    std::fs::remove_file(&json).ok();
}

/// `--threads N` gives byte-identical results on any number of threads: the cage and the
/// limit surface of a subdivision fit (foot points and surface → data distances run in
/// parallel), of bare points (reconstructed, measured to their discs), and a B-spline surface
/// (parameter correction in parallel), with every error figure of the reports equal.
#[test]
fn results_are_the_same_on_any_number_of_threads() {
    let samples = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("www/samples");
    let dir = std::env::temp_dir().join(format!("geofit-threads-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let cases = [
        ("bunny.obj", "loop", "--cage"),
        ("bun000-points.xyz", "catmull-clark", "--cage"),
        ("bun000-points.xyz", "bspline", "--surface-json"),
    ];
    for (file, scheme, export) in cases {
        let run = |threads: &str| {
            let out = dir.join(format!("{scheme}-{threads}.out"));
            let json = dir.join(format!("{scheme}-{threads}.json"));
            geofit_ok(&[
                "fit",
                samples.join(file).to_str().expect("utf-8"),
                "--scheme",
                scheme,
                "--threads",
                threads,
                "-q",
                export,
                out.to_str().expect("utf-8"),
                "--json",
                json.to_str().expect("utf-8"),
            ]);
            let report = read_json(&json);
            let errors: Vec<String> = ["e_avg_pct", "e_max_pct", "e_rms_pct", "e_back_max_pct"]
                .iter()
                .map(|k| report[k].to_string())
                .collect();
            (
                std::fs::read(&out).expect("export"),
                errors,
                report["iterations"].clone(),
            )
        };
        let one = run("1");
        assert_eq!(one, run("3"), "{file} {scheme}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// `--limit` of a B-spline surface writes what the page draws and the other exports write: the
/// surface cut to its trim. The whole rectangle curls away beyond the data: bun000's fit at
/// E_max 0.5 % reached z = −0.227 where the scan ends at −0.059 (68 % of the diagonal away).
#[test]
fn the_limit_of_a_bspline_surface_is_cut_to_its_trim() {
    let dir = std::env::temp_dir().join(format!("geofit-limit-trim-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let limit = dir.join("limit.obj");
    let scan = data_file("bun000.ply");
    if !scan.exists() {
        eprintln!("skipped: no {}", scan.display());
        return;
    }
    geofit_ok(&[
        "fit",
        scan.to_str().expect("utf-8 path"),
        "--scheme",
        "bspline-surface",
        "--tol-max",
        "0.5",
        "--quiet",
        "--limit",
        limit.to_str().expect("utf-8"),
    ]);
    let data = geofit::io::read_path(&scan).expect("bun000 reads").mesh;
    let bbox = data.bbox().expect("points");
    let slack = 0.02 * bbox.diagonal();
    let surface = geofit::io::read_path(&limit).expect("the limit reads").mesh;
    assert!(surface.num_faces() > 0);
    for p in surface.positions() {
        let outside = (bbox.min - *p).max(*p - bbox.max).max_element();
        assert!(
            outside <= slack,
            "{p:?} lies {outside} beyond the data's box"
        );
    }
}
