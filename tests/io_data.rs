//! The readers on every scan in the shared data directory, with counts checked independently
//! of geofit (by `grep -c '^v '` and `grep -c '^f '` on the OBJ files, and the PLY header).

mod common;

use common::data_file;
use geofit::io::{read_path, Format, LoadedFile};

fn load(name: &str) -> LoadedFile {
    let path = data_file(name);
    read_path(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn assert_obj(name: &str, vertices: usize, faces: usize) {
    let f = load(name);
    assert_eq!(f.format, Format::Obj);
    assert_eq!(f.mesh.num_vertices(), vertices, "{name} vertices");
    assert_eq!(f.mesh.num_faces(), faces, "{name} faces");
    // Every face in these files is a triangle.
    assert_eq!(f.mesh.num_triangles(), faces, "{name} triangles");
    assert!(f.polylines.is_empty());
    assert_eq!(f.dimension, 3);
}

/// One test per OBJ scan: `test: file, vertices, faces;`.
macro_rules! obj_tests {
    ($($test:ident: $file:literal, $vertices:expr, $faces:expr;)*) => {$(
        #[test]
        fn $test() {
            assert_obj($file, $vertices, $faces);
        }
    )*};
}

obj_tests! {
    stanford_bunny: "stanford-bunny.obj", 35_947, 69_451;
    fandisk: "fandisk.obj", 6_475, 12_946;
    rocker_arm: "rocker-arm.obj", 10_044, 20_088;
    spot: "spot.obj", 2_930, 5_856;
    teapot: "teapot.obj", 3_644, 6_320;
}

#[test]
fn bun000_range_scan() {
    let f = load("bun000.ply");
    assert_eq!(f.format, Format::Ply);
    assert_eq!(f.mesh.num_vertices(), 40_256);
    assert_eq!(
        f.mesh.num_faces(),
        0,
        "the range grid stays out of the mesh"
    );
    let grid = f.range_grid.expect("bun000 has a range grid");
    assert_eq!((grid.cols(), grid.rows()), (512, 400));
    let measured = (0..grid.rows())
        .flat_map(|r| (0..grid.cols()).map(move |c| (c, r)))
        .filter(|&(c, r)| grid.cell(c, r).is_some())
        .count();
    assert_eq!(
        measured, 40_256,
        "every point sits in exactly one grid cell"
    );
    let tris = grid.triangles();
    assert!(tris.len() > 70_000, "{} grid triangles", tris.len());
    // The grid triangulation faces the scanner: the area-weighted normal points along +z.
    let p = f.mesh.positions();
    let n: geofit::geom::Vec3 = tris
        .iter()
        .map(|t| (p[t[1] as usize] - p[t[0] as usize]).cross(p[t[2] as usize] - p[t[0] as usize]))
        .sum();
    assert!(n.normalize().z > 0.5, "mean normal {n}");
    // The sample spacing is the scanner's 0.5 mm pitch (obj_info echo_lgincr 0.000500) or a
    // little more where the surface slopes; a few spacings drop only the silhouette bridges.
    let spacing = grid.spacing(p).expect("neighbouring samples");
    assert!((0.0005..0.0008).contains(&spacing), "spacing {spacing}");
    let kept = grid.triangles_within(p, 4.0 * spacing).len();
    assert!(
        kept < tris.len() && kept * 100 > tris.len() * 97,
        "{kept} of {}",
        tris.len()
    );
}
