//! Cache prefetch hints for reads that hardware prefetching cannot foresee: the simplifier's
//! corners and faces, and the next foot point's patch data. A no-op off x86-64 (the browser
//! build).

/// Bytes of one cache line.
const LINE: usize = 64;

/// Asks the processor to load the cache lines of `x` without waiting for them (its first and
/// last byte: for values of up to two lines).
#[inline]
pub(crate) fn prefetch<T>(x: &T) {
    let first = (x as *const T).cast::<u8>();
    hint(first);
    hint(first.wrapping_add(std::mem::size_of::<T>().saturating_sub(1)));
}

/// Asks the processor to load every cache line of `xs` without waiting for them.
#[inline]
pub(crate) fn prefetch_slice<T>(xs: &[T]) {
    let first = xs.as_ptr().cast::<u8>();
    let bytes = std::mem::size_of_val(xs);
    for offset in (0..bytes).step_by(LINE) {
        hint(first.wrapping_add(offset));
    }
    if bytes > 0 {
        hint(first.wrapping_add(bytes - 1));
    }
}

#[inline(always)]
fn hint(at: *const u8) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        // SAFETY: a prefetch is a hint that never faults nor reads into the program (any
        // address will do), and SSE, which provides it, is part of every x86-64 processor.
        unsafe { _mm_prefetch::<_MM_HINT_T0>(at.cast::<i8>()) };
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = at;
}
