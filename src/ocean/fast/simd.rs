//! Run-time dispatch to the instruction sets, the per-vertex wave formula every path shares,
//! and the per-wave row loops.
//!
//! Each loop is `#[inline(always)]` and generic over the vector type, and is instantiated
//! inside one `#[target_feature]` entry point per instruction set, so the same source is
//! compiled for AVX-512, AVX2+FMA and the portable baseline; the binary stays portable and the
//! widest path is picked at run time. The per-wave loops are plain Rust over slices that LLVM
//! vectorises; they cover every exponent and are the baseline the fused loop is measured
//! against.

use super::math::{pow_abs, powi};
use super::phase::{Power, Tables, WaveConsts};
#[cfg(target_arch = "x86_64")]
use super::vector::{Avx2, Avx512};
use super::vector::{Lane, Portable, Real, Vector};

/// The instruction set a fast kernel runs with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Isa {
    /// 512-bit vectors (AVX-512F) with FMA.
    Avx512,
    /// 256-bit vectors (AVX2) with FMA.
    Avx2,
    /// The target's baseline (SSE2 on x86-64), no FMA.
    Portable,
}

impl Isa {
    /// The widest instruction set this CPU supports.
    pub fn detect() -> Isa {
        Isa::available()[0]
    }

    /// Every instruction set this CPU supports, widest first (tests run them all).
    pub fn available() -> Vec<Isa> {
        let mut out = Vec::new();
        #[cfg(target_arch = "x86_64")]
        {
            let fma_avx2 = is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma");
            if fma_avx2 && is_x86_feature_detected!("avx512f") {
                out.push(Isa::Avx512);
            }
            if fma_avx2 {
                out.push(Isa::Avx2);
            }
        }
        out.push(Isa::Portable);
        out
    }

    /// Name for reports.
    pub fn name(self) -> &'static str {
        match self {
            Isa::Avx512 => "avx512",
            Isa::Avx2 => "avx2",
            Isa::Portable => "portable",
        }
    }
}

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
/// (0..=MAX_INT_EXP).
macro_rules! by_exp {
    ($e:expr, $f:ident::<$($g:tt),*>($($arg:expr),*)) => {
        match $e {
            0 => $f::<$($g,)* 0>($($arg),*),
            1 => $f::<$($g,)* 1>($($arg),*),
            2 => $f::<$($g,)* 2>($($arg),*),
            3 => $f::<$($g,)* 3>($($arg),*),
            4 => $f::<$($g,)* 4>($($arg),*),
            5 => $f::<$($g,)* 5>($($arg),*),
            6 => $f::<$($g,)* 6>($($arg),*),
            7 => $f::<$($g,)* 7>($($arg),*),
            8 => $f::<$($g,)* 8>($($arg),*),
            9 => $f::<$($g,)* 9>($($arg),*),
            10 => $f::<$($g,)* 10>($($arg),*),
            11 => $f::<$($g,)* 11>($($arg),*),
            12 => $f::<$($g,)* 12>($($arg),*),
            _ => unreachable!("exponent above MAX_INT_EXP"),
        }
    };
}
pub(super) use by_exp;

/// One wave's inputs along one row: its column tables (`stride` long, padding included), its
/// row values and its constants.
#[derive(Clone, Copy)]
pub struct WaveRow<'a> {
    /// sin of the column half angles.
    pub sa: &'a [f32],
    /// cos of the column half angles.
    pub ca: &'a [f32],
    /// sin of the row half angle.
    pub sb: f32,
    /// cos of the row half angle.
    pub cb: f32,
    /// Amplitude and the slope factors: A, cx, cy.
    pub k: [f32; 3],
}

impl<'a> WaveRow<'a> {
    /// Wave `w` along row `i` of the band `tables` covers.
    #[inline(always)]
    pub fn new(waves: &[WaveConsts], tables: &'a Tables, w: usize, i: usize) -> Self {
        let (stride, m, wave) = (tables.stride, tables.rows, &waves[w]);
        let cols = w * stride..(w + 1) * stride;
        WaveRow {
            sa: &tables.col_sin[cols.clone()],
            ca: &tables.col_cos[cols],
            sb: tables.row_sin[w * m + i],
            cb: tables.row_cos[w * m + i],
            k: [wave.amp, wave.cx, wave.cy],
        }
    }
}

/// One wave at one point (or one vector of points): with the vertex's half angle θ = θa + θb,
/// h = sin θ and g = cos θ by angle addition of the column's (sa, ca) and the row's (sb, cb),
/// the height and slope terms of [`power_terms`].
#[inline(always)]
pub fn wave_terms<R: Real, const S: bool>(
    (sa, ca): (R, R),
    (sb, cb): (R, R),
    pow: impl Fn(R) -> R,
) -> (R, R) {
    let h = sa.mul_add(cb, ca * sb);
    let g = if S {
        ca.mul_add(cb, -(sa * sb))
    } else {
        R::splat(0.0)
    };
    power_terms::<R, S>(h, g, pow)
}

