//! Per-wave constants and the separable phase tables.
//!
//! The phase S = a·x + (b·y + φ·t) splits into a column part and a row part, so sin and cos of
//! the half angle θ = S/2 + π/4 come from one table entry per column and one value per row by
//! angle addition. Every phase is reduced to a fraction of a turn in f64 before it becomes an
//! f32, which keeps large t and large grids as accurate as small ones.

use crate::ocean::mesh::Grid;
use crate::ocean::waves::WaveSet;
use std::f64::consts::{FRAC_PI_4, PI};

/// Largest exponent 2k − 2 evaluated by repeated multiplication; above it the polynomial
/// exp/log path is used.
pub const MAX_INT_EXP: u32 = 12;

/// Column tables are padded to a multiple of this many entries, the widest fused tile, so
/// tiles at a row's end load whole vectors (the padding is 0 and its lanes are never stored).
pub const COL_PAD: usize = 128;

/// How |h|^(2k−2) is evaluated for one wave.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Power {
    /// Half-integer k: the exponent 2k − 2 is this integer, so a few multiplies suffice.
    Int(u32),
    /// Any other k: exp((2k − 2)·ln|h|) with polynomial exp and log.
    General(f32),
}

/// The per-wave values the inner loops need, hoisted out of them.
#[derive(Clone, Debug)]
pub struct WaveConsts {
    /// Amplitude A (height term A·|h|^(2k)).
    pub amp: f32,
    /// k·(2π/L)·A·Dx: ∂f/∂x = cx·|h|^(2k−2)·h·g, since cos S = 2·sin θ·cos θ.
    pub cx: f32,
    /// k·(2π/L)·A·Dy, the y counterpart of `cx`.
    pub cy: f32,
    /// How the power is evaluated.
    pub power: Power,
    /// Dx/L in f64: column phase in turns per unit x.
    col_turns: f64,
    /// Dy/L in f64: row phase in turns per unit y.
    row_turns: f64,
    /// speed/L in f64: turns per second.
    time_turns: f64,
}

impl WaveConsts {
    /// Constants of every enabled wave, in set order (disabled waves cost nothing).
    pub fn from_set(waves: &WaveSet) -> Vec<WaveConsts> {
        waves
            .enabled()
            .map(|w| {
                let [dx, dy] = w.unit_direction();
                let k = w.steepness;
                let twice = 2.0 * k;
                let power = if twice.fract() == 0.0 && twice - 2.0 <= MAX_INT_EXP as f32 {
                    Power::Int((twice - 2.0) as u32)
                } else {
                    Power::General(twice - 2.0)
                };
                let c = k * w.frequency() * w.amplitude;
                let inv_l = 1.0 / w.wavelength as f64;
                WaveConsts {
                    amp: w.amplitude,
                    cx: c * dx,
                    cy: c * dy,
                    power,
                    col_turns: dx as f64 * inv_l,
                    row_turns: dy as f64 * inv_l,
                    time_turns: w.speed as f64 * inv_l,
                }
            })
            .collect()
    }
}

impl WaveConsts {
    /// The half angle θ = S/2 + π/4 of a point (x, y) at time t, in turns of π, as
    /// `a·x + b·y + c` with `[a, b, c]`: the time phase and the π/4 reduced in f64 first, so
    /// only the point's own part is rounded to f32 (the projected grid's per-vertex path).
    pub fn point_turns(&self, t: f64) -> [f32; 3] {
        self.point_turns_f64(t).map(|v| v as f32)
    }

    /// `point_turns` before its rounding to f32, for phases summed in f64 (rows of points on
    /// a line).
    pub fn point_turns_f64(&self, t: f64) -> [f64; 3] {
        let c = self.time_turns * t + 0.25;
        [self.col_turns, self.row_turns, c - c.floor()]
    }
}

/// Half angle π·frac(turns): the reduction to [0, π) flips the sign of both sin θ and cos θ at
/// most, which leaves sin²θ and sin θ·cos θ (all the kernel uses) unchanged.
fn half_angle(turns: f64) -> f64 {
    PI * (turns - turns.floor())
}

/// f32s starting on a 64-byte boundary: a whole-vector load from the start of a cache line
/// never straddles two, which on the AVX-512 machine measured costs 1.7 cycles instead of 1.
#[derive(Debug, Default)]
pub struct Aligned {
    buf: Vec<f32>,
    start: usize,
    len: usize,
}

impl Aligned {
    /// The values of `values`, aligned.
    pub fn from_slice(values: &[f32]) -> Aligned {
        let mut buf = vec![0.0; values.len() + 15];
        let start = buf.as_ptr().align_offset(64).min(15);
        buf[start..start + values.len()].copy_from_slice(values);
        Aligned {
            buf,
            start,
            len: values.len(),
        }
    }
}

impl Clone for Aligned {
    /// A new buffer, aligned in its own right.
    fn clone(&self) -> Self {
        Aligned::from_slice(self)
    }
}

impl std::ops::Deref for Aligned {
    type Target = [f32];
    fn deref(&self) -> &[f32] {
        &self.buf[self.start..self.start + self.len]
    }
}

/// x^e for 0 <= e < 16 by squaring, with e's bits as selects (no loop, no library call).
fn pow_small(x: f64, e: u32) -> f64 {
    let (mut p, mut b) = (1.0, x);
    for bit in 0..4 {
        p *= if e >> bit & 1 == 1 { b } else { 1.0 };
        b *= b;
    }
    p
}

