//! `geofit fit --scheme bspline-curve` end to end: report fields, exports, and clear failures on bad input.

mod common;

use std::path::PathBuf;
use std::process::Command;

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn fit_curve_reports_and_exports() {
    let dir = std::env::temp_dir().join(format!("geofit-curve-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for method in ["geometric", "knots"] {
        let json = dir.join(format!("{method}.json"));
        common::run_ok(
            Command::new(env!("CARGO_BIN_EXE_geofit"))
                .arg("fit")
                .arg(repo().join("tests/data/fandisk_section_x.xyz"))
                .args([
                    "--scheme",
                    "bspline-curve",
                    "--closed",
                    "--method",
                    method,
                    "--tol-max",
                    "0.01",
                    "--json",
                ])
                .arg(&json)
                .arg("--iges")
                .arg(dir.join(format!("{method}.igs")))
                .arg("--step")
                .arg(dir.join(format!("{method}.stp"))),
        );
        let r: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
        assert_eq!(r["converged"], true, "{method}");
        assert!(r["e_max_pct"].as_f64().unwrap() <= 0.01);
        assert!(r["final_control_points"].as_u64().unwrap() >= 4);
        assert_eq!(r["samples"].as_array().unwrap().len(), 101);
        assert!(!r["history"].as_array().unwrap().is_empty());
        assert!(dir.join(format!("{method}.igs")).exists());
        assert!(dir.join(format!("{method}.stp")).exists());
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn fit_curve_fails_cleanly_on_bad_input() {
    let dir = std::env::temp_dir().join(format!("geofit-curve-bad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("three.xyz");
    std::fs::write(&bad, "0 0\n1 0\n1 1\n").unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_geofit"))
        .args(["fit", "--scheme", "bspline-curve"])
        .arg(&bad)
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("too few data points"), "{err}");
    let out = Command::new(env!("CARGO_BIN_EXE_geofit"))
        .args(["fit", "--scheme", "bspline-curve"])
        .arg(repo().join("tests/data/bunny_section.xyz"))
        .args(["--degree", "9"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("degree"));
    std::fs::remove_dir_all(&dir).ok();
}
