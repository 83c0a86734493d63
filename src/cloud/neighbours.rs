//! k-nearest-neighbour lists over the points (kd-tree), and the local spacing they give.

use crate::geom::Point3;
use crate::progress::{self, Part};
use kiddo::immutable::float::kdtree::ImmutableKdTree;
use kiddo::SquaredEuclidean;
use std::num::NonZero;

/// A kd-tree over points, queried for nearest neighbours.
pub(super) struct Neighbours {
    tree: ImmutableKdTree<f64, u64, 3, 32>,
    count: usize,
}

impl Neighbours {
    /// A tree over `points` (at least one).
    pub(super) fn new(points: &[Point3]) -> Neighbours {
        let coords: Vec<[f64; 3]> = points.iter().map(|p| p.to_array()).collect();
        Neighbours {
            tree: ImmutableKdTree::new_from_slice(&coords),
            count: points.len(),
        }
    }

    /// Up to `k` nearest points of `p` (itself included if it is one), nearest first, with
    /// their squared distances.
    pub(super) fn nearest(&self, p: Point3, k: usize) -> Vec<(usize, f64)> {
        let Some(k) = NonZero::new(k.min(self.count)) else {
            return Vec::new();
        };
        self.tree
            .nearest_n::<SquaredEuclidean>(&p.to_array(), k)
            .into_iter()
            .map(|n| (n.item as usize, n.distance))
            .collect()
    }

    /// For every point, the mean distance to its `k` nearest other points.
    /// Reports its progress as `part`.
    pub(super) fn mean_distances(&self, points: &[Point3], k: usize, part: Part) -> Vec<f64> {
        points
            .iter()
            .enumerate()
            .map(|(i, &p)| {
                if i % progress::BATCH == 0 {
                    part.count(i, points.len());
                }
                let near = self.nearest(p, k + 1);
                let others = near.len().saturating_sub(1).max(1) as f64;
                near.iter().skip(1).map(|n| n.1.sqrt()).sum::<f64>() / others
            })
            .collect()
    }
}
