//! The trim of a fitted surface: the outline of its data's foot-point parameters
//! ([`TrimRegion::outline`]), with the two areas that say how well it covers the data.

use crate::geom::Point3;
use crate::spline::{BSplineSurface, Outline, TrimError, TrimOptions, TrimRegion};

/// Cells per side of the (u, v) grid the trimmed area is integrated on.
const AREA_GRID: usize = 256;

/// A fitted surface's trim region and its figures.
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceTrim {
    /// The region of the domain the data covers.
    pub region: TrimRegion,
    /// Area of the data's triangulated region: the outline's Delaunay triangles with the data
    /// points at their corners.
    pub data_area: f64,
    /// Area of the surface over the region, integrated on a 256 × 256 grid of the domain.
    pub trimmed_area: f64,
    /// Loops of the outline left out (islands apart from the main region, small holes).
    pub dropped_loops: usize,
}

/// The outline of the parameters `uv` (clamped into `surface`'s domain first, so the loops lie
/// on the surface): what the exports trim to and the page draws.
pub(crate) fn outline_on(
    surface: &BSplineSurface,
    uv: &[[f64; 2]],
    options: &TrimOptions,
) -> Result<Outline, TrimError> {
    let ((u0, u1), (v0, v1)) = surface.domain();
    let clamped: Vec<[f64; 2]> = uv
        .iter()
        .map(|p| [p[0].clamp(u0, u1), p[1].clamp(v0, v1)])
        .collect();
    TrimRegion::outline(&clamped, options)
}

impl SurfaceTrim {
    /// The trim of `surface` fitted to `data` with foot-point parameters `uv` (clamped into
    /// the domain first, so the loops lie on the surface).
    pub fn of(
        surface: &BSplineSurface,
        uv: &[[f64; 2]],
        data: &[Point3],
        options: &TrimOptions,
    ) -> Result<SurfaceTrim, TrimError> {
        let outline = outline_on(surface, uv, options)?;
        let data_area = outline
            .triangles
            .iter()
            .filter_map(|t| {
                Some(triangle_area(
                    *data.get(t[0])?,
                    *data.get(t[1])?,
                    *data.get(t[2])?,
                ))
            })
            .sum();
        Ok(SurfaceTrim {
            trimmed_area: trimmed_area(surface, &outline.region),
            region: outline.region,
            data_area,
            dropped_loops: outline.dropped_loops,
        })
    }

    /// The figures for the fit report.
    pub fn details(&self) -> serde_json::Value {
        serde_json::json!({
            "loops": self.region.loops().count(),
            "vertices": self.region.num_vertices(),
            "dropped_loops": self.dropped_loops,
            "trimmed_area": self.trimmed_area,
            "data_area": self.data_area,
        })
    }
}

fn triangle_area(a: Point3, b: Point3, c: Point3) -> f64 {
    (b - a).cross(c - a).length() / 2.0
}

/// ∫∫ |S_u × S_v| du dv over the region, by the midpoint rule on the grid cells whose centre
/// the region contains.
fn trimmed_area(s: &BSplineSurface, region: &TrimRegion) -> f64 {
    let ((u0, u1), (v0, v1)) = s.domain();
    let (du, dv) = ((u1 - u0) / AREA_GRID as f64, (v1 - v0) / AREA_GRID as f64);
    let mut area = 0.0;
    for i in 0..AREA_GRID {
        let u = u0 + (i as f64 + 0.5) * du;
        for j in 0..AREA_GRID {
            let v = v0 + (j as f64 + 0.5) * dv;
            if region.contains(u, v) {
                let d = s.derivs(u, v, 1);
                area += d.skl[1][0].cross(d.skl[0][1]).length() * du * dv;
            }
        }
    }
    area
}
