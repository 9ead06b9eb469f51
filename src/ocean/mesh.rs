//! The N×N grid, its structure-of-arrays vertex and normal storage, and its triangulation.

use crate::input::InputError;

/// Largest N accepted anywhere (a 4096² mesh is 400 MiB of vertices and normals in two copies).
pub const MAX_SIZE: usize = 4096;

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
        if !(2..=MAX_SIZE).contains(&n) {
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

/// Vertex positions and normals as separate arrays (structure of arrays), so kernels vectorise and
/// the frame loop copies six flat slices.
#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    /// The grid this mesh covers.
    pub grid: Grid,
    /// x of each vertex (fixed by the grid).
    pub x: Vec<f32>,
    /// y of each vertex (fixed by the grid).
    pub y: Vec<f32>,
    /// Height of each vertex, rewritten every step.
    pub z: Vec<f32>,
    /// x component of each unit normal.
    pub nx: Vec<f32>,
    /// y component of each unit normal.
    pub ny: Vec<f32>,
    /// z component of each unit normal.
    pub nz: Vec<f32>,
}

impl Mesh {
    /// A flat mesh at height 0 with upward normals.
    pub fn new(grid: Grid) -> Self {
        let v = grid.vertices();
        let mut x = Vec::with_capacity(v);
        let mut y = Vec::with_capacity(v);
        for i in 0..grid.n {
            for j in 0..grid.n {
                x.push(j as f32 * grid.spacing);
                y.push(i as f32 * grid.spacing);
            }
        }
        Mesh {
            grid,
            x,
            y,
            z: vec![0.0; v],
            nx: vec![0.0; v],
            ny: vec![0.0; v],
            nz: vec![1.0; v],
        }
    }

    /// Copies every position and normal from `src` (the hand-off to the render buffer).
    pub fn copy_from(&mut self, src: &Mesh) {
        debug_assert_eq!(self.grid, src.grid);
        self.x.copy_from_slice(&src.x);
        self.y.copy_from_slice(&src.y);
        self.z.copy_from_slice(&src.z);
        self.nx.copy_from_slice(&src.nx);
        self.ny.copy_from_slice(&src.ny);
        self.nz.copy_from_slice(&src.nz);
    }

    /// A band of whole rows: their positions to read and their heights and normals to write.
    pub fn rows_mut(&mut self, rows: std::ops::Range<usize>) -> MeshRows<'_> {
        let n = self.grid.n;
        assert!(
            rows.start <= rows.end && rows.end <= n,
            "rows {rows:?} outside 0..{n}"
        );
        let span = rows.start * n..rows.end * n;
        MeshRows {
            grid: self.grid,
            first_row: rows.start,
            x: &self.x[span.clone()],
            y: &self.y[span.clone()],
            z: &mut self.z[span.clone()],
            nx: &mut self.nx[span.clone()],
            ny: &mut self.ny[span.clone()],
            nz: &mut self.nz[span],
        }
    }

    /// Bytes held by one mesh's six arrays.
    pub fn bytes(grid: Grid) -> usize {
        6 * grid.vertices() * std::mem::size_of::<f32>()
    }
}

/// Whole rows `first_row..first_row + z.len() / n` of a mesh, so several threads can each fill
/// their own band of one mesh at once. Every slice covers exactly the band's vertices.
#[derive(Debug)]
pub struct MeshRows<'a> {
    /// The whole mesh's grid.
    pub grid: Grid,
    /// Row index (in the whole mesh) of the band's first row.
    pub first_row: usize,
    /// x of the band's vertices.
    pub x: &'a [f32],
    /// y of the band's vertices.
    pub y: &'a [f32],
    /// Heights of the band's vertices.
    pub z: &'a mut [f32],
    /// Normal x of the band's vertices.
    pub nx: &'a mut [f32],
    /// Normal y of the band's vertices.
    pub ny: &'a mut [f32],
    /// Normal z of the band's vertices.
    pub nz: &'a mut [f32],
}

impl MeshRows<'_> {
    /// Rows in the band.
    pub fn rows(&self) -> usize {
        self.z.len() / self.grid.n
    }
}
