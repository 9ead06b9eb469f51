//! The ring of mesh slots the helpers write and the main thread consumes, and the two steps of a
//! threaded frame that touch it: every `unsafe` access to the slots is in this file.
//!
//! The slots are sound because of the ring protocol, which only these steps follow: frame k
//! lives in slot k mod depth; helper h writes its band of that slot and its stamp only after its
//! ring's `wait_free` said the slot is free (the main thread released the frame that last used
//! it), and the main thread reads a slot only after every helper published its frame there and
//! before it releases it. Each pair of sides is a release/acquire edge of the helper's ring.

use super::barrier::{Broken, PhaseBarrier};
use super::consume::{self, Consume};
use super::frames::FrameCounter;
use super::timeline::{PhaseMarks, TRACED_PHASES};
use super::{LoopError, LoopSpec};
use crate::measure::FrameRecord;
use crate::ocean::{Mesh, MeshRows, SharedMesh, Stepper};
use crate::sched;
use crate::sync::{Handoff, Slot};
use crate::workload::Work;
use std::ops::Range;
use std::time::{Duration, Instant};

/// What a helper leaves next to its band of a slot: which frame it holds, how long it took, and
/// when it was started and published.
#[derive(Clone, Copy)]
struct Stamp {
    index: u64,
    step_ns: u64,
    started: Instant,
    published: Instant,
    /// The helper's wait for this slot to be free: wall and CPU time.
    waited: Waited,
}

/// How long a wait took, on the wall clock and on the waiting thread's CPU clock.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Waited {
    pub ns: u64,
    pub cpu_ns: u64,
}

/// Times a wait on both clocks.
pub(super) fn timed<T>(wait: impl FnOnce() -> T) -> (T, Waited) {
    let (t0, c0) = (Instant::now(), sched::thread_cpu_ns().unwrap_or(0));
    let out = wait();
    let waited = Waited {
        ns: ns(t0.elapsed()),
        cpu_ns: sched::thread_cpu_ns().unwrap_or(0).saturating_sub(c0),
    };
    (out, waited)
}

/// One helper's share of every frame: its rows, its ring and its stamp in each slot.
pub(super) struct Part {
    rows: Range<usize>,
    /// The ring between this helper and the main thread.
    pub handoff: Box<dyn Handoff>,
    stamps: Vec<Slot<Stamp>>,
    /// Beside each stamp, when each phase of a split step ran; only in a traced loop.
    phases: Option<Vec<Slot<PhaseMarks>>>,
}

/// The ring of `depth` meshes, each split among the helpers in bands of whole rows, with one
/// ring hand-off per helper (so every sync method works unchanged for any helper count).
pub(super) struct Shared {
    slots: Vec<SharedMesh>,
    /// One per helper.
    pub parts: Vec<Part>,
    /// Where the helpers meet between the phases of a banded step.
    barrier: PhaseBarrier,
}

impl Shared {
    /// A ring of `spec.depth` meshes for `spec`'s grid, split evenly among `spec.helpers()`;
    /// `traced`: with room for the phases' instants a trace draws.
    pub fn new(spec: &LoopSpec, traced: bool) -> Shared {
        let depth = spec.depth.max(1);
        let slots = (0..depth)
            .map(|_| SharedMesh::new(spec.blank_mesh()))
            .collect();
        let now = Instant::now();
        let blank = Stamp {
            index: u64::MAX,
            step_ns: 0,
            started: now,
            published: now,
            waited: Waited::default(),
        };
        let (n, h) = (spec.grid.n, spec.helpers().max(1));
        let parts = (0..h)
            .map(|k| Part {
                rows: k * n / h..(k + 1) * n / h,
                handoff: spec.sync.handoff(depth),
                stamps: (0..depth).map(|_| Slot::new(blank)).collect(),
                phases: traced.then(|| {
                    (0..depth)
                        .map(|_| Slot::new([None; TRACED_PHASES]))
                        .collect()
                }),
            })
            .collect();
        Shared {
            slots,
            parts,
            barrier: PhaseBarrier::new(h),
        }
    }

    /// Stops every helper: any waiting one, at its ring or at the phase barrier, returns.
    pub fn shutdown(&self) {
        for part in &self.parts {
            part.handoff.shutdown();
        }
        self.barrier.cancel();
    }

