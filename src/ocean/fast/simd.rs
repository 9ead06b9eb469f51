//! The row loops of the fast kernel and their run-time dispatch.
//!
//! Each loop is plain Rust over slices, `#[inline(always)]`, and is instantiated inside
//! `#[target_feature]` entry points, so LLVM vectorises the same source for AVX-512, AVX2+FMA
//! and the portable baseline; the binary stays portable and the widest path is picked at run
//! time.

use super::math::{fma, pow_abs, powi};
use super::norm;
use super::phase::{Power, Tables, WaveConsts};

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

/// Runs one step with `isa`, which the caller has checked this CPU supports.
pub fn step(isa: Isa, waves: &[WaveConsts], tables: &Tables, out: Out, analytic: bool) {
    match isa {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: `isa` comes from `Isa::available`, so the CPU has these features.
        Isa::Avx512 => unsafe { step_avx512(waves, tables, out, analytic) },
        #[cfg(target_arch = "x86_64")]
        // SAFETY: as above.
        Isa::Avx2 => unsafe { step_avx2(waves, tables, out, analytic) },
        _ => step_body::<false, false>(waves, tables, out, analytic),
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx2,fma")]
fn step_avx512(waves: &[WaveConsts], tables: &Tables, out: Out, analytic: bool) {
    step_body::<true, true>(waves, tables, out, analytic)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn step_avx2(waves: &[WaveConsts], tables: &Tables, out: Out, analytic: bool) {
    step_body::<true, false>(waves, tables, out, analytic)
}

/// Calls `$f::<F, E>` with the compile-time exponent matching `$e` (0..=MAX_INT_EXP).
macro_rules! by_exp {
    ($e:expr, $f:ident, $F:ident, ($($arg:expr),*)) => {
        match $e {
            0 => $f::<$F, 0>($($arg),*),
            1 => $f::<$F, 1>($($arg),*),
            2 => $f::<$F, 2>($($arg),*),
            3 => $f::<$F, 3>($($arg),*),
            4 => $f::<$F, 4>($($arg),*),
            5 => $f::<$F, 5>($($arg),*),
            6 => $f::<$F, 6>($($arg),*),
            7 => $f::<$F, 7>($($arg),*),
            8 => $f::<$F, 8>($($arg),*),
            9 => $f::<$F, 9>($($arg),*),
            10 => $f::<$F, 10>($($arg),*),
            11 => $f::<$F, 11>($($arg),*),
            12 => $f::<$F, 12>($($arg),*),
            _ => unreachable!("exponent above MAX_INT_EXP"),
        }
    };
}

/// Row by row, wave by wave: the row's outputs stay in L1 while every wave adds to them, and
/// the per-wave branch on the power kind is taken once per row, outside the vector loop.
/// `W` selects the AVX-512 normalisation (only instantiated inside `step_avx512`).
#[inline(always)]
fn step_body<const F: bool, const W: bool>(
    waves: &[WaveConsts],
    tables: &Tables,
    out: Out,
    analytic: bool,
) {
    let (n, m) = (tables.grid.n, tables.rows);
    let rows = out
        .z
        .chunks_exact_mut(n)
        .zip(out.nx.chunks_exact_mut(n))
        .zip(out.ny.chunks_exact_mut(n).zip(out.nz.chunks_exact_mut(n)));
    for (i, ((z, nx), (ny, nz))) in rows.enumerate() {
        z.fill(0.0);
        if analytic {
            nx.fill(0.0);
            ny.fill(0.0);
        }
        for (w, wave) in waves.iter().enumerate() {
            let sa = &tables.col_sin[w * n..(w + 1) * n];
            let ca = &tables.col_cos[w * n..(w + 1) * n];
            let (sb, cb) = (tables.row_sin[w * m + i], tables.row_cos[w * m + i]);
            let a = wave.amp;
            match (analytic, wave.power) {
                (false, Power::Int(e)) => by_exp!(e, heights_int, F, (sa, ca, sb, cb, a, z)),
                (false, Power::General(e)) => heights_gen::<F>(sa, ca, sb, cb, a, e, z),
                (true, Power::Int(e)) => {
                    by_exp!(e, full_int, F, (sa, ca, sb, cb, wave, z, nx, ny))
                }
                (true, Power::General(e)) => full_gen::<F>(sa, ca, sb, cb, wave, e, z, nx, ny),
            }
        }
        if analytic {
            #[cfg(target_arch = "x86_64")]
            if W {
                // SAFETY: W is only set in `step_avx512`, which runs on AVX-512 CPUs.
                unsafe { norm::slopes_avx512(nx, ny, nz) };
                continue;
            }
            norm::slopes::<F>(nx, ny, nz);
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

/// Adds A·|h|^(E+2) = A·((sin S + 1)/2)^k to a row of heights.
#[inline(always)]
fn heights_int<const F: bool, const E: u32>(
    sa: &[f32],
    ca: &[f32],
    sb: f32,
    cb: f32,
    amp: f32,
    z: &mut [f32],
) {
    for ((z, &sa), &ca) in z.iter_mut().zip(sa).zip(ca) {
        let h = half_sin::<F>(sa, ca, sb, cb);
        *z = fma::<F>(amp, powi::<E>(h.abs()) * (h * h), *z);
    }
}

/// `heights_int` for any exponent e = 2k − 2.
#[inline(always)]
fn heights_gen<const F: bool>(
    sa: &[f32],
    ca: &[f32],
    sb: f32,
    cb: f32,
    amp: f32,
    e: f32,
    z: &mut [f32],
) {
    for ((z, &sa), &ca) in z.iter_mut().zip(sa).zip(ca) {
        let h = half_sin::<F>(sa, ca, sb, cb);
        *z = fma::<F>(amp, pow_abs::<F>(h, e) * (h * h), *z);
    }
}

/// Adds one wave's height and slope (cos S = 2·sin θ·cos θ) to a row.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn full_int<const F: bool, const E: u32>(
    sa: &[f32],
    ca: &[f32],
    sb: f32,
    cb: f32,
    wave: &WaveConsts,
    z: &mut [f32],
    dx: &mut [f32],
    dy: &mut [f32],
) {
    let (amp, cx, cy) = (wave.amp, wave.cx, wave.cy);
    let outs = z.iter_mut().zip(dx.iter_mut()).zip(dy.iter_mut());
    for (((z, dx), dy), (&sa, &ca)) in outs.zip(sa.iter().zip(ca)) {
        let h = half_sin::<F>(sa, ca, sb, cb);
        let g = half_cos::<F>(sa, ca, sb, cb);
        let p = powi::<E>(h.abs());
        *z = fma::<F>(amp, p * (h * h), *z);
        let q = p * (h * g);
        *dx = fma::<F>(cx, q, *dx);
        *dy = fma::<F>(cy, q, *dy);
    }
}

/// `full_int` for any exponent e = 2k − 2.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn full_gen<const F: bool>(
    sa: &[f32],
    ca: &[f32],
    sb: f32,
    cb: f32,
    wave: &WaveConsts,
    e: f32,
    z: &mut [f32],
    dx: &mut [f32],
    dy: &mut [f32],
) {
    let (amp, cx, cy) = (wave.amp, wave.cx, wave.cy);
    let outs = z.iter_mut().zip(dx.iter_mut()).zip(dy.iter_mut());
    for (((z, dx), dy), (&sa, &ca)) in outs.zip(sa.iter().zip(ca)) {
        let h = half_sin::<F>(sa, ca, sb, cb);
        let g = half_cos::<F>(sa, ca, sb, cb);
        let p = pow_abs::<F>(h, e);
        *z = fma::<F>(amp, p * (h * h), *z);
        let q = p * (h * g);
        *dx = fma::<F>(cx, q, *dx);
        *dy = fma::<F>(cy, q, *dy);
    }
}
