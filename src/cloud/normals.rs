//! Normals of a point cloud: principal component analysis of each point's k nearest
//! neighbours, oriented consistently by propagation along a minimum spanning tree of the
//! neighbour graph (Hoppe et al. 1992, "Surface reconstruction from unorganized points").

use super::neighbours::Neighbours;
use crate::geom::principal_frame;
use crate::geom::{Point3, Vec3};
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// Unoriented unit normals: the least principal axis of each point's `k` nearest neighbours.
/// Where a neighbourhood is degenerate (coincident points), `fallback` is used.
pub(super) fn pca_normals(
    points: &[Point3],
    tree: &Neighbours,
    k: usize,
    fallback: Vec3,
) -> Vec<Vec3> {
    points
        .iter()
        .map(|&p| {
            let near = tree.nearest(p, k);
            let f = principal_frame(near.iter().map(|&(i, _)| points[i]));
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
/// neighbour graph with cost 1 − |nᵢ·nⱼ| (nearly parallel normals first), starting in each
/// connected piece from its highest point, whose normal is made to point up (+z): the
/// outward direction at an extreme point of a closed surface.
pub(super) fn orient(points: &[Point3], normals: &mut [Vec3], tree: &Neighbours, k: usize) {
    let n = points.len();
    let graph: Vec<Vec<u32>> = points
        .iter()
        .map(|&p| {
            tree.nearest(p, k + 1)
                .iter()
                .map(|&(i, _)| i as u32)
                .collect()
        })
        .collect();
    // Make the graph symmetric so every piece is reached from any of its points.
    let mut adjacency = graph.clone();
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
    let mut heap = BinaryHeap::new();
    for &seed in &by_height {
        if done[seed as usize] {
            continue;
        }
        if normals[seed as usize].z < 0.0 {
            normals[seed as usize] = -normals[seed as usize];
        }
        done[seed as usize] = true;
        push_edges(seed, &adjacency, normals, &done, &mut heap);
        while let Some(e) = heap.pop() {
            let to = e.to as usize;
            if done[to] {
                continue;
            }
            if normals[to].dot(normals[e.from as usize]) < 0.0 {
                normals[to] = -normals[to];
            }
            done[to] = true;
            push_edges(e.to, &adjacency, normals, &done, &mut heap);
        }
    }
}

fn push_edges(
    from: u32,
    adjacency: &[Vec<u32>],
    normals: &[Vec3],
    done: &[bool],
    heap: &mut BinaryHeap<Edge>,
) {
    let nf = normals[from as usize];
    for &to in &adjacency[from as usize] {
        if !done[to as usize] {
            heap.push(Edge {
                cost: 1.0 - nf.dot(normals[to as usize]).abs(),
                from,
                to,
            });
        }
    }
}
