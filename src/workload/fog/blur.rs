//! The article's blur: a separable filter whose weights are a row of Pascal's triangle
//! (C(w − 1, t) / 2^(w − 1), the binomial approximation of a Gaussian), one pass per axis,
//! sampling beyond an edge wrapped to the opposite side so that the tiled volume has no seam.
//!
//! Every pass is a weighted sum of whole rows (x: of shifted copies of the row; y and z: of
//! neighbouring rows), so each runs as vector loops over contiguous memory; the z pass walks one
//! column of rows at a time so the w rows it sums stay in cache from one output row to the next.

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
    assert_eq!(volume.len(), n * n * n, "an n³ volume");
    assert_eq!(scratch.len(), volume.len(), "a scratch volume as large");
    let stopped = || stop.is_some_and(|s| s.load(Ordering::Relaxed));
    let r = weights.len() / 2;
    let wrap = |i: usize, t: usize| (i + n * (r / n + 1) + t - r) % n;

    // x: each row against its own wrapped copy.
    let mut padded = vec![0.0f32; n + 2 * r];
    for (row, out) in volume.chunks_exact(n).zip(scratch.chunks_exact_mut(n)) {
        for (t, p) in padded.iter_mut().enumerate() {
            *p = row[wrap(t, 0)];
        }
        out.fill(0.0);
        for (t, &w) in weights.iter().enumerate() {
            axpy(out, w, &padded[t..t + n]);
        }
    }
    if stopped() {
        return false;
    }
    // y: within each plane, rows from the neighbouring rows.
    let plane = n * n;
    for (src, dst) in scratch
        .chunks_exact(plane)
        .zip(volume.chunks_exact_mut(plane))
    {
        for (j, out) in dst.chunks_exact_mut(n).enumerate() {
            out.fill(0.0);
            for (t, &w) in weights.iter().enumerate() {
                let s = wrap(j, t) * n;
                axpy(out, w, &src[s..s + n]);
            }
        }
        if stopped() {
            return false;
        }
    }
    // z: rows from the same row of the neighbouring planes, a column of rows at a time.
    for j in 0..n {
        for k in 0..n {
            let out = &mut scratch[k * plane + j * n..][..n];
            out.fill(0.0);
            for (t, &w) in weights.iter().enumerate() {
                let s = wrap(k, t) * plane + j * n;
                axpy(out, w, &volume[s..s + n]);
            }
        }
        if stopped() {
            return false;
        }
    }
    std::mem::swap(volume, scratch);
    true
}

/// out += w · x, a loop LLVM vectorises.
#[inline]
fn axpy(out: &mut [f32], w: f32, x: &[f32]) {
    for (o, &x) in out.iter_mut().zip(x) {
        *o += w * x;
    }
}
