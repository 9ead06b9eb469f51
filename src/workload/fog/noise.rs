//! Improved (gradient) Perlin noise over a regular voxel grid, as the `noise` crate's `Perlin`
//! computes it point by point: the same permutation table from the same seed, the same 12-edge
//! gradient set, quintic fade and scale, evaluated a whole row of voxels at a time.
//!
//! Along a row only x varies, so the y and z halves of every lattice gradient's dot product and
//! the y-z interpolation are done once per lattice column (a value `a + b·dx` for the column),
//! and each voxel is a linear blend of its cell's two columns: about ten flops per sample, in a
//! loop without gathers that LLVM vectorises ([`crate::isa`]).

use crate::isa::{self, Isa};
use std::sync::atomic::{AtomicBool, Ordering};

/// Largest difference the tests allow between this noise (f32) and the `noise` crate's Perlin
/// (f64) on a volume of octave sums in [−1, 1]: a few f32 roundings of values of order 1.
pub const ORACLE_TOLERANCE: f32 = 2e-6;

/// Entries of a permutation table (lattice coordinates wrap at this period).
const TABLE: usize = 256;

/// The `noise` crate's scale for 3-D Perlin noise, 2/√3: its unscaled range is ±√3/2.
const SCALE: f32 = 1.154_700_5;

/// Gradient components indexed by the low four bits of a corner's hash: the twelve cube
/// edges, four of them twice, in the `noise` crate's order.
const GX: [f32; 16] = [
    1., -1., 1., -1., 1., -1., 1., -1., 0., 0., 0., 0., 1., -1., 0., 0.,
];
const GY: [f32; 16] = [
    1., 1., -1., -1., 0., 0., 0., 0., 1., -1., 1., -1., 1., 1., -1., -1.,
];
const GZ: [f32; 16] = [
    0., 0., 0., 0., 1., 1., -1., -1., 1., 1., -1., -1., 0., 0., 1., -1.,
];

/// A permutation of 0..=255, shuffled from a seed exactly as `noise::PermutationTable::new`
/// does (a xorshift128 generator seeded with `[1, 0, 0, 0, seed × 3]` in bytes, then
/// `rand` 0.8's Fisher-Yates with its widening-multiply range sampler), so that a seed here is
/// the same noise as the same seed there.
pub fn permutation(seed: u32) -> [u8; TABLE] {
    let mut bytes = [0u8; 16];
    bytes[0] = 1;
    for i in 1..4 {
        bytes[i * 4..i * 4 + 4].copy_from_slice(&seed.to_le_bytes());
    }
    let word = |i: usize| u32::from_le_bytes(bytes[i * 4..i * 4 + 4].try_into().expect("4 bytes"));
    // Never all zero: byte 0 is 1.
    let mut s = [word(0), word(1), word(2), word(3)];
    let mut next = move || {
        let t = s[0] ^ (s[0] << 11);
        s = [s[1], s[2], s[3], s[3] ^ (s[3] >> 19) ^ (t ^ (t >> 8))];
        s[3]
    };
    let mut below = move |range: u32| loop {
        let zone = (range << range.leading_zeros()).wrapping_sub(1);
        let m = u64::from(next()) * u64::from(range);
        if (m as u32) <= zone {
            return (m >> 32) as usize;
        }
    };
    let mut table = [0u8; TABLE];
    for (i, v) in table.iter_mut().enumerate() {
        *v = i as u8;
    }
    for i in (1..TABLE).rev() {
        table.swap(i, below(i as u32 + 1));
    }
    table
}

/// One octave: its lattice spacing in voxels, its weight in the sum and its permutation.
#[derive(Clone, Debug)]
pub struct Octave {
    /// Voxels per lattice cell.
    pub stride: f64,
    /// Weight of the octave in the volume (the weights are normalised to sum to 1).
    pub weight: f32,
    /// The octave's permutation table.
    pub table: [u8; TABLE],
}

/// The noise volume's sample positions for one frame: voxel (i, j, k) of octave o samples
/// Perlin noise at ((i, j, k) + offset) / stride_o.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// Voxels the volume's origin has moved (the fog drifting), per axis.
    pub offset: [f64; 3],
}

impl Frame {
    /// The lattice coordinate of voxel `i` on `axis` for an octave of `stride`.
    pub fn coordinate(&self, axis: usize, i: usize, stride: f64) -> f64 {
        (i as f64 + self.offset[axis]) / stride
    }
}

/// Where along one axis each voxel falls in its lattice cell, for one octave: the cell's
/// lattice index, the fraction within it and its quintic fade, for every voxel; the runs of
/// voxels sharing a cell.
struct Axis {
    cell: Vec<i64>,
    frac: Vec<f32>,
    fade: Vec<f32>,
}

impl Axis {
    fn new(n: usize, frame: &Frame, axis: usize, stride: f64) -> Axis {
        let mut a = Axis {
            cell: Vec::with_capacity(n),
            frac: Vec::with_capacity(n),
            fade: Vec::with_capacity(n),
        };
        for i in 0..n {
            let p = frame.coordinate(axis, i, stride);
            let cell = p.floor();
            let u = (p - cell) as f32;
            a.cell.push(cell as i64);
            a.frac.push(u);
            a.fade.push(quintic(u));
        }
        a
    }
}

fn quintic(u: f32) -> f32 {
    u * u * u * (u * (u * 6.0 - 15.0) + 10.0)
}

fn lerp(a: f32, b: f32, t: f32) -> f32 {
    a + t * (b - a)
}

