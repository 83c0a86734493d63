//! The GLB writer: what it stores (read back by geofit's own glTF reader and by inspecting the
//! JSON), its errors, and sample files for the Khronos glTF-Validator.
//!
//! Every test here also writes its GLB into `$GEOFIT_GLB_DIR` (default `target/glb-samples/`
//! of the repository); `node scripts/validate-glb.mjs [DIR]` then validates them all and fails
//! on any error.

use geofit::geom::{Point3, Vec3};
use geofit::io::{diverging_colour, read_bytes, to_glb_bytes, Format, GlbOptions, WriteError};
use geofit::mesh::PolyMesh;
use serde_json::{json, Value};
use std::path::PathBuf;

fn sample_dir() -> PathBuf {
    std::env::var_os("GEOFIT_GLB_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target/glb-samples"))
}

fn save(name: &str, bytes: &[u8]) {
    let dir = sample_dir();
    std::fs::create_dir_all(&dir).expect("sample dir");
    std::fs::write(dir.join(name), bytes).expect("write sample");
}

/// The JSON chunk of a GLB.
fn json_of(glb: &[u8]) -> Value {
    let len = u32::from_le_bytes([glb[12], glb[13], glb[14], glb[15]]) as usize;
    assert_eq!(&glb[16..20], b"JSON");
    serde_json::from_slice(&glb[20..20 + len]).expect("JSON chunk")
}

/// The f32 values of accessor `a` (tightly packed floats).
/// The values of vertex attribute `name` of the first primitive.
fn attribute(glb: &[u8], doc: &Value, name: &str) -> Vec<f32> {
    let attributes = &doc["meshes"][0]["primitives"][0]["attributes"];
    floats(glb, doc, attributes[name].as_u64().expect(name) as usize)
}

fn floats(glb: &[u8], doc: &Value, a: usize) -> Vec<f32> {
    let json_len = u32::from_le_bytes([glb[12], glb[13], glb[14], glb[15]]) as usize;
    let bin = &glb[20 + json_len + 8..];
    let acc = &doc["accessors"][a];
    let view = &doc["bufferViews"][acc["bufferView"].as_u64().expect("view") as usize];
    let off = view["byteOffset"].as_u64().unwrap_or(0) as usize;
    let len = view["byteLength"].as_u64().expect("length") as usize;
    bin[off..off + len]
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect()
}

/// A bumpy open grid of quads (n × n cells), so that normals and deviations vary.
fn bumpy_grid(n: u32) -> PolyMesh {
    let mut p = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (f64::from(i) / f64::from(n), f64::from(j) / f64::from(n));
            p.push(Point3::new(
                x * 40.0,
                y * 30.0,
                3.0 * (6.0 * x).sin() * (4.0 * y).cos(),
            ));
        }
    }
    let faces = (0..n).flat_map(|j| {
        (0..n).map(move |i| {
            let a = j * (n + 1) + i;
            vec![a, a + 1, a + n + 2, a + n + 1]
        })
    });
    PolyMesh::try_new(p, faces).expect("grid")
}

#[test]
fn positions_triangles_normals_and_bounds() {
    let mesh = bumpy_grid(12);
    let glb = to_glb_bytes(&mesh, &GlbOptions::default()).expect("glb");
    save("plain.glb", &glb);
    let back = read_bytes(&glb, None).expect("reads back");
    assert_eq!(back.format, Format::Glb);
    assert_eq!(back.mesh.num_vertices(), mesh.num_vertices());
    assert_eq!(back.mesh.num_triangles(), mesh.num_triangles());
    for (a, b) in mesh.positions().iter().zip(back.mesh.positions()) {
        let f32_round = Point3::new(a.x as f32 as f64, a.y as f32 as f64, a.z as f32 as f64);
        assert_eq!(f32_round, *b);
    }
    let doc = json_of(&glb);
    let prim = &doc["meshes"][0]["primitives"][0];
    let pos = prim["attributes"]["POSITION"].as_u64().expect("POSITION") as usize;
    let values = floats(&glb, &doc, pos);
    for k in 0..3 {
        let column = values.iter().skip(k).step_by(3);
        let min = column.clone().fold(f32::INFINITY, |m, &v| m.min(v));
        let max = column.fold(f32::NEG_INFINITY, |m, &v| m.max(v));
        assert_eq!(
            doc["accessors"][pos]["min"][k].as_f64(),
            Some(f64::from(min))
        );
        assert_eq!(
            doc["accessors"][pos]["max"][k].as_f64(),
            Some(f64::from(max))
        );
    }
    let normals = attribute(&glb, &doc, "NORMAL");
    for n in normals.chunks_exact(3) {
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        assert!((len - 1.0).abs() < 1e-6, "{len}");
        assert!(n[2] > 0.0, "counter-clockwise quads face +z: {n:?}");
    }
    assert!(prim.get("COLOR_0").is_none() && prim["attributes"].get("_DEVIATION").is_none());
    assert_eq!(prim["mode"], 4);
}

