//! The fused wave loop: every wave of a row in one pass, for wave sets whose exponents 2k − 2
//! are all integers (half-integer steepness, the default set among them).
//!
//! The per-wave loop loads and stores the row's z (and both slopes) once per wave, so at the
//! default four waves the loads and stores of the outputs cost as much as the arithmetic. Here
//! a row is cut into tiles of `K` vectors whose z and slopes stay in registers while every
//! wave adds to them; the slopes become normals before the tile is stored, once.
//!
//! The wave loop inside a tile runs over however many waves there are (1 to `MAX_WAVES`) and
//! dispatches each wave to its compile-time exponent once per tile, so a tile of 64 vertices
//! (AVX-512) pays one predictable indirect branch per wave. Only exponents are monomorphised
//! (13 of them), never wave counts or exponent combinations. Each vertex gets the per-wave
//! path's operations in its order, so the two paths agree bit for bit on one instruction set.

use super::phase::{Power, Tables, WaveConsts};
use super::simd::{by_exp, dispatch, int_pow, wave_terms, ForIsa, Isa, Out};
use super::vector::Vector;
use crate::ocean::waves::MAX_WAVES;

/// Whether the fused loop covers `waves`: every exponent 2k − 2 an integer up to
/// `MAX_INT_EXP`.
pub fn covers(waves: &[WaveConsts]) -> bool {
    waves.iter().all(|w| matches!(w.power, Power::Int(_)))
}

/// The fused step: `step` through `dispatch`.
struct Fused<'a> {
    waves: &'a [WaveConsts],
    tables: &'a Tables,
    out: Out<'a>,
    analytic: bool,
}

/// Runs one fused step with `isa`, which the caller has checked this CPU supports; `waves`
/// must be covered (see [`covers`]).
pub fn step(isa: Isa, waves: &[WaveConsts], tables: &Tables, out: Out, analytic: bool) {
    assert!(covers(waves), "fused step needs integer exponents");
    dispatch(
        isa,
        Fused {
            waves,
            tables,
            out,
            analytic,
        },
    )
}

impl ForIsa for Fused<'_> {
    type Output = ();

    #[inline(always)]
    fn run<const F: bool, const K: usize, V: Vector>(self) {
        if self.analytic {
            rows::<V, K, true>(self);
        } else {
            rows::<V, K, false>(self);
        }
    }
}

/// Every row, tile by tile: heights and, with `S`, normals from the slopes.
#[inline(always)]
fn rows<V: Vector, const K: usize, const S: bool>(step: Fused) {
    let Fused {
        waves, tables, out, ..
    } = step;
    let (n, m, stride, tile) = (tables.grid.n, tables.rows, tables.stride, K * V::LANES);
    assert_eq!(stride % tile, 0, "column tables padded to whole tiles");
    assert!(waves.len() <= MAX_WAVES);
    // Each wave's exponent and constants, and below each row's values, gathered where the
    // tile loop indexes them without bounds checks.
    let (mut exps, mut consts) = ([0u32; MAX_WAVES], [[0.0f32; 3]; MAX_WAVES]);
    for ((e, k), wave) in exps.iter_mut().zip(&mut consts).zip(waves) {
        *e = match wave.power {
            Power::Int(e) => e,
            Power::General(_) => unreachable!("excluded by `covers`"),
        };
        *k = [wave.amp, wave.cx, wave.cy];
    }
    for (i, [z, nx, ny, nz]) in out.rows(n).enumerate() {
        let mut rot = [[0.0f32; 2]; MAX_WAVES];
        for (w, r) in rot.iter_mut().enumerate().take(waves.len()) {
            *r = [tables.row_sin[w * m + i], tables.row_cos[w * m + i]];
        }
        for c in (0..n).step_by(tile) {
            let mut acc = [[V::splat(0.0); 3]; K];
            for w in 0..waves.len() {
                let at = w * stride + c;
                let cols = (
                    &tables.col_sin[at..at + tile],
                    &tables.col_cos[at..at + tile],
                );
                // Splatted before the dispatch, so each broadcast is one load, not an FP op
                // in every arm.
                let ([sb, cb], [amp, cx, cy]) = (rot[w], consts[w]);
                let b = (V::splat(sb), V::splat(cb));
                let k = [V::splat(amp), V::splat(cx), V::splat(cy)];
                by_exp!(exps[w], add_tile::<V, K, S>(&mut acc, cols, b, k));
            }
            let out = [&mut *z, &mut *nx, &mut *ny, &mut *nz];
            // The tail's partial stores are kept apart so they cannot make the whole tiles
            // spill their accumulators.
            if c + tile <= n {
                store_tile::<V, K, S, true>(acc, out, c);
            } else {
                store_tile::<V, K, S, false>(acc, out, c);
            }
        }
    }
}

/// Stores a tile's heights and, with `S`, its normals at column `c` of the row `out` (z, nx,
/// ny, nz); `WHOLE` when the tile lies inside the row.
#[inline(always)]
fn store_tile<V: Vector, const K: usize, const S: bool, const WHOLE: bool>(
    acc: [[V; 3]; K],
    [z, nx, ny, nz]: [&mut [f32]; 4],
    c: usize,
) {
    let n = z.len();
    for (k, [hz, dx, dy]) in acc.into_iter().enumerate() {
        let at = c + k * V::LANES;
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

/// Adds one wave with exponent `E` to a tile's accumulators: `sa`, `ca` are the tile's
/// columns, `b` the row's half angle (sin, cos) and `k` the wave's A, cx, cy, all splatted.
#[inline(always)]
fn add_tile<V: Vector, const K: usize, const S: bool, const E: u32>(
    acc: &mut [[V; 3]; K],
    (sa, ca): (&[f32], &[f32]),
    b: (V, V),
    [amp, cx, cy]: [V; 3],
) {
    for (j, [z, dx, dy]) in acc.iter_mut().enumerate() {
        let l = j * V::LANES;
        let a = (V::load(&sa[l..]), V::load(&ca[l..]));
        let (t, q) = wave_terms::<V, S>(a, b, int_pow::<V, E>);
        *z = amp.mul_add(t, *z);
        if S {
            *dx = cx.mul_add(q, *dx);
            *dy = cy.mul_add(q, *dy);
        }
    }
}