/// The volume's noise, stopped early when `stop` is raised (then `false`).
///
/// `volume` is `n`³ voxels, x fastest: voxel (i, j, k) at `(k·n + j)·n + i`. Each is the
/// weighted sum of the octaves' Perlin noise, each octave clamped to ±1 as the `noise` crate
/// does, the weights normalised to sum to 1.
pub fn fill(
    volume: &mut [f32],
    n: usize,
    octaves: &[Octave],
    frame: &Frame,
    stop: Option<&AtomicBool>,
) -> bool {
    fill_with(Isa::detect(), volume, n, octaves, frame, stop)
}

/// [`fill`] with the instruction set given (tests run every one).
pub fn fill_with(
    isa: Isa,
    volume: &mut [f32],
    n: usize,
    octaves: &[Octave],
    frame: &Frame,
    stop: Option<&AtomicBool>,
) -> bool {
    assert_eq!(volume.len(), n * n * n, "an n³ volume");
    let total: f32 = octaves.iter().map(|o| o.weight).sum();
    volume.fill(0.0);
    for octave in octaves {
        let weight = octave.weight / total;
        let axes = [0, 1, 2].map(|a| Axis::new(n, frame, a, octave.stride));
        let (first, last) = (axes[0].cell[0], axes[0].cell[n - 1]);
        let columns = (last - first + 2) as usize;
        // The runs of voxels of each lattice cell along x: cell c covers runs[c]..runs[c + 1].
        let mut runs = vec![0usize; columns];
        for (i, &c) in axes[0].cell.iter().enumerate() {
            runs[(c - first + 1) as usize] = i + 1;
        }
        // A stride below one voxel skips cells: they get empty runs.
        for c in 1..columns {
            runs[c] = runs[c].max(runs[c - 1]);
        }
        let mut rows = Rows {
            a: vec![0.0; columns],
            b: vec![0.0; columns],
            runs,
            first,
            axes: &axes,
            weight,
            table: &octave.table,
        };
        for (r, row) in volume.chunks_exact_mut(n).enumerate() {
            if r % 64 == 0 && stop.is_some_and(|s| s.load(Ordering::Relaxed)) {
                return false;
            }
            rows.row(isa, r % n, r / n, row);
        }
    }
    true
}

/// One octave's per-row state: the columns' `a + b·dx` and the x runs.
struct Rows<'a> {
    a: Vec<f32>,
    b: Vec<f32>,
    runs: Vec<usize>,
    first: i64,
    axes: &'a [Axis; 3],
    weight: f32,
    table: &'a [u8; TABLE],
}

impl Rows<'_> {
    /// Adds the octave to row (j, k).
    fn row(&mut self, isa: Isa, j: usize, k: usize, out: &mut [f32]) {
        let p = self.table;
        let (y, v, sy) = (
            self.axes[1].cell[j],
            self.axes[1].frac[j],
            self.axes[1].fade[j],
        );
        let (z, w, sz) = (
            self.axes[2].cell[k],
            self.axes[2].frac[k],
            self.axes[2].fade[k],
        );
        let wrap = |c: i64| (c & 0xff) as usize;
        let (y0, y1, z0, z1) = (wrap(y), wrap(y + 1), wrap(z), wrap(z + 1));
        for (col, (a, b)) in self.a.iter_mut().zip(&mut self.b).enumerate() {
            let px = p[wrap(self.first + col as i64)] as usize;
            let (hy0, hy1) = (p[px ^ y0] as usize, p[px ^ y1] as usize);
            let corner = |hy: usize, zc: usize, dy: f32, dz: f32| {
                let h = (p[hy ^ zc] & 15) as usize;
                (GY[h] * dy + GZ[h] * dz, GX[h])
            };
            // The noise crate's order: z first, then y.
            let (a00, b00) = corner(hy0, z0, v, w);
            let (a01, b01) = corner(hy0, z1, v, w - 1.0);
            let (a10, b10) = corner(hy1, z0, v - 1.0, w);
            let (a11, b11) = corner(hy1, z1, v - 1.0, w - 1.0);
            *a = lerp(lerp(a00, a01, sz), lerp(a10, a11, sz), sy);
            *b = lerp(lerp(b00, b01, sz), lerp(b10, b11, sz), sy);
        }
        isa::run(isa, Samples { rows: self, out });
    }
}

/// Adds the octave's samples to a row, one run of a lattice cell at a time: within a run the
/// cell's two columns are constants and the loop is a vector loop.
struct Samples<'a, 'b> {
    rows: &'a Rows<'b>,
    out: &'a mut [f32],
}

impl isa::Loop for Samples<'_, '_> {
    type Output = ();

    #[inline(always)]
    fn run(self) {
        let r = self.rows;
        let (u, s) = (&r.axes[0].frac, &r.axes[0].fade);
        for c in 0..r.runs.len() - 1 {
            let (start, end) = (r.runs[c], r.runs[c + 1]);
            let (a0, b0, a1, b1) = (r.a[c], r.b[c], r.a[c + 1], r.b[c + 1]);
            let out = &mut self.out[start..end];
            for ((o, &u), &s) in out.iter_mut().zip(&u[start..end]).zip(&s[start..end]) {
                let g0 = a0 + b0 * u;
                let g1 = a1 + b1 * (u - 1.0);
                let noise = (lerp(g0, g1, s) * SCALE).clamp(-1.0, 1.0);
                *o += r.weight * noise;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_tile_the_row() {
        let frame = Frame {
            offset: [0.3, 0.0, 0.0],
        };
        let a = Axis::new(20, &frame, 0, 3.5);
        assert_eq!(a.cell[0], 0);
        assert_eq!(a.cell[19], ((19.3f64) / 3.5).floor() as i64);
        assert!(a.frac.iter().all(|&u| (0.0..1.0).contains(&u)));
    }
}
