//! Stray points left out of a fit: found by [`find_strays`](crate::geom::find_strays) before
//! the bounding-box diagonal is taken, since every tolerance is a percentage of it.

use super::FitData;
use crate::geom::find_strays;
use crate::io::RangeGrid;
use crate::mesh::{PolyMesh, NONE};
use serde::Serialize;

/// The data points a fit left out as strays.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct StrayPoints {
    /// Their indices among the data's points, in order.
    pub indices: Vec<u32>,
}

impl StrayPoints {
    /// One line for people: `"left out 2 stray points far from the rest (points 0, 17)"`.
    pub fn note(&self) -> String {
        const SHOWN: usize = 5;
        let list: Vec<String> = self
            .indices
            .iter()
            .take(SHOWN)
            .map(u32::to_string)
            .collect();
        let n = self.indices.len();
        let more = if n > SHOWN { ", …" } else { "" };
        let s = if n == 1 { "" } else { "s" };
        format!(
            "left out {n} stray point{s} far from the rest (point{s} {}{more})",
            list.join(", ")
        )
    }
}

/// The data of a fit with its stray points taken out.
pub(super) struct WithoutStrays {
    mesh: PolyMesh,
    grid: Option<RangeGrid>,
    polylines: Vec<Vec<u32>>,
    /// What was taken out.
    pub(super) strays: StrayPoints,
}

impl WithoutStrays {
    /// `data` without its strays, or `None` when it has none. Faces through a stray are
    /// dropped, its range-grid cell emptied, and polylines skip it.
    pub(super) fn of(data: &FitData) -> Option<WithoutStrays> {
        let indices = find_strays(data.mesh.positions());
        if indices.is_empty() {
            return None;
        }
        let (mesh, new_index) = data.mesh.without_vertices(&indices);
        let polylines = data
            .polylines
            .iter()
            .map(|line| {
                line.iter()
                    .filter_map(|&v| new_index.get(v as usize).copied())
                    .filter(|&v| v != NONE)
                    .collect()
            })
            .collect();
        Some(WithoutStrays {
            mesh,
            grid: data.grid.map(|g| g.renumbered(&new_index)),
            polylines,
            strays: StrayPoints { indices },
        })
    }

    /// The fit's data: these points, with the control mesh of `data`.
    pub(super) fn data<'a>(&'a self, data: &FitData<'a>) -> FitData<'a> {
        FitData {
            mesh: &self.mesh,
            grid: self.grid.as_ref(),
            polylines: &self.polylines,
            control: data.control,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Point3;

    #[test]
    fn strays_leave_the_mesh_the_grid_and_the_polylines() {
        // A 6×6 grid of points on a plane, with point 8 thrown far away.
        let mut pos: Vec<Point3> = (0..36)
            .map(|k| Point3::new((k % 6) as f64, (k / 6) as f64, 0.0))
            .collect();
        pos[8] = Point3::new(0.0, 0.0, 1e6);
        let mesh = PolyMesh::try_new(pos, [[7u32, 8, 14], [0, 1, 7]]).unwrap();
        let grid = RangeGrid::try_new(6, 6, (0..36).map(Some).collect()).unwrap();
        let lines = vec![vec![6, 7, 8, 9]];
        let data = FitData {
            mesh: &mesh,
            grid: Some(&grid),
            polylines: &lines,
            control: None,
        };
        let kept = WithoutStrays::of(&data).expect("point 8 strays");
        assert_eq!(kept.strays.indices, vec![8]);
        assert_eq!(
            kept.strays.note(),
            "left out 1 stray point far from the rest (point 8)"
        );
        let d = kept.data(&data);
        assert_eq!(d.mesh.num_vertices(), 35);
        assert_eq!(d.mesh.faces().collect::<Vec<_>>(), vec![&[0u32, 1, 7][..]]);
        assert_eq!(d.grid.unwrap().cell(2, 1), None);
        assert_eq!(d.grid.unwrap().cell(3, 1), Some(8));
        assert_eq!(d.polylines, &[vec![6, 7, 8]]);
        assert!(WithoutStrays::of(&d).is_none());
    }
}
