//! The bottle of the skinning fit's figures (docs/sections.md), shared by its example and test.

use geofit::geom::Point3;

/// The bottle: the front 160° of a surface of revolution, profiles (rows, along z, 2 mm pitch)
/// at 51 angles; radius 36 mm up to the shoulder crease at z = 60, then 12 + 24·(1 − t)² to
/// the neck (t = (z − 60)/30: a tangent jump of 58° at the shoulder, a curvature jump at the
/// neck), then the neck, radius 12, to z = 100.
pub fn bottle() -> Vec<Point3> {
    let radius = |z: f64| {
        if z <= 60.0 {
            36.0
        } else if z <= 90.0 {
            let t = (z - 60.0) / 30.0;
            12.0 + 24.0 * (1.0 - t).powi(2)
        } else {
            12.0
        }
    };
    (0..51)
        .flat_map(|r| {
            let theta = (-80.0 + 160.0 * r as f64 / 50.0_f64).to_radians();
            (0..51).map(move |k| {
                let z = 2.0 * k as f64;
                let rad = radius(z);
                Point3::new(rad * theta.sin(), rad * theta.cos(), z)
            })
        })
        .collect()
}