    /// The rows of each helper's band, helper k at index k.
    pub fn bands(&self) -> Vec<Range<usize>> {
        self.parts.iter().map(|p| p.rows.clone()).collect()
    }

    fn slot_of(&self, frame: u64) -> usize {
        (frame % self.slots.len() as u64) as usize
    }

    /// Helper k's band of slot `s`.
    ///
    /// # Safety
    /// The caller is helper k, its ring gave it slot `s`, and it is one of several helpers (a
    /// lone helper uses the whole mesh), so only disjoint bands are alive.
    #[allow(clippy::mut_from_ref)]
    unsafe fn band(&self, s: usize, k: usize) -> MeshRows<'_> {
        let rows = self.parts[k].rows.clone();
        // SAFETY: bands partition the rows, and the caller's ring gave it this slot.
        unsafe { self.slots[s].rows(rows) }
    }
}

/// Helper `h`'s side of frame k: compute its rows of the frame into its slot and publish them.
/// The caller's ring has just said the slot is free, after a wait of `waited`. With several
/// helpers and a stepper of several phases, every helper meets at the barrier before each
/// phase; a shutdown or a stalled helper there ends the frame unpublished.
pub(super) fn produce(
    spec: &LoopSpec,
    k: u64,
    ocean: &mut dyn Stepper,
    shared: &Shared,
    h: usize,
    waited: Waited,
) -> Result<(), Broken> {
    spec.stall_at(k);
    let part = &shared.parts[h];
    let s = shared.slot_of(k);
    let t = spec.time_of(k);
    let started = Instant::now();
    if shared.parts.len() == 1 {
        // SAFETY: the only helper owns the free slot, so nobody else touches its mesh.
        ocean.step(t, unsafe { &mut *shared.slots[s].get() });
    } else if ocean.phases() == 1 {
        // SAFETY: helper h owns its band of the free slot; other helpers only touch theirs.
        ocean.step_rows(t, unsafe { shared.band(s, h) });
    } else {
        for phase in 0..ocean.phases() {
            // Before phase 0 too: no helper starts frame k while another still reads frame
            // k − 1's shared state in its last phase.
            shared.barrier.wait(Instant::now() + spec.timeout)?;
            let began = part.phases.is_some().then(Instant::now);
            // SAFETY: as above.
            ocean.step_phase(phase, t, unsafe { shared.band(s, h) });
            if let (Some(marks), Some(began)) = (&part.phases, began) {
                if phase < TRACED_PHASES {
                    // SAFETY: like the stamp, helper h's until it publishes.
                    unsafe { (*marks[s].get_mut())[phase] = Some((began, Instant::now())) };
                }
            }
        }
    }
    let published = Instant::now();
    // SAFETY: the stamp of a free slot belongs to helper h until it publishes.
    unsafe {
        *part.stamps[s].get_mut() = Stamp {
            index: k,
            step_ns: ns(published - started),
            started,
            published,
            waited,
        };
    }
    part.handoff.publish();
    Ok(())
}

