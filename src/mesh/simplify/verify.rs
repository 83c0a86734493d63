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
use crate::mesh::repair::{RepairOptions, RepairReport};

/// The report of a repair that found nothing to do, or `None` when the mesh needs repair.
pub(super) fn clean_report(e: &Engine) -> Option<RepairReport> {
    if !e.faces_are_sound() {
        return None;
    }
    let sizes = component_sizes_of_fans(e)?;
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

/// The number of faces of each connected component, or `None` when the faces of some vertex
/// do not form one fan. One sweep over the vertices: each is joined to the next corners of its
/// faces, which joins every side of every face, and a component's faces are its corners over 3.
fn component_sizes_of_fans(e: &Engine) -> Option<Vec<usize>> {
    let n = e.num_vertices();
    let mut parent: Vec<u32> = (0..n as u32).collect();
    let mut around = Vec::new();
    for v in 0..n as u32 {
        if !single_fan(e, v, &mut around) {
            return None;
        }
        // Each inner side is the next side of both its ends; a side on the boundary only of
        // the end it leaves (it is no face's previous side there).
        for &(next, _) in &around {
            if next > v || !around.iter().any(|c| c.1 == next) {
                let (r, s) = (root(&mut parent, v), root(&mut parent, next));
                parent[s as usize] = r;
            }
        }
    }
    let mut corners = vec![0usize; n];
    for v in 0..n as u32 {
        let r = root(&mut parent, v);
        corners[r as usize] += e.faces_of(v).len();
    }
    corners.retain(|&c| c > 0);
    corners.iter_mut().for_each(|c| *c /= 3);
    Some(corners)
}

/// The representative of `v`'s set, halving the path on the way.
fn root(parent: &mut [u32], mut v: u32) -> u32 {
    while parent[v as usize] != v {
        let up = parent[parent[v as usize] as usize];
        parent[v as usize] = up;
        v = up;
    }
    v
}
