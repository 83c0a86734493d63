//! The scanner grid of a raw range scan: which point, if any, each grid cell measured.

use crate::geom::Point3;

/// A `cols × rows` scanner grid (PLY `range_grid`, as written by Cyberware scanners). Cell
/// `(col, row)` holds the index of the point it measured, or nothing where the laser saw no
/// surface. Neighbouring cells are neighbouring samples, so the grid triangulates a
/// single-view scan without any surface reconstruction.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RangeGrid {
    cols: usize,
    rows: usize,
    cells: Vec<Option<u32>>,
}

impl RangeGrid {
    /// A grid from row-major cells; `None` unless `cells.len() == cols * rows`.
    pub fn try_new(cols: usize, rows: usize, cells: Vec<Option<u32>>) -> Option<RangeGrid> {
        (cols.checked_mul(rows) == Some(cells.len())).then_some(RangeGrid { cols, rows, cells })
    }

    /// Number of columns (samples per scan line).
    pub fn cols(&self) -> usize {
        self.cols
    }

    /// Number of rows (scan lines).
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// The point measured at `(col, row)`, or `None` for an empty or out-of-grid cell.
    pub fn cell(&self, col: usize, row: usize) -> Option<u32> {
        if col >= self.cols || row >= self.rows {
            return None;
        }
        self.cells[row * self.cols + col]
    }

    /// Triangles over the grid: a cell square whose four corners were all measured gives two
    /// triangles (split along the diagonal from `(col, row)` to `(col + 1, row + 1)`), one with
    /// exactly three measured corners gives one. Every triangle winds counter-clockwise in
    /// (col, row) coordinates; in Cyberware scans columns run along +x and rows along +y, so
    /// the normals face the scanner (+z).
    pub fn triangles(&self) -> Vec<[u32; 3]> {
        let mut out = Vec::new();
        for row in 0..self.rows.saturating_sub(1) {
            for col in 0..self.cols.saturating_sub(1) {
                let a = self.cell(col, row);
                let b = self.cell(col + 1, row);
                let c = self.cell(col, row + 1);
                let d = self.cell(col + 1, row + 1);
                push_cell(&mut out, [a, b, c, d]);
            }
        }
        out
    }
}

impl RangeGrid {
    /// The grid over the points renumbered by `new_index` (the new index of every old point,
    /// [`crate::mesh::NONE`] for one left out, whose cell becomes empty).
    pub fn renumbered(&self, new_index: &[u32]) -> RangeGrid {
        let cells = self
            .cells
            .iter()
            .map(|c| {
                c.and_then(|i| new_index.get(i as usize).copied())
                    .filter(|&i| i != crate::mesh::NONE)
            })
            .collect();
        RangeGrid { cells, ..*self }
    }

    /// The scan's sample spacing: the median distance between measured cells that are
    /// neighbours along a row or a column. `None` when no two neighbours were measured (or
    /// `positions` is not the scan's point list). The natural unit for
    /// [`RangeGrid::triangles_within`].
    pub fn spacing(&self, positions: &[Point3]) -> Option<f64> {
        let mut d = Vec::new();
        for row in 0..self.rows {
            for col in 0..self.cols {
                for (c, r) in [(col + 1, row), (col, row + 1)] {
                    if let Some(len) = self.edge(positions, (col, row), (c, r)) {
                        d.push(len);
                    }
                }
            }
        }
        if d.is_empty() {
            return None;
        }
        let mid = d.len() / 2;
        Some(*d.select_nth_unstable_by(mid, f64::total_cmp).1)
    }

    /// [`RangeGrid::triangles`] without the triangles whose longest edge exceeds `max_edge`.
    /// At silhouettes and depth jumps neighbouring samples lie on different surfaces, and the
    /// plain grid triangulation bridges them with long thin triangles; a few times
    /// [`RangeGrid::spacing`] keeps the surface and drops the bridges. Triangles with an index
    /// beyond `positions` are dropped too.
    pub fn triangles_within(&self, positions: &[Point3], max_edge: f64) -> Vec<[u32; 3]> {
        let max_sq = max_edge * max_edge;
        let mut out = self.triangles();
        out.retain(|t| {
            let corners = t.map(|i| positions.get(i as usize));
            let [Some(a), Some(b), Some(c)] = corners else {
                return false;
            };
            [
                a.distance_squared(*b),
                b.distance_squared(*c),
                c.distance_squared(*a),
            ]
            .iter()
            .all(|&e| e <= max_sq)
        });
        out
    }

    fn edge(&self, positions: &[Point3], a: (usize, usize), b: (usize, usize)) -> Option<f64> {
        let pa = positions.get(self.cell(a.0, a.1)? as usize)?;
        let pb = positions.get(self.cell(b.0, b.1)? as usize)?;
        Some(pa.distance(*pb))
    }
}

/// Corners `a = (col, row)`, `b = (col + 1, row)`, `c = (col, row + 1)`, `d = (col + 1, row + 1)`:
/// two triangles `a b d`, `a d c`, or the one triangle the three measured corners make, all
/// counter-clockwise in (col, row).
fn push_cell(out: &mut Vec<[u32; 3]>, corners: [Option<u32>; 4]) {
    match corners {
        [Some(a), Some(b), Some(c), Some(d)] => {
            out.push([a, b, d]);
            out.push([a, d, c]);
        }
        [None, Some(b), Some(c), Some(d)] => out.push([b, d, c]),
        [Some(a), None, Some(c), Some(d)] => out.push([a, d, c]),
        [Some(a), Some(b), None, Some(d)] => out.push([a, b, d]),
        [Some(a), Some(b), Some(c), None] => out.push([a, b, c]),
        _ => {}
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn full_and_three_corner_cells_triangulate() {
        // 3 × 2 grid: the left square is complete, the right one lacks cell (2, 0).
        let g = RangeGrid::try_new(
            3,
            2,
            vec![Some(0), Some(1), None, Some(2), Some(3), Some(4)],
        )
        .unwrap();
        assert_eq!(g.triangles(), vec![[0, 1, 3], [0, 3, 2], [1, 4, 3]]);
        assert_eq!(g.cell(2, 0), None);
        assert_eq!(g.cell(9, 9), None);
        assert!(RangeGrid::try_new(2, 2, vec![None; 3]).is_none());
    }

    #[test]
    fn long_edges_over_a_depth_jump_are_dropped() {
        // 3 × 2 samples one unit apart; the right column lies 10 units deeper.
        let p = |x: f64, y: f64, z: f64| Point3::new(x, y, z);
        let positions = vec![
            p(0.0, 0.0, 0.0),
            p(1.0, 0.0, 0.0),
            p(2.0, 0.0, 10.0),
            p(0.0, 1.0, 0.0),
            p(1.0, 1.0, 0.0),
            p(2.0, 1.0, 10.0),
        ];
        let g = RangeGrid::try_new(3, 2, (0..6).map(Some).collect()).unwrap();
        assert_eq!(g.spacing(&positions), Some(1.0));
        assert_eq!(g.triangles().len(), 4);
        assert_eq!(
            g.triangles_within(&positions, 2.0),
            vec![[0, 1, 4], [0, 4, 3]]
        );
        assert!(g.triangles_within(&positions[..2], 100.0).is_empty());
        assert_eq!(
            RangeGrid::try_new(1, 1, vec![None])
                .unwrap()
                .spacing(&positions),
            None
        );
    }
}
