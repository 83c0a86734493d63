//! Parse time of every shared scan, from bytes in memory (disk reads excluded).
//!
//! Run: `cargo bench --bench io_read` (set `GEOFIT_DATA` to point elsewhere than
//! `../shared/data`). Prints, per file, the median wall time of 15 parses and the median and
//! minimum CPU time of the parsing thread (Linux `/proc/thread-self/schedstat`; on a loaded
//! machine wall time includes waiting for a core, CPU time does not).

use std::path::PathBuf;
use std::time::{Duration, Instant};

fn data_dir() -> PathBuf {
    if let Some(dir) = std::env::var_os("GEOFIT_DATA") {
        return PathBuf::from(dir);
    }
    let beside = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/data");
    if beside.is_dir() {
        beside
    } else {
        PathBuf::from("/work/shared/data")
    }
}

/// Nanoseconds this thread has run on a CPU, where the kernel reports it.
fn cpu_ns() -> Option<u64> {
    let stat = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    stat.split_whitespace().next()?.parse().ok()
}

/// Median wall time, median CPU time and minimum CPU time of `runs` calls (CPU falls back to
/// wall time where the kernel gives no per-thread figure).
fn time<T>(runs: usize, mut f: impl FnMut() -> T) -> [Duration; 3] {
    let mut wall = Vec::with_capacity(runs);
    let mut cpu = Vec::with_capacity(runs);
    for _ in 0..runs {
        let (c0, start) = (cpu_ns(), Instant::now());
        std::hint::black_box(f());
        let elapsed = start.elapsed();
        wall.push(elapsed);
        cpu.push(match (c0, cpu_ns()) {
            (Some(a), Some(b)) => Duration::from_nanos(b - a),
            _ => elapsed,
        });
    }
    wall.sort();
    cpu.sort();
    [wall[runs / 2], cpu[runs / 2], cpu[0]]
}

fn main() {
    let dir = data_dir();
    let mut names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .filter_map(|e| e.ok().map(|e| e.file_name().to_string_lossy().into_owned()))
        .collect();
    names.sort();
    println!(
        "{:<24} {:>6} {:>9} {:>9} {:>9}",
        "file", "MB", "wall ms", "cpu ms", "min cpu"
    );
    for name in names {
        let bytes = std::fs::read(dir.join(&name)).expect("readable file");
        let parse = || geofit::io::read_bytes(&bytes, Some(&name)).expect("valid file");
        let mb = format!("{:.2}", bytes.len() as f64 / 1e6);
        report(&name, &mb, time(15, parse));
        if let Some(grid) = parse().range_grid {
            report(
                &format!("  {name} grid→tris"),
                "",
                time(15, || grid.triangles()),
            );
        }
    }
}

fn report(label: &str, mb: &str, [wall, cpu, min]: [Duration; 3]) {
    let ms = |d: Duration| d.as_secs_f64() * 1e3;
    println!(
        "{label:<24} {mb:>6} {:>9.1} {:>9.1} {:>9.1}",
        ms(wall),
        ms(cpu),
        ms(min)
    );
}
