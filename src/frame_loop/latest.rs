//! The `latest` policy's loop (Vulkan's MAILBOX): one persistent helper computes frame j, at
//! t = j · time_step, into a buffer of its own and publishes it, never waiting; the main thread
//! takes the newest published mesh at its consume point and waits only for the very first.
//! Helper frames the main thread never took are dropped; a mesh taken in two frames running is
//! consumed twice.
//!
//! The buffers are the method's mailbox (three of them, see [`crate::sync::MailboxIn`]); this
//! file needs no `unsafe`, since each side owns the buffer it holds.

use super::consume;
use super::frames::FrameCounter;
use super::pool::{drive, Helpers, Stop};
use super::slots::{main_record, ns, timed};
use super::{Budget, LoopError, LoopSpec, Measured};
use crate::measure::FrameRecord;
use crate::ocean::{Mesh, Stepper};
use crate::sync::{MailboxIn, MailboxOut};
use crate::workload::Work;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::Instant;

/// A mailbox buffer: a mesh and what the helper noted about it.
#[derive(Clone)]
struct Frame {
    mesh: Mesh,
    /// The frame the mesh was computed for; `None` before the helper's first publication.
    index: Option<u64>,
    step_ns: u64,
    started: Instant,
    published: Instant,
}

/// What the main thread and the helper share besides the mailbox.
struct Latest {
    done: AtomicBool,
    /// Frames the helper has published.
    published: AtomicU64,
}

impl Stop for Latest {
    fn shutdown(&self) {
        self.done.store(true, Ordering::Release);
    }
}

/// Runs the loop from the calling thread with one free-running helper.
pub(super) fn run<F: FnMut(u64, &Mesh)>(
    spec: &LoopSpec,
    budget: &Budget,
    trace: Option<usize>,
    ocean: Box<dyn Stepper>,
    work: &mut Work,
    mut observe: F,
) -> Result<Measured, LoopError> {
    let now = Instant::now();
    let blank = Frame {
        mesh: spec.blank_mesh(),
        index: None,
        step_ns: 0,
        started: now,
        published: now,
    };
    let (input, mut output) = spec
        .sync
        .mailbox(&blank)
        .ok_or_else(|| LoopError::Helper(format!("{} has no mailbox", spec.sync)))?;
    let mut input = Some(input);
    let shared = Latest {
        done: AtomicBool::new(false),
        published: AtomicU64::new(0),
    };
    let start = || {
        Helpers::start(spec, shared, |_, shared| {
            let (shared, spec, mut ocean) = (shared.clone(), spec.clone(), ocean.clone());
            let mut input = input.take().expect("`latest` runs one helper");
            move || {
                for j in 0.. {
                    if shared.done.load(Ordering::Acquire) {
                        break;
                    }
                    produce(&spec, j, &mut *ocean, &mut *input);
                    shared.published.store(j + 1, Ordering::Release);
                }
                Ok(())
            }
        })
    };
    let mut main = MainSide {
        render: spec.blank_mesh(),
        last: None,
        work,
    };
    drive(spec, budget, trace, start, |frames, shared| {
        consume(spec, frames, shared, &mut *output, &mut main, &mut observe)
    })
}

/// The helper's frame j: computed into the buffer it holds, then published.
fn produce(spec: &LoopSpec, j: u64, ocean: &mut dyn Stepper, input: &mut dyn MailboxIn<Frame>) {
    spec.stall_at(j);
    let frame = input.buffer();
    frame.started = Instant::now();
    ocean.step(spec.time_of(j), &mut frame.mesh);
    frame.published = Instant::now();
    frame.step_ns = ns(frame.published - frame.started);
    frame.index = Some(j);
    input.publish();
}

/// The main thread's frame k: workload, take the newest mesh (waiting only for the first),
/// consume it and run the work that reads it.
fn consume<F: FnMut(u64, &Mesh)>(
    spec: &LoopSpec,
    frames: &mut FrameCounter,
    shared: &Latest,
    output: &mut dyn MailboxOut<Frame>,
    main: &mut MainSide<'_>,
    observe: &mut F,
) -> Result<FrameRecord, LoopError> {
    let k = frames.frame;
    let t0 = frames.start();
    spec.work_before_wait(&mut *main.work, k)?;
    let t1 = Instant::now();
    let (taken, waited) = timed(|| take(spec, output, t1));
    taken?;
    let t2 = Instant::now();
    let frame = output.buffer();
    let index = frame
        .index
        .expect("`take` returns holding a published mesh");
    let MainSide { render, last, work } = main;
    if last.is_some_and(|l| index < l) {
        return Err(LoopError::Helper(format!(
            "the mesh of frame {index} was taken after frame {}'s",
            last.unwrap_or(0)
        )));
    }
    if t2.saturating_duration_since(frame.published) > spec.timeout {
        return Err(spec.stalled("the main thread (no newer mesh came)"));
    }
    *last = Some(index);
    let (consumed, read) = consume::apply(spec.consume, &frame.mesh, render);
    if let Some(sum) = read {
        frames.read(sum);
    }
    let on_mesh = spec.work_on_mesh(work, index, consumed)?;
    observe(index, consumed);
    let t3 = Instant::now();
    if let Some(mut marks) = frames.marks() {
        // The free-running helper never waits for a buffer.
        marks.helper(0, 0, frame.started, frame.published);
        marks.main([t1, t2, t3], on_mesh);
    }
    let ahead = shared
        .published
        .load(Ordering::Acquire)
        .saturating_sub(index + 1);
    Ok(FrameRecord {
        step_ns: frame.step_ns,
        age_ns: ns(t2.saturating_duration_since(frame.published)),
        latency_ns: ns(t2.saturating_duration_since(frame.started)),
        mesh_frame: index,
        work_counts: work.output().counts(),
        ..main_record([t0, t1, t2, t3], on_mesh, waited, ahead)
    })
}

/// What the main thread keeps from frame to frame.
struct MainSide<'w> {
    /// The copy of the mesh under `copy`.
    render: Mesh,
    /// The index of the mesh consumed the frame before.
    last: Option<u64>,
    /// The main thread's work.
    work: &'w mut Work,
}

/// Takes the newest published mesh, if one came since the last take; before the first, waits
/// for it (yielding, with the timeout and stop flag looked at on every turn).
fn take(
    spec: &LoopSpec,
    output: &mut dyn MailboxOut<Frame>,
    from: Instant,
) -> Result<(), LoopError> {
    if output.update() || output.buffer().index.is_some() {
        return Ok(());
    }
    let deadline = from + spec.timeout;
    while !output.update() {
        if Instant::now() >= deadline {
            return Err(spec.stalled("the main thread (waiting for the first mesh)"));
        }
        if spec.stopped() {
            return Err(LoopError::Interrupted);
        }
        std::thread::yield_now();
    }
    Ok(())
}
