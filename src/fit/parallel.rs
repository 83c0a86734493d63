//! Data-parallel loops over the points of a fit, on scoped standard-library threads.
//!
//! Only work whose result per point does not depend on how the points are split is run here
//! (foot points, one per data point), so a fit gives the same numbers on one thread or many.
//! The browser build (wasm32, no threads) runs everything on the calling thread. The thread
//! count is the machine's available parallelism, or `GEOFIT_THREADS` when set (1 makes every
//! fit single-threaded, as the benchmarks against single-threaded peers do).

use std::sync::OnceLock;

/// Below this many items per thread, spawning costs more than it saves.
const MIN_ITEMS_PER_THREAD: usize = 2048;

/// Threads to use for `items` independent items.
fn threads_for(items: usize) -> usize {
    max_threads().min(items / MIN_ITEMS_PER_THREAD).max(1)
}

/// `GEOFIT_THREADS` if it is a positive number, else the available parallelism (1 on wasm32).
fn max_threads() -> usize {
    static MAX: OnceLock<usize> = OnceLock::new();
    *MAX.get_or_init(|| {
        if cfg!(target_arch = "wasm32") {
            return 1;
        }
        let given = std::env::var("GEOFIT_THREADS")
            .ok()
            .and_then(|v| v.trim().parse::<usize>().ok())
            .filter(|&n| n > 0);
        given.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
    })
}

/// Calls `f` on matching chunks of `a`, `b` and `c` (all of `a`'s length), in parallel when
/// there are enough items; `f` sees each item exactly once.
pub(crate) fn zip_chunks<A, B, C, F>(a: &[A], b: &mut [B], c: &mut [C], f: F)
where
    A: Sync,
    B: Send,
    C: Send,
    F: Fn(&[A], &mut [B], &mut [C]) + Sync,
{
    assert!(
        b.len() == a.len() && c.len() == a.len(),
        "chunks of unequal slices"
    );
    let threads = threads_for(a.len());
    if threads <= 1 {
        f(a, b, c);
        return;
    }
    let size = a.len().div_ceil(threads);
    let f = &f;
    std::thread::scope(|scope| {
        let chunks = a
            .chunks(size)
            .zip(b.chunks_mut(size))
            .zip(c.chunks_mut(size));
        for ((a, b), c) in chunks {
            scope.spawn(move || f(a, b, c));
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_item_is_visited_once() {
        for n in [0, 1, 2047, 2048, 10_000, 100_001] {
            let a: Vec<usize> = (0..n).collect();
            let mut b = vec![0usize; n];
            let mut c = vec![0usize; n];
            zip_chunks(&a, &mut b, &mut c, |a, b, c| {
                for ((x, y), z) in a.iter().zip(b.iter_mut()).zip(c.iter_mut()) {
                    *y += x * 2;
                    *z += 1;
                }
            });
            assert!(b.iter().enumerate().all(|(i, &y)| y == 2 * i), "n {n}");
            assert!(c.iter().all(|&z| z == 1), "n {n}");
        }
    }
}
