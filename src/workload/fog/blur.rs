//! The article's blur: a separable filter whose weights are a row of Pascal's triangle
//! (C(w − 1, t) / 2^(w − 1), the binomial approximation of a Gaussian), one pass per axis,
//! sampling beyond an edge wrapped to the opposite side so that the tiled volume has no seam.
//!
//! Every pass makes each output row a weighted sum of w input rows (x: shifted windows of the
//! row padded with its own wrapped ends; y and z: the neighbouring rows of the plane, or the same
//! row of the neighbouring planes), so each is a vector loop over contiguous memory. The z pass
//! walks one column of rows at a time so the w rows it sums stay in cache from one output row to
//! the next, and each pass reads one buffer and writes the other: three passes of memory
//! traffic, as three copies.

use super::isa::{self, Isa};
use std::sync::atomic::{AtomicBool, Ordering};

/// Pascal's triangle row `width − 1`, normalised to sum to 1.
pub fn weights(width: usize) -> Vec<f32> {
    let mut row = vec![1.0f64];
    for _ in 1..width {
        let mut next = vec![1.0; row.len() + 1];
        for t in 1..row.len() {
            next[t] = row[t - 1] + row[t];
        }
        row = next;
    }
    let total = 2f64.powi(width as i32 - 1);
    row.iter().map(|&c| (c / total) as f32).collect()
}

/// Blurs the `n`³ volume (x fastest) along x, y and z with `weights`, wrapping at the edges;
/// `scratch` is another `n`³ buffer. The passes go volume → scratch → volume → scratch and the
/// two are swapped at the end, so the result is in `volume` without a fourth pass. `false` when
/// `stop` was raised first.
pub fn blur(
    volume: &mut Vec<f32>,
    scratch: &mut Vec<f32>,
    n: usize,
    weights: &[f32],
    stop: Option<&AtomicBool>,
) -> bool {
    blur_with(Isa::detect(), volume, scratch, n, weights, stop)
}

/// [`blur`] with the instruction set given.
pub fn blur_with(
    isa: Isa,
    volume: &mut Vec<f32>,
    scratch: &mut Vec<f32>,
    n: usize,
    weights: &[f32],
    stop: Option<&AtomicBool>,
) -> bool {
    assert_eq!(volume.len(), n * n * n, "an n³ volume");
    assert_eq!(scratch.len(), volume.len(), "a scratch volume as large");
    let done = isa::run(
        isa,
        Passes {
            volume,
            scratch,
            n,
            weights,
            stop,
        },
    );
    if done {
        std::mem::swap(volume, scratch);
    }
    done
}

/// The three passes, compiled per instruction set.
struct Passes<'a> {
    volume: &'a mut [f32],
    scratch: &'a mut [f32],
    n: usize,
    weights: &'a [f32],
    stop: Option<&'a AtomicBool>,
}

impl isa::Loop for Passes<'_> {
    type Output = bool;

    #[inline(always)]
    fn run(self) -> bool {
        let Passes {
            volume,
            scratch,
            n,
            weights,
            stop,
        } = self;
        let stopped = || stop.is_some_and(|s| s.load(Ordering::Relaxed));
        let r = weights.len() / 2;
        // (i + t − r) mod n, for t in 0..width.
        let wrap = |i: usize, t: usize| (i + n * (r / n + 1) + t - r) % n;
        let plane = n * n;

        // x: each row against its wrapped ends.
        let mut padded = vec![0.0f32; n + 2 * r];
        for (row, out) in volume.chunks_exact(n).zip(scratch.chunks_exact_mut(n)) {
            if r <= n {
                padded[..r].copy_from_slice(&row[n - r..]);
                padded[r..r + n].copy_from_slice(row);
                padded[r + n..].copy_from_slice(&row[..r]);
            } else {
                for (t, p) in padded.iter_mut().enumerate() {
                    *p = row[wrap(t, 0)];
                }
            }
            combine(out, weights, |t| &padded[t..t + n]);
        }
        if stopped() {
            return false;
        }
        // y: within each plane, rows from the neighbouring rows.
        for (src, dst) in scratch
            .chunks_exact(plane)
            .zip(volume.chunks_exact_mut(plane))
        {
            for (j, out) in dst.chunks_exact_mut(n).enumerate() {
                combine(out, weights, |t| &src[wrap(j, t) * n..][..n]);
            }
            if stopped() {
                return false;
            }
        }
        // z: rows from the same row of the neighbouring planes, a column of rows at a time.
        for j in 0..n {
            for k in 0..n {
                let out = &mut scratch[k * plane + j * n..][..n];
                combine(out, weights, |t| &volume[wrap(k, t) * plane + j * n..][..n]);
            }
            if stopped() {
                return false;
            }
        }
        true
    }
}

/// out = Σ_t weights[t] · row(t).
#[inline(always)]
fn combine<'a>(out: &mut [f32], weights: &[f32], row: impl Fn(usize) -> &'a [f32]) {
    let (&w0, rest) = weights.split_first().expect("a blur has taps");
    for (o, &x) in out.iter_mut().zip(row(0)) {
        *o = w0 * x;
    }
    for (t, &w) in rest.iter().enumerate() {
        for (o, &x) in out.iter_mut().zip(row(t + 1)) {
            *o += w * x;
        }
    }
}