#[test]
fn deviation_colours_extras_and_units() {
    let mesh = bumpy_grid(16);
    let tol = 0.5;
    let deviation: Vec<f64> = mesh
        .positions()
        .iter()
        .map(|p| (p.x - 20.0) / 20.0 * 2.0 * tol * (p.y / 10.0).sin())
        .collect();
    let extras = json!({ "scheme": "loop", "e_max_percent": 0.049, "iterations": 30 });
    let options = GlbOptions::default()
        .with_deviation(&deviation)
        .with_tolerance(tol)
        .with_extras(&extras)
        .with_unit_to_metres(0.001);
    let glb = to_glb_bytes(&mesh, &options).expect("glb");
    save("deviation-mm.glb", &glb);
    let doc = json_of(&glb);
    assert_eq!(doc["scenes"][0]["extras"], extras);
    assert_eq!(doc["nodes"][0]["scale"], json!([0.001, 0.001, 0.001]));
    let dev = attribute(&glb, &doc, "_DEVIATION");
    assert_eq!(dev.len(), deviation.len());
    for (a, b) in dev.iter().zip(&deviation) {
        assert_eq!(*a, *b as f32);
    }
    let colours = attribute(&glb, &doc, "COLOR_0");
    for (c, &d) in colours.chunks_exact(3).zip(&deviation) {
        assert!(c.iter().all(|v| (0.0..=1.0).contains(v)));
        let srgb = diverging_colour(d, tol);
        // Linear values: darker than sRGB for mid-tones, equal at 0 and 1.
        for k in 0..3 {
            assert!(c[k] <= srgb[k] + 1e-6);
        }
        if d > tol {
            assert!(c[0] > c[2], "outside +tol is red: {c:?}");
        }
        if d < -tol {
            assert!(c[2] > c[0], "outside -tol is blue: {c:?}");
        }
    }
    // The node scale puts the coordinates in metres for a reader that applies the scene graph.
    let back = read_bytes(&glb, None).expect("reads back");
    let bbox = back.mesh.bbox().expect("points");
    assert!((bbox.max.x - 0.04).abs() < 1e-6, "{}", bbox.max.x);
}

#[test]
fn custom_colour_map_given_normals_and_points_only() {
    let mesh = bumpy_grid(4);
    let deviation = vec![0.25; mesh.num_vertices()];
    let normals = vec![Vec3::new(0.0, 0.0, 2.0); mesh.num_vertices()];
    let map = |d: f64| [d as f32, 0.5, 1.0];
    let options = GlbOptions::default()
        .with_deviation(&deviation)
        .with_normals(&normals)
        .with_colour_map(&map);
    let glb = to_glb_bytes(&mesh, &options).expect("glb");
    save("custom-map.glb", &glb);
    let doc = json_of(&glb);
    let colours = attribute(&glb, &doc, "COLOR_0");
    assert!(
        (colours[1] - 0.214).abs() < 1e-3 && colours[2] == 1.0,
        "{colours:?}"
    );
    let n = attribute(&glb, &doc, "NORMAL");
    assert_eq!(&n[..3], &[0.0, 0.0, 1.0]);

    let points =
        PolyMesh::from_points(vec![Point3::ZERO, Point3::new(1.0, 2.0, 3.0)]).expect("points");
    let glb = to_glb_bytes(&points, &GlbOptions::default()).expect("glb");
    save("points.glb", &glb);
    let doc = json_of(&glb);
    assert_eq!(doc["meshes"][0]["primitives"][0]["mode"], 0);
    assert_eq!(
        read_bytes(&glb, None).expect("reads").mesh.num_vertices(),
        2
    );
}

