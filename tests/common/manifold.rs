//! Topology checks for triangle meshes: manifoldness, orientation, Euler characteristic and
//! boundary loops.

use geofit::mesh::PolyMesh;
use std::collections::{BTreeMap, BTreeSet};

/// Panics with a message unless every edge has one or two faces, the faces are consistently
/// oriented (no directed edge twice) and every used vertex's link is one cycle or one path.
pub fn assert_manifold(mesh: &PolyMesh) {
    let tris = mesh.triangles();
    let mut directed = BTreeSet::new();
    let mut undirected: BTreeMap<(u32, u32), usize> = BTreeMap::new();
    for t in &tris {
        assert!(
            t[0] != t[1] && t[1] != t[2] && t[0] != t[2],
            "degenerate face {t:?}"
        );
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            assert!(
                directed.insert((a, b)),
                "directed edge {a}->{b} twice: orientation"
            );
            *undirected.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    for (e, n) in &undirected {
        assert!(*n <= 2, "edge {e:?} has {n} faces");
    }
    // Link of each vertex: the edges opposite it; must form a single cycle or a single path.
    let mut links: BTreeMap<u32, Vec<(u32, u32)>> = BTreeMap::new();
    for t in &tris {
        for k in 0..3 {
            links
                .entry(t[k])
                .or_default()
                .push((t[(k + 1) % 3], t[(k + 2) % 3]));
        }
    }
    for (v, link) in &links {
        assert_link_is_disc(*v, link);
    }
}

fn assert_link_is_disc(v: u32, link: &[(u32, u32)]) {
    let next: BTreeMap<u32, u32> = link.iter().copied().collect();
    assert_eq!(next.len(), link.len(), "vertex {v}: link branches");
    let starts: Vec<u32> = link
        .iter()
        .map(|e| e.0)
        .filter(|a| !link.iter().any(|e| e.1 == *a))
        .collect();
    assert!(
        starts.len() <= 1,
        "vertex {v}: link has {} pieces",
        starts.len()
    );
    let start = starts.first().copied().unwrap_or(link[0].0);
    let mut seen = 1;
    let mut cur = start;
    while let Some(&n) = next.get(&cur) {
        if n == start {
            break;
        }
        cur = n;
        seen += 1;
        assert!(seen <= link.len() + 1, "vertex {v}: link loops");
    }
    let expected = if starts.is_empty() {
        link.len()
    } else {
        link.len() + 1
    };
    assert_eq!(seen, expected, "vertex {v}: link is not one cycle or path");
}

/// V − E + F over vertices used by faces.
pub fn euler_characteristic(mesh: &PolyMesh) -> i64 {
    let tris = mesh.triangles();
    let mut verts = BTreeSet::new();
    let mut edges = BTreeSet::new();
    for t in &tris {
        for k in 0..3 {
            verts.insert(t[k]);
            let (a, b) = (t[k], t[(k + 1) % 3]);
            edges.insert((a.min(b), a.max(b)));
        }
    }
    verts.len() as i64 - edges.len() as i64 + tris.len() as i64
}

/// Boundary edges (one face), directed as in their face.
pub fn boundary_edges(mesh: &PolyMesh) -> Vec<(u32, u32)> {
    let tris = mesh.triangles();
    let mut count: BTreeMap<(u32, u32), usize> = BTreeMap::new();
    for t in &tris {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *count.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    let mut out = Vec::new();
    for t in &tris {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if count[&(a.min(b), a.max(b))] == 1 {
                out.push((a, b));
            }
        }
    }
    out
}

/// Number of closed boundary loops (of a manifold mesh).
pub fn boundary_loops(mesh: &PolyMesh) -> usize {
    let next: BTreeMap<u32, u32> = boundary_edges(mesh).into_iter().collect();
    let mut seen = BTreeSet::new();
    let mut loops = 0;
    for &start in next.keys() {
        if seen.contains(&start) {
            continue;
        }
        loops += 1;
        let mut cur = start;
        while seen.insert(cur) {
            match next.get(&cur) {
                Some(&n) => cur = n,
                None => break,
            }
        }
    }
    loops
}
