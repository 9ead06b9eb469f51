//! The paper's first build: a new helper thread for every frame, created and joined inside the
//! frame.

use super::frames::FrameCounter;
use super::slots::{consume, produce, timed, Shared};
use super::{Budget, CoreWatch, LoopError, LoopSpec, Measured, ThreadWatch};
use crate::affinity::{self, Pin};
use crate::ocean::{Mesh, Stepper};
use crate::sched::ThreadNoise;
use crate::sync::Free;
use crate::workload::Work;
use std::sync::Arc;
use std::time::Instant;

/// Runs the loop from the calling thread, starting and joining a helper every frame.
pub(super) fn run<F: FnMut(u64, &Mesh)>(
    spec: &LoopSpec,
    budget: &Budget,
    trace: Option<usize>,
    ocean: Box<dyn Stepper>,
    work: &mut Work,
    mut observe: F,
) -> Result<Measured, LoopError> {
    let main_pin = affinity::pin_current(spec.main_core);
    let (cores, main) = (CoreWatch::start(spec), ThreadWatch::start(spec.main_core));
    let core = spec.helper_cores[0];
    let shared = Arc::new(Shared::new(spec, trace.is_some()));
    let mut ocean = Some(ocean);
    let mut helpers = Pin { core, held: true };
    let mut suffered = ThreadNoise {
        thread: "helper 0 (a thread per frame)".into(),
        core,
        ..ThreadNoise::default()
    };
    let mut render = spec.blank_mesh();
    let mut frames = FrameCounter::new(budget, trace, 1);
    let mut held = 0;
    loop {
        let k = frames.frame;
        let helper = {
            let (shared, spec) = (Arc::clone(&shared), spec.clone());
            let mut ocean = ocean
                .take()
                .expect("the ocean is returned by every joined helper");
            // The new thread inherits the main thread's mask, so it pins itself explicitly.
            std::thread::Builder::new()
                .name("ocean-helper".into())
                .spawn(move || {
                    let pin = affinity::pin_current(core);
                    let watch = ThreadWatch::start(core);
                    // Depth 1: the previous frame's thread was joined and its slot released.
                    let (free, waited) = timed(|| {
                        shared.parts[0]
                            .handoff
                            .wait_free(Instant::now() + spec.timeout)
                    });
                    if free == Ok(Free::Slot) {
                        produce(&spec, k, &mut *ocean, &shared, 0, waited)
                            .expect("a lone helper meets no barrier");
                    }
                    (ocean, pin, watch.stop(String::new()))
                })
                .map_err(|e| LoopError::Helper(e.to_string()))?
        };
        let record = consume(
            spec,
            &mut frames,
            &shared,
            &mut render,
            &mut held,
            work,
            &mut observe,
        )?;
        let (back, pin, noise) = helper
            .join()
            .map_err(|_| LoopError::Helper("helper thread panicked".into()))?;
        ocean = Some(back);
        helpers.held &= pin.held;
        suffered.cpu_ns += noise.cpu_ns;
        suffered.run_delay_ns += noise.run_delay_ns;
        suffered.involuntary_switches += noise.involuntary_switches;
        // The frame, which ends after the join, includes creating and joining its thread, as
        // the paper's first build did.
        if frames.finish(record, spec)? {
            break;
        }
    }
    let (trial, timeline) = frames.trial();
    Ok(Measured {
        trial,
        timeline,
        main_pin,
        helper_pins: vec![helpers],
        noise: cores.stop(vec![main.stop("main".into()), suffered]),
    })
}
