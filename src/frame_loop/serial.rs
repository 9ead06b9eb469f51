//! The paper's non-threaded build: one thread runs the workload, the mesh step and the copy in
//! turn.

use super::consume;
use super::frames::FrameCounter;
use super::slots::ns;
use super::{Budget, CoreWatch, LoopError, LoopSpec, Measured, ThreadWatch};
use crate::affinity;
use crate::measure::FrameRecord;
use crate::ocean::{Mesh, Stepper};
use crate::workload::Work;
use std::time::Instant;

/// Runs the loop on the calling thread until the budget is met.
pub(super) fn run<F: FnMut(u64, &Mesh)>(
    spec: &LoopSpec,
    budget: &Budget,
    trace: Option<usize>,
    mut ocean: Box<dyn Stepper>,
    work: &mut Work,
    mut observe: F,
) -> Result<Measured, LoopError> {
    let main_pin = affinity::pin_current(spec.main_core);
    let (cores, main) = (CoreWatch::start(spec), ThreadWatch::start(spec.main_core));
    let mut mesh = spec.blank_mesh();
    let mut render = spec.blank_mesh();
    let mut frames = FrameCounter::new(budget, trace, 0);
    loop {
        let k = frames.frame;
        let t0 = frames.start();
        spec.work_before_wait(work, k)?;
        let t1 = Instant::now();
        ocean.step(spec.time_of(k), &mut mesh);
        let t2 = Instant::now();
        let (consumed, read) = consume::apply(spec.consume, &mesh, &mut render);
        if let Some(sum) = read {
            frames.read(sum);
        }
        let on_mesh = spec.work_on_mesh(work, k, consumed)?;
        observe(k, consumed);
        let t3 = Instant::now();
        if let Some(mut marks) = frames.marks() {
            // The step ran on this thread, with no wait for a slot.
            marks.helper(0, 0, t1, t2);
            marks.main([t1, t2, t3], on_mesh);
        }
        let record = FrameRecord {
            total_ns: ns(t3 - t0),
            workload_ns: ns(t1 - t0 + on_mesh),
            wait_ns: 0,
            copy_ns: ns(t3 - t2 - on_mesh),
            step_ns: ns(t2 - t1),
            // The mesh is used in the frame it was computed in, from the step's start.
            latency_ns: ns(t2 - t1),
            mesh_frame: k,
            work_counts: work.output().counts(),
            ..FrameRecord::default()
        };
        if frames.finish(record, spec)? {
            break;
        }
    }
    let (trial, timeline) = frames.trial();
    Ok(Measured {
        trial,
        timeline,
        main_pin,
        helper_pins: Vec::new(),
        noise: cores.stop(vec![main.stop("main".into())]),
    })
}
