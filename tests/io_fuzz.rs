//! Generated bad input: random bytes, and valid files of every format with bytes flipped,
//! inserted or cut off and header numbers replaced. The readers must never panic, and whatever
//! they accept must be consistent: finite coordinates and every index in range.

mod common;

use common::fuzz::{apply, cases, edit, read_checked, read_sample};
use geofit::geom::Point3;
use geofit::io::to_ply_bytes;
use geofit::mesh::PolyMesh;
use proptest::prelude::*;

/// Small valid samples covering each reader's paths.
fn samples() -> Vec<(&'static str, Vec<u8>)> {
    let tri = PolyMesh::try_new(
        vec![Point3::ZERO, Point3::X, Point3::Y, Point3::ONE],
        [vec![0, 1, 2], vec![1, 3, 2]],
    )
    .expect("valid mesh");
    let mut big_endian = b"ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty float x\n\
        property float y\nproperty float z\nelement tristrips 1\n\
        property list int int vertex_indices\nend_header\n"
        .to_vec();
    for v in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
        big_endian.extend(v.to_be_bytes());
    }
    for i in [4i32, 0, 1, 2, -1] {
        big_endian.extend(i.to_be_bytes());
    }
    let mut stl = b"binary".to_vec();
    stl.resize(80, b' ');
    stl.extend(1u32.to_le_bytes());
    for v in [
        0.0f32, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0,
    ] {
        stl.extend(v.to_le_bytes());
    }
    stl.extend([0, 0]);
    vec![
        ("a.ply", to_ply_bytes(&tri).expect("in memory")),
        ("a.ply", big_endian),
        (
            "scan.ply",
            b"ply\nformat ascii 1.0\nobj_info num_cols 3\nobj_info num_rows 2\n\
              element vertex 4\nproperty float x\nproperty float y\nproperty float z\n\
              element range_grid 6\nproperty list uchar int vertex_indices\n\
              element junk 1\nproperty list ushort double stuff\nend_header\n\
              0 0 0\n1 0 0\n0 1 0\n1 1 0.5\n1 0\n1 1\n0\n1 2\n1 3\n0\n2 1.5 2.5\n"
                .to_vec(),
        ),
        (
            "a.obj",
            b"# c\nv 0 0 0\nv 1 0 0 1\nv 0 1 0\nv 1 1 0\nvt 0 0\nvn 0 0 1\n\
              f 1/1/1 2/1/1 3/1/1\nf -3//1 -1//1 -2//1\nl 1 2 4\ng x\n"
                .to_vec(),
        ),
        (
            "a.stl",
            b"solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n\
              vertex 0 1 0\nendloop\nendfacet\nendsolid s\n"
                .to_vec(),
        ),
        ("b.stl", stl),
        ("a.xyz", b"x,y,z,i\n1,2,3,4\n5,6,7,8\n".to_vec()),
        ("a.pts", b"2\n1 2 3 4 5 6 7\n8 9 10 11 12 13 14\n".to_vec()),
    ]
}

/// What the mutations insert: tokens the text readers and the PLY header parse.
const TEXT_WORDS: [&[u8]; 12] = [
    b"-1",
    b" ",
    b"\n",
    b"nan",
    b"inf",
    b"1e309",
    b"4294967295",
    b"-",
    b"/",
    b"list",
    b"end_header\n",
    b"\r\n",
];

#[test]
fn samples_are_valid() {
    for (name, bytes) in samples() {
        read_sample(name, &bytes);
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(2000), failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn random_bytes_never_panic(
        bytes in prop::collection::vec(any::<u8>(), 0..600),
        name in prop::sample::select(vec![None, Some("a.ply"), Some("a.obj"), Some("a.stl"), Some("a.csv")]),
    ) {
        read_checked(&bytes, name);
    }

    #[test]
    fn random_text_never_panics(
        text in "(ply\n|v |f |l |solid |vertex |facet |element |property |[0-9 .,;/eE+-]{1,12}|-1|\n){0,60}",
    ) {
        read_checked(text.as_bytes(), None);
    }

    #[test]
    fn mutated_samples_never_panic(
        which in any::<prop::sample::Index>(),
        edits in prop::collection::vec(edit(TEXT_WORDS.to_vec()), 1..5),
        cut in prop::option::of(any::<prop::sample::Index>()),
    ) {
        let all = samples();
        let (name, mut bytes) = all[which.index(all.len())].clone();
        for e in &edits {
            apply(&mut bytes, e, None);
        }
        if let Some(cut) = cut {
            bytes.truncate(cut.index(bytes.len() + 1));
        }
        read_checked(&bytes, Some(name));
        read_checked(&bytes, None);
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 12, failure_persistence: None, ..ProptestConfig::default() })]

    /// Truncations and flips of the real scans: the readers fail at the damage or read
    /// consistent data, and never panic.
    #[test]
    fn damaged_real_files_never_panic(
        which in prop::sample::select(vec!["bun000.ply", "teapot.obj"]),
        cut in any::<prop::sample::Index>(),
        flip in any::<prop::sample::Index>(),
        byte in any::<u8>(),
    ) {
        let mut bytes = std::fs::read(common::data_file(which)).expect("shared data present");
        let at = flip.index(bytes.len());
        bytes[at] = byte;
        bytes.truncate(cut.index(bytes.len() + 1));
        read_checked(&bytes, Some(which));
    }
}
