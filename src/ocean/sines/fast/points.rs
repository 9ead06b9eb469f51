//! The fast kernel at scattered points: the projected grid's vertices lie anywhere on the sea
//! plane, so the grid's separable phase tables do not apply. The per-wave loops of `simd` add
//! each wave's height and slope as they do on the regular grid; what differs is where each
//! vertex's sin and cos of the half angle come from.
//!
//! - A row whose vertices lie evenly spaced on a line (every row of a camera whose image's
//!   right is horizontal, short of the far clamp) has phases in arithmetic progression. The
//!   row is cut into segments of `SEG` vertices: one polynomial sin and cos per segment for
//!   its first vertex, one table of `SEG` for the advance along the segment, and angle
//!   addition, as on the regular grid, for each vertex. Phases are summed in f64 and reduced
//!   before they become f32.
//! - Any other row (the far line's arc, a rolled camera) takes each vertex's half angle from
//!   its own x, y by a polynomial sin and cos of π·r (r reduced to [−½, ½]), written lane by
//!   lane so LLVM vectorises it. On the fused loop (AVX-512), those sin and cos are a tile's
//!   columns with a row factor of 1, so every wave adds to the tile in registers there too.

use super::fused::{self, add_tile, store_tile};
use super::math::fma;
use super::phase::{Power, WaveConsts};
use super::simd::{self, by_exp, full, AbsPow, IntExp, Isa};
use super::vector::Vector;
use crate::ocean::mesh::MeshRows;
use crate::ocean::row_line::{RowLine, RowLines};
use crate::ocean::waves::{WaveSet, MAX_WAVES};
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

/// The f64 counterpart of `ROUNDER`: rounds an f64 below 2^51 in magnitude to an integer.
const ROUNDER_F64: f64 = 6_755_399_441_055_744.0;

/// Vertices per segment of a row on a line: the row's polynomial evaluations per wave are
/// one per segment plus one per vertex of a segment, fewest near √n over the grids run here.
const SEG: usize = 32;

/// sin and cos of π·r for r in [−½, ½].
#[inline(always)]
fn sin_cos_pi<const F: bool>(r: f32) -> (f32, f32) {
    let r2 = r * r;
    let mut ps = SIN[5];
    for k in (0..5).rev() {
        ps = fma::<F>(ps, r2, SIN[k]);
    }
    let mut pc = COS[6];
    for k in (0..6).rev() {
        pc = fma::<F>(pc, r2, COS[k]);
    }
    (ps * r, pc)
}

/// q less its nearest integer, in [−½, ½], as an f32.
#[inline(always)]
fn reduce(q: f64) -> f32 {
    (q - ((q + ROUNDER_F64) - ROUNDER_F64)) as f32
}

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
        (*s, *co) = sin_cos_pi::<F>(q - ((q + ROUNDER) - ROUNDER));
    }
}

/// A wave's half angle along a row on `line`, in turns of π: q0 at the first vertex, dq more
/// at each next one, from the wave's `point_turns_f64`.
#[inline(always)]
fn line_phase(line: RowLine, [a, b, c]: [f64; 3]) -> (f64, f64) {
    (a * line.x0 + b * line.y0 + c, a * line.dx + b * line.dy)
}

/// One wave's half angles along a row on a line: sin and cos at each segment's first vertex
/// (`first_*`, one per segment) and of the advance from it to each vertex of a segment
/// (`along_*`, `SEG` entries); vertex s·SEG + k's angle is the sum of the two.
#[inline(always)]
fn line_angles<const F: bool>(
    turns: [f64; 3],
    line: RowLine,
    [first_sin, first_cos, along_sin, along_cos]: [&mut [f32]; 4],
) {
    let (q0, dq) = line_phase(line, turns);
    for (s, (fs, fc)) in first_sin.iter_mut().zip(first_cos.iter_mut()).enumerate() {
        let q = q0 + (s * SEG) as i32 as f64 * dq;
        (*fs, *fc) = sin_cos_pi::<F>(reduce(q));
    }
    for (k, (ls, lc)) in along_sin.iter_mut().zip(along_cos.iter_mut()).enumerate() {
        (*ls, *lc) = sin_cos_pi::<F>(reduce(k as i32 as f64 * dq));
    }
}

