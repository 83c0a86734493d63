//! The scanner and glTF readers on the files `scripts/make-format-samples.py` wrote with each
//! format's own Python writer (pye57, laspy + lazrs, pypcd4, pygltflib, PTX/PTS by hand):
//! exact point and triangle counts, coordinates (poses and node transforms applied) against
//! what the script computed in f64 from the stored numbers, grids, scan counts, and the errors
//! of damaged files.

use geofit::geom::Point3;
use geofit::io::{read_bytes, Format, LoadedFile, Location, ReadError};
use serde_json::Value;
use std::path::PathBuf;

fn dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/formats")
}

fn bytes(name: &str) -> Vec<u8> {
    std::fs::read(dir().join(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn expected(name: &str) -> Value {
    let text = std::fs::read_to_string(dir().join("expected.json")).expect("expected.json");
    let all: Value = serde_json::from_str(&text).expect("valid JSON");
    all[name].clone()
}

fn point(v: &Value) -> Point3 {
    let c = |k: usize| v[k].as_f64().expect("number");
    Point3::new(c(0), c(1), c(2))
}

/// Reads `name` with its file name as the hint and again without it (the content alone must
/// give the same format).
fn read(name: &str) -> LoadedFile {
    let b = bytes(name);
    let f = read_bytes(&b, Some(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
    let g = read_bytes(&b, None).unwrap_or_else(|e| panic!("{name} without a name: {e}"));
    assert_eq!(f.format, g.format, "{name}");
    f
}

/// Compares counts, bounding box, coordinate sums and the first and last points with the
/// script's figures, within `tol` (relative to the data's size).
fn check(name: &str, format: Format, tol: f64) -> LoadedFile {
    let f = read(name);
    let e = expected(name);
    assert_eq!(f.format, format, "{name}");
    let n = e["points"].as_u64().expect("points") as usize;
    assert_eq!(f.mesh.num_vertices(), n, "{name}: points");
    assert_eq!(
        f.mesh.num_triangles(),
        e["triangles"].as_u64().expect("triangles") as usize,
        "{name}: triangles"
    );
    let bbox = f.mesh.bbox().expect("points");
    let size = (point(&e["bbox_max"]) - point(&e["bbox_min"]))
        .length()
        .max(1.0);
    let close = |a: Point3, b: Point3, what: &str, scale: f64| {
        assert!(
            (a - b).length() <= tol * size * scale,
            "{name}: {what} {a} vs {b}"
        );
    };
    close(bbox.min, point(&e["bbox_min"]), "bbox min", 1.0);
    close(bbox.max, point(&e["bbox_max"]), "bbox max", 1.0);
    let p = f.mesh.positions();
    close(p[0], point(&e["first"]), "first point", 1.0);
    close(p[n - 1], point(&e["last"]), "last point", 1.0);
    let sum = p.iter().fold(Point3::ZERO, |s, &q| s + q);
    close(sum, point(&e["sum"]), "coordinate sum", n as f64);
    if let Some(scans) = e.get("scans") {
        assert_eq!(
            f.scans,
            Some(scans.as_u64().expect("scans") as usize),
            "{name}"
        );
    }
    match e["grid"].as_array() {
        Some(g) => {
            let grid = f
                .range_grid
                .as_ref()
                .unwrap_or_else(|| panic!("{name}: no grid"));
            let size = (grid.cols(), grid.rows());
            let want = (
                g[0].as_u64().unwrap_or(0) as usize,
                g[1].as_u64().unwrap_or(0) as usize,
            );
            assert_eq!(size, want, "{name}: grid size");
            let measured = (0..grid.rows())
                .flat_map(|r| (0..grid.cols()).map(move |c| (c, r)))
                .filter(|&(c, r)| grid.cell(c, r).is_some())
                .count();
            assert_eq!(measured, n, "{name}: every point in one grid cell");
            for cell in e["cells"].as_array().expect("cells") {
                let (c, r) = (
                    cell[0].as_u64().unwrap_or(0) as usize,
                    cell[1].as_u64().unwrap_or(0) as usize,
                );
                let i = grid
                    .cell(c, r)
                    .unwrap_or_else(|| panic!("{name}: cell ({c}, {r}) empty"));
                let want = Point3::new(
                    cell[2].as_f64().unwrap_or(0.0),
                    cell[3].as_f64().unwrap_or(0.0),
                    cell[4].as_f64().unwrap_or(0.0),
                );
                close(p[i as usize], want, "grid cell point", 1.0);
            }
        }
        None => assert!(f.range_grid.is_none(), "{name}: unexpected grid"),
    }
    f
}

/// f64 maths on stored values: only rounding of the sums and transforms differs.
const EXACT: f64 = 1e-12;

#[test]
#[cfg_attr(not(feature = "e57"), ignore = "needs the e57 feature")]
fn e57_structured_scan_keeps_its_grid_with_the_pose_applied() {
    let f = check("bun000-grid.e57", Format::E57, EXACT);
    assert_eq!(f.unit_to_metres, Some(1.0));
    // The grid triangulates the scan as the Cyberware grid does.
    assert!(!f.range_grid.expect("grid").triangles().is_empty());
}

#[test]
#[cfg_attr(not(feature = "e57"), ignore = "needs the e57 feature")]
fn e57_two_scans_merge_without_a_grid() {
    check("two-scans.e57", Format::E57, EXACT);
}

#[test]
#[cfg_attr(not(feature = "laz"), ignore = "needs the laz feature")]
fn las_and_laz_apply_scale_and_offset() {
    let las = check("bunny.las", Format::Las, EXACT);
    let laz = check("bunny.laz", Format::Laz, EXACT);
    assert_eq!(las.mesh.positions(), laz.mesh.positions());
    let v14 = check("bunny-14.las", Format::Las, EXACT);
    assert_eq!(las.mesh.positions(), v14.mesh.positions());
}

#[test]
fn pcd_ascii_binary_and_compressed_agree() {
    // ascii stores ten decimals (pypcd4's "%.10f").
    let a = check("bunny-ascii.pcd", Format::Pcd, 1e-9);
    let b = check("bunny-binary.pcd", Format::Pcd, EXACT);
    let c = check("bunny-compressed.pcd", Format::Pcd, EXACT);
    assert_eq!(b.mesh.positions(), c.mesh.positions());
    for (p, q) in a.mesh.positions().iter().zip(b.mesh.positions()) {
        assert!((*p - *q).length() < 1e-9);
    }
}

#[test]
fn ptx_grid_in_column_order_with_the_pose() {
    let f = check("bun000-grid.ptx", Format::Ptx, EXACT);
    assert_eq!(f.scans, Some(1));
}

#[test]
fn ptx_two_scans_keep_no_grid() {
    check("two-scans.ptx", Format::Ptx, EXACT);
}

#[test]
fn pts_count_line_and_extra_columns() {
    let f = check("bunny.pts", Format::Xyz, EXACT);
    assert_eq!(f.dimension, 3);
}

#[test]
fn glb_scene_graph_transforms_and_primitive_modes() {
    let f = check("suzanne-scene.glb", Format::Glb, EXACT);
    assert_eq!(f.unit_to_metres, Some(1.0));
    // The node outside the scene (translated by 100) is not read.
    assert!(f.mesh.bbox().expect("points").max.x < 50.0);
}

#[test]
fn gltf_with_an_embedded_buffer_and_interleaved_attributes() {
    check("suzanne-embedded.gltf", Format::Gltf, EXACT);
}

#[test]
fn gltf_external_buffer_is_a_typed_error() {
    let text = br#"{"asset":{"version":"2.0"},"buffers":[{"uri":"mesh.bin","byteLength":36}],
        "bufferViews":[{"buffer":0,"byteLength":36}],
        "accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"}],
        "meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}]}"#;
    let e = read_bytes(text, Some("a.gltf")).unwrap_err();
    assert!(
        matches!(&e, ReadError::ExternalData { uri, at: Location::Item("buffer", 0), .. } if uri == "mesh.bin"),
        "{e}"
    );
    assert!(e.to_string().contains("'mesh.bin'"), "{e}");
}

#[test]
fn gltf_sparse_accessor_and_draco_extension() {
    // Three zero positions (no bufferView), the middle one replaced by the sparse values.
    let data: Vec<u8> = [1u32]
        .iter()
        .flat_map(|i| i.to_le_bytes())
        .chain([5.0f32, 6.0, 7.0].iter().flat_map(|v| v.to_le_bytes()))
        .collect();
    let b64 = base64(&data);
    let text = format!(
        r#"{{"asset":{{"version":"2.0"}},"buffers":[{{"uri":"data:application/octet-stream;base64,{b64}","byteLength":16}}],
        "bufferViews":[{{"buffer":0,"byteLength":4}},{{"buffer":0,"byteOffset":4,"byteLength":12}}],
        "accessors":[{{"componentType":5126,"count":3,"type":"VEC3",
            "sparse":{{"count":1,"indices":{{"bufferView":0,"componentType":5125}},"values":{{"bufferView":1}}}}}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}]}}"#
    );
    let f = read_bytes(text.as_bytes(), None).expect("sparse glTF");
    assert_eq!(
        f.mesh.positions(),
        &[Point3::ZERO, Point3::new(5.0, 6.0, 7.0), Point3::ZERO]
    );
    assert_eq!(f.mesh.num_triangles(), 1);
    let draco = text.replace(
        r#""asset""#,
        r#""extensionsRequired":["KHR_draco_mesh_compression"],"asset""#,
    );
    let e = read_bytes(draco.as_bytes(), None).unwrap_err();
    assert!(matches!(e, ReadError::Unsupported { .. }), "{e}");
}

fn base64(data: &[u8]) -> String {
    const A: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::new();
    for c in data.chunks(3) {
        let n = (u32::from(c[0]) << 16)
            | (u32::from(*c.get(1).unwrap_or(&0)) << 8)
            | u32::from(*c.get(2).unwrap_or(&0));
        for k in 0..=c.len() {
            s.push(A[(n >> (18 - 6 * k) & 63) as usize] as char);
        }
    }
    while s.len() % 4 != 0 {
        s.push('=');
    }
    s
}

/// Reading `data` fails as a truncated `format` file, at `at` where given; returns the error.
fn assert_truncated(data: &[u8], format: Format, at: Option<Location>) -> ReadError {
    let e = read_bytes(data, None).unwrap_err();
    assert!(
        matches!(
            &e,
            ReadError::Truncated { format: f, at: a, .. }
                if *f == format && at.is_none_or(|at| *a == at)
        ),
        "{e}"
    );
    e
}

#[test]
#[cfg_attr(
    not(all(feature = "e57", feature = "laz")),
    ignore = "needs the e57 and laz features"
)]
fn damaged_headers_give_typed_errors_at_the_place() {
    // LAS: point count far beyond the file.
    let mut las = bytes("bunny.las");
    las[107..111].copy_from_slice(&u32::MAX.to_le_bytes());
    assert_truncated(&las, Format::Las, None);
    // LAZ: point count beyond what the compressed bytes can hold.
    let mut laz = bytes("bunny.laz");
    laz[107..111].copy_from_slice(&u32::MAX.to_le_bytes());
    assert_truncated(&laz, Format::Laz, Some(Location::Byte(107)));
    // E57: the XML section claims to be longer than the file.
    let mut e57 = bytes("bun000-grid.e57");
    e57[32..40].copy_from_slice(&(1u64 << 40).to_le_bytes());
    assert_truncated(&e57, Format::E57, None);
    // E57 with a flipped data byte fails its page checksum.
    let mut e57 = bytes("bun000-grid.e57");
    e57[2000] ^= 0x55;
    assert!(read_bytes(&e57, None).is_err());
    // PTX: more cells than the bytes can hold.
    let ptx = String::from_utf8(bytes("bun000-grid.ptx")).expect("text");
    let huge = ptx.replacen("52\n40\n", "52000000\n40000000\n", 1);
    assert_truncated(huge.as_bytes(), Format::Ptx, Some(Location::Line(1)));
    // PCD: more points than the binary body holds.
    let pcd = bytes("bunny-binary.pcd");
    let text = String::from_utf8_lossy(&pcd);
    let at = text.find("POINTS 799").expect("POINTS line");
    let mut bad = pcd.clone();
    bad.splice(at..at + 10, b"POINTS 999".iter().copied());
    let e = assert_truncated(&bad, Format::Pcd, None);
    assert!(e.to_string().contains("declares 999 points"), "{e}");
    // GLB: the header length beyond the file.
    let mut glb = bytes("suzanne-scene.glb");
    glb[8..12].copy_from_slice(&u32::MAX.to_le_bytes());
    assert_truncated(&glb, Format::Glb, Some(Location::Byte(8)));
}

