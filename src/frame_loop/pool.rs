//! The paper's thread pool: persistent helpers, created once per loop, one per band of rows.

use super::frames::FrameCounter;
use super::slots::{consume, produce, timed, Shared};
use super::{Budget, CoreWatch, LoopError, LoopRun, LoopSpec, ThreadWatch};
use crate::affinity::{self, Pin};
use crate::ocean::{Mesh, Ocean};
use crate::sched::ThreadNoise;
use crate::sync::Free;
use std::convert::Infallible;
use std::sync::mpsc::{self, Receiver, RecvTimeoutError};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Instant;

/// What a helper returns when it is shut down: its pin and what it suffered.
type HelperEnd = Result<(Pin, ThreadNoise), LoopError>;

/// The running helpers. Dropping the pool shuts them down, so no early return or panic of the
/// main thread leaves a helper waiting for a release; the helpers are then left behind, never
/// joined, since a stalled one may never return.
struct Pool {
    shared: Arc<Shared>,
    helpers: Vec<JoinHandle<HelperEnd>>,
    /// Disconnects once every helper has ended: each holds a sender until it returns or unwinds.
    ended: Receiver<Infallible>,
}

impl Pool {
    /// Starts one pinned helper per part, each with its own `Ocean` (the fast kernel keeps
    /// per-band tables in it).
    fn start(spec: &LoopSpec, ocean: &Ocean) -> Result<Pool, LoopError> {
        let shared = Arc::new(Shared::new(spec));
        let (ending, ended) = mpsc::channel();
        let mut pool = Pool {
            shared: Arc::clone(&shared),
            helpers: Vec::with_capacity(shared.parts.len()),
            ended,
        };
        for (h, &core) in spec.helper_cores.iter().enumerate() {
            let (shared, spec, mut ocean) = (Arc::clone(&shared), spec.clone(), ocean.clone());
            let ending = ending.clone();
            let helper = std::thread::Builder::new()
                .name(format!("ocean-helper-{h}"))
                .spawn(move || -> HelperEnd {
                    // Held until this helper returns or unwinds: how `finish` learns it ended.
                    let _ending = ending;
                    let pin = affinity::pin_current(core);
                    let watch = ThreadWatch::start(core);
                    let handoff = &*shared.parts[h].handoff;
                    for k in 0.. {
                        let (free, waited) =
                            timed(|| handoff.wait_free(Instant::now() + spec.timeout));
                        match free {
                            Ok(Free::Slot) => produce(&spec, k, &mut ocean, &shared, h, waited),
                            Ok(Free::Shutdown) => break,
                            Err(_) => {
                                return Err(spec.stalled("the helper (waiting for a free slot)"))
                            }
                        }
                    }
                    Ok((pin, watch.stop(format!("helper {h}"))))
                })
                .map_err(|e| LoopError::Helper(e.to_string()))?;
            pool.helpers.push(helper);
        }
        Ok(pool)
    }

    /// Shuts the helpers down and collects their pins and noise, helper k at index k. A helper
    /// that has not ended within the hand-off timeout is stuck in a step for a frame past the
    /// last one: it is left behind, never joined, and the loop ends as a stalled hand-off.
    fn finish(mut self, spec: &LoopSpec) -> Result<Vec<(Pin, ThreadNoise)>, LoopError> {
        self.shared.shutdown();
        let Err(RecvTimeoutError::Disconnected) = self.ended.recv_timeout(spec.timeout) else {
            return Err(spec.stalled("the main thread (waiting for the helpers to stop)"));
        };
        std::mem::take(&mut self.helpers)
            .into_iter()
            .map(|h| {
                h.join()
                    .map_err(|_| LoopError::Helper("helper thread panicked".into()))?
            })
            .collect()
    }
}

impl Drop for Pool {
    fn drop(&mut self) {
        self.shared.shutdown();
    }
}

/// Runs the loop from the calling thread with one persistent helper per band.
pub(super) fn run<F: FnMut(u64, &Mesh)>(
    spec: &LoopSpec,
    budget: &Budget,
    ocean: Ocean,
    mut observe: F,
) -> Result<LoopRun, LoopError> {
    let main_pin = affinity::pin_current(spec.main_core);
    let (cores, main) = (CoreWatch::start(spec), ThreadWatch::start(spec.main_core));
    let pool = Pool::start(spec, &ocean)?;
    let mut render = Mesh::new(spec.grid);
    let mut frames = FrameCounter::new(budget);
    let mut held = 0;
    loop {
        let record = consume(
            spec,
            &mut frames,
            &pool.shared,
            &mut render,
            &mut held,
            &mut observe,
        )?;
        if frames.finish(record, spec)? {
            break;
        }
    }
    let mut threads = vec![main.stop("main".into())];
    let mut helper_pins = Vec::new();
    for (pin, noise) in pool.finish(spec)? {
        helper_pins.push(pin);
        threads.push(noise);
    }
    Ok(LoopRun {
        trial: frames.trial(),
        main_pin,
        helper_pins,
        noise: cores.stop(threads),
    })
}
