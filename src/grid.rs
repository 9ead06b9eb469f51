//! The N×N grid every mesh, camera and workload is laid on: its size and spacing, vertex
//! indexing and triangulation. Plain data below the ocean models, so the camera places itself
//! over the patch without importing them.

use crate::input::InputError;

/// Largest N accepted anywhere (a 4096² mesh is 400 MiB of vertices and normals in two copies).
pub const MAX_SIZE: usize = 4096;

/// The smallest grid size N (a grid needs two vertices a side).
pub const MIN_SIZE: usize = 2;

/// An N×N grid of vertices: vertex (i, j) lies at x = j·spacing, y = i·spacing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid {
    /// Vertices per side (N >= 2).
    pub n: usize,
    /// Distance between neighbouring vertices.
    pub spacing: f32,
}

impl Grid {
    /// A grid of `n`×`n` vertices; rejects n < 2, n > MAX_SIZE and non-positive spacing.
    pub fn new(n: usize, spacing: f32) -> Result<Self, InputError> {
        if !(MIN_SIZE..=MAX_SIZE).contains(&n) {
            return Err(InputError(format!(
                "size: must be 2 to {MAX_SIZE}, got {n}"
            )));
        }
        if !(spacing.is_finite() && spacing > 0.0) {
            return Err(InputError(format!(
                "spacing: must be a finite number > 0, got {spacing}"
            )));
        }
        Ok(Grid { n, spacing })
    }

    /// Number of vertices, N².
    pub fn vertices(&self) -> usize {
        self.n * self.n
    }

    /// Index of vertex (i, j) in the arrays: row-major, i the row (y), j the column (x).
    pub fn index(&self, i: usize, j: usize) -> usize {
        i * self.n + j
    }

    /// The triangle index list: two counter-clockwise (upward-facing) triangles per cell, cells in
    /// row-major order, so triangle 2c and 2c+1 belong to cell c.
    pub fn triangles(&self) -> Vec<[u32; 3]> {
        let n = self.n;
        let mut tris = Vec::with_capacity(2 * (n - 1) * (n - 1));
        for i in 0..n - 1 {
            for j in 0..n - 1 {
                let a = self.index(i, j) as u32;
                let b = self.index(i, j + 1) as u32;
                let c = self.index(i + 1, j) as u32;
                let d = self.index(i + 1, j + 1) as u32;
                tris.push([a, b, c]);
                tris.push([b, d, c]);
            }
        }
        tris
    }
}

/// The cell holding coordinate `u` (in cells) of a grid that repeats every `n` cells, the cell
/// after it, and how far into the cell `u` lies: for bilinear and trilinear lookups of a
/// repeating patch or volume.
///
/// The cell wraps in f32 rather than by integer division, which would cost more than the rest
/// of a lookup: exact for cells below 2²⁴ in magnitude (the quotient by n rounds to the right
/// integer, and every product and difference is an integer below 2²⁴); beyond, the cell is
/// clamped into 0..n. NaN gives cell 0. The same operations on every instruction set.
#[inline(always)]
pub fn periodic_cell(u: f32, n: usize) -> (usize, usize, f32) {
    let nf = n as f32;
    let cell = u.floor();
    // `as` saturates (NaN to 0), and the clamp keeps a far cell in range.
    let i0 = ((cell - (cell / nf).floor() * nf) as usize).min(n - 1);
    let i1 = if i0 + 1 == n { 0 } else { i0 + 1 };
    (i0, i1, u - cell)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_periodic_cell_is_the_integer_remainder_below_2_to_the_24() {
        let far = 1i64 << 24;
        for n in [2usize, 3, 7, 64, 100, 2048] {
            let edges = [-far + 1, far - 1, -far + 2, 12_345_677, -9_999_991];
            for c in (-5000i64..5000).chain(edges) {
                let want = c.rem_euclid(n as i64) as usize;
                for frac in [0.0f32, 0.25] {
                    let u = c as f32 + frac;
                    if (u - u.floor()) != frac {
                        continue; // no fraction left at this magnitude
                    }
                    let (i0, i1, f) = periodic_cell(u, n);
                    assert_eq!(i0, want, "n {n}, cell {c}");
                    assert_eq!(i1, (want + 1) % n, "n {n}, cell {c}");
                    assert_eq!(f, frac);
                }
            }
            for u in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 1e30, -1e30] {
                let (i0, i1, _) = periodic_cell(u, n);
                assert!(i0 < n && i1 < n, "n {n}, u {u}: {i0}, {i1}");
            }
        }
    }
}
