//! Public reader behaviour: format detection and one test per kind of bad input, each checking
//! that the error says what and where.

mod common;

use common::test_file;
use geofit::fit::FitData;
use geofit::io::{read_bytes, read_path, Format, Location, ReadError};

fn err(bytes: &[u8], name: Option<&str>) -> ReadError {
    match read_bytes(bytes, name) {
        Ok(f) => panic!(
            "accepted as {:?} with {} points",
            f.format,
            f.mesh.num_vertices()
        ),
        Err(e) => e,
    }
}

#[test]
fn detects_formats_from_content_and_name() {
    let cases: [(&[u8], Option<&str>, Format); 6] = [
        (b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n1 2\n", None, Format::Ply),
        (b"v 1 2 3\n", None, Format::Obj),
        (b"v 1 2 3\n", Some("points.xyz"), Format::Obj),
        (b"solid\nfacet normal 0 0 0\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n", None, Format::Stl),
        (b"X Y Z\n1 2 3\n", None, Format::Xyz),
        (b"1;2\n3;4\n", Some("plane.csv"), Format::Xyz),
    ];
    for (bytes, name, format) in cases {
        let f = read_bytes(bytes, name).unwrap_or_else(|e| panic!("{name:?}: {e}"));
        assert_eq!(f.format, format, "{}", String::from_utf8_lossy(bytes));
    }
}

#[test]
fn empty_and_unknown_input() {
    assert_eq!(err(b"", Some("a.ply")), ReadError::Empty);
    assert_eq!(
        err(b"\x00\x9f\x92\x96 binary junk", None),
        ReadError::UnknownFormat
    );
    assert_eq!(
        err(b"hello world\n", Some("notes.md")),
        ReadError::UnknownFormat
    );
    // A known extension with unrecognisable content gets that format's own message.
    let e = err(b"hello world\n", Some("scan.ply"));
    assert_eq!(
        e.to_string(),
        "PLY line 1: the file does not start with 'ply'"
    );
    assert!(matches!(
        err(b"# nothing\n", Some("a.obj")),
        ReadError::NoPoints {
            format: Format::Obj
        }
    ));
}

#[test]
fn truncated_binary_ply_reports_the_byte_offset() {
    let header = b"ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\n\
        property float y\nproperty float z\nend_header\n";
    let mut bytes = header.to_vec();
    bytes.extend([0u8; 20]); // 2 vertices need 24 bytes
    let e = err(&bytes, None);
    // The header check refuses it before reading a value.
    assert!(
        matches!(e, ReadError::Truncated { at: Location::Byte(b), .. } if b == header.len()),
        "{e}"
    );
    // A list whose items run past the end fails at the offset of the missing value.
    let header = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty uchar x\n\
        property uchar y\nelement face 1\nproperty list uchar uint vertex_indices\nend_header\n";
    let mut bytes = header.to_vec();
    bytes.extend([0, 0, 1, 0, 0, 1, 3, 0, 0, 0, 0, 1, 0, 0, 0]);
    let e = err(&bytes, None);
    let at = header.len() + 6 + 1 + 8;
    assert_eq!(
        e.to_string(),
        format!("PLY byte {at}: file ends early: while reading property 'vertex_indices' of face 0 (of 1)")
    );
}

#[test]
fn wrong_counts_and_bad_indices() {
    let e = err(b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nend_header\n1 2\n3 4\n", None);
    assert!(matches!(e, ReadError::Truncated { .. }), "{e}");
    let e = err(b"v 0 0 0\nv 1 0 0\nf 1 2 3\n", None);
    assert_eq!(
        e,
        ReadError::IndexOutOfRange {
            format: Format::Obj,
            at: Location::Line(3),
            index: 3,
            count: 2
        }
    );
    let e = err(b"v 0 0 0\nl 1 2\n", None);
    assert!(
        e.to_string().starts_with("OBJ line 2: vertex index 2"),
        "{e}"
    );
    let e = err(
        b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n\
        element tristrips 1\nproperty list int int vertex_indices\nend_header\n0 0\n3 0 0 -2\n",
        None,
    );
    assert!(e.to_string().contains("vertex index -2"), "{e}");
}

#[test]
fn non_finite_and_text_in_numbers() {
    for (bytes, at) in [
        (&b"v 1 2 3\nv 1 nan 3\n"[..], "line 2"),
        (b"1 2 3\n-inf 2 3\n", "line 2"),
        (b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n1 1e999\n", "line 7"),
    ] {
        let e = err(bytes, None);
        assert!(matches!(e, ReadError::NonFinite { .. }), "{e}");
        assert!(e.to_string().contains(at), "{e}");
    }
    let mut stl = vec![b' '; 80];
    stl.extend(1u32.to_le_bytes());
    stl.extend([0u8; 12]);
    stl.extend(f32::NAN.to_le_bytes());
    stl.extend([0u8; 34]);
    assert_eq!(
        err(&stl, None).to_string(),
        "STL byte 96: coordinate is not a finite number"
    );
    let e = err(b"x y z\n1 2 3\n4 5 six\n", None);
    assert_eq!(e.to_string(), "XYZ line 3: expected a number, found 'six'");
}

#[test]
fn absurd_header_counts_fail_fast() {
    let start = std::time::Instant::now();
    for count in ["4000000000", "999999999999999"] {
        for format in ["ascii", "binary_little_endian", "binary_big_endian"] {
            let src = format!(
                "ply\nformat {format} 1.0\nelement vertex {count}\nproperty float x\nproperty float y\nend_header\n1 2\n"
            );
            let e = err(src.as_bytes(), None);
            assert!(matches!(e, ReadError::Truncated { .. }), "{e}");
        }
    }
    let mut stl = vec![b' '; 80];
    stl.extend(u32::MAX.to_le_bytes());
    assert!(matches!(
        err(&stl, Some("a.stl")),
        ReadError::Truncated { .. }
    ));
    assert!(
        start.elapsed().as_millis() < 500,
        "took {:?}",
        start.elapsed()
    );
}

#[test]
fn malformed_sample_files() {
    for (name, expected) in [
        ("huge-count.ply", "declares 4000000000 'vertex' elements"),
        (
            "bad-index.ply",
            "PLY line 13: vertex index 7 is out of range (the file has 3 vertices)",
        ),
        (
            "text-in-number.obj",
            "OBJ line 3: expected a number, found 'zero'",
        ),
        ("truncated.stl", "STL byte 184: file ends early"),
    ] {
        let e = read_path(&test_file(name)).expect_err(name);
        assert!(e.to_string().contains(expected), "{name}: {e}");
    }
    let e = read_path(&test_file("missing.obj")).expect_err("missing");
    assert!(matches!(e, ReadError::Io(_)));
}

#[test]
fn curve_points_follow_the_longest_polyline_and_see_it_closed() {
    let obj = b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 9 9 9\nl 1 2\nl 1 2 3 4 1\n";
    let (points, closed) =
        FitData::from(&read_bytes(obj, Some("c.obj")).expect("obj")).curve_points();
    assert!(closed);
    assert_eq!(points.len(), 4, "the repeated first vertex is given once");
    assert_eq!(points[2].to_array(), [1.0, 1.0, 0.0]);
    let open = b"v 0 0 0\nv 1 0 0\nv 2 1 0\nl 3 2 1\n";
    let (points, closed) =
        FitData::from(&read_bytes(open, Some("o.obj")).expect("obj")).curve_points();
    assert!(!closed);
    assert_eq!(
        points[0].to_array(),
        [2.0, 1.0, 0.0],
        "polyline order, not file order"
    );
    let file = read_bytes(b"0 0 0\n1 0 0\n2 0 0\n", Some("p.xyz")).expect("xyz");
    let (points, closed) = FitData::from(&file).curve_points();
    assert_eq!(
        (points.len(), closed),
        (3, false),
        "bare points: all, in file order"
    );
}
