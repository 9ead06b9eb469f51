//! The sampled spectrum in the transforms' layout, and its value at time t: the packed spectra
//! each frame's transforms start from. The time step is written to vectorise: the phase ωt is
//! reduced to a quarter turn in f64 without a libm call and its sine and cosine are f32
//! polynomials, so one code path runs 8 or 16 wave vectors at a time on AVX2 or AVX-512 and
//! gives the same bits on every instruction set (no fused multiply-add is ever formed).

use super::spectrum::Spectrum;
use rustfft::num_complex::Complex;
use std::f64::consts::FRAC_PI_2;
use std::ops::Range;

/// The sampled spectrum in the transforms' layout (b·N + a, see [`super::transform::Inverse2d`]),
/// in f32 but for ω, kept in f64 so that ωt keeps its fraction of a turn at large t.
#[derive(Clone, Debug)]
pub struct Terms {
    /// Wavenumber of each index (the same for x and y: the patch is square).
    k: Vec<f32>,
    /// h̃₀(k).
    h0: Vec<Complex<f32>>,
    /// conj(h̃₀(−k)).
    h0_minus: Vec<Complex<f32>>,
    omega: Vec<f64>,
    /// 1/|k| (0 at k = 0).
    inv_k: Vec<f32>,
    /// ∂Dx/∂y shares a transform with h, which is larger by about |k|⁻¹ and would drown it in
    /// the transform's rounding: it is packed times this power of two, near h's RMS over its.
    pub dxy_scale: f32,
}

impl Terms {
    /// The spectrum's terms, transposed.
    pub fn new(spectrum: &Spectrum) -> Self {
        let n = spectrum.n();
        let transposed = |f: &dyn Fn(usize, usize) -> Complex<f64>| -> Vec<Complex<f32>> {
            (0..n)
                .flat_map(|b| (0..n).map(move |a| (a, b)))
                .map(|(a, b)| {
                    let c = f(a, b);
                    Complex::new(c.re as f32, c.im as f32)
                })
                .collect()
        };
        let inv_k = transposed(&|a, b| {
            let (kx, ky) = spectrum.wave_vector(a, b);
            let k = kx.hypot(ky);
            Complex::new(if k > 0.0 { 1.0 / k } else { 0.0 }, 0.0)
        });
        let (mut h_power, mut dxy_power) = (0.0, 0.0);
        for a in 0..n {
            for b in 0..n {
                let (kx, ky) = spectrum.wave_vector(a, b);
                let p = spectrum.h0(a, b).norm_sqr();
                h_power += p;
                dxy_power += p * (kx * ky).powi(2) / (kx * kx + ky * ky).max(f64::MIN_POSITIVE);
            }
        }
        let ratio = (h_power / dxy_power).sqrt();
        let dxy_scale = if ratio.is_finite() && ratio > 0.0 {
            2f32.powi(ratio.log2().round().clamp(-60.0, 60.0) as i32)
        } else {
            1.0
        };
        Terms {
            dxy_scale,
            k: (0..n)
                .map(|m| spectrum.wave_vector(0, m).0 as f32)
                .collect(),
            h0: transposed(&|a, b| spectrum.h0(a, b)),
            h0_minus: transposed(&|a, b| spectrum.h0_minus(a, b)),
            omega: (0..n)
                .flat_map(|b| (0..n).map(move |a| (a, b)))
                .map(|(a, b)| spectrum.omega(a, b))
                .collect(),
            inv_k: inv_k.into_iter().map(|c| c.re).collect(),
        }
    }

    /// h̃(k, t) of element e alone, unpacked.
    #[cfg(test)]
    pub fn coefficient(&self, e: usize, t: f64) -> Complex<f32> {
        coefficient(self.h0[e], self.h0_minus[e], self.omega[e], t)
    }

    /// The first `out.len()` (2 or 4) packed spectra at time t of the transposed rows `rows`
    /// (x-wavenumber indices), row `rows.start` at the start of each of `out`: (h, ∂Dx/∂y ·
    /// [`Terms::dxy_scale`]), (Dx, Dy), (∂h/∂x, ∂h/∂y), (∂Dx/∂x, ∂Dy/∂y).
    pub fn spectra(&self, t: f32, rows: Range<usize>, out: &mut [&mut [Complex<f32>]]) {
        #[cfg(target_arch = "x86_64")]
        {
            if is_x86_feature_detected!("avx512f") && is_x86_feature_detected!("avx512dq") {
                // SAFETY: the CPU has AVX-512F and DQ, checked above.
                return unsafe { self.spectra_avx512(t, rows, out) };
            }
            if is_x86_feature_detected!("avx2") {
                // SAFETY: the CPU has AVX2, checked above.
                return unsafe { self.spectra_avx2(t, rows, out) };
            }
        }
        self.spectra_rows(t, rows, out)
    }

    /// `spectra_rows` compiled for AVX-512.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx512dq,avx2")]
    fn spectra_avx512(&self, t: f32, rows: Range<usize>, out: &mut [&mut [Complex<f32>]]) {
        self.spectra_rows(t, rows, out)
    }

