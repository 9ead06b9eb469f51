//! The sampled spectrum: h̃₀(k) drawn once from the Phillips spectrum and the seed, the wave
//! vectors and frequencies of an N×N grid, h̃(k, t), and the direct f64 sum of every field the
//! transforms compute, kept as their oracle.

use crate::ocean::phillips::FftParams;
use crate::stats::SplitMix64;
use rustfft::num_complex::Complex;
use std::f64::consts::TAU;

/// h̃₀ and ω on an N×N grid of wave vectors, in f64. Index (a, b): a the y-wavenumber index, b
/// the x one, both in FFT order (0, 1, …, N/2 − 1, −N/2, …, −1).
#[derive(Clone, Debug)]
pub struct Spectrum {
    n: usize,
    /// Wavenumber 2π·m'/L of each index m (m' its signed value).
    k: Vec<f64>,
    /// h̃₀ at a·N + b; zero at k = 0 and on the Nyquist row and column, which have no −k of
    /// their own, so every field's spectrum is Hermitian and its transform real.
    h0: Vec<Complex<f64>>,
    /// ω(|k|) at a·N + b.
    omega: Vec<f64>,
}

impl Spectrum {
    /// Samples h̃₀(k) = (ξr + iξi)·√(P(k)/2), ξ standard normal draws from the seed, one pair per
    /// grid point in row-major order (drawn even where h̃₀ is zero, so each point's draw does not
    /// depend on which others are kept).
    pub fn new(params: &FftParams, n: usize) -> Self {
        let k = wavenumbers(params, n);
        let mut rng = SplitMix64(params.seed);
        let h0 = (0..n * n)
            .map(|e| {
                let (xi_r, xi_i) = gaussian_pair(&mut rng);
                let amp = (params.phillips(k[e % n], k[e / n]) / 2.0).sqrt();
                Complex::new(xi_r * amp, xi_i * amp)
            })
            .collect();
        Self::with_amplitudes(params, n, h0)
    }

    /// The spectrum with the given h̃₀ at a·N + b (a hand-made sea, such as one mode), its
    /// Nyquist row and column and k = 0 set to zero.
    pub fn with_amplitudes(params: &FftParams, n: usize, mut h0: Vec<Complex<f64>>) -> Self {
        assert_eq!(h0.len(), n * n, "one amplitude per grid point");
        let k = wavenumbers(params, n);
        let mut omega = Vec::with_capacity(n * n);
        for (e, h) in h0.iter_mut().enumerate() {
            let (a, b) = (e / n, e % n);
            if a == n / 2 || b == n / 2 || e == 0 {
                *h = Complex::default();
            }
            omega.push(params.omega(k[b].hypot(k[a])));
        }
        Spectrum { n, k, h0, omega }
    }

    /// Vertices per side.
    pub fn n(&self) -> usize {
        self.n
    }

    /// The wave vector (kx, ky) of index (a, b), in rad/m.
    pub fn wave_vector(&self, a: usize, b: usize) -> (f64, f64) {
        (self.k[b], self.k[a])
    }

    /// ω of index (a, b), in rad/s.
    pub fn omega(&self, a: usize, b: usize) -> f64 {
        self.omega[a * self.n + b]
    }

    /// h̃₀ of index (a, b).
    pub fn h0(&self, a: usize, b: usize) -> Complex<f64> {
        self.h0[a * self.n + b]
    }

    /// conj(h̃₀(−k)) of index (a, b): the partner term of h̃(k, t).
    pub fn h0_minus(&self, a: usize, b: usize) -> Complex<f64> {
        let n = self.n;
        self.h0[((n - a) % n) * n + (n - b) % n].conj()
    }

    /// h̃(k, t) = h̃₀(k)·e^{iωt} + conj(h̃₀(−k))·e^{−iωt}.
    pub fn coefficient(&self, a: usize, b: usize, t: f64) -> Complex<f64> {
        let turn = Complex::from_polar(1.0, self.omega(a, b) * t);
        self.h0(a, b) * turn + self.h0_minus(a, b) * turn.conj()
    }

