//! Run-time dispatch to the instruction sets, the per-vertex wave formula every path shares,
//! and the per-wave row loops.
//!
//! Each loop is `#[inline(always)]` and generic over the vector type, and is instantiated
//! inside one `#[target_feature]` entry point per instruction set, so the same source is
//! compiled for AVX-512, AVX2+FMA and the portable baseline; the binary stays portable and the
//! widest path is picked at run time. The per-wave loops are plain Rust over slices that LLVM
//! vectorises; they cover every exponent and are the baseline the fused loop is measured
//! against.

use super::math::{fma, pow_abs};
use super::phase::{Power, Tables, WaveConsts};
use super::vector::powi;
#[cfg(target_arch = "x86_64")]
use super::vector::{Avx2, Avx512};
use super::vector::{Lane, Portable, Vector};

pub use crate::isa::Isa;

/// The output rows of one step (the rows its `Tables` cover): heights and, for analytic normals,
/// the normal components.
pub struct Out<'a> {
    /// Heights.
    pub z: &'a mut [f32],
    /// Normal x; holds ∂f/∂x while a row is summed.
    pub nx: &'a mut [f32],
    /// Normal y; holds ∂f/∂y while a row is summed.
    pub ny: &'a mut [f32],
    /// Normal z.
    pub nz: &'a mut [f32],
}

impl<'a> Out<'a> {
    /// Row by row: `[z, nx, ny, nz]` of each row of `n` vertices.
    pub fn rows(self, n: usize) -> impl Iterator<Item = [&'a mut [f32]; 4]> {
        let Out { z, nx, ny, nz } = self;
        let zs = z.chunks_exact_mut(n).zip(nx.chunks_exact_mut(n));
        let ns = ny.chunks_exact_mut(n).zip(nz.chunks_exact_mut(n));
        zs.zip(ns).map(|((z, nx), (ny, nz))| [z, nx, ny, nz])
    }
}

/// Work generic over the instruction set: `run` is instantiated once per set with its vector
/// type `V`, whether it has FMA (`F`, for scalar `Lane<F>` loops) and the vectors in a fused
/// tile (`K`: 4 of AVX-512's 32 registers' worth, 2 for the 16-register sets).
pub trait ForIsa {
    /// What the work returns.
    type Output;
    /// Runs the work; implementations are `#[inline(always)]` so it is compiled with `V`'s
    /// target features.
    fn run<const F: bool, const K: usize, V: Vector>(self) -> Self::Output;
}

/// Runs `work` with `isa`, which the caller has checked this CPU supports.
pub fn dispatch<T: ForIsa>(isa: Isa, work: T) -> T::Output {
    match isa {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: `isa` comes from `Isa::available`, so the CPU has these features.
        Isa::Avx512 => unsafe { run_avx512(work) },
        #[cfg(target_arch = "x86_64")]
        // SAFETY: as above.
        Isa::Avx2 => unsafe { run_avx2(work) },
        _ => work.run::<false, 2, Portable>(),
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx2,fma")]
fn run_avx512<T: ForIsa>(work: T) -> T::Output {
    work.run::<true, 4, Avx512>()
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn run_avx2<T: ForIsa>(work: T) -> T::Output {
    work.run::<true, 2, Avx2>()
}

/// Calls `$f::<generics…, E>(args…)` with the compile-time exponent E matching `$e`
/// (0..=MAX_INT_EXP); or, given `E => body`, evaluates `body` with the constant `E` so bound.
macro_rules! by_exp {
    (@arms $e:expr, $E:ident => $body:expr, $($n:literal)*) => {
        match $e {
            $($n => {
                const $E: u32 = $n;
                $body
            })*
            _ => unreachable!("exponent above MAX_INT_EXP"),
        }
    };
    ($e:expr, $f:ident::<$($g:tt),*>($($arg:expr),*)) => {
        by_exp!($e, E => $f::<$($g,)* E>($($arg),*))
    };
    ($e:expr, $E:ident => $body:expr) => {
        by_exp!(@arms $e, $E => $body, 0 1 2 3 4 5 6 7 8 9 10 11 12)
    };
}
pub(super) use by_exp;

/// One step's inputs and outputs, for either row loop.
pub struct Step<'a> {
    /// The enabled waves' constants.
    pub waves: &'a [WaveConsts],
    /// Their tables for the band `out` covers.
    pub tables: &'a Tables,
    /// The band's output rows.
    pub out: Out<'a>,
    /// Whether to fill normals from the slopes, not heights alone.
    pub analytic: bool,
}

/// A step on the per-wave loop, for [`dispatch`].
pub struct PerWave<'a>(pub Step<'a>);

impl ForIsa for PerWave<'_> {
    type Output = ();

    /// Row by row, wave by wave: the row's outputs stay in L1 while every wave adds to them, and
    /// the per-wave branch on the power kind is taken once per row, outside the vector loop.
    /// This and the loops below are main's per-wave kernel as it was, the baseline the fused
    /// loop is measured against: only the table stride and the dispatch around it changed.
    #[inline(always)]
    fn run<const F: bool, const K: usize, V: Vector>(self) {
        let Step {
            waves,
            tables,
            out,
            analytic,
        } = self.0;
        let (n, m, stride) = (tables.grid.n, tables.rows, tables.stride);
        for (i, [z, nx, ny, nz]) in out.rows(n).enumerate() {
            z.fill(0.0);
            if analytic {
                nx.fill(0.0);
                ny.fill(0.0);
            }
            for (w, wave) in waves.iter().enumerate() {
                let sa = &tables.col_sin[w * stride..w * stride + n];
                let ca = &tables.col_cos[w * stride..w * stride + n];
                let (sb, cb) = (tables.row_sin[w * m + i], tables.row_cos[w * m + i]);
                let a = wave.amp;
                match (analytic, wave.power) {
                    (false, Power::Int(e)) => {
                        by_exp!(e, E => heights::<F>(sa, ca, sb, cb, a, IntExp::<E>, z))
                    }
                    (false, Power::General(e)) => heights::<F>(sa, ca, sb, cb, a, e, z),
                    (true, Power::Int(e)) => {
                        by_exp!(e, E => full::<F>(sa, ca, sb, cb, wave, IntExp::<E>, z, nx, ny))
                    }
                    (true, Power::General(e)) => full::<F>(sa, ca, sb, cb, wave, e, z, nx, ny),
                }
            }
            if analytic {
                V::slopes_to_normals::<F>(nx, ny, nz);
            }
        }
    }
}

