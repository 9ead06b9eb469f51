//! The N×N grid, its structure-of-arrays vertex and normal storage, and its triangulation.

pub use crate::grid::{Grid, MAX_SIZE, MIN_SIZE};
use aligned_vec::{AVec, ConstAlign};

/// The bytes every mesh array starts on: a cache line, so that a kernel's whole AVX-512 vectors
/// (and aligned AVX2 pairs) never straddle two lines. With `Vec`'s 16-byte start every 64-byte
/// access split across two lines, and the `neighbors` stencil ran about 1.7 times slower at
/// 256² on an AVX-512 Xeon (docs/performance.md).
pub const FIELD_ALIGN: usize = 64;

/// One per-vertex array of a mesh, starting on a [`FIELD_ALIGN`] boundary.
pub type Field = AVec<f32, ConstAlign<FIELD_ALIGN>>;

/// A field of `len` copies of `value`.
pub fn field(len: usize, value: f32) -> Field {
    Field::from_iter(FIELD_ALIGN, std::iter::repeat_n(value, len))
}

/// Vertex positions and normals as separate arrays (structure of arrays), so kernels vectorise and
/// the frame loop copies flat slices.
///
/// The fold fields are optional: a model that fills them builds its meshes [`Mesh::with_fold`],
/// one that does not leaves them empty. They are empty fields rather than `Option`s so that
/// copying, reading and splitting into bands treat every field alike (an empty field is a
/// zero-length slice) and a mesh without them costs nothing.
#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    /// The grid this mesh covers.
    pub grid: Grid,
    /// x of each vertex: at rest on the grid unless the model displaces it.
    pub x: Field,
    /// y of each vertex: at rest on the grid unless the model displaces it.
    pub y: Field,
    /// Height of each vertex, rewritten every step.
    pub z: Field,
    /// x component of each unit normal.
    pub nx: Field,
    /// y component of each unit normal.
    pub ny: Field,
    /// z component of each unit normal.
    pub nz: Field,
    /// The Jacobian J of the horizontal displacement at each vertex (below 1: the surface folds);
    /// empty when the model does not fill it.
    pub fold: Field,
    /// x of the direction in which each vertex folds; empty with `fold`.
    pub fold_dx: Field,
    /// y of the direction in which each vertex folds; empty with `fold`.
    pub fold_dy: Field,
}

impl Mesh {
    /// A flat mesh at height 0 with upward normals.
    pub fn new(grid: Grid) -> Self {
        let v = grid.vertices();
        let n = grid.n;
        let x = (0..v).map(|k| (k % n) as f32 * grid.spacing);
        let y = (0..v).map(|k| (k / n) as f32 * grid.spacing);
        Mesh {
            grid,
            x: Field::from_iter(FIELD_ALIGN, x),
            y: Field::from_iter(FIELD_ALIGN, y),
            z: field(v, 0.0),
            nx: field(v, 0.0),
            ny: field(v, 0.0),
            nz: field(v, 1.0),
            fold: field(0, 0.0),
            fold_dx: field(0, 0.0),
            fold_dy: field(0, 0.0),
        }
    }

    /// The same mesh with the fold fields, J = 1 (no fold) and no direction.
    pub fn with_fold(mut self) -> Self {
        let v = self.grid.vertices();
        self.fold = field(v, 1.0);
        self.fold_dx = field(v, 0.0);
        self.fold_dy = field(v, 0.0);
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

    /// The vertices `at` (indices within the band) of every array a model may write, in the
    /// order x, y, z, nx, ny, nz, fold, fold_dx, fold_dy. A band of a mesh with no fold fields
    /// has none to give: asking it panics.
    pub fn outputs(&mut self, at: std::ops::Range<usize>) -> [&mut [f32]; 9] {
        [
            &mut self.x[at.clone()],
            &mut self.y[at.clone()],
            &mut self.z[at.clone()],
            &mut self.nx[at.clone()],
            &mut self.ny[at.clone()],
            &mut self.nz[at.clone()],
            &mut self.fold[at.clone()],
            &mut self.fold_dx[at.clone()],
            &mut self.fold_dy[at],
        ]
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

    #[test]
    fn every_field_starts_a_cache_line_and_holds_the_rest_grid() {
        let grid = Grid::new(5, 2.0).unwrap();
        let mesh = Mesh::new(grid).with_fold();
        let clone = mesh.clone();
        for m in [&mesh, &clone] {
            let fields = [
                &m.x, &m.y, &m.z, &m.nx, &m.ny, &m.nz, &m.fold, &m.fold_dx, &m.fold_dy,
            ];
            for f in fields {
                assert_eq!(f.len(), 25);
                assert_eq!(f.as_ptr() as usize % FIELD_ALIGN, 0, "{:p}", f.as_ptr());
            }
        }
        // Row i, column j at (j, i) × spacing.
        assert_eq!((mesh.x[7], mesh.y[7]), (4.0, 2.0));
        assert_eq!((mesh.x[24], mesh.y[24]), (8.0, 8.0));
        assert!(mesh.nz.iter().all(|&v| v == 1.0) && mesh.fold.iter().all(|&v| v == 1.0));
    }
}
