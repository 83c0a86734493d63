//! Limit-surface evaluation rate: one million (patch, u, v) samples with first and second
//! derivatives on a QEM-decimated Stanford bunny (718 control points, 1,219 triangles, open,
//! most vertices extraordinary), for Loop, Catmull–Clark (on its quadrangulation) and
//! Doo–Sabin (one patch per face corner at an interior vertex).
//!
//! Run: `cargo bench --bench limit_eval`. Prints samples per second for each scheme. A plain
//! timing loop (no criterion) keeps the dev-dependencies and the build small.

use geofit::subdiv::{build, LimitSurface, PatchDomain, Scheme, SurfaceParam};
use std::hint::black_box;
use std::path::PathBuf;
use std::time::Instant;

const SAMPLES: usize = 1_000_000;

/// CPU time of this thread in seconds (Linux), so the figure means something on a busy machine;
/// `None` elsewhere.
fn thread_cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/thread-self/stat").ok()?;
    let after = &stat[stat.rfind(')')? + 2..];
    let fields: Vec<&str> = after.split_whitespace().collect();
    let ticks: f64 = fields.get(11)?.parse::<f64>().ok()? + fields.get(12)?.parse::<f64>().ok()?;
    Some(ticks / 100.0)
}

fn samples(surface: &dyn LimitSurface, n: usize) -> Vec<SurfaceParam> {
    let mut s: u64 = 0x2545_F491_4F6C_DD1D;
    let mut next = || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    let patches = surface.num_patches() as f64;
    (0..n)
        .map(|_| {
            let patch = ((next() * patches) as u32).min(surface.num_patches() as u32 - 1);
            let (mut u, mut v) = (next(), next());
            if surface.domain() == PatchDomain::Triangle && u + v > 1.0 {
                (u, v) = (1.0 - u, 1.0 - v);
            }
            SurfaceParam { patch, u, v }
        })
        .collect()
}

fn main() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/subdiv/bunny_coarse.obj");
    let mesh = match geofit::io::read_path(&path) {
        Ok(loaded) => loaded.mesh,
        Err(e) => {
            eprintln!("cannot read {}: {e}", path.display());
            return;
        }
    };
    for scheme in [Scheme::Loop, Scheme::CatmullClark, Scheme::DooSabin] {
        let start = Instant::now();
        let surface = match build(scheme, &mesh) {
            Ok(s) => s,
            Err(e) => {
                eprintln!("{scheme:?}: {e}");
                continue;
            }
        };
        let setup = start.elapsed().as_secs_f64();
        let params = samples(surface.as_ref(), SAMPLES);
        let mut acc = 0.0;
        for p in &params[..10_000] {
            acc += surface.eval(*p).point.x;
        }
        let start = Instant::now();
        let cpu0 = thread_cpu_seconds();
        for p in &params {
            let e = surface.eval(black_box(*p));
            acc += e.point.x + e.du.y + e.dvv.z;
        }
        let wall = start.elapsed().as_secs_f64();
        let cpu = cpu0
            .and_then(|c0| Some(thread_cpu_seconds()? - c0))
            .filter(|&c| c > 0.0);
        let secs = cpu.unwrap_or(wall);
        let mut stencil = Vec::new();
        let start = Instant::now();
        for p in &params[..100_000] {
            stencil.clear();
            surface.stencil(black_box(*p), &mut stencil);
            acc += stencil.len() as f64;
        }
        let stencil_secs = start.elapsed().as_secs_f64() * 10.0;
        println!(
            "{scheme:?}: {} patches, set-up {:.1} ms, eval with 1st+2nd derivatives: {:.2} M samples/s per core ({:.0} ns each; {:.2} s CPU, {:.2} s wall); stencil: {:.2} M/s (wall)  [{}]",
            surface.num_patches(),
            setup * 1e3,
            SAMPLES as f64 / secs / 1e6,
            secs / SAMPLES as f64 * 1e9,
            cpu.unwrap_or(f64::NAN),
            wall,
            SAMPLES as f64 / stencil_secs / 1e6,
            if acc.is_finite() { "ok" } else { "non-finite!" }
        );
    }
}
