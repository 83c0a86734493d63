//! Which format a file is, from its content first and its name second.

use super::{stl, xyz, Format};

/// How much of the file start the text classifier looks at.
const SNIFF_BYTES: usize = 64 * 1024;

/// The format of `bytes`. Unambiguous content wins (PLY magic, a binary STL whose size matches
/// its triangle count, `solid`, OBJ statements, rows of numbers); the name's extension decides
/// only when the content does not, so that a damaged `.ply` still gets a PLY error message;
/// last, a binary STL with padding after its triangles is recognised.
pub fn detect(bytes: &[u8], name: Option<&str>) -> Option<Format> {
    if bytes.starts_with(b"ply") && matches!(bytes.get(3), Some(b'\n' | b'\r')) {
        return Some(Format::Ply);
    }
    if stl::is_binary(bytes) {
        return Some(Format::Stl);
    }
    let head = &bytes[..bytes.len().min(SNIFF_BYTES)];
    classify_text(head)
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
        _ => None,
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
        let mut stl = vec![0u8; 84 + 50];
        stl[..5].copy_from_slice(b"solid");
        stl[80] = 1;
        assert_eq!(detect(&stl, None), Some(Format::Stl));
    }
}
