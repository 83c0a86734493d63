//! Data-parallel loops over the points of a fit, on scoped standard-library threads.
//!
//! Only work whose result per point does not depend on how the points are split is run here
//! (foot points, one per data point), so a fit gives the same numbers on one thread or many.
//! The browser build (wasm32, no threads) runs everything on the calling thread. The thread
//! count is the machine's available parallelism, or `GEOFIT_THREADS` when set, or what
//! [`set_max_threads`] fixed first (the CLI's `--threads`); 1 makes every fit
//! single-threaded, as the benchmarks against single-threaded peers do.

use std::sync::OnceLock;

/// The thread count, fixed at its first use.
static MAX: OnceLock<usize> = OnceLock::new();

/// Below this many items per thread, spawning costs more than it saves.
const MIN_ITEMS_PER_THREAD: usize = 2048;

/// Threads to use for `items` independent items.
fn threads_for(items: usize) -> usize {
    max_threads().min(items / MIN_ITEMS_PER_THREAD).max(1)
}

/// Fixes the number of threads every parallel loop of this process uses (at least 1; wasm32
/// always uses 1). Returns `false`, changing nothing, when the count was already fixed: by an
/// earlier call, or by a parallel loop that ran before. Results do not depend on the count.
pub fn set_max_threads(n: usize) -> bool {
    MAX.set(n.max(1)).is_ok()
}

/// What [`set_max_threads`] fixed, else `GEOFIT_THREADS` if it is a positive number, else the
/// available parallelism (1 on wasm32).
pub fn max_threads() -> usize {
    if cfg!(target_arch = "wasm32") {
        return 1;
    }
    *MAX.get_or_init(|| {
        let given = std::env::var("GEOFIT_THREADS")
            .ok()
            .and_then(|v| v.trim().parse::<usize>().ok())
            .filter(|&n| n > 0);
        given.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
    })
}

/// Chunks per thread of [`map`] and [`fill`]: the threads claim chunks as they finish the
/// last, so a part of the items that costs more (the densely sampled patches of a surface
/// → data measure come last) is shared too. Each item's result is its own, so how the items
/// are chunked changes nothing but the time.
const CHUNKS_PER_THREAD: usize = 8;

/// Runs `work(k, chunk)` on every chunk `k` of `chunks` on `threads` threads (the calling
/// thread's scope), each claiming the next chunk not yet taken.
fn claim_chunks<C, W>(chunks: Vec<C>, threads: usize, work: W)
where
    C: Send,
    W: Fn(usize, C) + Sync,
{
    use std::sync::atomic::{AtomicUsize, Ordering};
    use std::sync::Mutex;
    let slots: Vec<Mutex<Option<C>>> = chunks.into_iter().map(|c| Mutex::new(Some(c))).collect();
    let next = AtomicUsize::new(0);
    let (slots, next, work) = (&slots, &next, &work);
    std::thread::scope(|scope| {
        for _ in 0..threads {
            scope.spawn(move || loop {
                let k = next.fetch_add(1, Ordering::Relaxed);
                let Some(slot) = slots.get(k) else { break };
                let chunk = slot.lock().map(|mut c| c.take()).unwrap_or(None);
                if let Some(chunk) = chunk {
                    work(k, chunk);
                }
            });
        }
    });
}

/// The chunk size for `len` items on `threads` threads.
fn chunk_size(len: usize, threads: usize) -> usize {
    len.div_ceil(threads * CHUNKS_PER_THREAD).max(1)
}

/// `f` of every item of `items`, in order, in parallel when there are enough of them.
pub(crate) fn map<A, T, F>(items: &[A], f: F) -> Vec<T>
where
    A: Sync,
    T: Send,
    F: Fn(&A) -> T + Sync,
{
    let threads = threads_for(items.len());
    if threads <= 1 {
        return items.iter().map(f).collect();
    }
    let size = chunk_size(items.len(), threads);
    let parts: Vec<std::sync::Mutex<Vec<T>>> = items
        .chunks(size)
        .map(|_| std::sync::Mutex::new(Vec::new()))
        .collect();
    claim_chunks(items.chunks(size).collect(), threads, |k, chunk: &[A]| {
        let done: Vec<T> = chunk.iter().map(&f).collect();
        if let Ok(mut part) = parts[k].lock() {
            *part = done;
        }
    });
    let mut out = Vec::with_capacity(items.len());
    for part in parts {
        out.extend(part.into_inner().unwrap_or_default());
    }
    out
}

/// Sets every item of `out` to `f` of its index, in parallel when there are enough items.
pub(crate) fn fill<T, F>(out: &mut [T], f: F)
where
    T: Send,
    F: Fn(usize) -> T + Sync,
{
    let threads = threads_for(out.len());
    if threads <= 1 {
        for (i, o) in out.iter_mut().enumerate() {
            *o = f(i);
        }
        return;
    }
    let size = chunk_size(out.len(), threads);
    claim_chunks(
        out.chunks_mut(size).collect(),
        threads,
        |k, chunk: &mut [T]| {
            for (i, o) in chunk.iter_mut().enumerate() {
                *o = f(k * size + i);
            }
        },
    );
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
    let size = chunk_size(a.len(), threads);
    let chunks = a
        .chunks(size)
        .zip(b.chunks_mut(size))
        .zip(c.chunks_mut(size));
    claim_chunks(chunks.collect(), threads, |_, ((a, b), c)| f(a, b, c));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn map_and_fill_keep_the_order() {
        for n in [0, 1, 2047, 2048, 10_000, 100_001] {
            let a: Vec<usize> = (0..n).collect();
            let squares = map(&a, |&x| x * x);
            assert_eq!(squares, a.iter().map(|x| x * x).collect::<Vec<_>>());
            let mut b = vec![0usize; n];
            fill(&mut b, |i| 3 * i + 1);
            assert!(b.iter().enumerate().all(|(i, &x)| x == 3 * i + 1));
        }
    }

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