/// Adds one wave to a row on a line, segment by segment, from its `line_angles`.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn line_wave<const F: bool>(
    [first_sin, first_cos, along_sin, along_cos]: [&[f32]; 4],
    wave: &WaveConsts,
    pow: impl AbsPow<F>,
    z: &mut [f32],
    nx: &mut [f32],
    ny: &mut [f32],
) {
    // Whole segments as arrays, so each `full` runs a loop of known length (SEG / lanes whole
    // vectors, no remainder); the row's last, shorter segment after them.
    let (zs, z_tail) = z.as_chunks_mut::<SEG>();
    let (nxs, nx_tail) = nx.as_chunks_mut::<SEG>();
    let (nys, ny_tail) = ny.as_chunks_mut::<SEG>();
    let along: (&[f32; SEG], &[f32; SEG]) = (
        along_sin.try_into().expect("SEG entries"),
        along_cos.try_into().expect("SEG entries"),
    );
    let whole = zs.len();
    let segs = zs.iter_mut().zip(nxs.iter_mut()).zip(nys.iter_mut());
    let firsts = first_sin.iter().zip(first_cos);
    for (((z, nx), ny), (&sb, &cb)) in segs.zip(firsts) {
        full::<F>(along.0, along.1, sb, cb, wave, pow, z, nx, ny);
    }
    let k = z_tail.len();
    if k > 0 {
        let (sb, cb) = (first_sin[whole], first_cos[whole]);
        full::<F>(
            &along.0[..k],
            &along.1[..k],
            sb,
            cb,
            wave,
            pow,
            z_tail,
            nx_tail,
            ny_tail,
        );
    }
}

/// The fused loop's row values (see `Tables::row_scale`) of a half angle with this sin and
/// cos, for a wave of power 2k = `power` (at most 15): t, the one of sin/cos and cos/sin at
/// most 1 in magnitude, and the larger's |·|^(2k), negated when it is the sin. In f32 and
/// branch-free, so a row's tiles and waves run as one vector loop.
#[inline(always)]
fn fused_factor(sin: f32, cos: f32, power: u32) -> (f32, f32) {
    let cos_larger = cos.abs() >= sin.abs();
    let (f, other) = if cos_larger { (cos, sin) } else { (sin, cos) };
    let (mut p, mut b) = (1.0f32, f.abs());
    for bit in 0..4 {
        p *= if power >> bit & 1 == 1 { b } else { 1.0 };
        b *= b;
    }
    (other / f, if cos_larger { p } else { -p })
}

/// Entries of a tile's table of advances that take a polynomial each: the tile's others come
/// from them by angle addition, one rotation per further `SEEDS` entries.
const SEEDS: usize = 16;

/// Rows on a line whose phases, polynomials and factors are built together, in loops long
/// enough to pay for their set-up; a block's values (18 KB at 4 waves and 256 columns) stay in L1.
const BLOCK: usize = 16;

/// The fused line loop's tables: a block of rows' polynomials and factors, and one row's table
/// of a tile's advances, in buffers kept from block to block.
#[derive(Clone, Debug, Default)]
struct LineTables {
    /// Each wave's table of a tile's advances for the row being stepped (sin, then cos, `tile`
    /// entries each), from `start`, the first entry on a 64-byte boundary.
    along: Vec<f32>,
    start: usize,
    /// The (waves, tile, tiles) the fixed parts below were built for.
    shape: (usize, usize, usize),
    /// The advances a row takes a polynomial of, in steps of dq: the `SEEDS` advances (k·dq),
    /// then the rotations (m·SEEDS·dq, m < tile / SEEDS).
    advances: Vec<f64>,
    /// The tile firsts, in steps of dq from q0 (s·tile).
    firsts: Vec<f64>,
    /// The power of each (row, wave, tile)'s factor: its wave's exponent + 2. The kernel's
    /// waves never change, so this is built with the shape.
    powers: Vec<u32>,
    /// The block's half angles, reduced, in turns of π: every (row, wave)'s advances, then every
    /// (row, wave)'s tile firsts, so each part runs as one vector loop. `sin` and `cos` hold
    /// their polynomials, in the same order.
    turns: Vec<f32>,
    sin: Vec<f32>,
    cos: Vec<f32>,
    /// Per row, wave and tile (`[(row·waves + w)·tiles + s]`): the factor's t and its scale.
    ts: Vec<f32>,
    scales: Vec<f32>,
}