/// From h = sin θ and g = cos θ (up to a common factor): |h|^(2k), the height term before the
/// amplitude, and with `S` |h|^(2k−2)·h·g, the slope term before its factor (cos S = 2·h·g);
/// `pow` gives |h|^(2k−2).
#[inline(always)]
pub fn power_terms<R: Real, const S: bool>(h: R, g: R, pow: impl Fn(R) -> R) -> (R, R) {
    let p = pow(h);
    let q = if S { p * (h * g) } else { R::splat(0.0) };
    (p * (h * h), q)
}

/// |h|^E, the power of a half-integer k (E = 2k − 2); even powers need no |·|.
#[inline(always)]
pub fn int_pow<R: Real, const E: u32>(h: R) -> R {
    powi::<R, E>(if E % 2 == 1 { h.abs() } else { h })
}

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
    #[inline(always)]
    fn run<const F: bool, const K: usize, V: Vector>(self) {
        let Step {
            waves,
            tables,
            out,
            analytic,
        } = self.0;
        for (i, [z, nx, ny, nz]) in out.rows(tables.grid.n).enumerate() {
            z.fill(0.0);
            if analytic {
                nx.fill(0.0);
                ny.fill(0.0);
            }
            for w in 0..waves.len() {
                let row = WaveRow::new(waves, tables, w, i);
                let (z, dx, dy) = (&mut *z, &mut *nx, &mut *ny);
                match (analytic, waves[w].power) {
                    (false, Power::Int(e)) => by_exp!(e, row_int::<F, false>(row, z, dx, dy)),
                    (true, Power::Int(e)) => by_exp!(e, row_int::<F, true>(row, z, dx, dy)),
                    (false, Power::General(e)) => row_gen::<F, false>(row, e, z, dx, dy),
                    (true, Power::General(e)) => row_gen::<F, true>(row, e, z, dx, dy),
                }
            }
            if analytic {
                V::slopes_to_normals::<F>(nx, ny, nz);
            }
        }
    }
}

/// Adds one wave to a row: z and, with `S`, the slopes in `dx`, `dy`. Each output is read
/// just before it is written, as on main: this loop is the baseline the fused one is measured
/// against, so it keeps today's memory order, though reading all three first would avoid the
/// 4K-aliasing stalls between the page-aligned mesh arrays (see docs/performance.md).
#[inline(always)]
fn add_row<const F: bool, const S: bool>(
    row: WaveRow,
    z: &mut [f32],
    dx: &mut [f32],
    dy: &mut [f32],
    pow: impl Fn(Lane<F>) -> Lane<F>,
) {
    let (b, [amp, cx, cy]) = ((Lane(row.sb), Lane(row.cb)), row.k.map(Lane));
    let cols = row.sa[..z.len()].iter().zip(&row.ca[..z.len()]);
    // Heights alone stream three arrays, not five: the vectoriser then needs no overlap checks
    // against the slopes.
    if S {
        let outs = z.iter_mut().zip(dx.iter_mut()).zip(dy.iter_mut());
        for (((z, dx), dy), (&sa, &ca)) in outs.zip(cols) {
            let (t, q) = wave_terms::<_, true>((Lane(sa), Lane(ca)), b, &pow);
            *z = amp.mul_add(t, Lane(*z)).0;
            *dx = cx.mul_add(q, Lane(*dx)).0;
            *dy = cy.mul_add(q, Lane(*dy)).0;
        }
    } else {
        for (z, (&sa, &ca)) in z.iter_mut().zip(cols) {
            let (t, _) = wave_terms::<_, false>((Lane(sa), Lane(ca)), b, &pow);
            *z = amp.mul_add(t, Lane(*z)).0;
        }
    }
}

/// `add_row` for a half-integer k, exponent E = 2k − 2.
#[inline(always)]
fn row_int<const F: bool, const S: bool, const E: u32>(
    row: WaveRow,
    z: &mut [f32],
    dx: &mut [f32],
    dy: &mut [f32],
) {
    add_row::<F, S>(row, z, dx, dy, int_pow::<Lane<F>, E>)
}

/// `add_row` for any exponent e = 2k − 2 (polynomial exp and log).
#[inline(always)]
fn row_gen<const F: bool, const S: bool>(
    row: WaveRow,
    e: f32,
    z: &mut [f32],
    dx: &mut [f32],
    dy: &mut [f32],
) {
    add_row::<F, S>(row, z, dx, dy, |h| Lane(pow_abs::<F>(h.0, e)))
}