#[test]
fn truncated_files_fail_and_never_panic() {
    for name in [
        "bun000-grid.e57",
        "two-scans.e57",
        "bunny.las",
        "bunny.laz",
        "bunny-14.las",
        "bunny-ascii.pcd",
        "bunny-binary.pcd",
        "bunny-compressed.pcd",
        "bun000-grid.ptx",
        "two-scans.ptx",
        "suzanne-scene.glb",
        "suzanne-embedded.gltf",
    ] {
        if (name.ends_with(".e57") && !cfg!(feature = "e57"))
            || (name.ends_with(".laz") && !cfg!(feature = "laz"))
        {
            continue;
        }
        let b = bytes(name);
        let full = read_bytes(&b, Some(name))
            .expect("whole file")
            .mesh
            .num_vertices();
        for k in 1..40 {
            let cut = b.len() * k / 40;
            if let Ok(f) = read_bytes(&b[..cut], Some(name)) {
                // Text formats may end at a line boundary; then they hold fewer points,
                // never more.
                assert!(f.mesh.num_vertices() <= full, "{name} cut at {cut}");
                assert!(
                    matches!(f.format, Format::Xyz | Format::Pcd | Format::Ptx),
                    "{name} cut at {cut} read as {:?}",
                    f.format
                );
            }
        }
    }
}

#[test]
#[cfg(not(all(feature = "e57", feature = "laz")))]
fn formats_left_out_of_the_build_say_so() {
    let built = [
        ("bun000-grid.e57", "e57", cfg!(feature = "e57")),
        ("bunny.laz", "laz", cfg!(feature = "laz")),
    ];
    for (name, feature, _) in built.into_iter().filter(|b| !b.2) {
        match read_bytes(&bytes(name), Some(name)) {
            Err(ReadError::Unsupported { message, .. }) => {
                assert!(message.contains(feature), "{message}")
            }
            other => panic!("{name}: {other:?}"),
        }
    }
}