impl LineTables {
    /// Builds the polynomials and factors of a block of rows on `lines` (at most `BLOCK`) in
    /// tiles of `tile` vertices, `tiles` of them: the phases in f64, one (row, wave) at a time;
    /// the polynomials and the firsts' factors each as one vector loop over the block.
    #[inline(always)]
    fn fill<const F: bool>(
        &mut self,
        turns: &[[f64; 3]],
        exps: &[u32],
        lines: &[RowLine],
        tile: usize,
        tiles: usize,
    ) {
        let (waves, per) = (turns.len(), SEEDS + tile / SEEDS);
        assert_eq!(tile % SEEDS, 0, "a tile is whole rotations of the seeds");
        assert!(lines.len() <= BLOCK);
        if self.shape != (waves, tile, tiles) {
            self.shape = (waves, tile, tiles);
            let steps = (0..SEEDS).chain((0..tile / SEEDS).map(|m| m * SEEDS));
            self.advances = steps.map(|k| k as f64).collect();
            self.firsts = (0..tiles).map(|s| (s * tile) as f64).collect();
            let row = exps.iter().flat_map(|&e| std::iter::repeat_n(e + 2, tiles));
            self.powers = row.cycle().take(BLOCK * waves * tiles).collect();
            let all = BLOCK * waves * (per + tiles);
            (self.turns, self.sin, self.cos) = (vec![0.0; all], vec![0.0; all], vec![0.0; all]);
            self.ts = vec![0.0; BLOCK * waves * tiles];
            self.scales = vec![0.0; BLOCK * waves * tiles];
        }
        let pairs = lines.len() * waves;
        let (advances, firsts) = self.turns.split_at_mut(BLOCK * waves * per);
        let outs = advances
            .chunks_exact_mut(per)
            .zip(firsts.chunks_exact_mut(tiles));
        let each = lines
            .iter()
            .flat_map(|&line| turns.iter().map(move |&w| (line, w)));
        for ((line, turns_w), (advances, firsts)) in each.zip(outs) {
            let (q0, dq) = line_phase(line, turns_w);
            for (r, &k) in advances.iter_mut().zip(&self.advances) {
                *r = reduce(k * dq);
            }
            for (r, &k) in firsts.iter_mut().zip(&self.firsts) {
                *r = reduce(q0 + k * dq);
            }
        }
        let (all, at) = (BLOCK * waves * per, pairs * per);
        let spans = [0..at, all..all + pairs * tiles];
        for span in spans {
            let outs = self.sin[span.clone()]
                .iter_mut()
                .zip(&mut self.cos[span.clone()]);
            for (&r, (s, c)) in self.turns[span].iter().zip(outs) {
                (*s, *c) = sin_cos_pi::<F>(r);
            }
        }
        let firsts = self.sin[all..].iter().zip(&self.cos[all..]);
        let factors = self.ts.iter_mut().zip(self.scales.iter_mut());
        let each = factors.zip(firsts.zip(&self.powers)).take(pairs * tiles);
        for ((t, scale), ((&s, &c), &power)) in each {
            (*t, *scale) = fused_factor(s, c, power);
        }
    }