#[test]
fn bad_options_are_typed_errors() {
    let mesh = bumpy_grid(2);
    let short = [0.0; 3];
    let e = to_glb_bytes(&mesh, &GlbOptions::default().with_deviation(&short)).unwrap_err();
    assert!(matches!(e, WriteError::Invalid { .. }), "{e}");
    assert_eq!(
        e.to_string(),
        "cannot write GLB: 3 deviations for 9 vertices"
    );
    let e = to_glb_bytes(&mesh, &GlbOptions::default().with_unit_to_metres(-1.0)).unwrap_err();
    assert!(matches!(e, WriteError::Invalid { .. }), "{e}");
    // A position beyond f32's range never reaches the writer: the mesh refuses it.
    let far = PolyMesh::from_points(vec![Point3::new(1e300, 0.0, 0.0)]).unwrap_err();
    assert!(
        matches!(
            far,
            geofit::mesh::MeshError::CoordinateOutOfRange { vertex: 0, .. }
        ),
        "{far}"
    );
}

#[test]
fn degenerate_triangles_and_lone_vertices_still_give_unit_normals() {
    // Triangle 1 is degenerate (a repeated corner), vertex 4 is in no triangle: both would
    // give a zero normal, which glTF forbids; the writer puts +z there.
    let mesh = PolyMesh::try_new(
        vec![
            Point3::ZERO,
            Point3::X,
            Point3::Y,
            Point3::new(2.0, 2.0, 0.0),
            Point3::new(5.0, 5.0, 5.0),
        ],
        [vec![0, 1, 2], vec![1, 3, 3]],
    )
    .expect("mesh");
    let dev = [0.0, 1.0, -1.0, 0.0, 3.0];
    let glb = to_glb_bytes(&mesh, &GlbOptions::default().with_deviation(&dev)).expect("glb");
    save("degenerate.glb", &glb);
    let doc = json_of(&glb);
    let n = attribute(&glb, &doc, "NORMAL");
    assert_eq!(&n[12..15], &[0.0, 0.0, 1.0]);
    for v in n.chunks_exact(3) {
        assert!(((v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt() - 1.0).abs() < 1e-6);
    }
}

#[test]
fn a_fitted_surface_exports_with_its_deviation_and_figures() {
    use geofit::fit::{FitData, FitSpec, Scheme};
    let data = bumpy_grid(16);
    let mut spec = FitSpec::new(Scheme::Loop);
    spec.initial = Some(40);
    spec.max_iter = Some(3);
    let mut fitter = spec.build(&FitData::points(&data)).expect("fitter");
    fitter.run().expect("run");
    let glb = geofit::export::glb_of(fitter.as_ref(), Some(0.001)).expect("glb");
    save("fit-loop.glb", &glb);
    let doc = json_of(&glb);
    let attributes = &doc["meshes"][0]["primitives"][0]["attributes"];
    for name in ["POSITION", "NORMAL", "COLOR_0", "_DEVIATION"] {
        assert!(attributes[name].is_u64(), "{name} in {attributes}");
    }
    let extras = &doc["scenes"][0]["extras"];
    assert_eq!(extras["scheme"], "loop");
    assert!(extras["e_max_pct"].as_f64().is_some_and(f64::is_finite));
    assert!(extras.get("history").is_none());
    assert_eq!(doc["nodes"][0]["scale"][0].as_f64(), Some(0.001));
    // Deviations are the data's signed errors, at most E_max in size.
    let dev = floats(
        &glb,
        &doc,
        attributes["_DEVIATION"].as_u64().unwrap() as usize,
    );
    let e_max = fitter.stats().e_max;
    assert!(dev.iter().any(|&d| d != 0.0));
    assert!(dev
        .iter()
        .all(|&d| f64::from(d.abs()) <= e_max * (1.0 + 1e-6) + 1e-9));
    // A curve has no surface to export.
    let line = PolyMesh::from_points(
        (0..20)
            .map(|i| Point3::new(f64::from(i), 0.0, 0.0))
            .collect(),
    )
    .expect("points");
    let curve = FitSpec::new(Scheme::BsplineCurve)
        .build(&FitData::points(&line))
        .expect("curve");
    let err = geofit::export::glb_of(curve.as_ref(), None).expect_err("no surface");
    assert!(err.to_string().contains("no surface"), "{err}");
}
