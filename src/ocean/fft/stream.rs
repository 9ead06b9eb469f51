//! Non-temporal stores for the FFT ocean's row pass over fields too large for the caches: its
//! strips go to memory without each line first being read into the cache only to be
//! overwritten (a read for ownership), which past the caches is a second trip through memory
//! for every line written. The values are the same bits either way.
//!
//! The fill's mesh rows streamed the same way (made in cache, then copied with these stores)
//! were slower at 1024² and 2048² in results/bench-fft-scaling-20261128T173305Z, and are
//! written plainly.

use rustfft::num_complex::Complex;

/// The field size from which the row pass writes its strips with non-temporal stores. Past it
/// a step's strips no longer stay in the caches until the column pass reads them (the four
/// fields of a 1024² step are 32 MiB). Below it the column pass finds them in cache. On the
/// Intel Xeon VM the 512² step (2 MiB a field) was slower with the strips streamed in a quick
/// trial, the 1024² and 2048² steps faster (docs/fft-ocean.md, "What it computes").
pub const STREAM_FIELD_BYTES: usize = 8 << 20;

/// Whether an N×N field of complex f32 is past the caches ([`STREAM_FIELD_BYTES`]).
pub fn past_the_caches(n: usize) -> bool {
    n * n * std::mem::size_of::<Complex<f32>>() >= STREAM_FIELD_BYTES
}

/// `*to = *from` for one 64-byte-aligned cache line of eight complex f32.
#[inline(always)]
pub fn line(to: &mut [Complex<f32>; 8], from: &[Complex<f32>; 8]) {
    #[cfg(target_arch = "x86_64")]
    {
        debug_assert!(to.as_ptr().cast::<u8>().align_offset(64) == 0);
        let from = from.as_ptr().cast::<f32>();
        let to = to.as_mut_ptr().cast::<f32>();
        for k in 0..4 {
            // SAFETY: SSE is part of x86_64; both pointers cover the line's 16 f32, and `to`
            // is 64-byte aligned (the caller's), so each 16-byte store is aligned as
            // `_mm_stream_ps` requires.
            unsafe {
                use std::arch::x86_64::{_mm_loadu_ps, _mm_stream_ps};
                _mm_stream_ps(to.add(4 * k), _mm_loadu_ps(from.add(4 * k)));
            }
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        *to = *from;
    }
}

/// Orders the non-temporal stores before whatever reads their lines next: the next pass on this
/// thread, or another thread after a hand-off (whose release store alone does not order them).
#[inline(always)]
pub fn fence() {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: SSE is part of x86_64.
    unsafe {
        std::arch::x86_64::_mm_sfence()
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_from_1024_are_past_the_caches() {
        assert!(!past_the_caches(512));
        assert!(past_the_caches(1024));
    }
}