/// sin θ of one vertex by angle addition of the column and row half angles.
#[inline(always)]
fn half_sin<const F: bool>(sa: f32, ca: f32, sb: f32, cb: f32) -> f32 {
    fma::<F>(sa, cb, ca * sb)
}

/// cos θ of one vertex by angle addition.
#[inline(always)]
fn half_cos<const F: bool>(sa: f32, ca: f32, sb: f32, cb: f32) -> f32 {
    fma::<F>(ca, cb, -(sa * sb))
}

/// |h|^e, the power in the wave formula, as the row loops compute it for one kind of exponent.
pub(super) trait AbsPow<const F: bool>: Copy {
    /// |h| to this power.
    fn of(self, h: f32) -> f32;
}

/// A compile-time integer exponent E, by repeated squaring.
#[derive(Clone, Copy)]
pub(super) struct IntExp<const E: u32>;

impl<const F: bool, const E: u32> AbsPow<F> for IntExp<E> {
    #[inline(always)]
    fn of(self, h: f32) -> f32 {
        powi::<Lane<F>, E>(Lane(h.abs())).0
    }
}

/// Any exponent e = 2k − 2, by the polynomial log and exp.
impl<const F: bool> AbsPow<F> for f32 {
    #[inline(always)]
    fn of(self, h: f32) -> f32 {
        pow_abs::<F>(h, self)
    }
}

/// Adds A·|h|^(e+2) = A·((sin S + 1)/2)^k to a row of heights, |h|^e by `pow`.
#[inline(always)]
fn heights<const F: bool>(
    sa: &[f32],
    ca: &[f32],
    sb: f32,
    cb: f32,
    amp: f32,
    pow: impl AbsPow<F>,
    z: &mut [f32],
) {
    for ((z, &sa), &ca) in z.iter_mut().zip(sa).zip(ca) {
        let h = half_sin::<F>(sa, ca, sb, cb);
        *z = fma::<F>(amp, pow.of(h) * (h * h), *z);
    }
}

/// Adds one wave's height and slope (cos S = 2·sin θ·cos θ) to a row, |h|^e by `pow`.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(super) fn full<const F: bool>(
    sa: &[f32],
    ca: &[f32],
    sb: f32,
    cb: f32,
    wave: &WaveConsts,
    pow: impl AbsPow<F>,
    z: &mut [f32],
    dx: &mut [f32],
    dy: &mut [f32],
) {
    let (amp, cx, cy) = (wave.amp, wave.cx, wave.cy);
    let outs = z.iter_mut().zip(dx.iter_mut()).zip(dy.iter_mut());
    for (((z, dx), dy), (&sa, &ca)) in outs.zip(sa.iter().zip(ca)) {
        let h = half_sin::<F>(sa, ca, sb, cb);
        let g = half_cos::<F>(sa, ca, sb, cb);
        let p = pow.of(h);
        *z = fma::<F>(amp, p * (h * h), *z);
        let q = p * (h * g);
        *dx = fma::<F>(cx, q, *dx);
        *dy = fma::<F>(cy, q, *dy);
    }
}