    /// `spectra_rows` compiled for AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn spectra_avx2(&self, t: f32, rows: Range<usize>, out: &mut [&mut [Complex<f32>]]) {
        self.spectra_rows(t, rows, out)
    }

    #[inline(always)]
    fn spectra_rows(&self, t: f32, rows: Range<usize>, out: &mut [&mut [Complex<f32>]]) {
        let n = self.k.len();
        let t = t as f64;
        let scale = self.dxy_scale;
        for (r, b) in rows.enumerate() {
            let kx = self.k[b];
            let e = b * n..(b + 1) * n;
            let (h0, h0m) = (&self.h0[e.clone()], &self.h0_minus[e.clone()]);
            let (omega, inv_k) = (&self.omega[e.clone()], &self.inv_k[e]);
            let o = r * n..(r + 1) * n;
            match out {
                [f0, f1] => {
                    let (f0, f1) = (&mut f0[o.clone()], &mut f1[o]);
                    for a in 0..n {
                        let h = coefficient(h0[a], h0m[a], omega[a], t);
                        let (ky, ik) = (self.k[a], inv_k[a]);
                        f0[a] = h * Complex::new(1.0, kx * ky * ik * scale);
                        f1[a] = h * Complex::new(ky * ik, -kx * ik);
                    }
                }
                [f0, f1, f2, f3] => {
                    let (f0, f1) = (&mut f0[o.clone()], &mut f1[o.clone()]);
                    let (f2, f3) = (&mut f2[o.clone()], &mut f3[o]);
                    for a in 0..n {
                        let h = coefficient(h0[a], h0m[a], omega[a], t);
                        let (ky, ik) = (self.k[a], inv_k[a]);
                        f0[a] = h * Complex::new(1.0, kx * ky * ik * scale);
                        f1[a] = h * Complex::new(ky * ik, -kx * ik);
                        f2[a] = h * Complex::new(-ky, kx);
                        f3[a] = h * Complex::new(kx * kx * ik, ky * ky * ik);
                    }
                }
                _ => unreachable!("2 or 4 fields"),
            }
        }
    }
}

/// h̃(k, t) = h̃₀(k)·e^{iωt} + conj(h̃₀(−k))·e^{−iωt}.
#[inline(always)]
pub fn coefficient(h0: Complex<f32>, h0_minus: Complex<f32>, omega: f64, t: f64) -> Complex<f32> {
    let turn = unit(omega * t);
    h0 * turn + h0_minus * turn.conj()
}

/// e^{iθ} in f32 for any θ below 2⁵⁰ rad: θ = q·π/2 + r with q the nearest integer and
/// |r| ≤ π/4 (in f64, where π/2's rounding costs q·1e-16 rad), then Cephes' sinf and cosf
/// polynomials on r (within 1e-7 of the true values) and q's quadrant applied by swapping and
/// sign bits. Branch-free, so it vectorises.
#[inline(always)]
pub fn unit(theta: f64) -> Complex<f32> {
    // Adding 1.5·2⁵² rounds to an integer in the low mantissa bits, where q mod 4 is read.
    const ROUND: f64 = 6_755_399_441_055_744.0;
    let shifted = theta * (1.0 / FRAC_PI_2) + ROUND;
    let q = shifted - ROUND;
    let quadrant = shifted.to_bits() as u32;
    let r = (theta - q * FRAC_PI_2) as f32;
    let z = r * r;
    let sin = ((-1.951_529_6e-4 * z + 8.332_161e-3) * z - 1.666_665_5e-1) * z * r + r;
    let cos = ((2.443_315_7e-5 * z - 1.388_731_6e-3) * z + 4.166_664_6e-2) * z * z - 0.5 * z + 1.0;
    // Quadrants 1 and 3 swap sine and cosine; 2 and 3 negate the sine, 1 and 2 the cosine.
    let swap = quadrant & 1 != 0;
    let (s, c) = if swap { (cos, sin) } else { (sin, cos) };
    let sin_sign = (quadrant & 2) << 30;
    let cos_sign = (quadrant.wrapping_add(1) & 2) << 30;
    Complex::new(
        f32::from_bits(c.to_bits() ^ cos_sign),
        f32::from_bits(s.to_bits() ^ sin_sign),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_unit_turn_is_within_2e_7_of_sine_and_cosine_everywhere() {
        let mut worst = 0.0f64;
        let mut theta = -3.0e4;
        while theta < 3.0e4 {
            let got = unit(theta);
            let (s, c) = theta.sin_cos();
            worst = worst.max((got.re as f64 - c).abs().max((got.im as f64 - s).abs()));
            theta += 0.0123;
        }
        for theta in [0.0, FRAC_PI_2, -FRAC_PI_2, std::f64::consts::PI, 1e9 + 0.5] {
            let got = unit(theta);
            let (s, c) = theta.sin_cos();
            worst = worst.max((got.re as f64 - c).abs().max((got.im as f64 - s).abs()));
        }
        assert!(worst < 2e-7, "{worst:e}");
    }
}
