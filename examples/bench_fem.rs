//! FEM quad-mesh timing (scripts/bench_fem.sh): fits bun000 with one B-spline surface and spot
//! with Catmull–Clark (defaults), then meshes each fitted surface at several element counts,
//! best of 5 runs, and times writing the largest as MSH. Prints one line per case.
//!
//! cargo run --release --example bench_fem [DATA_DIR]

use geofit::fem::{mesh_fit, FemOptions};
use geofit::fit::{FitData, FitSpec, Fitter, Scheme};
use geofit::io::{read_path, to_msh_bytes};
use std::path::PathBuf;
use std::time::Instant;

fn fitted(dir: &std::path::Path, name: &str, scheme: Scheme) -> Box<dyn Fitter> {
    let file = read_path(&dir.join(name)).expect("read the scan");
    let mut fit = FitSpec::new(scheme)
        .build(&FitData::from(&file))
        .expect("set up the fit");
    fit.run().expect("fit");
    fit
}

fn main() {
    let dir = std::env::args()
        .nth(1)
        .map_or_else(|| PathBuf::from("/work/shared/data"), PathBuf::from);
    for (name, scheme) in [
        ("bun000.ply", Scheme::BsplineSurface),
        ("spot.obj", Scheme::CatmullClark),
    ] {
        let fit = fitted(&dir, name, scheme);
        for count in [10_000, 100_000, 390_000, 1_000_000] {
            let options = FemOptions::default().with_count(count);
            let mut best = f64::INFINITY;
            let mut last = None;
            for _ in 0..5 {
                let start = Instant::now();
                let fem = mesh_fit(fit.as_ref(), &options).expect("FEM mesh");
                best = best.min(start.elapsed().as_secs_f64());
                last = Some(fem);
            }
            let Some(fem) = last else { continue };
            let q = fem.quality();
            let start = Instant::now();
            let bytes = to_msh_bytes(fem.mesh()).expect("MSH");
            let write_s = start.elapsed().as_secs_f64();
            println!(
                "{name} {scheme}: {} quads, {} nodes: mesh {:.3} s ({:.2} M quads/s), MSH write {:.3} s ({:.1} MB); aspect mean {:.2}, skew max {:.1}°, Jacobian min {:.3}, inverted {} ({} on folds of the surface)",
                q.elements,
                q.nodes,
                best,
                q.elements as f64 / best / 1e6,
                write_s,
                bytes.len() as f64 / 1e6,
                q.aspect_mean,
                q.skew_max_deg,
                q.jacobian_min,
                q.inverted,
                q.inverted - q.inverted_off_folds
            );
        }
    }
}
