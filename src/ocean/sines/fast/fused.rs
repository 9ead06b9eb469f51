//! The fused wave loop: every wave of a row in one pass, for wave sets whose exponents 2k − 2
//! are all integers (half-integer steepness, the default set among them).
//!
//! The per-wave loop loads and stores the row's z (and both slopes) once per wave. Here a row
//! is cut into tiles of vectors whose z and slopes stay in registers while every wave adds to
//! them; the slopes become normals before the tile is stored, once. A tile is `K` vectors
//! with normals (4 on AVX-512: 12 accumulators of 32 registers; 2 on the 16-register sets)
//! and twice that for heights alone.
//!
//! The wave loop inside a tile runs over however many waves there are (1 to `MAX_WAVES`) and
//! dispatches each wave to its compile-time exponent once per tile, so a tile of 64 or 128
//! vertices (AVX-512) pays one predictable indirect branch per wave. Only exponents are
//! monomorphised (13 of them), never wave counts or exponent combinations.
//!
//! The half angle's sin h and cos g come from the column's and the row's by angle addition,
//! as in the per-wave loop, but with the row's larger factor taken out (see
//! `Tables::row_scale`): h and g then cost one multiply-add each instead of two, and the factor
//! raised to the wave's power joins the wave's constants once per row. The results differ
//! from the per-wave loop's by rounding only.

use super::phase::{Power, WaveConsts};
use super::simd::{by_exp, ForIsa, Step};
use super::vector::powi;
use super::vector::Real;
use super::vector::Vector;
use crate::ocean::waves::MAX_WAVES;

/// Whether the fused loop covers `waves`: every exponent 2k − 2 an integer up to
/// `MAX_INT_EXP`.
pub fn covers(waves: &[WaveConsts]) -> bool {
    waves.iter().all(|w| matches!(w.power, Power::Int(_)))
}

/// The exponent of each wave, padded to `MAX_WAVES`; the waves must be covered (see
/// [`covers`]).
pub(super) fn exps(waves: &[WaveConsts]) -> [u32; MAX_WAVES] {
    assert!(waves.len() <= MAX_WAVES);
    let mut exps = [0u32; MAX_WAVES];
    for (e, wave) in exps.iter_mut().zip(waves) {
        *e = match wave.power {
            Power::Int(e) => e,
            Power::General(_) => unreachable!("excluded by `covers`"),
        };
    }
    exps
}

/// A step on the fused loop, for [`dispatch`](super::simd::dispatch); its waves must be
/// covered (see [`covers`]).
pub struct Fused<'a>(pub Step<'a>);

impl ForIsa for Fused<'_> {
    type Output = ();

    #[inline(always)]
    fn run<const F: bool, const K: usize, V: Vector>(self) {
        // Heights alone keep one accumulator per vector, so their tiles are twice as wide:
        // the dispatch per wave and tile is spread over twice the work.
        if self.0.analytic {
            rows::<V, K, 1, true>(self.0);
        } else {
            rows::<V, K, 2, false>(self.0);
        }
    }
}

/// Every row, tile by tile (`T` groups of `K` vectors): heights and, with `S`, normals from
/// the slopes.
#[inline(always)]
fn rows<V: Vector, const K: usize, const T: usize, const S: bool>(step: Step) {
    let Step {
        waves, tables, out, ..
    } = step;
    let (n, m, stride) = (tables.grid.n, tables.rows, tables.stride);
    let tile = T * K * V::LANES;
    assert_eq!(stride % tile, 0, "column tables padded to whole tiles");
    // Each wave's exponent and constants, and below each row's values, gathered where the
    // tile loop indexes them without bounds checks.
    let (exps, mut consts) = (exps(waves), [[0.0f32; 3]; MAX_WAVES]);
    for (k, wave) in consts.iter_mut().zip(waves) {
        *k = [wave.amp, wave.cx, wave.cy];
    }
    for (i, [z, nx, ny, nz]) in out.rows(n).enumerate() {
        // The row's factor (see `Tables::row_scale`) goes into the wave's constants. Written
        // element by element: copying `consts` whole would be a vector load of values just
        // stored as scalars, which the store buffer cannot forward.
        let (mut ts, mut ks, mut swap) = (
            [0.0f32; MAX_WAVES],
            [[0.0f32; 3]; MAX_WAVES],
            [false; MAX_WAVES],
        );
        for w in 0..waves.len() {
            let (scale, [amp, cx, cy]) = (tables.row_scale[w * m + i], consts[w]);
            ts[w] = tables.row_t[w * m + i];
            ks[w] = [amp * scale.abs(), cx * scale, cy * scale];
            swap[w] = scale < 0.0;
        }
        for c in (0..n).step_by(tile) {
            let mut acc = [[[V::splat(0.0); 3]; K]; T];
            for w in 0..waves.len() {
                let at = w * stride + c;
                let (sa, ca) = (
                    &tables.col_sin[at..at + tile],
                    &tables.col_cos[at..at + tile],
                );
                let cols = if swap[w] { (sa, ca) } else { (ca, sa) };
                // Splatted before the dispatch, so each broadcast is one load, not an FP op
                // in every arm.
                let ([amp, cx, cy], t) = (ks[w], ts[w]);
                let t = (V::splat(t), V::splat(-t));
                let k = [V::splat(amp), V::splat(cx), V::splat(cy)];
                by_exp!(exps[w], add_tile::<V, K, T, S>(&mut acc, cols, t, k));
            }
            let out = [&mut *z, &mut *nx, &mut *ny, &mut *nz];
            store_tile::<V, K, T, S>(acc, out, c, c + tile <= n);
        }
    }
}

