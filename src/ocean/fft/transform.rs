//! The inverse 2-D FFT of an N×N field: rustfft's plan made once, a pass over every row, an
//! in-place transpose, and a second pass over every row.

use rustfft::num_complex::Complex;
use rustfft::{Fft, FftPlanner};
use std::sync::Arc;

/// Side of the square tiles the transpose swaps: 32 × 32 complex f32 is 8 KiB, two tiles fit
/// in L1 together.
const TILE: usize = 32;

/// An unnormalised inverse 2-D transform, out[i][j] = Σ_a Σ_b in[b][a] e^{2πi(a·i + b·j)/N}:
/// its input is laid out transposed (row b holds the coefficients of x-wavenumber index b), so
/// that after the first row pass one transpose puts the output in row-major order.
#[derive(Clone)]
pub struct Inverse2d {
    n: usize,
    fft: Arc<dyn Fft<f32>>,
    scratch: Vec<Complex<f32>>,
}

impl std::fmt::Debug for Inverse2d {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Inverse2d").field("n", &self.n).finish()
    }
}

impl Inverse2d {
    /// Plans the length-`n` inverse transform once.
    pub fn new(n: usize) -> Self {
        let fft = FftPlanner::new().plan_fft_inverse(n);
        let scratch = vec![Complex::default(); fft.get_inplace_scratch_len()];
        Inverse2d { n, fft, scratch }
    }

    /// Transforms one field of N² values in place (layout: see [`Inverse2d`]).
    pub fn process(&mut self, field: &mut [Complex<f32>]) {
        assert_eq!(field.len(), self.n * self.n, "an N×N field");
        self.rows(field);
        transpose(field, self.n);
        self.rows(field);
    }

    /// The length-N transform of every row: half of [`Inverse2d::process`], no transpose.
    pub fn rows(&mut self, field: &mut [Complex<f32>]) {
        self.fft.process_with_scratch(field, &mut self.scratch);
    }
}

/// Transposes a square N×N matrix in place, tile by tile so both tiles stay in cache.
pub fn transpose(m: &mut [Complex<f32>], n: usize) {
    for ib in (0..n).step_by(TILE) {
        for jb in (ib..n).step_by(TILE) {
            for i in ib..(ib + TILE).min(n) {
                let from = if ib == jb { i + 1 } else { jb };
                for j in from..(jb + TILE).min(n) {
                    m.swap(i * n + j, j * n + i);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transpose_swaps_every_pair_once() {
        for n in [1, 5, 32, 33, 70] {
            let m: Vec<Complex<f32>> = (0..n * n).map(|v| Complex::new(v as f32, 0.0)).collect();
            let mut t = m.clone();
            transpose(&mut t, n);
            for i in 0..n {
                for j in 0..n {
                    assert_eq!(t[i * n + j], m[j * n + i], "n={n} ({i}, {j})");
                }
            }
        }
    }

    #[test]
    fn one_coefficient_gives_one_plane_wave() {
        let n = 16;
        let mut field = vec![Complex::default(); n * n];
        let (a, b) = (3, 5);
        field[b * n + a] = Complex::new(1.0, 0.0);
        Inverse2d::new(n).process(&mut field);
        for i in 0..n {
            for j in 0..n {
                let angle = 2.0 * std::f64::consts::PI * (a * i + b * j) as f64 / n as f64;
                let got = field[i * n + j];
                assert!((got.re as f64 - angle.cos()).abs() < 1e-5, "({i}, {j})");
                assert!((got.im as f64 - angle.sin()).abs() < 1e-5, "({i}, {j})");
            }
        }
    }
}
