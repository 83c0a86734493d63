//! Writers, checked by reading their output back.

mod common;

use geofit::geom::Point3;
use geofit::io::{read_bytes, to_obj_bytes, to_ply_bytes, to_stl_bytes, write_stl, Format};
use geofit::mesh::PolyMesh;
use proptest::prelude::*;

fn mixed_mesh() -> PolyMesh {
    let p = vec![
        Point3::new(0.1, -2.5e-7, 3.0),
        Point3::new(1.0 / 3.0, 0.0, -0.0),
        Point3::new(1e30, 1.0, 2.0),
        Point3::new(-4.0, 5.5, 6.25),
        Point3::new(7.0, 8.0, 9.0),
        Point3::new(-1.0, -1.0, -1.0),
    ];
    PolyMesh::try_new(p, [vec![0, 1, 2], vec![1, 3, 4, 2], vec![0, 2, 4, 3, 5]]).unwrap()
}

#[test]
fn obj_and_ply_round_trip_exactly() {
    let mesh = mixed_mesh();
    let obj = read_bytes(&to_obj_bytes(&mesh).unwrap(), None).unwrap();
    assert_eq!(obj.format, Format::Obj);
    assert_eq!(obj.mesh, mesh);
    let ply = read_bytes(&to_ply_bytes(&mesh).unwrap(), None).unwrap();
    assert_eq!(ply.format, Format::Ply);
    assert_eq!(ply.mesh, mesh);
}

#[test]
fn ply_writes_wide_polygons_and_point_clouds() {
    let n = 300;
    let ring: Vec<Point3> = (0..n)
        .map(|i| {
            let a = i as f64 / n as f64 * std::f64::consts::TAU;
            Point3::new(a.cos(), a.sin(), 0.0)
        })
        .collect();
    let polygon = PolyMesh::try_new(ring.clone(), [(0..n as u32).collect::<Vec<_>>()]).unwrap();
    assert_eq!(
        read_bytes(&to_ply_bytes(&polygon).unwrap(), None)
            .unwrap()
            .mesh,
        polygon
    );
    let cloud = PolyMesh::from_points(ring).unwrap();
    assert_eq!(
        read_bytes(&to_ply_bytes(&cloud).unwrap(), None)
            .unwrap()
            .mesh,
        cloud
    );
}

#[test]
fn stl_round_trips_within_f32_and_shares_vertices() {
    let mesh = PolyMesh::try_new(
        vec![
            Point3::new(0.1, 0.2, 0.3),
            Point3::X,
            Point3::Y,
            Point3::new(1.0, 1.0, 0.5),
        ],
        [vec![0, 1, 3, 2]],
    )
    .unwrap();
    let bytes = to_stl_bytes(&mesh).unwrap();
    assert_eq!(bytes.len(), 84 + 2 * 50);
    let back = read_bytes(&bytes, None).unwrap();
    assert_eq!(back.format, Format::Stl);
    assert_eq!(
        back.mesh.num_vertices(),
        4,
        "welded back to shared vertices"
    );
    // Same triangles corner by corner, up to f32 rounding (vertex numbers may differ).
    let corners = |m: &PolyMesh| -> Vec<Point3> {
        m.triangles()
            .iter()
            .flatten()
            .map(|&i| m.positions()[i as usize])
            .collect()
    };
    for (a, b) in corners(&back.mesh).iter().zip(corners(&mesh)) {
        assert!((*a - b).abs().max_element() < 1e-7, "{a} vs {b}");
    }
    // The first triangle's stored normal is the unit normal of (0.1,0.2,0.3), X, (1,1,0.5).
    let n: Vec<f32> = bytes[84..96]
        .chunks(4)
        .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
        .collect();
    let expected = (Point3::X - mesh.positions()[0])
        .cross(Point3::new(1.0, 1.0, 0.5) - mesh.positions()[0])
        .normalize();
    assert!((n[0] as f64 - expected.x).abs() < 1e-6 && (n[2] as f64 - expected.z).abs() < 1e-6);
}

/// A coordinate beyond f32's range cannot be in a mesh (`PolyMesh` refuses it, see
/// `tests/fit_strays.rs`), so STL (f32) writes whatever a mesh holds; 1e30 stays 1e30.
#[test]
fn stl_writes_the_largest_coordinates_a_mesh_holds() {
    let mut bytes = Vec::new();
    write_stl(&mixed_mesh(), &mut bytes).expect("in f32's range");
    let back = read_bytes(&bytes, None).expect("reads").mesh;
    let largest = back.positions().iter().map(|p| p.x).fold(0.0, f64::max);
    assert!((largest / 1e30 - 1.0).abs() < 1e-7, "{largest}");
}

#[test]
fn real_scan_round_trips() {
    let teapot = geofit::io::read_path(&common::data_file("teapot.obj"))
        .unwrap()
        .mesh;
    for bytes in [
        to_obj_bytes(&teapot).unwrap(),
        to_ply_bytes(&teapot).unwrap(),
    ] {
        assert_eq!(read_bytes(&bytes, None).unwrap().mesh, teapot);
    }
    let stl = read_bytes(&to_stl_bytes(&teapot).unwrap(), None)
        .unwrap()
        .mesh;
    assert_eq!(stl.num_triangles(), teapot.num_triangles());
    // STL cannot hold unreferenced or duplicate-position vertices, so compare against the
    // distinct positions the faces use.
    let mut used: Vec<[u64; 3]> = teapot
        .triangles()
        .iter()
        .flatten()
        .map(|&i| {
            teapot.positions()[i as usize]
                .to_array()
                .map(|c| (c as f32 as f64 + 0.0).to_bits())
        })
        .collect();
    used.sort_unstable();
    used.dedup();
    assert_eq!(stl.num_vertices(), used.len());
}

fn coordinate() -> impl Strategy<Value = f64> {
    prop_oneof![
        -1e6..1e6f64,
        // Any value a mesh holds: finite and within f32's range (positions are drawn as f32).
        any::<f64>().prop_filter("in range", |x| x.abs() <= f32::MAX as f64)
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn random_meshes_round_trip_through_obj_and_ply(
        points in prop::collection::vec([coordinate(), coordinate(), coordinate()], 3..30),
        faces in prop::collection::vec(prop::collection::vec(any::<prop::sample::Index>(), 3..7), 0..20),
    ) {
        let n = points.len();
        let mesh = PolyMesh::try_new(
            points.into_iter().map(Point3::from_array).collect(),
            faces.iter().map(|f| f.iter().map(|i| i.index(n) as u32).collect::<Vec<_>>()),
        ).unwrap();
        prop_assert_eq!(&read_bytes(&to_obj_bytes(&mesh).unwrap(), None).unwrap().mesh, &mesh);
        prop_assert_eq!(&read_bytes(&to_ply_bytes(&mesh).unwrap(), None).unwrap().mesh, &mesh);
    }
}
