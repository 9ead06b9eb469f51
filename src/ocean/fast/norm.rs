//! Row normalisation. `vsqrtps` plus `vdivps` cost more than all the waves' arithmetic, so the
//! AVX-512 path seeds with `vrsqrt14ps` and refines once with an error-compensated Newton step,
//! which is both faster and closer to the correctly rounded 1/√x than sqrt-then-divide.

use super::math::fma;

/// Slopes (∂f/∂x, ∂f/∂y) in `nx`, `ny` become unit normals (−∂f/∂x, −∂f/∂y, 1)/‖·‖.
#[inline(always)]
pub fn slopes<const F: bool>(nx: &mut [f32], ny: &mut [f32], nz: &mut [f32]) {
    for ((x, y), z) in nx.iter_mut().zip(ny.iter_mut()).zip(nz.iter_mut()) {
        let inv = 1.0 / fma::<F>(*x, *x, fma::<F>(*y, *y, 1.0)).sqrt();
        *x = -*x * inv;
        *y = -*y * inv;
        *z = inv;
    }
}

/// Summed face normals in `nx`, `ny`, `nz` become unit vectors, exactly as glam's
/// `normalize_or` would (the sums are never zero on a grid).
#[inline(always)]
pub fn sums(nx: &mut [f32], ny: &mut [f32], nz: &mut [f32]) {
    for ((x, y), z) in nx.iter_mut().zip(ny.iter_mut()).zip(nz.iter_mut()) {
        let inv = 1.0 / (*x * *x + *y * *y + *z * *z).sqrt();
        *x *= inv;
        *y *= inv;
        *z *= inv;
    }
}

#[cfg(target_arch = "x86_64")]
pub use avx512::{slopes_avx512, sums_avx512};

#[cfg(target_arch = "x86_64")]
mod avx512 {
    use std::arch::x86_64::*;

    /// Mask of the first min(left, 16) lanes.
    #[inline(always)]
    fn lanes(left: usize) -> __mmask16 {
        if left >= 16 {
            0xffff
        } else {
            (1u16 << left) - 1
        }
    }

    /// 1/√(x + x_lo) to about half an ulp: `vrsqrt14ps` (14 bits) then one Newton step whose
    /// residual 1 − x·r² is computed with the product's rounding error and x's low part.
    #[inline]
    #[target_feature(enable = "avx512f")]
    fn inv_sqrt(x: __m512, x_lo: __m512) -> __m512 {
        let one = _mm512_set1_ps(1.0);
        let r0 = _mm512_rsqrt14_ps(x);
        let u = _mm512_mul_ps(x, r0);
        let u_lo = _mm512_fmsub_ps(x, r0, u);
        let mut e = _mm512_fnmadd_ps(u, r0, one);
        e = _mm512_fnmadd_ps(u_lo, r0, e);
        e = _mm512_fnmadd_ps(_mm512_mul_ps(x_lo, r0), r0, e);
        _mm512_fmadd_ps(_mm512_mul_ps(r0, _mm512_set1_ps(0.5)), e, r0)
    }

    /// [`super::slopes`] 16 lanes at a time.
    ///
    /// # Safety
    /// The CPU must support AVX-512F.
    #[target_feature(enable = "avx512f")]
    pub fn slopes_avx512(nx: &mut [f32], ny: &mut [f32], nz: &mut [f32]) {
        let n = nx.len().min(ny.len()).min(nz.len());
        let one = _mm512_set1_ps(1.0);
        let zero = _mm512_setzero_ps();
        for j in (0..n).step_by(16) {
            // The row's tail goes through the same arithmetic under a mask, so every vertex gets
            // the same rounding.
            let k = lanes(n - j);
            // SAFETY: the mask `k` covers only lanes j..min(j + 16, n), inside all three slices.
            let (dx, dy) = unsafe {
                (
                    _mm512_maskz_loadu_ps(k, nx.as_ptr().add(j)),
                    _mm512_maskz_loadu_ps(k, ny.as_ptr().add(j)),
                )
            };
            let q = _mm512_fmadd_ps(dx, dx, _mm512_mul_ps(dy, dy));
            let x = _mm512_add_ps(one, q);
            // 1 + q loses q's low bits; Fast2Sum recovers them (q is small next to 1 here).
            let x_lo = _mm512_sub_ps(q, _mm512_sub_ps(x, one));
            let r = inv_sqrt(x, x_lo);
            let (ox, oy) = (_mm512_sub_ps(zero, dx), _mm512_sub_ps(zero, dy));
            // SAFETY: as for the loads.
            unsafe {
                _mm512_mask_storeu_ps(nx.as_mut_ptr().add(j), k, _mm512_mul_ps(ox, r));
                _mm512_mask_storeu_ps(ny.as_mut_ptr().add(j), k, _mm512_mul_ps(oy, r));
                _mm512_mask_storeu_ps(nz.as_mut_ptr().add(j), k, r);
            }
        }
    }

    /// [`super::sums`] 16 lanes at a time (to within an ulp of it).
    ///
    /// # Safety
    /// The CPU must support AVX-512F.
    #[target_feature(enable = "avx512f")]
    pub fn sums_avx512(nx: &mut [f32], ny: &mut [f32], nz: &mut [f32]) {
        let n = nx.len().min(ny.len()).min(nz.len());
        for j in (0..n).step_by(16) {
            let k = lanes(n - j);
            // SAFETY: the mask `k` covers only lanes j..min(j + 16, n), inside all three slices;
            // masked-off lanes load 1, which keeps their (discarded) arithmetic finite.
            let (x, y, z) = unsafe {
                (
                    _mm512_maskz_loadu_ps(k, nx.as_ptr().add(j)),
                    _mm512_maskz_loadu_ps(k, ny.as_ptr().add(j)),
                    _mm512_mask_loadu_ps(_mm512_set1_ps(1.0), k, nz.as_ptr().add(j)),
                )
            };
            let len2 = _mm512_fmadd_ps(x, x, _mm512_fmadd_ps(y, y, _mm512_mul_ps(z, z)));
            let r = inv_sqrt(len2, _mm512_setzero_ps());
            // SAFETY: as for the loads.
            unsafe {
                _mm512_mask_storeu_ps(nx.as_mut_ptr().add(j), k, _mm512_mul_ps(x, r));
                _mm512_mask_storeu_ps(ny.as_mut_ptr().add(j), k, _mm512_mul_ps(y, r));
                _mm512_mask_storeu_ps(nz.as_mut_ptr().add(j), k, _mm512_mul_ps(z, r));
            }
        }
    }
}
