//! `geofit info` end to end: the built binary on every shared scan and on corrupt files.

mod common;

use common::{data_file, test_file};
use std::path::Path;
use std::process::{Command, Output};

fn info(path: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_geofit"))
        .arg("info")
        .arg(path)
        .arg("--json")
        .output()
        .expect("the geofit binary runs")
}

fn info_json(name: &str) -> serde_json::Value {
    let out = info(&data_file(name));
    assert!(
        out.status.success(),
        "{name}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8(out.stdout).expect("UTF-8 output");
    assert_eq!(stdout.trim().lines().count(), 1, "one JSON line: {stdout}");
    serde_json::from_str(&stdout).expect("valid JSON")
}

#[test]
fn reports_exact_counts_for_every_shared_file() {
    let expected = [
        ("bun000.ply", "ply", 40_256, 0),
        ("stanford-bunny.obj", "obj", 35_947, 69_451),
        ("fandisk.obj", "obj", 6_475, 12_946),
        ("rocker-arm.obj", "obj", 10_044, 20_088),
        ("spot.obj", "obj", 2_930, 5_856),
        ("teapot.obj", "obj", 3_644, 6_320),
    ];
    for (name, format, points, triangles) in expected {
        let v = info_json(name);
        assert_eq!(v["format"], format, "{name}");
        assert_eq!(v["points"], points, "{name}");
        assert_eq!(v["triangles"], triangles, "{name}");
        for k in 0..3 {
            let (lo, hi) = (&v["bbox_min"][k], &v["bbox_max"][k]);
            assert!(
                lo.as_f64().unwrap() <= hi.as_f64().unwrap(),
                "{name} bbox {v}"
            );
        }
    }
    assert_eq!(
        info_json("bun000.ply")["range_grid"],
        serde_json::json!([512, 400])
    );
    assert!(info_json("teapot.obj").get("range_grid").is_none());
}

#[test]
fn bunny_bbox_matches_the_file() {
    // Extremes of the `v` lines of stanford-bunny.obj, found with awk.
    let v = info_json("stanford-bunny.obj");
    assert_eq!(
        v["bbox_min"],
        serde_json::json!([-0.09469, 0.032987, -0.061874])
    );
    assert_eq!(
        v["bbox_max"],
        serde_json::json!([0.061009, 0.187321, 0.0588])
    );
}

#[test]
fn corrupt_files_exit_1_with_one_line_on_stderr() {
    let cases = [
        ("huge-count.ply", "4000000000"),
        ("bad-index.ply", "line 13"),
        ("text-in-number.obj", "line 3"),
        ("truncated.stl", "declares 5 triangles"),
        ("unknown.bin", "unknown file format"),
        ("no-such-file.ply", "cannot read"),
    ];
    for (name, needle) in cases {
        let out = info(&test_file(name));
        assert_eq!(out.status.code(), Some(1), "{name}");
        assert!(out.stdout.is_empty(), "{name}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(err.trim_end().lines().count(), 1, "{name}: {err}");
        assert!(err.contains(needle), "{name}: {err}");
    }
}

#[test]
fn a_closed_output_pipe_is_not_a_crash() {
    // The reader goes away before geofit writes (as `geofit info scan.ply | head -1` does once
    // head has its line): the command must finish normally instead of panicking.
    let mut child = Command::new(env!("CARGO_BIN_EXE_geofit"))
        .arg("info")
        .arg(data_file("fandisk.obj"))
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("the geofit binary runs");
    drop(child.stdout.take());
    let out = child.wait_with_output().expect("geofit finishes");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
}
