//! Normals of a point cloud: principal component analysis of each point's k nearest
//! neighbours, oriented consistently by propagation along a minimum spanning tree of the
//! neighbour graph (Hoppe et al. 1992, "Surface reconstruction from unorganized points").

use super::neighbours::Neighbours;
use crate::geom::principal_frame;
use crate::geom::{Point3, Vec3};
use crate::progress::{self, Part};
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// The `k + 1` nearest points of every point, nearest first (the point itself among them): the
/// neighbourhoods of [`pca_normals`] (the first `k`) and the graph of [`orient`], found once.
/// Reports its progress as `part`.
pub(super) fn neighbourhoods(
    points: &[Point3],
    tree: &Neighbours,
    k: usize,
    part: Part,
) -> Vec<Vec<u32>> {
    points
        .iter()
        .enumerate()
        .map(|(i, &p)| {
            if i % progress::BATCH == 0 {
                part.count(i, points.len());
            }
            tree.nearest(p, k + 1)
                .iter()
                .map(|&(i, _)| i as u32)
                .collect()
        })
        .collect()
}

/// Unoriented unit normals: the least principal axis of each point's `k` nearest neighbours
/// (the first `k` of its [`neighbourhoods`]). Where a neighbourhood is degenerate (coincident
/// points), `fallback` is used.
pub(super) fn pca_normals(
    points: &[Point3],
    near: &[Vec<u32>],
    k: usize,
    fallback: Vec3,
) -> Vec<Vec3> {
    near.iter()
        .map(|near| {
            let f = principal_frame(near.iter().take(k).map(|&i| points[i as usize]));
            if f.values[1] > 0.0 && f.axes[0] != Vec3::ZERO {
                f.axes[0]
            } else {
                fallback
            }
        })
        .collect()
}

/// An edge of the neighbour graph waiting in Prim's queue.
struct Edge {
    cost: f64,
    from: u32,
    to: u32,
}

impl PartialEq for Edge {
    fn eq(&self, o: &Edge) -> bool {
        self.cmp(o) == Ordering::Equal
    }
}
impl Eq for Edge {}
impl PartialOrd for Edge {
    fn partial_cmp(&self, o: &Edge) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Edge {
    /// Reversed for a min-heap; ties by index for determinism.
    fn cmp(&self, o: &Edge) -> Ordering {
        o.cost
            .total_cmp(&self.cost)
            .then(o.to.cmp(&self.to))
            .then(o.from.cmp(&self.from))
    }
}

/// Flips normals so that neighbours agree: Prim's minimum spanning tree over the k-nearest
/// neighbour `graph` ([`neighbourhoods`]) with cost 1 − |nᵢ·nⱼ| (nearly parallel normals first), starting in each
/// connected piece from its highest point, whose normal is made to point up (+z): the
/// outward direction at an extreme point of a closed surface.
pub(super) fn orient(points: &[Point3], normals: &mut [Vec3], graph: &[Vec<u32>]) {
    let n = points.len();
    // Make the graph symmetric so every piece is reached from any of its points.
    let mut adjacency = graph.to_vec();
    for (i, list) in graph.iter().enumerate() {
        for &j in list {
            adjacency[j as usize].push(i as u32);
        }
    }
    for list in &mut adjacency {
        list.sort_unstable();
        list.dedup();
    }
    let mut by_height: Vec<u32> = (0..n as u32).collect();
    by_height.sort_by(|&a, &b| {
        points[b as usize]
            .z
            .total_cmp(&points[a as usize].z)
            .then(a.cmp(&b))
    });
    let mut done = vec![false; n];
    let mut best = vec![(f64::INFINITY, u32::MAX); n];
    let mut heap = BinaryHeap::new();
    for &seed in &by_height {
        if done[seed as usize] {
            continue;
        }
        if normals[seed as usize].z < 0.0 {
            normals[seed as usize] = -normals[seed as usize];
        }
        done[seed as usize] = true;
        push_edges(seed, &adjacency, normals, &done, &mut best, &mut heap);
        while let Some(e) = heap.pop() {
            let to = e.to as usize;
            if done[to] {
                continue;
            }
            if normals[to].dot(normals[e.from as usize]) < 0.0 {
                normals[to] = -normals[to];
            }
            done[to] = true;
            push_edges(e.to, &adjacency, normals, &done, &mut best, &mut heap);
        }
    }
}

/// Queues the edges from `from` to the points not yet reached, each only when it beats the
/// best edge queued to its end so far (`best`: cost and start), which is the one Prim's queue
/// would take of the two (ties by start). On a 500K-point sheet the queue held every edge of
/// the neighbour graph, and its pops took 1.7 s of the reconstruction.
fn push_edges(
    from: u32,
    adjacency: &[Vec<u32>],
    normals: &[Vec3],
    done: &[bool],
    best: &mut [(f64, u32)],
    heap: &mut BinaryHeap<Edge>,
) {
    let nf = normals[from as usize];
    for &to in &adjacency[from as usize] {
        if done[to as usize] {
            continue;
        }
        let cost = 1.0 - nf.dot(normals[to as usize]).abs();
        let (b, f) = best[to as usize];
        if cost.total_cmp(&b).then(from.cmp(&f)).is_lt() {
            best[to as usize] = (cost, from);
            heap.push(Edge { cost, from, to });
        }
    }
}
