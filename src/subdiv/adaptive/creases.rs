//! Crease tags through a local refinement: the refinements work on untagged polygon meshes
//! and keep the old vertices' numbers, so the crease edges of the refined mesh follow from the
//! old mesh's: an old crease edge that is still an edge stays one, and one that was split is
//! the two edges through the new vertex joined to both of its ends (the edge point every
//! scheme's split puts on it).

use crate::mesh::{ControlMesh, PolyMesh};
use std::collections::{HashMap, HashSet};

/// The crease edges of `refined`, a local refinement of `old` (old vertices keep their numbers,
/// new ones follow): vertex pairs, smaller first, sorted. A split crease edge becomes the two
/// edges through the new vertex adjacent to both its ends that is closest to its midpoint; a
/// crease edge the refinement removed otherwise (which none of the schemes' splits does) is
/// dropped.
pub fn carried_creases(old: &ControlMesh, refined: &PolyMesh) -> Vec<[u32; 2]> {
    let creases = old.creases();
    if creases.is_empty() {
        return Vec::new();
    }
    let first_new = old.num_vertices() as u32;
    let ends: HashSet<u32> = creases.iter().flatten().copied().collect();
    let key = |x: u32, y: u32| (x.min(y), x.max(y));
    let mut edges = HashSet::new();
    // The new vertices next to each end of an old crease edge.
    let mut fresh: HashMap<u32, Vec<u32>> = HashMap::new();
    for f in refined.faces() {
        for k in 0..f.len() {
            let (x, y) = (f[k], f[(k + 1) % f.len()]);
            edges.insert(key(x, y));
            for (old_end, new) in [(x, y), (y, x)] {
                if new >= first_new && ends.contains(&old_end) {
                    let list = fresh.entry(old_end).or_default();
                    if !list.contains(&new) {
                        list.push(new);
                    }
                }
            }
        }
    }
    let pos = refined.positions();
    let mut out = Vec::with_capacity(2 * creases.len());
    for [a, b] in creases {
        if edges.contains(&(a, b)) {
            out.push([a, b]);
            continue;
        }
        let (Some(near_a), Some(near_b)) = (fresh.get(&a), fresh.get(&b)) else {
            continue;
        };
        let mid = (pos[a as usize] + pos[b as usize]) * 0.5;
        let split = near_a
            .iter()
            .filter(|m| near_b.contains(m))
            .min_by(|&&m, &&n| {
                let (dm, dn) = (pos[m as usize].distance(mid), pos[n as usize].distance(mid));
                dm.total_cmp(&dn).then(m.cmp(&n))
            });
        if let Some(&m) = split {
            out.push([a.min(m), a.max(m)]);
            out.push([b.min(m), b.max(m)]);
        }
    }
    out.sort_unstable();
    out.dedup();
    out
}

/// Tags the edges `creases` of `control` sharp; pairs that are no edge, and boundary edges
/// (sharp already), change nothing.
pub fn tag_creases(control: &mut ControlMesh, creases: &[[u32; 2]]) {
    for &[a, b] in creases {
        // `set_sharp` fails only for a pair that is no edge, which this skips.
        let _ = control.set_sharp(a, b, true);
    }
}
