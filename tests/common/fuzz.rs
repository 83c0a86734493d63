//! What the reader fuzz tests share: the invariants of anything a reader accepts, and the
//! byte-level mutations (set, insert, remove, overwrite a little-endian word, replace a number).

use geofit::io::{read_bytes, LoadedFile};
use proptest::prelude::*;

/// What must hold for anything a reader accepts.
pub fn check_consistent(f: &LoadedFile) {
    let n = f.mesh.num_vertices();
    assert!(n > 0);
    assert!(f.mesh.positions().iter().all(|p| p.is_finite()));
    assert!(f
        .mesh
        .faces()
        .all(|face| face.iter().all(|&i| (i as usize) < n)));
    assert!(f.polylines.iter().flatten().all(|&i| (i as usize) < n));
    if let Some(g) = &f.range_grid {
        assert!(g.triangles().iter().flatten().all(|&i| (i as usize) < n));
    }
    assert!(f.dimension == 2 || f.dimension == 3);
}

/// Reads the valid sample `bytes` named `name`, checks it is consistent and returns it.
pub fn read_sample(name: &str, bytes: &[u8]) -> LoadedFile {
    let f = read_bytes(bytes, Some(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
    check_consistent(&f);
    f
}

/// Reads `bytes`: what is accepted is consistent, what is refused says why.
pub fn read_checked(bytes: &[u8], name: Option<&str>) {
    match read_bytes(bytes, name) {
        Ok(f) => check_consistent(&f),
        Err(e) => assert!(!e.to_string().is_empty()),
    }
}

/// `$PROPTEST_CASES` when set (for a deeper run), else `default`.
pub fn cases(default: u32) -> u32 {
    std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// One mutation of a file's bytes.
#[derive(Debug, Clone)]
pub enum Edit {
    Set(usize, u8),
    /// Overwrite four bytes with a little-endian word (counts and offsets of binary headers).
    Word(usize, u32),
    Insert(usize, Vec<u8>),
    Remove(usize, usize),
    /// Replace the n-th run of ASCII digits with another number.
    Number(usize, u64),
}

/// Mutations, inserting one of `words` where they insert.
pub fn edit(words: Vec<&'static [u8]>) -> impl Strategy<Value = Edit> {
    let big = prop::sample::select(vec![0u32, 1, 0x7fff_ffff, u32::MAX, 1 << 20]);
    prop_oneof![
        (any::<usize>(), any::<u8>()).prop_map(|(i, b)| Edit::Set(i, b)),
        (any::<usize>(), big).prop_map(|(i, w)| Edit::Word(i, w)),
        (any::<usize>(), prop::sample::select(words))
            .prop_map(|(i, w)| Edit::Insert(i, w.to_vec())),
        (any::<usize>(), 1usize..16).prop_map(|(i, n)| Edit::Remove(i, n)),
        (any::<usize>(), any::<u64>()).prop_map(|(i, v)| Edit::Number(i, v)),
    ]
}

/// Applies `e` within the first `span` bytes (all of them when `None`).
pub fn apply(bytes: &mut Vec<u8>, e: &Edit, span: Option<usize>) {
    let span = span.map_or(bytes.len(), |s| bytes.len().min(s)).max(1);
    match e {
        Edit::Set(i, b) if !bytes.is_empty() => bytes[i % span] = *b,
        Edit::Word(i, w) if bytes.len() >= 4 => {
            let at = i % (span.min(bytes.len() - 3));
            bytes[at..at + 4].copy_from_slice(&w.to_le_bytes());
        }
        Edit::Insert(i, w) => {
            let at = i % (span + 1).min(bytes.len() + 1);
            bytes.splice(at..at, w.iter().copied());
        }
        Edit::Remove(i, n) if !bytes.is_empty() => {
            let at = i % span;
            bytes.drain(at..(at + n).min(bytes.len()));
        }
        Edit::Number(k, v) => {
            let runs = digit_runs(bytes);
            if let Some(&(s, t)) = runs.get(k % runs.len().max(1)) {
                bytes.splice(s..t, v.to_string().into_bytes());
            }
        }
        _ => {}
    }
}

/// The first 200 runs of ASCII digits, as byte ranges.
fn digit_runs(bytes: &[u8]) -> Vec<(usize, usize)> {
    let mut runs = Vec::new();
    let mut i = 0;
    while i < bytes.len() && runs.len() < 200 {
        if bytes[i].is_ascii_digit() {
            let s = i;
            while i < bytes.len() && bytes[i].is_ascii_digit() {
                i += 1;
            }
            runs.push((s, i));
        } else {
            i += 1;
        }
    }
    runs
}
