//! The paper's thread pool: persistent helpers, created once per loop, one per band of rows; and
//! the persistent-helper machinery the `latest` loop shares with it (starting pinned helpers,
//! stopping them without ever hanging on a stalled one, and driving the main thread's frames).

use super::barrier::Broken;
use super::frames::FrameCounter;
use super::slots::{consume, produce, timed, Shared};
use super::{Budget, CoreWatch, LoopError, LoopSpec, Measured, ThreadWatch};
use crate::affinity::{self, Pin};
use crate::measure::FrameRecord;
use crate::ocean::{Mesh, Stepper};
use crate::sched::ThreadNoise;
use crate::sync::Free;
use crate::workload::Work;
use std::convert::Infallible;
use std::sync::mpsc::{self, Receiver, RecvTimeoutError};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Instant;

/// What the main thread and its persistent helpers share: the one thing the pool needs of it
/// is a way to tell every helper to stop.
pub(super) trait Stop: Send + Sync + 'static {
    /// Stops every helper: a waiting one wakes and returns, a working one returns after its
    /// step.
    fn shutdown(&self);
}

impl Stop for Shared {
    fn shutdown(&self) {
        Shared::shutdown(self);
    }
}

/// What a helper returns when it is shut down: its pin and what it suffered.
type HelperEnd = Result<(Pin, ThreadNoise), LoopError>;

/// The running helpers. Dropping them shuts them down, so no early return or panic of the main
/// thread leaves a helper waiting for a release; the helpers are then left behind, never
/// joined, since a stalled one may never return.
pub(super) struct Helpers<S: Stop> {
    /// What the helpers share with the main thread.
    pub shared: Arc<S>,
    threads: Vec<JoinHandle<HelperEnd>>,
    /// Disconnects once every helper has ended: each holds a sender until it returns or unwinds.
    ended: Receiver<Infallible>,
}

impl<S: Stop> Helpers<S> {
    /// Starts one helper per helper core, pinned to it and running `body(h)` until it returns.
    pub fn start<B>(
        spec: &LoopSpec,
        shared: S,
        mut body: impl FnMut(usize, &Arc<S>) -> B,
    ) -> Result<Helpers<S>, LoopError>
    where
        B: FnOnce() -> Result<(), LoopError> + Send + 'static,
    {
        let (ending, ended) = mpsc::channel();
        let mut helpers = Helpers {
            shared: Arc::new(shared),
            threads: Vec::with_capacity(spec.helpers()),
            ended,
        };
        for (h, &core) in spec.helper_cores.iter().enumerate() {
            let (ending, body) = (ending.clone(), body(h, &helpers.shared));
            let thread = std::thread::Builder::new()
                .name(format!("ocean-helper-{h}"))
                .spawn(move || -> HelperEnd {
                    // Held until this helper returns or unwinds: how `finish` learns it ended.
                    let _ending = ending;
                    let pin = affinity::pin_current(core);
                    let watch = ThreadWatch::start(core);
                    body()?;
                    Ok((pin, watch.stop(format!("helper {h}"))))
                })
                .map_err(|e| LoopError::Helper(e.to_string()))?;
            helpers.threads.push(thread);
        }
        Ok(helpers)
    }

    /// Shuts the helpers down and collects their pins and noise, helper k at index k. A helper
    /// that has not ended within the hand-off timeout is stuck in a step for a frame past the
    /// last one: it is left behind, never joined, and the loop ends as a stalled hand-off.
    fn finish(mut self, spec: &LoopSpec) -> Result<Vec<(Pin, ThreadNoise)>, LoopError> {
        self.shared.shutdown();
        let Err(RecvTimeoutError::Disconnected) = self.ended.recv_timeout(spec.timeout) else {
            return Err(spec.stalled("the main thread (waiting for the helpers to stop)"));
        };
        std::mem::take(&mut self.threads)
            .into_iter()
            .map(|h| {
                h.join()
                    .map_err(|_| LoopError::Helper("helper thread panicked".into()))?
            })
            .collect()
    }
}

impl<S: Stop> Drop for Helpers<S> {
    fn drop(&mut self) {
        self.shared.shutdown();
    }
}

/// Runs a loop with persistent helpers from the calling thread: pins it, starts the helpers,
/// runs `frame` until the budget is met, stops the helpers and reports.
pub(super) fn drive<S: Stop>(
    spec: &LoopSpec,
    budget: &Budget,
    trace: Option<usize>,
    start: impl FnOnce() -> Result<Helpers<S>, LoopError>,
    mut frame: impl FnMut(&mut FrameCounter, &S) -> Result<FrameRecord, LoopError>,
) -> Result<Measured, LoopError> {
    let main_pin = affinity::pin_current(spec.main_core);
    let (cores, main) = (CoreWatch::start(spec), ThreadWatch::start(spec.main_core));
    let helpers = start()?;
    let mut frames = FrameCounter::new(budget, trace, spec.helpers());
    loop {
        let record = frame(&mut frames, &helpers.shared)?;
        if frames.finish(record, spec)? {
            break;
        }
    }
    let mut threads = vec![main.stop("main".into())];
    let mut helper_pins = Vec::new();
    for (pin, noise) in helpers.finish(spec)? {
        helper_pins.push(pin);
        threads.push(noise);
    }
    let (trial, timeline) = frames.trial();
    Ok(Measured {
        trial,
        timeline,
        main_pin,
        helper_pins,
        noise: cores.stop(threads),
    })
}

/// Runs the loop from the calling thread with one persistent helper per band.
pub(super) fn run<F: FnMut(u64, &Mesh)>(
    spec: &LoopSpec,
    budget: &Budget,
    trace: Option<usize>,
    ocean: Box<dyn Stepper>,
    work: &mut Work,
    mut observe: F,
) -> Result<Measured, LoopError> {
    // Each helper gets its own stepper (the fast kernel keeps per-band tables in it), split
    // from the cell's so that a model whose phases read each other's bands shares that state.
    let start = || {
        let shared = Shared::new(spec, trace.is_some());
        let mut steppers = match shared.parts.len() {
            1 => vec![ocean],
            _ => ocean.split(&shared.bands()),
        }
        .into_iter();
        Helpers::start(spec, shared, |h, shared| {
            let (shared, spec) = (Arc::clone(shared), spec.clone());
            let mut ocean = steppers.next().expect("one stepper per helper");
            move || {
                let handoff = &*shared.parts[h].handoff;
                for k in 0.. {
                    let (free, waited) = timed(|| handoff.wait_free(Instant::now() + spec.timeout));
                    match free {
                        Ok(Free::Slot) => {
                            match produce(&spec, k, &mut *ocean, &shared, h, waited) {
                                Ok(()) => {}
                                Err(Broken::Shutdown) => break,
                                Err(Broken::Timeout) => {
                                    return Err(
                                        spec.stalled("a helper (waiting at the phase barrier)")
                                    )
                                }
                            }
                        }
                        Ok(Free::Shutdown) => break,
                        Err(_) => return Err(spec.stalled("the helper (waiting for a free slot)")),
                    }
                }
                Ok(())
            }
        })
    };
    let mut render = spec.blank_mesh();
    let mut held = 0;
    drive(spec, budget, trace, start, |frames, shared| {
        consume(
            spec,
            frames,
            shared,
            &mut render,
            &mut held,
            work,
            &mut observe,
        )
    })
}
