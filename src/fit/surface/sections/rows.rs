//! The rows of gridded data: cut from an ordered point list, or the largest smooth rectangle of
//! a range grid.

use crate::geom::Point3;

/// Rows of `points`: `Some(n)` points each, or else cut where the step to the next point is a
/// jump — longer than 4 times the median step, or going back against the scan direction (the
/// first step's).
pub fn detect_rows(points: &[Point3], per_row: Option<usize>) -> Vec<std::ops::Range<usize>> {
    if let Some(n) = per_row.filter(|&n| n > 0) {
        return (0..points.len())
            .step_by(n)
            .map(|s| s..(s + n).min(points.len()))
            .collect();
    }
    if points.len() < 2 {
        return std::iter::once(0..points.len()).collect();
    }
    let steps: Vec<_> = points.windows(2).map(|w| w[1] - w[0]).collect();
    let mut lengths: Vec<f64> = steps.iter().map(|s| s.length()).collect();
    lengths.sort_by(f64::total_cmp);
    let median = lengths[lengths.len() / 2];
    let dir = steps[0];
    let mut rows = Vec::new();
    let mut begin = 0;
    for (i, s) in steps.iter().enumerate() {
        if s.length() > 4.0 * median || s.dot(dir) < 0.0 {
            rows.push(begin..i + 1);
            begin = i + 1;
        }
    }
    rows.push(begin..points.len());
    rows
}

/// A step between neighbouring samples of a range grid longer than this many times the grid's
/// spacing ([`crate::io::RangeGrid::spacing`]) is a depth jump: the samples on either side lie
/// on different surfaces (an ear in front of the head), or on one seen at a grazing angle.
pub const JUMP_FACTOR: f64 = 4.0;

/// The rows of a range grid of the points `positions`: the largest rectangle of columns × rows
/// whose cells are all measured and none next to a depth jump ([`JUMP_FACTOR`]), as point
/// indices row by row. A skinned surface needs complete sections, and one smooth surface
/// cannot follow a jump: bun000's largest measured rectangle crosses the ears' and the
/// head's outlines, and its columns of control points jumped by 4.6 % of the diagonal there.
pub fn grid_rows(
    grid: &crate::io::RangeGrid,
    positions: &[Point3],
) -> (Vec<u32>, Vec<std::ops::Range<usize>>) {
    let (cols, rows) = (grid.cols(), grid.rows());
    let jump = grid
        .spacing(positions)
        .map_or(f64::INFINITY, |s| JUMP_FACTOR * s);
    let at = |c: usize, r: usize| grid.cell(c, r).and_then(|i| positions.get(i as usize));
    let smooth = |c: usize, r: usize| {
        let Some(&p) = at(c, r) else {
            return false;
        };
        let neighbours = [
            c.checked_sub(1).map(|c| (c, r)),
            Some((c + 1, r)),
            r.checked_sub(1).map(|r| (c, r)),
            Some((c, r + 1)),
        ];
        let far = |&(c, r): &(usize, usize)| at(c, r).is_some_and(|&q| p.distance(q) > jump);
        !neighbours.iter().flatten().any(far)
    };
    let mut height = vec![0usize; cols];
    let mut best = (0usize, 0, 0, 0, 0); // area, c0, c1, r0, r1 (inclusive-exclusive)
    for r in 0..rows {
        for (c, h) in height.iter_mut().enumerate() {
            *h = if smooth(c, r) { *h + 1 } else { 0 };
        }
        // Largest rectangle under the histogram `height`, ending at row r.
        let mut stack: Vec<usize> = Vec::new();
        for c in 0..=cols {
            let h = if c < cols { height[c] } else { 0 };
            while let Some(&top) = stack.last() {
                if height[top] < h {
                    break;
                }
                stack.pop();
                let left = stack.last().map_or(0, |&l| l + 1);
                let area = height[top] * (c - left);
                if area > best.0 {
                    best = (area, left, c, r + 1 - height[top], r + 1);
                }
            }
            stack.push(c);
        }
    }
    let (_, c0, c1, r0, r1) = best;
    let mut indices = Vec::with_capacity(best.0);
    let mut ranges = Vec::with_capacity(r1 - r0);
    for r in r0..r1 {
        let begin = indices.len();
        indices.extend((c0..c1).filter_map(|c| grid.cell(c, r)));
        ranges.push(begin..indices.len());
    }
    (indices, ranges)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_by_jump_and_by_count() {
        let pts: Vec<Point3> = (0..3)
            .flat_map(|r| (0..5).map(move |c| Point3::new(c as f64, r as f64, 0.0)))
            .collect();
        assert_eq!(detect_rows(&pts, None), vec![0..5, 5..10, 10..15]);
        assert_eq!(detect_rows(&pts, Some(5)), vec![0..5, 5..10, 10..15]);
        assert_eq!(detect_rows(&pts, Some(4)).len(), 4);
    }
}
