//! Whether the working mesh is already what [`repair`](crate::mesh::repair) would make of it:
//! then the simplifier skips the repair (and the copies it makes), which on a clean scan cost
//! a fifth of the whole simplification.
//!
//! The checks read the per-vertex face index the simplifier builds anyway: every face has
//! three distinct corners and a non-zero area; around every vertex the next corners of its
//! faces are distinct (no side twice in one direction, so no edge with three faces and no
//! clash of orientation) and the faces form one fan, a closed one of at least three faces (two
//! faces closing a fan are a face and its duplicate); and no component is small enough for
//! repair to leave it to the data only.

use super::engine::Engine;
use crate::mesh::repair::clean::has_area;
use crate::mesh::repair::{RepairOptions, RepairReport};

/// The report of a repair that found nothing to do, or `None` when the mesh needs repair.
pub(super) fn clean_report(e: &Engine) -> Option<RepairReport> {
    if !(0..e.num_faces()).all(|f| face_is_sound(e, f)) {
        return None;
    }
    let mut around = Vec::new();
    if !(0..e.num_vertices() as u32).all(|v| single_fan(e, v, &mut around)) {
        return None;
    }
    let sizes = component_sizes(e);
    let largest = sizes.iter().copied().max().unwrap_or(0);
    let tiny = RepairOptions::default().data_only_faces;
    if sizes.iter().any(|&s| s <= tiny && s < largest) {
        return None;
    }
    let mut report = RepairReport::default();
    report.components.count = sizes.len();
    let mut sorted = sizes;
    sorted.sort_unstable_by(|a, b| b.cmp(a));
    sorted.truncate(5);
    report.components.largest_faces = sorted;
    for v in e.unreferenced_inputs() {
        report.unreferenced_vertices.add(v);
    }
    report.summarise();
    Some(report)
}

/// Whether face `f` has three distinct corners and an area.
fn face_is_sound(e: &Engine, f: usize) -> bool {
    let t = e.face(f);
    if t[0] == t[1] || t[1] == t[2] || t[2] == t[0] {
        return false;
    }
    let [a, b, c] = t.map(|v| e.pos(v));
    let sides = (b - a).length_squared() + (c - b).length_squared() + (a - c).length_squared();
    has_area((b - a).cross(c - a).length(), sides)
}

/// Whether the faces of `v` form one fan with each side once (see the module docs);
/// `around` is scratch space.
fn single_fan(e: &Engine, v: u32, around: &mut Vec<(u32, u32)>) -> bool {
    around.clear();
    for &f in e.faces_of(v) {
        let t = e.face(f as usize);
        let k = if t[0] == v {
            0
        } else if t[1] == v {
            1
        } else {
            2
        };
        around.push((t[(k + 1) % 3], t[(k + 2) % 3]));
    }
    let d = around.len();
    if d == 0 {
        return true;
    }
    if (1..d).any(|i| around[..i].iter().any(|c| c.0 == around[i].0)) {
        return false;
    }
    // A fan's first face is the one whose previous corner is no face's next corner.
    let mut firsts = (0..d).filter(|&i| !around.iter().any(|c| c.0 == around[i].1));
    let (start, open) = match (firsts.next(), firsts.next()) {
        (None, _) => (0, false),
        (Some(i), None) => (i, true),
        (Some(_), Some(_)) => return false,
    };
    let mut count = 1;
    let mut at = start;
    while let Some(j) = around.iter().position(|c| c.1 == around[at].0) {
        if j == start {
            return !open && count == d && d >= 3;
        }
        at = j;
        count += 1;
        if count > d {
            return false;
        }
    }
    open && count == d
}

/// The number of faces of each connected component (faces joined through shared vertices,
/// which in a manifold with single fans is through shared edges).
fn component_sizes(e: &Engine) -> Vec<usize> {
    let mut parent: Vec<u32> = (0..e.num_vertices() as u32).collect();
    let root = |parent: &mut Vec<u32>, mut v: u32| {
        while parent[v as usize] != v {
            let up = parent[parent[v as usize] as usize];
            parent[v as usize] = up;
            v = up;
        }
        v
    };
    for f in 0..e.num_faces() {
        let t = e.face(f);
        let r0 = root(&mut parent, t[0]);
        for &w in &t[1..] {
            let r = root(&mut parent, w);
            parent[r as usize] = r0;
        }
    }
    let mut count = vec![0usize; e.num_vertices()];
    for f in 0..e.num_faces() {
        let r = root(&mut parent, e.face(f)[0]);
        count[r as usize] += 1;
    }
    count.retain(|&c| c > 0);
    count
}