/// Column tables (fixed for a grid) and the row values of the current step, for one band of
/// rows (the whole grid unless the mesh is split among helpers).
#[derive(Clone, Debug)]
pub struct Tables {
    /// The grid the tables were built for.
    pub grid: Grid,
    /// The first row of the band the row values cover.
    pub first_row: usize,
    /// Rows in the band: row values are `[wave·rows + i]`, i counted from `first_row`.
    pub rows: usize,
    /// Entries per wave in the column tables: n rounded up to a multiple of `COL_PAD`.
    pub stride: usize,
    /// sin of the column half angle, `[wave·stride + j]`.
    pub col_sin: Aligned,
    /// cos of the column half angle, `[wave·stride + j]`.
    pub col_cos: Aligned,
    /// sin of the row half angle at t = 0 (π/4 included), `[wave·rows + i]`, kept in f64 so the
    /// per-step rotation by the time phase adds no f32 error.
    row_sin0: Vec<f64>,
    /// cos counterpart of `row_sin0`.
    row_cos0: Vec<f64>,
    /// sin of the row half angle at the current t, `[wave·rows + i]`.
    pub row_sin: Vec<f32>,
    /// cos of the row half angle at the current t, `[wave·rows + i]`.
    pub row_cos: Vec<f32>,
    /// For the fused loop, `[wave·rows + i]`: of the row half angle's sin/cos and cos/sin,
    /// the one at most 1 in magnitude (t below).
    pub row_t: Vec<f32>,
    /// For the fused loop, `[wave·rows + i]`: |f|^(2k), f the larger of the row half angle's
    /// cos and sin in magnitude, negated when f is the sin. With t = sin/cos of the row,
    /// h = cos·(sa + ca·t) and g = cos·(ca − sa·t); with t = cos/sin, h = sin·(ca + sa·t) and
    /// g = −sin·(sa − ca·t). So the factor, raised to the wave's power, moves into the wave's
    /// constants for the row and h, g cost one multiply-add each.
    pub row_scale: Vec<f32>,
}

impl Tables {
    /// Builds the tables of a band from the band's own coordinates (`x`, `y` of its vertices:
    /// x of its first row, y of its first column), so the surface is evaluated at exactly the
    /// points the reference uses.
    pub fn for_rows(
        waves: &[WaveConsts],
        grid: Grid,
        first_row: usize,
        x: &[f32],
        y: &[f32],
    ) -> Tables {
        let n = grid.n;
        let rows = y.len() / n;
        let stride = n.next_multiple_of(COL_PAD);
        let (mut col_sin, mut col_cos) = (Vec::new(), Vec::new());
        let (mut row_sin0, mut row_cos0) = (Vec::new(), Vec::new());
        for w in waves {
            for &x in &x[..n] {
                let (s, c) = half_angle(w.col_turns * x as f64).sin_cos();
                col_sin.push(s as f32);
                col_cos.push(c as f32);
            }
            col_sin.resize(col_sin.len() + stride - n, 0.0);
            col_cos.resize(col_cos.len() + stride - n, 0.0);
            for i in 0..rows {
                let y = y[i * n] as f64;
                let (s, c) = (half_angle(w.row_turns * y) + FRAC_PI_4).sin_cos();
                row_sin0.push(s);
                row_cos0.push(c);
            }
        }
        Tables {
            grid,
            first_row,
            rows,
            stride,
            col_sin: Aligned::from_slice(&col_sin),
            col_cos: Aligned::from_slice(&col_cos),
            row_sin0,
            row_cos0,
            row_sin: vec![0.0; waves.len() * rows],
            row_cos: vec![0.0; waves.len() * rows],
            row_t: vec![0.0; waves.len() * rows],
            row_scale: vec![0.0; waves.len() * rows],
        }
    }

    /// Rotates every row half angle by the time phase of `t` (one f64 sin/cos per wave), into
    /// the row values the row loop in use reads: `row_sin`, `row_cos` for the per-wave loop,
    /// `row_t`, `row_scale` for the fused one (`fused`).
    pub fn set_time(&mut self, waves: &[WaveConsts], t: f64, fused: bool) {
        let m = self.rows;
        for (w, wave) in waves.iter().enumerate() {
            let (st, ct) = half_angle(wave.time_turns * t).sin_cos();
            let range = w * m..(w + 1) * m;
            let rows = self.row_sin0[range.clone()]
                .iter()
                .zip(&self.row_cos0[range.clone()])
                .map(|(&s0, &c0)| (s0 * ct + c0 * st, c0 * ct - s0 * st));
            if !fused {
                let dst = self.row_sin[range.clone()]
                    .iter_mut()
                    .zip(&mut self.row_cos[range]);
                for ((sin, cos), (s, c)) in rows.zip(dst) {
                    (*s, *c) = (sin as f32, cos as f32);
                }
                continue;
            }
            // 2k of the wave: the power |f| is raised to (General waves never run fused).
            let power = match wave.power {
                Power::Int(e) => e + 2,
                Power::General(_) => 0,
            };
            let dst = self.row_t[range.clone()]
                .iter_mut()
                .zip(&mut self.row_scale[range]);
            for ((sin, cos), (t, scale)) in rows.zip(dst) {
                // Selects, no branch: which of the two is larger changes from row to row
                // without a pattern, and this loop then vectorises.
                let cos_larger = cos.abs() >= sin.abs();
                let (f, other) = if cos_larger { (cos, sin) } else { (sin, cos) };
                *t = (other / f) as f32;
                let sign = if cos_larger { 1.0 } else { -1.0 };
                *scale = (sign * pow_small(f.abs(), power)) as f32;
            }
        }
    }
}
