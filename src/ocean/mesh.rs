//! The N×N grid, its structure-of-arrays vertex and normal storage, and its triangulation.

pub use crate::grid::{Grid, MAX_SIZE, MIN_SIZE};

/// Vertex positions and normals as separate arrays (structure of arrays), so kernels vectorise and
/// the frame loop copies flat slices.
///
/// The fold fields are optional: a model that fills them builds its meshes [`Mesh::with_fold`],
/// one that does not leaves them empty. They are empty `Vec`s rather than `Option`s so that
/// copying, reading and splitting into bands treat every field alike (an empty field is a
/// zero-length slice) and a mesh without them costs nothing.
#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    /// The grid this mesh covers.
    pub grid: Grid,
    /// x of each vertex: at rest on the grid unless the model displaces it.
    pub x: Vec<f32>,
    /// y of each vertex: at rest on the grid unless the model displaces it.
    pub y: Vec<f32>,
    /// Height of each vertex, rewritten every step.
    pub z: Vec<f32>,
    /// x component of each unit normal.
    pub nx: Vec<f32>,
    /// y component of each unit normal.
    pub ny: Vec<f32>,
    /// z component of each unit normal.
    pub nz: Vec<f32>,
    /// The Jacobian J of the horizontal displacement at each vertex (below 1: the surface folds);
    /// empty when the model does not fill it.
    pub fold: Vec<f32>,
    /// x of the direction in which each vertex folds; empty with `fold`.
    pub fold_dx: Vec<f32>,
    /// y of the direction in which each vertex folds; empty with `fold`.
    pub fold_dy: Vec<f32>,
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
            fold: Vec::new(),
            fold_dx: Vec::new(),
            fold_dy: Vec::new(),
        }
    }

    /// The same mesh with the fold fields, J = 1 (no fold) and no direction.
    pub fn with_fold(mut self) -> Self {
        let v = self.grid.vertices();
        self.fold = vec![1.0; v];
        self.fold_dx = vec![0.0; v];
        self.fold_dy = vec![0.0; v];
        self
    }

    /// Whether the mesh carries the fold fields.
    pub fn has_fold(&self) -> bool {
        !self.fold.is_empty()
    }

    /// Copies every position, normal and optional field from `src` (the hand-off to the render
    /// buffer); both meshes come from the same model, so they carry the same fields.
    pub fn copy_from(&mut self, src: &Mesh) {
        debug_assert_eq!(self.grid, src.grid);
        self.x.copy_from_slice(&src.x);
        self.y.copy_from_slice(&src.y);
        self.z.copy_from_slice(&src.z);
        self.nx.copy_from_slice(&src.nx);
        self.ny.copy_from_slice(&src.ny);
        self.nz.copy_from_slice(&src.nz);
        self.fold.copy_from_slice(&src.fold);
        self.fold_dx.copy_from_slice(&src.fold_dx);
        self.fold_dy.copy_from_slice(&src.fold_dy);
    }

    /// A band of whole rows: every field of its vertices (the optional ones empty when the mesh
    /// has none).
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
            x: &mut self.x[span.clone()],
            y: &mut self.y[span.clone()],
            z: &mut self.z[span.clone()],
            nx: &mut self.nx[span.clone()],
            ny: &mut self.ny[span.clone()],
            nz: &mut self.nz[span.clone()],
            fold: optional(&mut self.fold, span.clone()),
            fold_dx: optional(&mut self.fold_dx, span.clone()),
            fold_dy: optional(&mut self.fold_dy, span),
        }
    }

    /// Bytes held by one mesh's six required arrays.
    pub fn bytes(grid: Grid) -> usize {
        6 * grid.vertices() * std::mem::size_of::<f32>()
    }
}

/// The band `span` of an optional field: empty when the mesh does not carry it.
fn optional(field: &mut [f32], span: std::ops::Range<usize>) -> &mut [f32] {
    if field.is_empty() {
        field
    } else {
        &mut field[span]
    }
}

/// Whole rows `first_row..first_row + z.len() / n` of a mesh, so several threads can each fill
/// their own band of one mesh at once. Every slice covers exactly the band's vertices, but the
/// optional ones, which are empty when the mesh has none.
#[derive(Debug)]
pub struct MeshRows<'a> {
    /// The whole mesh's grid.
    pub grid: Grid,
    /// Row index (in the whole mesh) of the band's first row.
    pub first_row: usize,
    /// x of the band's vertices: a model that does not displace them reads them as the rest
    /// positions; one that does rewrites them from the grid every step.
    pub x: &'a mut [f32],
    /// y of the band's vertices, as `x`.
    pub y: &'a mut [f32],
    /// Heights of the band's vertices.
    pub z: &'a mut [f32],
    /// Normal x of the band's vertices.
    pub nx: &'a mut [f32],
    /// Normal y of the band's vertices.
    pub ny: &'a mut [f32],
    /// Normal z of the band's vertices.
    pub nz: &'a mut [f32],
    /// The fold value of the band's vertices (empty when the mesh has none).
    pub fold: &'a mut [f32],
    /// The fold direction's x (empty when the mesh has none).
    pub fold_dx: &'a mut [f32],
    /// The fold direction's y (empty when the mesh has none).
    pub fold_dy: &'a mut [f32],
}

impl MeshRows<'_> {
    /// Rows in the band.
    pub fn rows(&self) -> usize {
        self.z.len() / self.grid.n
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bands_and_copies_carry_the_fold_fields_only_when_present() {
        let grid = Grid::new(4, 1.0).unwrap();
        let mut plain = Mesh::new(grid);
        let band = plain.rows_mut(1..3);
        assert_eq!(band.z.len(), 8);
        assert!(band.fold.is_empty() && band.fold_dx.is_empty() && band.fold_dy.is_empty());

        let mut mesh = Mesh::new(grid).with_fold();
        assert!(mesh.has_fold() && !plain.has_fold());
        let band = mesh.rows_mut(1..3);
        assert_eq!(
            (band.fold.len(), band.fold_dx.len(), band.fold_dy.len()),
            (8, 8, 8)
        );
        band.fold[0] = 0.5;
        band.fold_dx[7] = -1.0;
        band.fold_dy[3] = 2.0;
        band.x[0] = 9.0;
        assert_eq!(
            mesh.fold[4], 0.5,
            "the band's first vertex is row 1's first"
        );
        assert_eq!(mesh.fold_dx[11], -1.0);
        assert_eq!(mesh.fold_dy[7], 2.0);
        assert_eq!(mesh.x[4], 9.0, "a model may displace x");

        let mut copy = Mesh::new(grid).with_fold();
        copy.copy_from(&mesh);
        assert_eq!(copy, mesh);
        plain.copy_from(&Mesh::new(grid));
        assert!(!plain.has_fold());
    }
}