/// The main thread's side of threaded frame k: workload, wait for every helper's frame k,
/// consume it, and release the frames its consumption no longer holds (every one for `copy`
/// and `read`; with `handle`, all but the latest depth − 1).
pub(super) fn consume<F: FnMut(u64, &Mesh)>(
    spec: &LoopSpec,
    frames: &mut FrameCounter,
    shared: &Shared,
    render: &mut Mesh,
    held: &mut u64,
    work: &mut Work,
    observe: &mut F,
) -> Result<FrameRecord, LoopError> {
    let k = frames.frame;
    let t0 = frames.start();
    spec.work_before_wait(work, k)?;
    let t1 = Instant::now();
    let deadline = t1 + spec.timeout;
    let (published_all, main_waited) = timed(|| {
        for part in &shared.parts {
            // In slices, so that a stop request ends a long wait too.
            loop {
                let slice = deadline.min(Instant::now() + STOP_CHECK);
                match part.handoff.wait_published(k, slice) {
                    Ok(()) => break,
                    Err(_) if Instant::now() >= deadline => {
                        return Err(spec.stalled("the main thread (waiting for the mesh)"))
                    }
                    Err(_) if spec.stopped() => return Err(LoopError::Interrupted),
                    Err(_) => {}
                }
            }
        }
        Ok(())
    });
    published_all?;
    let t2 = Instant::now();
    let s = shared.slot_of(k);
    // SAFETY: every helper published frame k into slot s and none has it released, so no
    // helper writes it until this thread releases it below.
    let mesh = unsafe { &*shared.slots[s].get() };
    let (consumed, read) = consume::apply(spec.consume, mesh, render);
    if let Some(sum) = read {
        frames.read(sum);
    }
    // The frame's step is its slowest band; its age runs from the last band's publication.
    let mut step_ns = 0;
    let mut helpers_waited = Waited::default();
    let mut started = t2;
    let mut published = None;
    let mut wrong = None;
    let mut marks = frames.marks();
    for (h, part) in shared.parts.iter().enumerate() {
        // SAFETY: as above, the stamp is published and not yet released.
        let stamp = unsafe { part.stamps[s].get() };
        if let Some(marks) = &mut marks {
            marks.helper(h, stamp.waited.ns, stamp.started, stamp.published);
            if let Some(phases) = &part.phases {
                // SAFETY: as above, published with the stamp and not yet released.
                marks.phases(h, unsafe { *phases[s].get() });
            }
        }
        step_ns = step_ns.max(stamp.step_ns);
        helpers_waited.ns = helpers_waited.ns.max(stamp.waited.ns);
        helpers_waited.cpu_ns += stamp.waited.cpu_ns;
        started = started.min(stamp.started);
        published = Some(published.map_or(stamp.published, |p: Instant| p.max(stamp.published)));
        if stamp.index != k {
            wrong = Some(stamp.index);
        }
    }
    let ahead = shared.parts[0].handoff.published().saturating_sub(k + 1);
    observe(k, consumed);
    *held += 1;
    let keep = match spec.consume {
        Consume::Handle => shared.slots.len() as u64 - 1,
        Consume::Copy | Consume::Read => 0,
    };
    let release = |held: &mut u64| {
        while *held > keep {
            for part in &shared.parts {
                part.handoff.release();
            }
            *held -= 1;
        }
    };
    // Work on a copy runs after the slot is back with the helper; work on the slot itself
    // holds it until done, which at depth 1 keeps the helper waiting (docs/pipelining.md).
    let on_mesh = if spec.consume == Consume::Copy {
        release(held);
        spec.work_on_mesh(work, k, consumed)?
    } else {
        let took = spec.work_on_mesh(work, k, consumed)?;
        release(held);
        took
    };
    let t3 = Instant::now();
    if let Some(mut marks) = frames.marks() {
        marks.main([t1, t2, t3], on_mesh);
    }
    if let Some(index) = wrong {
        return Err(LoopError::Helper(format!(
            "frame {k} expected, helper delivered frame {index}"
        )));
    }
    Ok(FrameRecord {
        step_ns,
        helper_wait_ns: helpers_waited.ns,
        helper_wait_cpu_ns: helpers_waited.cpu_ns,
        other_ns: 0,
        age_ns: published.map_or(0, |p| ns(t2.saturating_duration_since(p))),
        latency_ns: ns(t2.saturating_duration_since(started)),
        mesh_frame: k,
        work_counts: work.output().counts(),
        ..main_record([t0, t1, t2, t3], on_mesh, main_waited, ahead)
    })
}

/// The main thread's times in a threaded frame's record, one definition for every threaded
/// loop so that their frames divide alike: the frame ran from `t0` to `t3`, its work before the
/// wait ended at `t1`, the wait (`waited`) ended at `t2` with the mesh in hand; the work that
/// read the mesh (`on_mesh`, after `t2`) counts as workload, not as consumption. `ahead`: frames
/// the helper had finished beyond the consumed one.
pub(super) fn main_record(
    [t0, t1, t2, t3]: [Instant; 4],
    on_mesh: Duration,
    waited: Waited,
    ahead: u64,
) -> FrameRecord {
    FrameRecord {
        total_ns: ns(t3 - t0),
        workload_ns: ns(t1 - t0 + on_mesh),
        wait_ns: ns(t2 - t1),
        wait_cpu_ns: waited.cpu_ns,
        copy_ns: ns(t3 - t2 - on_mesh),
        age_frames: ahead.min(u64::from(u32::MAX)) as u32,
        ..FrameRecord::default()
    }
}

/// The longest a wait goes without looking at the stop flag.
const STOP_CHECK: Duration = Duration::from_millis(50);

/// Nanoseconds of a duration, as frame records keep them.
pub(super) fn ns(d: Duration) -> u64 {
    d.as_nanos() as u64
}
