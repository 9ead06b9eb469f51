//! How the main thread takes a finished mesh: the paper's copy into a render buffer, one read
//! pass over it in place (the least a CPU-side upload costs), or handing the slot on untouched as
//! a renderer does with a mapped dynamic buffer.

use crate::ocean::Mesh;

pub use crate::cell::Consume;

/// Consumes `mesh` as `how` says: the mesh the frame goes on with (the render buffer under
/// `copy`), and under `read` the read pass's folded checksum.
pub(super) fn apply<'a>(
    how: Consume,
    mesh: &'a Mesh,
    render: &'a mut Mesh,
) -> (&'a Mesh, Option<u64>) {
    match how {
        Consume::Copy => {
            render.copy_from(mesh);
            (render, None)
        }
        Consume::Read => (mesh, Some(read(mesh).folded())),
        Consume::Handle => (mesh, None),
    }
}

/// What a read pass found: the mesh's bounding box and a checksum of every value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReadPass {
    /// Smallest x, y, z.
    pub min: [f32; 3],
    /// Largest x, y, z.
    pub max: [f32; 3],
    /// Every coordinate's and normal component's bits, summed with wrapping.
    pub checksum: u64,
}

impl ReadPass {
    /// The checksum with the bounding box folded in, for a trial's running fold.
    pub fn folded(&self) -> u64 {
        self.min
            .iter()
            .chain(&self.max)
            .fold(self.checksum, |h, v| {
                h.rotate_left(7) ^ u64::from(v.to_bits())
            })
    }
}

/// Reads every vertex, normal and optional field of `mesh` once (an empty field adds nothing, so
/// a mesh without them sums as before they existed).
pub fn read(mesh: &Mesh) -> ReadPass {
    let extent = |v: &[f32]| {
        v.iter()
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &x| {
                (lo.min(x), hi.max(x))
            })
    };
    let (x, y, z) = (extent(&mesh.x), extent(&mesh.y), extent(&mesh.z));
    let checksum = [
        &mesh.x,
        &mesh.y,
        &mesh.z,
        &mesh.nx,
        &mesh.ny,
        &mesh.nz,
        &mesh.fold,
        &mesh.fold_dx,
        &mesh.fold_dy,
    ]
    .iter()
    .flat_map(|a| a.iter())
    .fold(0u64, |sum, v| sum.wrapping_add(u64::from(v.to_bits())));
    std::hint::black_box(ReadPass {
        min: [x.0, y.0, z.0],
        max: [x.1, y.1, z.1],
        checksum,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ocean::Grid;

    #[test]
    fn the_read_pass_sees_every_value() {
        let mut mesh = Mesh::new(Grid::new(3, 2.0).unwrap());
        mesh.z[4] = 1.5;
        let a = read(&mesh);
        assert_eq!((a.min, a.max), ([0.0, 0.0, 0.0], [4.0, 4.0, 1.5]));
        mesh.nx[8] = 0.25;
        let b = read(&mesh);
        assert_ne!(a.checksum, b.checksum);
        assert_ne!(a.folded(), b.folded());
    }

    #[test]
    fn copy_and_read_see_the_fold_fields_when_present() {
        let grid = Grid::new(3, 1.0).unwrap();
        let plain = read(&Mesh::new(grid));
        let mut mesh = Mesh::new(grid).with_fold();
        let unfolded = read(&mesh);
        assert_ne!(plain.checksum, unfolded.checksum, "J = 1 is read");
        for (field, at) in [(0, 2), (1, 5), (2, 7)] {
            let mut folded = mesh.clone();
            [&mut folded.fold, &mut folded.fold_dx, &mut folded.fold_dy][field][at] = 0.5;
            assert_ne!(read(&folded).checksum, unfolded.checksum, "field {field}");
        }
        mesh.fold[4] = -0.25;
        mesh.fold_dx[4] = 0.6;
        mesh.fold_dy[4] = 0.8;
        let mut render = Mesh::new(grid).with_fold();
        let (copied, _) = apply(Consume::Copy, &mesh, &mut render);
        assert_eq!(copied, &mesh);
        assert_eq!(
            (render.fold[4], render.fold_dx[4], render.fold_dy[4]),
            (-0.25, 0.6, 0.8)
        );
    }
}