/// Stores a tile of `T` groups of `K` vectors, its heights and, with `S`, its normals, at column
/// `c` of the row `out` (z, nx, ny, nz). `whole` says the tile lies inside the row; otherwise the
/// row ends inside the tile. Callers work `whole` out in their own loop's terms, which leaves
/// the machine code of their loops as it was when each wrote this branch itself.
#[inline(always)]
pub(super) fn store_tile<V: Vector, const K: usize, const T: usize, const S: bool>(
    acc: [[[V; 3]; K]; T],
    out: [&mut [f32]; 4],
    c: usize,
    whole: bool,
) {
    // The tail's partial stores are kept apart so they cannot make the whole tiles spill their
    // accumulators.
    if whole {
        store_part::<V, K, T, S, true>(acc, out, c);
    } else {
        store_part::<V, K, T, S, false>(acc, out, c);
    }
}

/// [`store_tile`] for a tile that lies inside the row (`WHOLE`) or runs past its end.
#[inline(always)]
fn store_part<V: Vector, const K: usize, const T: usize, const S: bool, const WHOLE: bool>(
    acc: [[[V; 3]; K]; T],
    [z, nx, ny, nz]: [&mut [f32]; 4],
    c: usize,
) {
    let n = z.len();
    for (g, group) in acc.into_iter().enumerate() {
        for (k, [hz, dx, dy]) in group.into_iter().enumerate() {
            let at = c + (g * K + k) * V::LANES;
            if !WHOLE && at >= n {
                break;
            }
            let r = at..(at + V::LANES).min(n);
            let normals = if S { V::slope_normal(dx, dy) } else { [hz; 3] };
            let outs = [&mut *z, &mut *nx, &mut *ny, &mut *nz];
            let count = if S { 4 } else { 1 };
            for (v, out) in [hz, normals[0], normals[1], normals[2]]
                .into_iter()
                .zip(outs)
                .take(count)
            {
                if WHOLE {
                    v.store(&mut out[at..]);
                } else {
                    v.store_prefix(&mut out[r.clone()]);
                }
            }
        }
    }
}

/// Adds one wave with exponent `E` to a tile's accumulators: with the row's (t, −t) and the
/// tile's columns (a, b) in the roles `Tables::row_scale` gives them, h and g up to the row's
/// factor are u = a·t + b and v = b·(−t) + a; `k` is the wave's A, cx, cy with that factor.
#[inline(always)]
pub(super) fn add_tile<V: Vector, const K: usize, const T: usize, const S: bool, const E: u32>(
    acc: &mut [[[V; 3]; K]; T],
    (a, b): (&[f32], &[f32]),
    (t, neg_t): (V, V),
    [amp, cx, cy]: [V; 3],
) {
    // Nested loops over the fixed sizes, which LLVM unrolls; `flatten` it does not, and the
    // accumulators then live in memory.
    for (g, group) in acc.iter_mut().enumerate() {
        for (j, [z, dx, dy]) in group.iter_mut().enumerate() {
            let l = (g * K + j) * V::LANES;
            let (a, b) = (V::load(&a[l..]), V::load(&b[l..]));
            let u = a.mul_add(t, b);
            let v = if S {
                b.mul_add(neg_t, a)
            } else {
                V::splat(0.0)
            };
            let (zt, q) = power_terms::<V, S>(u, v, int_pow::<V, E>);
            *z = amp.mul_add(zt, *z);
            if S {
                *dx = cx.mul_add(q, *dx);
                *dy = cy.mul_add(q, *dy);
            }
        }
    }
}

/// From h = sin θ and g = cos θ (up to a common factor): |h|^(2k), the height term before the
/// amplitude, and with `S` |h|^(2k−2)·h·g, the slope term before its factor (cos S = 2·h·g);
/// `pow` gives |h|^(2k−2).
#[inline(always)]
fn power_terms<R: Real, const S: bool>(h: R, g: R, pow: impl Fn(R) -> R) -> (R, R) {
    let p = pow(h);
    let q = if S { p * (h * g) } else { R::splat(0.0) };
    (p * (h * h), q)
}

/// |h|^E, the power of a half-integer k (E = 2k − 2); even powers need no |·|.
#[inline(always)]
fn int_pow<R: Real, const E: u32>(h: R) -> R {
    powi::<R, E>(if E % 2 == 1 { h.abs() } else { h })
}
