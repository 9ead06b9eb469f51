//! Non-temporal stores for the FFT ocean's passes over fields too large for the caches: the
//! row pass's strips and the fill's mesh rows go to memory without each line first being read
//! into the cache only to be overwritten (a read for ownership), which past the caches is a
//! second trip through memory for every line written. The values are the same bits either way.

use rustfft::num_complex::Complex;

/// The field size from which the passes write with non-temporal stores. Past it a step's
/// fields, their strips and the mesh no longer stay in the caches until they are read again
/// (the four fields of a 1024² step are 32 MiB; its mesh rows 36 MiB). Below it the next pass
/// finds them in cache. On the Intel Xeon VM the 512² step (2 MiB a field) was slower with the
/// strips streamed in a quick trial, the 1024² and 2048² steps faster (docs/fft-ocean.md, "What
/// it computes").
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

/// `to.copy_from_slice(from)`, the 16-byte-aligned middle of `to` with non-temporal stores.
#[inline(always)]
pub fn copy(to: &mut [f32], from: &[f32]) {
    assert_eq!(to.len(), from.len(), "slices of one length");
    #[cfg(target_arch = "x86_64")]
    {
        // align_offset may decline (usize::MAX): then every value goes the plain way.
        let head = to.as_ptr().align_offset(16).min(to.len());
        let body = head + (to.len() - head) / 4 * 4;
        to[..head].copy_from_slice(&from[..head]);
        for k in (head..body).step_by(4) {
            // SAFETY: SSE is part of x86_64; k + 4 ≤ body ≤ the slices' length, and to[k] is
            // 16-byte aligned (head aligns it, steps of four f32 keep it).
            unsafe {
                use std::arch::x86_64::{_mm_loadu_ps, _mm_stream_ps};
                _mm_stream_ps(to.as_mut_ptr().add(k), _mm_loadu_ps(from.as_ptr().add(k)));
            }
        }
        to[body..].copy_from_slice(&from[body..]);
    }
    #[cfg(not(target_arch = "x86_64"))]
    to.copy_from_slice(from);
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
    fn a_streamed_copy_is_the_copy_at_every_offset_and_length() {
        let from: Vec<f32> = (0..67).map(|k| k as f32 * 0.5 - 3.0).collect();
        for start in 0..4 {
            for len in [0, 1, 3, 4, 5, 16, 17, 63] {
                let mut to = vec![f32::NAN; 67];
                copy(&mut to[start..start + len], &from[start..start + len]);
                fence();
                assert!(
                    to[start..start + len] == from[start..start + len],
                    "{start} {len}"
                );
                assert!(to[..start]
                    .iter()
                    .chain(&to[start + len..])
                    .all(|v| v.is_nan()));
            }
        }
    }

    #[test]
    fn fields_from_1024_are_past_the_caches() {
        assert!(!past_the_caches(512));
        assert!(past_the_caches(1024));
    }
}