    /// Each wave's table of a tile's advances for row `row` of the block, by angle addition on
    /// its seeds (two f32 roundings more than a polynomial of their own).
    #[inline(always)]
    fn rotate<V: Vector>(&mut self, row: usize) {
        let (waves, tile, _) = self.shape;
        let per = SEEDS + tile / SEEDS;
        // Tables start on a 64-byte boundary, as the regular grid's (`phase::Aligned`): whole
        // vector loads that straddle no cache line.
        self.along.resize(waves * 2 * tile + 15, 0.0);
        self.start = self.along.as_ptr().align_offset(64).min(15);
        let along = &mut self.along[self.start..][..waves * 2 * tile];
        let at = row * waves * per..(row + 1) * waves * per;
        let angles = self.sin[at.clone()].chunks_exact(per);
        let angles = angles.zip(self.cos[at].chunks_exact(per));
        for (table, (sin_w, cos_w)) in along.chunks_exact_mut(2 * tile).zip(angles) {
            let (seed_s, seed_c) = (&sin_w[..SEEDS], &cos_w[..SEEDS]);
            let by = sin_w[SEEDS..].iter().zip(&cos_w[SEEDS..]);
            let (sin, cos) = table.split_at_mut(tile);
            // Rotation 0 is by sin 0 = 0 and cos 0 = 1, both exact: the seeds unchanged.
            let chunks = sin.chunks_exact_mut(SEEDS).zip(cos.chunks_exact_mut(SEEDS));
            for ((sin, cos), (&sm, &cm)) in chunks.zip(by) {
                let (sm, cm) = (V::splat(sm), V::splat(cm));
                for l in (0..SEEDS).step_by(V::LANES) {
                    let (s0, c0) = (V::load(&seed_s[l..]), V::load(&seed_c[l..]));
                    s0.mul_add(cm, c0 * sm).store(&mut sin[l..]);
                    c0.mul_add(cm, -(s0 * sm)).store(&mut cos[l..]);
                }
            }
        }
    }
}

/// Row `row` of the block `tables` was filled for, every wave at once (the fused loop of the
/// regular grid): its tiles of `K` vectors take the roles of the regular grid's rows, the
/// advance along a tile those of its columns. Per wave, one table of a tile's advances and one
/// factor per tile (`LineTables`); then each tile's heights and slopes stay in registers while
/// every wave adds to them.
#[inline(always)]
fn line_fused<V: Vector, const K: usize>(
    waves: &[WaveConsts],
    exps: &[u32; MAX_WAVES],
    tables: &mut LineTables,
    row: usize,
    [z, nx, ny, nz]: [&mut [f32]; 4],
) {
    let (n, tile) = (z.len(), K * V::LANES);
    let tiles = n.div_ceil(tile);
    assert_eq!(tables.shape, (waves.len(), tile, tiles));
    tables.rotate::<V>(row);
    let along = &tables.along[tables.start..][..waves.len() * 2 * tile];
    let at = row * waves.len() * tiles;
    let (ts, scales) = (&tables.ts[at..], &tables.scales[at..]);
    for s in 0..tiles {
        let mut acc = [[[V::splat(0.0); 3]; K]; 1];
        for (w, wave) in waves.iter().enumerate() {
            let (t, scale) = (ts[w * tiles + s], scales[w * tiles + s]);
            // Which of sin and cos plays which role changes from tile to tile without a
            // pattern, so it is picked by arithmetic on the offset, not by a branch.
            let table = &along[w * 2 * tile..(w + 1) * 2 * tile];
            let first = (scale >= 0.0) as usize * tile;
            let cols = (
                &table[first..first + tile],
                &table[tile - first..2 * tile - first],
            );
            let k = [wave.amp * scale.abs(), wave.cx * scale, wave.cy * scale].map(V::splat);
            let t = (V::splat(t), V::splat(-t));
            by_exp!(exps[w], add_tile::<V, K, 1, true>(&mut acc, cols, t, k));
        }
        let out = [&mut *z, &mut *nx, &mut *ny, &mut *nz];
        store_tile::<V, K, 1, true>(acc, out, s * tile, (s + 1) * tile <= n);
    }
}

