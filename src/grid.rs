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
