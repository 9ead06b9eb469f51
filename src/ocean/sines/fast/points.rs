//! The fast kernel at scattered points: the projected grid's vertices lie anywhere on the sea
//! plane, so the separable phase tables do not apply. Each vertex's half angle comes from its
//! own x, y by a polynomial sin and cos of π·r (r reduced to [−½, ½]), written lane by lane so
//! LLVM vectorises it; the per-wave loops of `simd` then add each wave's height and slope as
//! they do on the regular grid, reading the per-vertex sin and cos as their column tables.

use super::math::fma;
use super::phase::{Power, WaveConsts};
use super::simd::{self, by_exp, full, IntExp, Isa};
use super::vector::Vector;
use crate::ocean::mesh::MeshRows;
use crate::ocean::waves::WaveSet;
use std::f64::consts::PI;

/// Adding then subtracting 1.5·2^23 rounds an f32 below 2^22 in magnitude to an integer
/// without a library call (which the portable baseline, lacking `roundps`, would make).
const ROUNDER: f32 = 12_582_912.0;

/// Taylor coefficients of sin(π·r)/r in r², to r^10: below 1e-7 off on [−½, ½].
const SIN: [f32; 6] = [
    PI as f32,
    (-PI * PI * PI / 6.0) as f32,
    (PI * PI * PI * PI * PI / 120.0) as f32,
    (-PI * PI * PI * PI * PI * PI * PI / 5040.0) as f32,
    (PI * PI * PI * PI * PI * PI * PI * PI * PI / 362_880.0) as f32,
    (-PI * PI * PI * PI * PI * PI * PI * PI * PI * PI * PI / 39_916_800.0) as f32,
];

/// Taylor coefficients of cos(π·r) in r², to r^12: below 1e-7 off on [−½, ½].
const COS: [f32; 7] = [
    1.0,
    (-PI * PI / 2.0) as f32,
    (PI * PI * PI * PI / 24.0) as f32,
    (-PI * PI * PI * PI * PI * PI / 720.0) as f32,
    (PI * PI * PI * PI * PI * PI * PI * PI / 40_320.0) as f32,
    (-PI * PI * PI * PI * PI * PI * PI * PI * PI * PI / 3_628_800.0) as f32,
    (PI * PI * PI * PI * PI * PI * PI * PI * PI * PI * PI * PI / 479_001_600.0) as f32,
];

/// sin and cos of the half angle π·(a·x + b·y + c) of each point. The reduction by whole
/// turns of π may flip both signs, which leaves h² and h·g, all the wave formula uses,
/// unchanged.
#[inline(always)]
fn half_angles<const F: bool>(
    [a, b, c]: [f32; 3],
    x: &[f32],
    y: &[f32],
    sin: &mut [f32],
    cos: &mut [f32],
) {
    let outs = sin.iter_mut().zip(cos.iter_mut());
    for ((s, co), (&x, &y)) in outs.zip(x.iter().zip(y)) {
        let q = fma::<F>(a, x, fma::<F>(b, y, c));
        let r = q - ((q + ROUNDER) - ROUNDER);
        let r2 = r * r;
        let mut ps = SIN[5];
        for k in (0..5).rev() {
            ps = fma::<F>(ps, r2, SIN[k]);
        }
        let mut pc = COS[6];
        for k in (0..6).rev() {
            pc = fma::<F>(pc, r2, COS[k]);
        }
        *s = ps * r;
        *co = pc;
    }
}

/// The fast kernel's state for scattered points: the waves' constants, the instruction set,
/// and the per-vertex sin and cos of one row.
#[derive(Clone, Debug)]
pub struct PointsKernel {
    isa: Isa,
    waves: Vec<WaveConsts>,
    turns: Vec<[f32; 3]>,
    sin: Vec<f32>,
    cos: Vec<f32>,
}

impl PointsKernel {
    /// A kernel for `waves` on the widest instruction set this CPU has.
    pub fn new(waves: &WaveSet) -> Self {
        Self::with_isa(waves, Isa::detect())
    }

    /// A kernel forced to `isa`, one of `Isa::available()`.
    pub fn with_isa(waves: &WaveSet, isa: Isa) -> Self {
        assert!(Isa::available().contains(&isa), "{isa:?} not supported");
        PointsKernel {
            isa,
            waves: WaveConsts::from_set(waves),
            turns: Vec::new(),
            sin: Vec::new(),
            cos: Vec::new(),
        }
    }

    /// Fills heights and analytic normals of a band at the x, y it holds, at time `t`: the
    /// reference kernel's surface within the fast kernel's tolerance. Each vertex depends on
    /// its own x, y alone, so bands agree bit for bit with a whole-mesh step.
    pub fn step_rows(&mut self, rows: MeshRows<'_>, t: f32) {
        let n = rows.grid.n;
        self.sin.resize(n, 0.0);
        self.cos.resize(n, 0.0);
        self.turns.clear();
        let at_t = self.waves.iter().map(|w| w.point_turns(t as f64));
        self.turns.extend(at_t);
        simd::dispatch(
            self.isa,
            Points {
                waves: &self.waves,
                turns: &self.turns,
                rows,
                sin: &mut self.sin,
                cos: &mut self.cos,
            },
        );
    }
}

/// One step at scattered points, for [`simd::dispatch`].
struct Points<'a, 'm> {
    waves: &'a [WaveConsts],
    turns: &'a [[f32; 3]],
    rows: MeshRows<'m>,
    sin: &'a mut [f32],
    cos: &'a mut [f32],
}

impl simd::ForIsa for Points<'_, '_> {
    type Output = ();

    /// Row by row, wave by wave, as the regular grid's per-wave loop: a row's outputs stay in
    /// L1 while every wave adds to them.
    #[inline(always)]
    fn run<const F: bool, const K: usize, V: Vector>(self) {
        let Points {
            waves,
            turns,
            rows,
            sin,
            cos,
        } = self;
        let n = rows.grid.n;
        let xs = rows.x.chunks_exact(n).zip(rows.y.chunks_exact(n));
        let outs = simd::Out {
            z: rows.z,
            nx: rows.nx,
            ny: rows.ny,
            nz: rows.nz,
        };
        for ((x, y), [z, nx, ny, nz]) in xs.zip(outs.rows(n)) {
            z.fill(0.0);
            nx.fill(0.0);
            ny.fill(0.0);
            for (wave, &turns) in waves.iter().zip(turns) {
                half_angles::<F>(turns, x, y, sin, cos);
                // Row values 0 and 1: the angle addition then returns each vertex's own sin
                // and cos unchanged.
                let (s, c): (&[f32], &[f32]) = (sin, cos);
                match wave.power {
                    Power::Int(e) => {
                        by_exp!(e, E => full::<F>(s, c, 0.0, 1.0, wave, IntExp::<E>, z, nx, ny))
                    }
                    Power::General(e) => full::<F>(s, c, 0.0, 1.0, wave, e, z, nx, ny),
                }
            }
            V::slopes_to_normals::<F>(nx, ny, nz);
        }
    }
}