/// A row off any line, every wave at once: a tile's half angles vertex by vertex (as
/// `half_angles`), then the fused tile loop with those as its columns and a row factor of 1
/// (t = 0: h and g are each vertex's own sin and cos, exactly), so the tile's heights and
/// slopes stay in registers while every wave adds to them. `table` is scratch.
#[inline(always)]
fn points_fused<const F: bool, V: Vector, const K: usize>(
    waves: &[WaveConsts],
    exps: &[u32; MAX_WAVES],
    turns: &[[f32; 3]],
    [x, y]: [&[f32]; 2],
    table: &mut Vec<f32>,
    [z, nx, ny, nz]: [&mut [f32]; 4],
) {
    let (n, tile) = (z.len(), K * V::LANES);
    // Entries past a short last tile keep earlier values: they are computed on, never stored.
    if table.len() < waves.len() * 2 * tile {
        table.resize(waves.len() * 2 * tile, 0.0);
    }
    let zero = (V::splat(0.0), V::splat(-0.0));
    for s in 0..n.div_ceil(tile) {
        let cols = s * tile..((s + 1) * tile).min(n);
        let m = cols.len();
        let tables = table.chunks_exact_mut(2 * tile).zip(turns);
        for (table, &turns_w) in tables {
            let (sin, cos) = table.split_at_mut(tile);
            let (xs, ys) = (&x[cols.clone()], &y[cols.clone()]);
            half_angles::<F>(turns_w, xs, ys, &mut sin[..m], &mut cos[..m]);
        }
        let mut acc = [[[V::splat(0.0); 3]; K]; 1];
        for (w, (wave, table)) in waves.iter().zip(table.chunks_exact(2 * tile)).enumerate() {
            // add_tile's u = a·t + b and v = b·(−t) + a are then b = sin and a = cos.
            let (sin, cos) = table.split_at(tile);
            let k = [wave.amp, wave.cx, wave.cy].map(V::splat);
            by_exp!(
                exps[w],
                add_tile::<V, K, 1, true>(&mut acc, (cos, sin), zero, k)
            );
        }
        let out = [&mut *z, &mut *nx, &mut *ny, &mut *nz];
        store_tile::<V, K, 1, true>(acc, out, s * tile, m == tile);
    }
}

/// The fast kernel's state for scattered points: the waves' constants, the instruction set,
/// and the sin and cos buffers of one row (per vertex, or per segment and along one).
#[derive(Clone, Debug)]
pub struct PointsKernel {
    isa: Isa,
    fused: bool,
    waves: Vec<WaveConsts>,
    turns: Vec<[f32; 3]>,
    turns_f64: Vec<[f64; 3]>,
    sin: Vec<f32>,
    cos: Vec<f32>,
    along: Vec<f32>,
    line_tables: LineTables,
}

impl PointsKernel {
    /// A kernel for `waves` on the widest instruction set this CPU has.
    pub fn new(waves: &WaveSet) -> Self {
        Self::with_isa(waves, Isa::detect())
    }

    /// A kernel forced to `isa`, one of `Isa::available()`.
    pub fn with_isa(waves: &WaveSet, isa: Isa) -> Self {
        assert!(Isa::available().contains(&isa), "{isa:?} not supported");
        let waves = WaveConsts::from_set(waves);
        PointsKernel {
            isa,
            // As on the regular grid (`FastKernel::with_isa`): fused tiles pay on AVX-512 only.
            fused: isa == Isa::Avx512 && fused::covers(&waves),
            waves,
            turns: Vec::new(),
            turns_f64: Vec::new(),
            sin: Vec::new(),
            cos: Vec::new(),
            along: vec![0.0; 2 * SEG],
            line_tables: LineTables::default(),
        }
    }

    /// Fills heights and analytic normals of a band at the x, y it holds, at time `t`: the
    /// reference kernel's surface within the fast kernel's tolerance. `lines` says which rows
    /// lie on a line (checked here, row by row, when it is None). Each vertex depends on its
    /// own x, y alone, so bands agree bit for bit with a whole-mesh step.
    pub fn step_rows(&mut self, rows: MeshRows<'_>, t: f32, lines: RowLines<'_>) {
        let n = rows.grid.n;
        self.sin.resize(n, 0.0);
        self.cos.resize(n, 0.0);
        self.turns.clear();
        let at_t = self.waves.iter().map(|w| w.point_turns(t as f64));
        self.turns.extend(at_t);
        self.turns_f64.clear();
        let at_t = self.waves.iter().map(|w| w.point_turns_f64(t as f64));
        self.turns_f64.extend(at_t);
        simd::dispatch(
            self.isa,
            Points {
                fused: self.fused,
                waves: &self.waves,
                turns: &self.turns,
                turns_f64: &self.turns_f64,
                rows,
                lines,
                sin: &mut self.sin,
                cos: &mut self.cos,
                along: &mut self.along,
                line_tables: &mut self.line_tables,
            },
        );
    }
}

