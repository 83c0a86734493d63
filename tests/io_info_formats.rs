//! `geofit info --json` on one file of each scanner and glTF format: the format name, the
//! counts, and for E57, LAS/LAZ and PTX the scan count and whether a grid was kept.

use serde_json::{json, Value};
use std::path::PathBuf;
use std::process::Command;

fn info(name: &str) -> Value {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/formats")
        .join(name);
    let out = Command::new(env!("CARGO_BIN_EXE_geofit"))
        .arg("info")
        .arg(&path)
        .arg("--json")
        .output()
        .expect("the geofit binary runs");
    assert!(
        out.status.success(),
        "{name}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("one JSON object")
}

#[test]
fn reports_format_scans_and_grid() {
    // (file, format, points, triangles, scans, grid_kept, range_grid, unit)
    let cases = [
        (
            "bun000-grid.e57",
            "e57",
            406,
            0,
            json!(1),
            json!(true),
            json!([52, 40]),
            json!(1.0),
        ),
        (
            "two-scans.e57",
            "e57",
            473,
            0,
            json!(2),
            json!(false),
            Value::Null,
            json!(1.0),
        ),
        (
            "bunny.las",
            "las",
            799,
            0,
            json!(1),
            json!(false),
            Value::Null,
            Value::Null,
        ),
        (
            "bunny.laz",
            "laz",
            799,
            0,
            json!(1),
            json!(false),
            Value::Null,
            Value::Null,
        ),
        (
            "bun000-grid.ptx",
            "ptx",
            406,
            0,
            json!(1),
            json!(true),
            json!([52, 40]),
            Value::Null,
        ),
        (
            "two-scans.ptx",
            "ptx",
            199,
            0,
            json!(2),
            json!(false),
            Value::Null,
            Value::Null,
        ),
        (
            "bunny-compressed.pcd",
            "pcd",
            799,
            0,
            Value::Null,
            Value::Null,
            Value::Null,
            Value::Null,
        ),
        (
            "bunny.pts",
            "xyz",
            400,
            0,
            Value::Null,
            Value::Null,
            Value::Null,
            Value::Null,
        ),
        (
            "suzanne-scene.glb",
            "glb",
            1030,
            1943,
            Value::Null,
            Value::Null,
            Value::Null,
            json!(1.0),
        ),
        (
            "suzanne-embedded.gltf",
            "gltf",
            507,
            968,
            Value::Null,
            Value::Null,
            Value::Null,
            json!(1.0),
        ),
    ];
    for (name, format, points, triangles, scans, kept, grid, unit) in cases {
        if (format == "e57" && !cfg!(feature = "e57"))
            || (format == "laz" && !cfg!(feature = "laz"))
        {
            continue;
        }
        let v = info(name);
        assert_eq!(v["format"], format, "{name}: {v}");
        assert_eq!(v["points"], points, "{name}: {v}");
        assert_eq!(v["triangles"], triangles, "{name}: {v}");
        assert_eq!(v["scans"], scans, "{name}: {v}");
        assert_eq!(v["grid_kept"], kept, "{name}: {v}");
        assert_eq!(v["range_grid"], grid, "{name}: {v}");
        assert_eq!(v["unit_to_metres"], unit, "{name}: {v}");
    }
}
