//! The inverse 2-D FFT of an N×N field: rustfft's plan made once, a pass over every row, an
//! out-of-place transpose (the `transpose` crate's cache-oblivious one) into a spare buffer that
//! then takes the field's place, and a second pass over every row.

use rustfft::num_complex::Complex;
use rustfft::{Fft, FftPlanner};
use std::sync::Arc;

/// An unnormalised inverse 2-D transform, out[i][j] = Σ_a Σ_b in[b][a] e^{2πi(a·i + b·j)/N}:
/// its input is laid out transposed (row b holds the coefficients of x-wavenumber index b), so
/// that after the first row pass one transpose puts the output in row-major order.
#[derive(Clone)]
pub struct Inverse2d {
    n: usize,
    fft: Arc<dyn Fft<f32>>,
    scratch: Vec<Complex<f32>>,
    /// The transpose's destination, swapped with the field it transposes (made on first use:
    /// row passes alone never need it).
    spare: Vec<Complex<f32>>,
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
        Inverse2d {
            n,
            fft,
            scratch,
            spare: Vec::new(),
        }
    }

    /// Transforms one field of N² values (layout: see [`Inverse2d`]); the field's buffer
    /// afterwards is another of the same size.
    pub fn process(&mut self, field: &mut Vec<Complex<f32>>) {
        assert_eq!(field.len(), self.n * self.n, "an N×N field");
        self.rows(field);
        self.spare.resize(field.len(), Complex::default());
        transpose::transpose(field, &mut self.spare, self.n, self.n);
        std::mem::swap(field, &mut self.spare);
        self.rows(field);
    }

    /// The length-N transform of every row: half of [`Inverse2d::process`], no transpose.
    pub fn rows(&mut self, field: &mut [Complex<f32>]) {
        self.fft.process_with_scratch(field, &mut self.scratch);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_coefficient_gives_one_plane_wave() {
        for n in [16, 40] {
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
}