    /// Σ_k |h̃(k, t)|²: by Parseval, the mean of h² over the grid (the heights' mean is h̃(0) = 0).
    pub fn power(&self, t: f64) -> f64 {
        let n = self.n;
        (0..n)
            .flat_map(|a| (0..n).map(move |b| (a, b)))
            .map(|(a, b)| self.coefficient(a, b, t).norm_sqr())
            .sum()
    }

    /// The oracle: every field at (x, y, t) by the direct f64 sum over every wave vector,
    /// [h, Dx, Dy, ∂h/∂x, ∂h/∂y, ∂Dx/∂x, ∂Dy/∂y, ∂Dx/∂y], the displacements before λ scales them.
    pub fn fields_f64(&self, x: f64, y: f64, t: f64) -> [f64; 8] {
        let n = self.n;
        let mut sum = [0.0; 8];
        for a in 0..n {
            for b in 0..n {
                let (kx, ky) = self.wave_vector(a, b);
                let k = kx.hypot(ky);
                if k == 0.0 {
                    continue;
                }
                let h = self.coefficient(a, b, t) * Complex::from_polar(1.0, kx * x + ky * y);
                let i = Complex::i();
                let terms = [
                    h,
                    -i * (kx / k) * h,
                    -i * (ky / k) * h,
                    i * kx * h,
                    i * ky * h,
                    h * (kx * kx / k),
                    h * (ky * ky / k),
                    h * (kx * ky / k),
                ];
                for (s, term) in sum.iter_mut().zip(terms) {
                    *s += term.re;
                }
            }
        }
        sum
    }
}

/// The wavenumber 2π·m'/L of each FFT index m (m' its signed value).
fn wavenumbers(params: &FftParams, n: usize) -> Vec<f64> {
    (0..n)
        .map(|m| {
            let signed = if m < n / 2 {
                m as f64
            } else {
                m as f64 - n as f64
            };
            TAU * signed / params.patch_metres
        })
        .collect()
}

/// Two independent standard normal draws (Box-Muller).
fn gaussian_pair(rng: &mut SplitMix64) -> (f64, f64) {
    let unit = |v: u64| ((v >> 11) as f64 + 0.5) / (1u64 << 53) as f64;
    let (u1, u2) = (unit(rng.next_u64()), unit(rng.next_u64()));
    let r = (-2.0 * u1.ln()).sqrt();
    let (s, c) = (TAU * u2).sin_cos();
    (r * c, r * s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_draws_are_standard_normal() {
        let mut rng = SplitMix64(7);
        let draws: Vec<f64> = (0..20_000)
            .flat_map(|_| {
                let (a, b) = gaussian_pair(&mut rng);
                [a, b]
            })
            .collect();
        let mean = crate::stats::mean(&draws);
        let sd = crate::stats::stddev(&draws);
        // 40 000 draws: the mean's standard error is 0.005, the deviation's about 0.0035.
        assert!(mean.abs() < 0.02, "mean {mean}");
        assert!((sd - 1.0).abs() < 0.015, "sd {sd}");
    }

    #[test]
    fn the_same_seed_gives_the_same_sea_and_another_seed_another() {
        let p = FftParams::default();
        let a = Spectrum::new(&p, 16);
        assert_eq!(a.h0, Spectrum::new(&p, 16).h0);
        let other = Spectrum::new(&FftParams { seed: 2, ..p }, 16);
        assert_ne!(a.h0, other.h0);
    }

    #[test]
    fn the_coefficients_are_hermitian() {
        let s = Spectrum::new(&FftParams::default(), 16);
        for a in 0..16 {
            for b in 0..16 {
                let minus = s.coefficient((16 - a) % 16, (16 - b) % 16, 3.0);
                let diff = s.coefficient(a, b, 3.0) - minus.conj();
                assert!(diff.norm() <= 1e-15 * (1.0 + minus.norm()), "({a}, {b})");
            }
        }
    }
}
