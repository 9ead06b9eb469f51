//! The one-frame slot the helpers write and the main thread reads, and the two steps of a
//! threaded frame that touch it: every `unsafe` access to the slot is in this file.
//!
//! The slot is sound because of the hand-off protocol, which only these steps follow: helper h
//! writes its band and stamp only while its part is Empty (before its first publish, or after
//! `wait_released` returned `Next`), and the main thread reads the mesh and stamps only after
//! every part is published and before it releases them. Each pair of sides is a release/acquire
//! edge of the part's `Handoff`.

use super::{LoopError, LoopSpec};
use crate::measure::FrameRecord;
use crate::ocean::{Grid, Mesh, MeshRows, Ocean};
use crate::sync::{Handoff, Slot};
use crate::workload;
use std::cell::UnsafeCell;
use std::ops::Range;
use std::time::Instant;

/// What a helper leaves next to its band: which frame the band holds and how long it took.
#[derive(Default)]
struct Stamp {
    index: u64,
    step_ns: u64,
}

/// One helper's share of the frame: its rows, its hand-off and its stamp.
pub(super) struct Part {
    rows: Range<usize>,
    /// The hand-off between this helper and the main thread.
    pub handoff: Box<dyn Handoff>,
    stamp: Slot<Stamp>,
}

/// The one-frame slot: a mesh the helpers write band by band and the main thread copies whole,
/// with one hand-off per helper (so every sync method works unchanged for any helper count).
pub(super) struct Shared {
    mesh: UnsafeCell<Mesh>,
    /// Base pointers of x, y, z, nx, ny, nz, taken once while the mesh was uniquely owned, so
    /// helpers can make disjoint band slices without ever forming a `&mut Mesh` at once.
    base: [*mut f32; 6],
    /// One per helper.
    pub parts: Vec<Part>,
}

// SAFETY: the mesh and stamps are only touched under the hand-off protocol described at the
// top of this file; helpers write disjoint rows. The raw pointers point into the mesh's
// buffers, which are never resized.
unsafe impl Sync for Shared {}
// SAFETY: as above; the pointers are owned data of `mesh`, which moves with them.
unsafe impl Send for Shared {}

impl Shared {
    /// A slot for `spec`'s grid split evenly into one band of whole rows per helper.
    pub fn new(spec: &LoopSpec) -> Shared {
        let mut mesh = Mesh::new(spec.grid);
        let base = [
            mesh.x.as_mut_ptr(),
            mesh.y.as_mut_ptr(),
            mesh.z.as_mut_ptr(),
            mesh.nx.as_mut_ptr(),
            mesh.ny.as_mut_ptr(),
            mesh.nz.as_mut_ptr(),
        ];
        let (n, h) = (spec.grid.n, spec.helpers().max(1));
        let parts = (0..h)
            .map(|k| Part {
                rows: k * n / h..(k + 1) * n / h,
                handoff: spec.sync.handoff(),
                stamp: Slot::new(Stamp::default()),
            })
            .collect();
        Shared {
            mesh: UnsafeCell::new(mesh),
            base,
            parts,
        }
    }

    /// Stops every helper: any waiting one returns `Shutdown`.
    pub fn shutdown(&self) {
        for part in &self.parts {
            part.handoff.shutdown();
        }
    }

    /// Helper k's band of the mesh.
    ///
    /// # Safety
    /// The caller is helper k, owns its part, and is one of several helpers (a lone helper
    /// uses `whole`), so only disjoint bands are alive.
    #[allow(clippy::mut_from_ref)]
    unsafe fn band(&self, k: usize) -> MeshRows<'_> {
        let grid = self.grid();
        let rows = self.parts[k].rows.clone();
        let (start, len) = (rows.start * grid.n, rows.len() * grid.n);
        // SAFETY: `start + len` is within the mesh's N² elements; x and y are never written,
        // and the z..nz rows of different helpers do not overlap (bands partition the rows).
        unsafe {
            let read = |p: *mut f32| std::slice::from_raw_parts(p.add(start), len);
            let write = |p: *mut f32| std::slice::from_raw_parts_mut(p.add(start), len);
            MeshRows {
                grid,
                first_row: rows.start,
                x: read(self.base[0]),
                y: read(self.base[1]),
                z: write(self.base[2]),
                nx: write(self.base[3]),
                ny: write(self.base[4]),
                nz: write(self.base[5]),
            }
        }
    }

    fn grid(&self) -> Grid {
        // SAFETY: `grid` is never written after construction, so reading it races with nothing.
        unsafe { (*self.mesh.get()).grid }
    }
}

/// Helper `h`'s side of one frame: compute its rows of frame k into the slot and publish them.
/// The caller owns part `h`: it has not published since its last `Next` release.
pub(super) fn produce(spec: &LoopSpec, k: u64, ocean: &mut Ocean, shared: &Shared, h: usize) {
    if spec.stall_at_frame == Some(k) {
        // A helper that never publishes again: the main thread's timeout must end the cell.
        loop {
            std::thread::park();
        }
    }
    let part = &shared.parts[h];
    let t = spec.time_of(k);
    let t0 = Instant::now();
    if shared.parts.len() == 1 {
        // SAFETY: the only helper owns the slot (part Empty), so nobody else touches the mesh.
        ocean.step(t, unsafe { &mut *shared.mesh.get() });
    } else {
        // SAFETY: helper h owns part h; other helpers only touch their own rows.
        ocean.step_rows(t, unsafe { shared.band(h) });
    }
    // SAFETY: the stamp belongs to helper h until it publishes.
    let stamp = unsafe { part.stamp.get_mut() };
    stamp.step_ns = ns(t0.elapsed());
    stamp.index = k;
    part.handoff.publish();
}

/// The main thread's side of one threaded frame: workload, wait for every helper, copy,
/// release them all.
pub(super) fn consume<F: FnMut(u64, &Mesh)>(
    spec: &LoopSpec,
    k: u64,
    shared: &Shared,
    render: &mut Mesh,
    observe: &mut F,
) -> Result<FrameRecord, LoopError> {
    let t0 = Instant::now();
    workload::run(spec.workload_iterations, k);
    let t1 = Instant::now();
    for part in &shared.parts {
        part.handoff
            .wait_published(t1 + spec.timeout)
            .map_err(|_| spec.stalled("the main thread (waiting for the mesh)"))?;
    }
    let t2 = Instant::now();
    // SAFETY: every part is published and none released, so no helper is writing.
    render.copy_from(unsafe { &*shared.mesh.get() });
    // The frame's step is its slowest band: the time the main thread could have had to wait.
    let mut step_ns = 0;
    let mut wrong = None;
    for part in &shared.parts {
        // SAFETY: as above, the stamp is published and not yet released.
        let stamp = unsafe { part.stamp.get() };
        step_ns = step_ns.max(stamp.step_ns);
        if stamp.index != k {
            wrong = Some(stamp.index);
        }
    }
    for part in &shared.parts {
        part.handoff.release();
    }
    let t3 = Instant::now();
    if let Some(index) = wrong {
        return Err(LoopError::Helper(format!(
            "frame {k} expected, helper delivered frame {index}"
        )));
    }
    observe(k, render);
    Ok(FrameRecord {
        total_ns: ns(t3 - t0),
        workload_ns: ns(t1 - t0),
        wait_ns: ns(t2 - t1),
        copy_ns: ns(t3 - t2),
        step_ns,
    })
}

/// Nanoseconds of a duration, as frame records keep them.
pub(super) fn ns(d: std::time::Duration) -> u64 {
    d.as_nanos() as u64
}
