//! Which format a file is, from its content first and its name second.

use super::{gltf, las, pcd, ptx, stl, xyz, Format};

/// How much of the file start the text classifier looks at.
const SNIFF_BYTES: usize = 64 * 1024;

/// The format of `bytes`. Unambiguous content wins: the magic numbers (PLY `ply`, E57
/// `ASTM-E57`, LAS `LASF` with the compression bit telling LAZ, GLB `glTF`), a binary STL whose
/// size matches its triangle count, then text: glTF JSON (an object with `"asset"`), a PCD
/// header (`# .PCD` or `VERSION` then `FIELDS`), a PTX scan header (two counts, then four lines
/// of three numbers and four of four), `solid`, OBJ statements, rows of numbers. The name's
/// extension decides only when the content does not, so that a damaged `.ply` still gets a PLY
/// error message; last, a binary STL with padding after its triangles is recognised.
pub fn detect(bytes: &[u8], name: Option<&str>) -> Option<Format> {
    if bytes.starts_with(b"ply") && matches!(bytes.get(3), Some(b'\n' | b'\r')) {
        return Some(Format::Ply);
    }
    if bytes.starts_with(b"ASTM-E57") {
        return Some(Format::E57);
    }
    if las::looks_like(bytes) {
        return Some(if las::is_compressed(bytes) {
            Format::Laz
        } else {
            Format::Las
        });
    }
    if gltf::is_glb(bytes) {
        return Some(Format::Glb);
    }
    if stl::is_binary(bytes) {
        return Some(Format::Stl);
    }
    let head = &bytes[..bytes.len().min(SNIFF_BYTES)];
    classify_scanner_text(head)
        .or_else(|| classify_text(head))
        .or_else(|| name.and_then(from_name))
        .or_else(|| stl::looks_binary(bytes).then_some(Format::Stl))
}

/// The format a file name's extension suggests.
fn from_name(name: &str) -> Option<Format> {
    let ext = name.rsplit('.').next()?.to_ascii_lowercase();
    match ext.as_str() {
        "ply" => Some(Format::Ply),
        "obj" => Some(Format::Obj),
        "stl" => Some(Format::Stl),
        "xyz" | "csv" | "pts" | "txt" | "asc" => Some(Format::Xyz),
        "e57" => Some(Format::E57),
        "las" => Some(Format::Las),
        "laz" => Some(Format::Laz),
        "pcd" => Some(Format::Pcd),
        "ptx" => Some(Format::Ptx),
        "gltf" => Some(Format::Gltf),
        "glb" => Some(Format::Glb),
        _ => None,
    }
}

/// The text formats with a recognisable header: glTF JSON, PCD and PTX. Checked before the
/// generic classifier, which would take a PTX header (rows of numbers) for point text.
fn classify_scanner_text(head: &[u8]) -> Option<Format> {
    if gltf::looks_like_json(head) {
        Some(Format::Gltf)
    } else if pcd::looks_like(head) {
        Some(Format::Pcd)
    } else if ptx::looks_like(head) {
        Some(Format::Ptx)
    } else {
        None
    }
}

/// Looks at text lines until one is decisive: `solid` opens ASCII STL, an OBJ statement means
/// OBJ, a row of at least two numbers means point text. Comments and header lines are passed.
fn classify_text(head: &[u8]) -> Option<Format> {
    for (_, line) in super::text::lines(head) {
        let first = super::text::tokens(line).next();
        match first {
            Some(b"solid") => return Some(Format::Stl),
            Some(b"v" | b"vn" | b"vt" | b"f" | b"l" | b"o" | b"g" | b"mtllib" | b"usemtl") => {
                return Some(Format::Obj)
            }
            Some(_) if xyz::numeric_fields(line) >= 2 => return Some(Format::Xyz),
            _ => {}
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn content_first_then_name() {
        assert_eq!(detect(b"ply\nformat ascii 1.0\n", None), Some(Format::Ply));
        assert_eq!(detect(b"# c\nv 1 2 3\n", Some("a.xyz")), Some(Format::Obj));
        assert_eq!(detect(b"solid x\n", None), Some(Format::Stl));
        assert_eq!(detect(b"x,y,z\n1,2,3\n", None), Some(Format::Xyz));
        assert_eq!(detect(b"40256\n1 2 3 4\n", None), Some(Format::Xyz));
        assert_eq!(
            detect(b"# only a comment\n", Some("A.OBJ")),
            Some(Format::Obj)
        );
        assert_eq!(detect(b"\x00\x01garbage", None), None);
        assert_eq!(detect(b"ASTM-E57\0\0", None), Some(Format::E57));
        assert_eq!(detect(b"LASF", Some("a.xyz")), Some(Format::Las));
        assert_eq!(detect(b"glTF\x02\0\0\0", None), Some(Format::Glb));
        assert_eq!(
            detect(b" {\"asset\":{\"version\":\"2.0\"}}", None),
            Some(Format::Gltf)
        );
        assert_eq!(
            detect(b"# .PCD v0.7\nVERSION 0.7\n", None),
            Some(Format::Pcd)
        );
        assert_eq!(
            detect(b"VERSION 0.7\nFIELDS x y z\n", None),
            Some(Format::Pcd)
        );
        let ptx =
            b"3\n2\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n1 2 3 0.5\n";
        assert_eq!(detect(ptx, None), Some(Format::Ptx));
        assert_eq!(detect(b"2\n1 2 3 4 5 6 7\n", None), Some(Format::Xyz));
        assert_eq!(detect(b"junk", Some("scan.E57")), Some(Format::E57));
        assert_eq!(detect(b"junk", Some("a.laz")), Some(Format::Laz));
        let mut stl = vec![0u8; 84 + 50];
        stl[..5].copy_from_slice(b"solid");
        stl[80] = 1;
        assert_eq!(detect(&stl, None), Some(Format::Stl));
    }
}
