//! The article's blur: a separable filter whose weights are a row of Pascal's triangle
//! (C(w − 1, t) / 2^(w − 1), the binomial approximation of a Gaussian), one pass per axis,
//! sampling beyond an edge wrapped to the opposite side so that the tiled volume has no seam.
//!
//! Every pass is mostly one long weighted sum of w shifted windows of the input (x: the plane
//! shifted by voxels; y: by rows; z: whole neighbouring planes), a vector loop over contiguous
//! memory that holds its sums in registers; only the voxels whose taps wrap (each row's ends in
//! x, each plane's first and last rows in y) are summed apart. Each pass reads one buffer and writes the other, and the w rows
//! or planes it sums are mostly the last output's, still in cache: three passes of memory
//! traffic, as three copies.

use crate::isa::{self, Isa};
use std::sync::atomic::{AtomicBool, Ordering};

/// Widest blur, in taps.
pub const MAX_WIDTH: usize = 31;

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

        // x and y: a plane at a time. Inside the plane the voxels whose taps all lie in their own
        // row (x) or plane (y) are one long weighted sum of shifted windows; the rest, each
        // row's first and last r voxels (x) and the plane's first and last r rows (y), wrap.
        let x_edges: Vec<usize> = edges(n, r);
        for (src, dst) in volume
            .chunks_exact(plane)
            .zip(scratch.chunks_exact_mut(plane))
        {
            if n > 2 * r {
                combine(&mut dst[r..plane - r], weights, |t| {
                    &src[t..][..plane - 2 * r]
                });
            }
            for (row, out) in src.chunks_exact(n).zip(dst.chunks_exact_mut(n)) {
                for &i in &x_edges {
                    out[i] = weights
                        .iter()
                        .enumerate()
                        .map(|(t, &w)| w * row[wrap(i, t)])
                        .sum();
                }
            }
        }
        if stopped() {
            return false;
        }
        for (src, dst) in scratch
            .chunks_exact(plane)
            .zip(volume.chunks_exact_mut(plane))
        {
            if n > 2 * r {
                let inner = (n - 2 * r) * n;
                combine(&mut dst[r * n..][..inner], weights, |t| {
                    &src[t * n..][..inner]
                });
            }
            for &j in &x_edges {
                combine(&mut dst[j * n..][..n], weights, |t| {
                    &src[wrap(j, t) * n..][..n]
                });
            }
            if stopped() {
                return false;
            }
        }
        // z: whole planes from the neighbouring planes, w streams read in order.
        for (k, out) in scratch.chunks_exact_mut(plane).enumerate() {
            combine(out, weights, |t| &volume[wrap(k, t) * plane..][..plane]);
            if stopped() {
                return false;
            }
        }
        true
    }
}

/// The first and last r of 0..n (all of it when n ≤ 2r): the places whose taps wrap.
fn edges(n: usize, r: usize) -> Vec<usize> {
    if n > 2 * r {
        (0..r).chain(n - r..n).collect()
    } else {
        (0..n).collect()
    }
}

/// out = Σ_t weights[t] · row(t), blocks of lanes at a time with the sums held in registers, so
/// each output is stored once and each input loaded once: blocks of 64 (four AVX-512 registers,
/// independent sums for the FMA pipes to overlap), then of 16, then one lane at a time.
#[inline(always)]
fn combine<'a>(out: &mut [f32], weights: &[f32], row: impl Fn(usize) -> &'a [f32]) {
    let mut rows = [&[][..]; MAX_WIDTH];
    for (t, r) in rows.iter_mut().take(weights.len()).enumerate() {
        *r = &row(t)[..out.len()];
    }
    let rows = &rows[..weights.len()];
    let done = blocks::<64>(out, weights, rows, 0);
    let done = blocks::<16>(out, weights, rows, done);
    for (i, o) in out.iter_mut().enumerate().skip(done) {
        *o = weights.iter().zip(rows).map(|(&w, r)| w * r[i]).sum();
    }
}

/// [`combine`] over whole blocks of `B` lanes from `start`; where the blocks ended.
#[inline(always)]
fn blocks<const B: usize>(
    out: &mut [f32],
    weights: &[f32],
    rows: &[&[f32]],
    start: usize,
) -> usize {
    let end = start + (out.len() - start) / B * B;
    for at in (start..end).step_by(B) {
        let mut sum = [0.0f32; B];
        for (&w, r) in weights.iter().zip(rows) {
            let x: &[f32; B] = r[at..at + B].try_into().expect("a block");
            for (s, &x) in sum.iter_mut().zip(x) {
                *s += w * x;
            }
        }
        out[at..at + B].copy_from_slice(&sum);
    }
    end
}
