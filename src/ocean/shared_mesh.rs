//! A mesh several threads fill at once, each its own band of whole rows, without a `&mut Mesh`
//! at once: the frame loop's ring of slots, and the FFT ocean's patch that helpers sharing a
//! projected mesh fill together. Its users say, each with its own protocol, why no two live
//! bands overlap and why no band is alive while the whole mesh is read.

use super::mesh::{Grid, Mesh, MeshRows};
use std::cell::UnsafeCell;
use std::ops::Range;

/// A mesh with the base pointers of its arrays, taken while the mesh was uniquely owned, so that
/// threads can make disjoint band slices.
pub struct SharedMesh {
    mesh: UnsafeCell<Mesh>,
    grid: Grid,
    base: [*mut f32; 6],
    /// The fold fields' base pointers, when the mesh carries them.
    fold: Option<[*mut f32; 3]>,
}

// SAFETY: the mesh is only touched through `rows` and `get`, whose callers keep the bands they
// hold disjoint and hold none while the whole mesh is borrowed. The raw pointers point into the
// mesh's buffers, which are never resized, and move with it.
unsafe impl Sync for SharedMesh {}
// SAFETY: as above.
unsafe impl Send for SharedMesh {}

impl std::fmt::Debug for SharedMesh {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SharedMesh")
            .field("grid", &self.grid)
            .finish()
    }
}

impl SharedMesh {
    /// Shares `mesh`.
    pub fn new(mut mesh: Mesh) -> SharedMesh {
        let fold = mesh.has_fold().then_some([
            mesh.fold.as_mut_ptr(),
            mesh.fold_dx.as_mut_ptr(),
            mesh.fold_dy.as_mut_ptr(),
        ]);
        let base = [
            mesh.x.as_mut_ptr(),
            mesh.y.as_mut_ptr(),
            mesh.z.as_mut_ptr(),
            mesh.nx.as_mut_ptr(),
            mesh.ny.as_mut_ptr(),
            mesh.nz.as_mut_ptr(),
        ];
        SharedMesh {
            grid: mesh.grid,
            mesh: UnsafeCell::new(mesh),
            base,
            fold,
        }
    }

    /// The grid of the mesh.
    pub fn grid(&self) -> Grid {
        self.grid
    }

    /// The whole mesh, for a caller to borrow when no band is alive.
    pub fn get(&self) -> *mut Mesh {
        self.mesh.get()
    }

    /// The mesh, no longer shared.
    pub fn into_inner(self) -> Mesh {
        self.mesh.into_inner()
    }

    /// The band `rows` of the mesh, every field it carries.
    ///
    /// # Safety
    /// No other reference to these rows of the mesh is alive while the band is.
    #[allow(clippy::mut_from_ref)]
    pub unsafe fn rows(&self, rows: Range<usize>) -> MeshRows<'_> {
        let grid = self.grid;
        assert!(rows.end <= grid.n, "rows {rows:?} outside 0..{}", grid.n);
        let (start, len) = (rows.start * grid.n, rows.len() * grid.n);
        let (base, fold) = (&self.base, self.fold);
        // SAFETY: `start + len` is within the mesh's N² elements of every field the mesh
        // carries, and the caller holds no other reference to these rows.
        unsafe {
            let write = |p: *mut f32| std::slice::from_raw_parts_mut(p.add(start), len);
            let optional = |k: usize| fold.map_or(&mut [][..], |f| write(f[k]));
            MeshRows {
                grid,
                first_row: rows.start,
                x: write(base[0]),
                y: write(base[1]),
                z: write(base[2]),
                nx: write(base[3]),
                ny: write(base[4]),
                nz: write(base[5]),
                fold: optional(0),
                fold_dx: optional(1),
                fold_dy: optional(2),
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bands_of_a_slot_reach_their_own_rows_of_every_field() {
        let grid = Grid::new(4, 1.0).unwrap();
        for fold in [false, true] {
            let mesh = Mesh::new(grid);
            let slot = SharedMesh::new(if fold { mesh.with_fold() } else { mesh });
            // SAFETY: the two bands are disjoint and nothing else touches the mesh meanwhile.
            let (a, b) = unsafe { (slot.rows(0..1), slot.rows(1..4)) };
            assert_eq!((a.first_row, a.rows(), b.first_row, b.rows()), (0, 1, 1, 3));
            assert_eq!(
                (a.fold.len(), b.fold_dy.len()),
                if fold { (4, 12) } else { (0, 0) }
            );
            for (band, value) in [(a, 1.0), (b, 2.0)] {
                for field in [band.x, band.y, band.z, band.nx, band.ny, band.nz] {
                    field.fill(value);
                }
                for field in [band.fold, band.fold_dx, band.fold_dy] {
                    field.fill(value);
                }
            }
            let mesh = slot.into_inner();
            let want = |v: usize| if v < 4 { 1.0 } else { 2.0 };
            let fields = [&mesh.x, &mesh.y, &mesh.z, &mesh.nx, &mesh.ny, &mesh.nz];
            let optional = [&mesh.fold, &mesh.fold_dx, &mesh.fold_dy];
            for field in fields
                .into_iter()
                .chain(fold.then_some(optional).into_iter().flatten())
            {
                assert!(
                    field.iter().enumerate().all(|(v, &x)| x == want(v)),
                    "{field:?}"
                );
            }
            assert_eq!(mesh.has_fold(), fold);
        }
    }
}
