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
    scales: (f32, f32),
    points: (&[f32], &[f32], &[f32]),
    out: &mut [f32],
) -> usize {
    // A cell over a power of two is the cell times its inverse, bit for bit (both scale the
    // exponent alone), and a multiply costs a tenth of a divide.
    // SAFETY: as the caller guarantees.
    unsafe {
        if n.is_power_of_two() {
            lanes::<true>(volume, n, scales, points, out)
        } else {
            lanes::<false>(volume, n, scales, points, out)
        }
    }
}

/// [`noise`] with the cell's quotient by n a multiply when `POW2` (n is a power of two).
///
/// # Safety
/// As [`noise`]'s.
#[target_feature(enable = "avx512f")]
unsafe fn lanes<const POW2: bool>(
    volume: &[f32],
    n: usize,
    (scale, inv): (f32, f32),
    (x, y, z): (&[f32], &[f32], &[f32]),
    out: &mut [f32],
) -> usize {
    let nf = n as f32;
    let (nf_v, recip, top, zero) = (
        _mm512_set1_ps(nf),
        _mm512_set1_ps(1.0 / nf),
        _mm512_set1_ps((n - 1) as f32),
        _mm512_setzero_ps(),
    );
    let (n_i, plane_i, last, one) = (
        _mm512_set1_epi32(n as i32),
        _mm512_set1_epi32((n * n) as i32),
        _mm512_set1_epi32(n as i32 - 1),
        _mm512_set1_epi32(1),
    );
    let (scale_v, inv_v, half) = (
        _mm512_set1_ps(scale),
        _mm512_set1_ps(inv),
        _mm512_set1_ps(0.5),
    );
    // Where a pair (x0, x0 + 1) lands in one gather of 8 pairs, the first source's or the
    // second's: x0's values are the pairs' even floats, x1's the odd.
    let even = _mm512_setr_epi32(0, 2, 4, 6, 8, 10, 12, 14, 16, 18, 20, 22, 24, 26, 28, 30);
    let odd = _mm512_add_epi32(even, one);
    const FLOOR: i32 = _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC;
    // periodic_cell: the cell below, wrapped into [0, n) through f32, clamped (NaN to 0, as `as
    // usize` does: max returns its second operand when either is NaN), its upper neighbour, and
    // the fraction.
    let split = |c: __m512| {
        let cell = _mm512_roundscale_ps::<FLOOR>(c);
        let quotient = if POW2 {
            _mm512_mul_ps(cell, recip)
        } else {
            _mm512_div_ps(cell, nf_v)
        };
        let turns = _mm512_roundscale_ps::<FLOOR>(quotient);
        let r = _mm512_sub_ps(cell, _mm512_mul_ps(turns, nf_v));
        let i0 = _mm512_cvttps_epi32(_mm512_min_ps(_mm512_max_ps(r, zero), top));
        let next = _mm512_add_epi32(i0, one);
        let i1 = _mm512_maskz_mov_epi32(!_mm512_cmpeq_epi32_mask(next, n_i), next);
        (i0, i1, _mm512_sub_ps(c, cell))
    };
    let lerp =
        |a: __m512, b: __m512, t: __m512| _mm512_add_ps(a, _mm512_mul_ps(t, _mm512_sub_ps(b, a)));
    let base = volume.as_ptr();
    // SAFETY (both lookups): every index is below n³ (each cell below n), which the caller
    // guarantees the volume holds.
    let at = |row: __m512i, xi: __m512i| unsafe {
        _mm512_i32gather_ps::<4>(_mm512_add_epi32(row, xi), base)
    };
    // Both x corners of a row at once, as pairs of adjacent floats: half the gathered elements.
    // Only where no lane wraps (x0 < n − 1), so that x0 + 1 is x1 and lies inside the volume.
    let pairs = |row: __m512i, x0: __m512i| unsafe {
        let index = _mm512_add_epi32(row, x0);
        let low = _mm512_i32gather_pd::<4>(_mm512_castsi512_si256(index), base.cast());
        let high = _mm512_i32gather_pd::<4>(_mm512_extracti64x4_epi64::<1>(index), base.cast());
        let (low, high) = (_mm512_castpd_ps(low), _mm512_castpd_ps(high));
        (
            _mm512_permutex2var_ps(low, even, high),
            _mm512_permutex2var_ps(low, odd, high),
        )
    };
    // A vector's cells and fractions, and the rows and planes scaled to indices.
    let cells = |i: usize| {
        // SAFETY: i + 16 ≤ out.len(), the length of x, y and z too (the loops below).
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
        let ys = (_mm512_mullo_epi32(y0, n_i), _mm512_mullo_epi32(y1, n_i));
        let zs = (
            _mm512_mullo_epi32(z0, plane_i),
            _mm512_mullo_epi32(z1, plane_i),
        );
        let wraps = _mm512_cmpeq_epi32_mask(x0, last) != 0;
        (x0, x1, (fx, fy, fz), ys, zs, wraps)
    };
    type Cells = (
        __m512i,
        __m512i,
        (__m512, __m512, __m512),
        (__m512i, __m512i),
        (__m512i, __m512i),
        bool,
    );
    let value = |(x0, x1, (fx, fy, fz), (y0, y1), (z0, z1), wraps): Cells| {
        let plane = |zi: __m512i| {
            let (r0, r1) = (_mm512_add_epi32(zi, y0), _mm512_add_epi32(zi, y1));
            let (a, b, c, d) = if wraps {
                (at(r0, x0), at(r0, x1), at(r1, x0), at(r1, x1))
            } else {
                let ((a, b), (c, d)) = (pairs(r0, x0), pairs(r1, x0));
                (a, b, c, d)
            };
            lerp(lerp(a, b, fx), lerp(c, d, fx), fy)
        };
        lerp(plane(z0), plane(z1), fz)
    };
    // Two vectors at a time, both vectors' cells first: one vector's chain from coordinates
    // to gathered values is longer than the out-of-order window overlaps with the next's.
    let full = out.len() / LANES * LANES;
    let twos = full / (2 * LANES) * (2 * LANES);
    for i in (0..twos).step_by(2 * LANES) {
        let (c0, c1) = (cells(i), cells(i + LANES));
        let (s0, s1) = (value(c0), value(c1));
        // SAFETY: as the loads.
        unsafe {
            _mm512_storeu_ps(out.as_mut_ptr().add(i), s0);
            _mm512_storeu_ps(out.as_mut_ptr().add(i + LANES), s1);
        }
    }
    for i in (twos..full).step_by(LANES) {
        let s = value(cells(i));
        // SAFETY: as the loads.
        unsafe { _mm512_storeu_ps(out.as_mut_ptr().add(i), s) };
    }
    full
}
