//! The skinning fit in the paper's form (docs/sections.md): a 51 × 51 grid (2 mm pitch) of a
//! bottle with a shoulder crease at a 0.1 mm threshold; σ with the multiple knots only and at
//! the end, and the least-squares and geometric surface fits on as many control points.
//!
//! `cargo run --release --example sections_bottle`

mod bottle;

use geofit::fit::{FitData, FitSpec, Fitter, Method, Scheme, TolMode};
use geofit::mesh::PolyMesh;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let points = bottle::bottle();
    let mesh = PolyMesh::from_points(points.clone())?;
    let data = FitData::points(&mesh);
    let diag = geofit::geom::Aabb::from_points(&points)
        .map(|b| b.diagonal())
        .unwrap_or(1.0);
    let tol_pct = 0.1 / diag * 100.0;
    let mm = |pct: f64| pct / 100.0 * diag;
    // The paper's threshold bounds every point: noise-free sections are judged exactly.
    let mut spec = FitSpec::new(Scheme::BsplineSurface)
        .with_method(Some(Method::Sections))
        .with_tol_max(Some(tol_pct));
    spec.tol_mode = TolMode::Exact;
    let mut fit = spec.build(&data)?;
    let d0 = fit.details();
    let status = fit.run()?;
    let d = fit.details();
    let (nu, nv) = (
        d["control_points_u"].as_u64().unwrap_or(0) as usize,
        d["control_points_v"].as_u64().unwrap_or(0) as usize,
    );
    println!(
        "bottle: {} points, diagonal {diag:.3} mm, threshold 0.1 mm",
        points.len()
    );
    println!("| fit | control points | E_avg mm | E_max mm | E_rms mm | σ mm | status |");
    println!("|---|---|---|---|---|---|---|");
    println!(
        "| sections, multiple knots only | {} × {} | | | | {:.4} | |",
        d0["control_points_u"],
        d0["control_points_v"],
        d0["sigma"].as_f64().unwrap_or(f64::NAN)
    );
    let row = |name: &str, fit: &dyn Fitter, sigma: f64, status| {
        let s = fit.stats();
        println!(
            "| {name} | {nu} × {nv} | {:.4} | {:.4} | {:.4} | {sigma:.4} | {status:?} |",
            mm(s.e_avg_pct),
            mm(s.e_max_pct),
            mm(s.e_rms_pct)
        );
    };
    row(
        "sections, end",
        fit.as_ref(),
        d["sigma"].as_f64().unwrap_or(f64::NAN),
        status,
    );
    for method in [Method::LeastSquares, Method::Geometric] {
        let mut spec = FitSpec::new(Scheme::BsplineSurface)
            .with_method(Some(method))
            .with_tol_max(Some(tol_pct))
            .with_refine(false);
        spec.grid = Some([nu, nv]);
        spec.tol_mode = TolMode::Exact;
        let mut other = spec.build(&data)?;
        let status = other.run()?;
        let e = other.point_errors();
        let n = e.len().max(1) as f64;
        let mean = e.iter().sum::<f64>() / n;
        let sigma = (e.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n).sqrt();
        row(&method.to_string(), other.as_ref(), sigma, status);
    }
    Ok(())
}