/// One step at scattered points, for [`simd::dispatch`].
struct Points<'a, 'm> {
    fused: bool,
    waves: &'a [WaveConsts],
    turns: &'a [[f32; 3]],
    turns_f64: &'a [[f64; 3]],
    rows: MeshRows<'m>,
    lines: RowLines<'a>,
    sin: &'a mut [f32],
    cos: &'a mut [f32],
    along: &'a mut Vec<f32>,
    line_tables: &'a mut LineTables,
}

impl simd::ForIsa for Points<'_, '_> {
    type Output = ();

    /// Row by row, as the regular grid: a row's outputs stay in L1 while every wave adds to
    /// them. On the fused loop, the tables of a block of `BLOCK` rows are filled at its first.
    #[inline(always)]
    fn run<const F: bool, const K: usize, V: Vector>(self) {
        let Points {
            fused,
            waves,
            turns,
            turns_f64,
            rows,
            lines,
            sin,
            cos,
            along,
            line_tables,
        } = self;
        let n = rows.grid.n;
        let (all_x, all_y) = (&*rows.x, &*rows.y);
        let xs = all_x.chunks_exact(n).zip(all_y.chunks_exact(n));
        let outs = simd::Out {
            z: rows.z,
            nx: rows.nx,
            ny: rows.ny,
            nz: rows.nz,
        };
        let exps = if fused {
            fused::exps(waves)
        } else {
            [0; MAX_WAVES]
        };
        // The block's lines, and which of its rows on a line comes next.
        let (mut block, mut next) = ([None; BLOCK], 0);
        for (r, ((x, y), [z, nx, ny, nz])) in xs.zip(outs.rows(n)).enumerate() {
            // A block's lines are found, and its tables filled, at its first row.
            if r % BLOCK == 0 {
                let these = r..(r + BLOCK).min(all_x.len() / n);
                for (i, line) in these.clone().zip(&mut block) {
                    *line = match lines {
                        Some(lines) => lines[i],
                        None => RowLine::of(&all_x[i * n..][..n], &all_y[i * n..][..n]),
                    };
                }
                if fused {
                    let (mut on, mut count) = ([RowLine::default(); BLOCK], 0);
                    for line in block[..these.len()].iter().flatten() {
                        on[count] = *line;
                        count += 1;
                    }
                    let (tile, tiles) = (K * V::LANES, n.div_ceil(K * V::LANES));
                    let exps = &exps[..waves.len()];
                    line_tables.fill::<F>(turns_f64, exps, &on[..count], tile, tiles);
                    next = 0;
                }
            }
            let line = block[r % BLOCK];
            debug_assert!(
                line.is_none() || RowLine::of(x, y) == line,
                "row {r} vouched for as a line is not one"
            );
            if let (Some(_), true) = (line, fused) {
                line_fused::<V, K>(waves, &exps, line_tables, next, [z, nx, ny, nz]);
                next += 1;
                continue;
            }
            if fused {
                points_fused::<F, V, K>(waves, &exps, turns, [x, y], along, [z, nx, ny, nz]);
                continue;
            }
            z.fill(0.0);
            nx.fill(0.0);
            ny.fill(0.0);
            if let Some(line) = line {
                let segs = n.div_ceil(SEG);
                let (first_sin, first_cos) = (&mut sin[..segs], &mut cos[..segs]);
                let (along_sin, rest) = along.split_at_mut(SEG);
                let along_cos = &mut rest[..SEG];
                for (wave, &turns) in waves.iter().zip(turns_f64) {
                    let angles = [&mut *first_sin, &mut *first_cos, along_sin, along_cos];
                    line_angles::<F>(turns, line, angles);
                    let angles = [&*first_sin, &*first_cos, &*along_sin, &*along_cos];
                    match wave.power {
                        Power::Int(e) => {
                            by_exp!(e, E => line_wave::<F>(angles, wave, IntExp::<E>, z, nx, ny))
                        }
                        Power::General(e) => line_wave::<F>(angles, wave, e, z, nx, ny),
                    }
                }
                V::slopes_to_normals::<F>(nx, ny, nz);
                continue;
            }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Camera;
    use crate::ocean::mesh::{Grid, Mesh};

    #[test]
    fn rows_on_lines_and_off_them_give_the_surface_at_their_points() {
        let waves = WaveSet::default();
        let n = 100;
        let grid = Grid::new(n, 1.0).unwrap();
        let mut mesh = Mesh::new(grid);
        // Each row a line of its own spacing, from under a metre between vertices to several
        // wavelengths (a phase advance of more than a turn per vertex); every fifth row bent
        // off its line, so the per-vertex path runs beside the line path.
        let mut bent = 0;
        for i in 0..n {
            let (x0, y0) = (-40.0 + i as f32, 7.0 - 0.5 * i as f32);
            let (dx, dy) = (0.3 + 0.7 * i as f32, 0.2 * i as f32 - 5.0);
            for j in 0..n {
                let v = grid.index(i, j);
                mesh.x[v] = x0 + j as f32 * dx;
                mesh.y[v] = y0 + j as f32 * dy;
                if i % 5 == 0 {
                    mesh.x[v] += (j as f32 * 0.3).sin();
                }
            }
            let row = i * n..(i + 1) * n;
            bent += RowLine::of(&mesh.x[row.clone()], &mesh.y[row]).is_none() as usize;
        }
        assert_eq!(bent, n / 5);
        let lines: Vec<_> = (0..n)
            .map(|i| RowLine::of(&mesh.x[i * n..][..n], &mesh.y[i * n..][..n]))
            .collect();
        for isa in Isa::available() {
            for t in [0.0, 37.25] {
                // Told which rows are lines, the kernel takes them as it finds them itself.
                let mut told = mesh.clone();
                let rows = told.rows_mut(0..n);
                PointsKernel::with_isa(&waves, isa).step_rows(rows, t, Some(&lines));
                PointsKernel::with_isa(&waves, isa).step_rows(mesh.rows_mut(0..n), t, None);
                assert_eq!(
                    [&told.z, &told.nx, &told.ny, &told.nz],
                    [&mesh.z, &mesh.nx, &mesh.ny, &mesh.nz],
                    "{isa:?} t {t}"
                );
                for v in 0..n * n {
                    let (x, y, t) = (mesh.x[v] as f64, mesh.y[v] as f64, t as f64);
                    let z = waves.height_f64(x, y, t);
                    let normal = waves.normal_f64(x, y, t);
                    let got = [mesh.nx[v], mesh.ny[v], mesh.nz[v]].map(f64::from);
                    let off = (0..3)
                        .map(|k| (got[k] - normal[k]).abs())
                        .fold(0.0, f64::max);
                    let at = format!("{isa:?} t {t} vertex {v} ({x}, {y})");
                    assert!(
                        (mesh.z[v] as f64 - z).abs() < 1e-4,
                        "{at}: z {} vs {z}",
                        mesh.z[v]
                    );
                    assert!(off < 1e-4, "{at}: normal {got:?} vs {normal:?}");
                }
            }
        }
    }

    #[test]
    fn the_default_camera_s_rows_short_of_far_are_lines_and_its_far_row_is_not() {
        let n = 256;
        let grid = Grid::new(n, 1.0).unwrap();
        let view = Camera::default().view_at(grid, 1.5);
        let mut mesh = Mesh::new(grid);
        let mut lines = Vec::new();
        crate::projected::place(&view, &mut mesh.rows_mut(0..n), &mut lines);
        assert_eq!(lines.len(), n);
        let (mut short, mut clamped) = (0, 0);
        for (i, &line) in lines.iter().enumerate() {
            let (x, y) = (&mesh.x[i * n..][..n], &mesh.y[i * n..][..n]);
            // What the placement says of a row is what the check finds in it.
            assert!(line.is_none() || line == RowLine::of(x, y), "row {i}");
            let reach = |j: usize| (x[j] - view.eye.x).hypot(y[j] - view.eye.y);
            if (0..n).all(|j| reach(j) < 0.999 * view.far) {
                assert!(RowLine::of(x, y).is_some(), "row {i} is short of far");
                assert!(line.is_some(), "row {i} is placed as a line");
                short += 1;
            } else if (0..n).all(|j| reach(j) > 0.999 * view.far) {
                assert_eq!(RowLine::of(x, y), None, "row {i} lies on the far arc");
                assert_eq!(line, None, "row {i} lies on the far arc");
                clamped += 1;
            }
        }
        assert!(
            short > n / 2 && clamped > 0,
            "{short} rows short of far, {clamped} clamped"
        );
    }
}
