//! The fog coefficient pass's noise lookups sixteen vertices at a time with AVX-512's gathers:
//! LLVM leaves the trilinear lookup scalar even when unchecked (its cost model without a CPU to
//! tune for rates gathers dear), and one vertex at a time it was about half the pass.
//!
//! Each lane does [`super::coefficient::sample`]'s IEEE operations in its order (no fused
//! multiply-add, the cell wrapped as `grid::periodic_cell` does), so the noise is the same bit
//! for bit as the scalar lookup's (tested there).

use std::arch::x86_64::*;

/// Lanes of one pass.
const LANES: usize = 16;

/// The volume's noise at each point (x, y, z) into `out`, for the leading multiple of 16 points;
/// returns how many it did, the rest left to the scalar lookup.
///
/// # Safety
/// The CPU has AVX-512F; `volume` holds n³ values and n³ fits an `i32`; `x`, `y`, `z` and `out`
/// have one length.
#[target_feature(enable = "avx512f")]
pub unsafe fn noise(
    volume: &[f32],
    n: usize,
    (scale, inv): (f32, f32),
    (x, y, z): (&[f32], &[f32], &[f32]),
    out: &mut [f32],
) -> usize {
    let nf = n as f32;
    let (nf_v, top, zero) = (
        _mm512_set1_ps(nf),
        _mm512_set1_ps((n - 1) as f32),
        _mm512_setzero_ps(),
    );
    let (n_i, one) = (_mm512_set1_epi32(n as i32), _mm512_set1_epi32(1));
    let (scale_v, inv_v, half) = (
        _mm512_set1_ps(scale),
        _mm512_set1_ps(inv),
        _mm512_set1_ps(0.5),
    );
    const FLOOR: i32 = _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC;
    // periodic_cell: the cell below, wrapped into [0, n) through f32, clamped (NaN to 0, as `as
    // usize` does: max returns its second operand when either is NaN), its upper neighbour, and
    // the fraction.
    let split = |c: __m512| {
        let cell = _mm512_roundscale_ps::<FLOOR>(c);
        let turns = _mm512_roundscale_ps::<FLOOR>(_mm512_div_ps(cell, nf_v));
        let r = _mm512_sub_ps(cell, _mm512_mul_ps(turns, nf_v));
        let i0 = _mm512_cvttps_epi32(_mm512_min_ps(_mm512_max_ps(r, zero), top));
        let next = _mm512_add_epi32(i0, one);
        let i1 = _mm512_maskz_mov_epi32(!_mm512_cmpeq_epi32_mask(next, n_i), next);
        (i0, i1, _mm512_sub_ps(c, cell))
    };
    let lerp =
        |a: __m512, b: __m512, t: __m512| _mm512_add_ps(a, _mm512_mul_ps(t, _mm512_sub_ps(b, a)));
    let base = volume.as_ptr();
    let at = |xi: __m512i, yi: __m512i, zi: __m512i| {
        let row = _mm512_add_epi32(_mm512_mullo_epi32(zi, n_i), yi);
        let index = _mm512_add_epi32(_mm512_mullo_epi32(row, n_i), xi);
        // SAFETY: every index is below n³ (each cell below n), which the caller guarantees the
        // volume holds.
        unsafe { _mm512_i32gather_ps::<4>(index, base) }
    };
    let full = out.len() / LANES * LANES;
    for i in (0..full).step_by(LANES) {
        // SAFETY: i + 16 ≤ out.len(), the length of x, y and z too.
        let (px, py, pz) = unsafe {
            (
                _mm512_loadu_ps(x.as_ptr().add(i)),
                _mm512_loadu_ps(y.as_ptr().add(i)),
                _mm512_loadu_ps(z.as_ptr().add(i)),
            )
        };
        let u = _mm512_mul_ps(px, scale_v);
        let v = _mm512_mul_ps(py, scale_v);
        let w = _mm512_mul_ps(_mm512_add_ps(_mm512_mul_ps(pz, inv_v), half), scale_v);
        let ((x0, x1, fx), (y0, y1, fy), (z0, z1, fz)) = (split(u), split(v), split(w));
        let plane = |zi: __m512i| {
            lerp(
                lerp(at(x0, y0, zi), at(x1, y0, zi), fx),
                lerp(at(x0, y1, zi), at(x1, y1, zi), fx),
                fy,
            )
        };
        let s = lerp(plane(z0), plane(z1), fz);
        // SAFETY: as the loads.
        unsafe { _mm512_storeu_ps(out.as_mut_ptr().add(i), s) };
    }
    full
}
