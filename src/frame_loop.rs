//! The game loops: `serial` (one thread does workload, mesh and copy) and threaded (a helper
//! computes frame k's mesh while the main thread runs frame k's workload, then hands it over).

use crate::affinity::{self, Pin};
use crate::measure::{FrameRecord, Trial};
use crate::ocean::{Grid, Kernel, Mesh, NormalMethod, Ocean, WaveSet};
use crate::sync::{Handoff, Released, Slot, SyncMethod};
use crate::workload;
use serde::{Deserialize, Serialize};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Where the two threads run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum Mode {
    /// One thread: workload, mesh step and copy in turn (the paper's non-threaded build).
    Serial,
    /// Main and helper threads pinned to the same core (uniprocessor).
    Up,
    /// Main and helper threads pinned to two different cores (dual processor).
    Dp,
}

impl Mode {
    /// The name used in configs, flags and results.
    pub fn name(self) -> &'static str {
        match self {
            Mode::Serial => "serial",
            Mode::Up => "up",
            Mode::Dp => "dp",
        }
    }

    /// Distinct cores the mode needs.
    pub fn cores_needed(self) -> usize {
        match self {
            Mode::Dp => 2,
            _ => 1,
        }
    }
}

/// How the helper thread comes to exist.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum Threading {
    /// One persistent helper, created once (the paper's thread pool).
    Pool,
    /// A new helper thread every frame (the paper's first implementation).
    Spawn,
}

impl Threading {
    /// The name used in configs, flags and results.
    pub fn name(self) -> &'static str {
        match self {
            Threading::Pool => "pool",
            Threading::Spawn => "spawn",
        }
    }
}

/// Everything that defines one cell's loop.
#[derive(Clone, Debug)]
pub struct LoopSpec {
    /// The mesh grid.
    pub grid: Grid,
    /// The waves summed.
    pub waves: WaveSet,
    /// How normals are computed.
    pub normals: NormalMethod,
    /// Which kernel fills the heights.
    pub kernel: Kernel,
    /// serial, up or dp.
    pub mode: Mode,
    /// The hand-off method (ignored in `serial`).
    pub sync: SyncMethod,
    /// Persistent or per-frame helper (ignored in `serial`).
    pub threading: Threading,
    /// Workload iterations the main thread runs per frame.
    pub workload_iterations: u64,
    /// Core of the main thread.
    pub main_core: usize,
    /// Core of the helper (equal to `main_core` in `up`).
    pub helper_core: usize,
    /// Simulated seconds per frame: frame k's mesh is the surface at t = k · time_step.
    pub time_step: f64,
    /// How long a hand-off wait may take before the cell is aborted.
    pub timeout: Duration,
    /// Set from outside (Ctrl-C, SIGTERM) to stop the loop after the current frame.
    pub stop: Option<Arc<AtomicBool>>,
    /// Fault injection for testing the timeout: the helper stops producing at this frame.
    pub stall_at_frame: Option<u64>,
}

impl LoopSpec {
    fn stopped(&self) -> bool {
        self.stop
            .as_ref()
            .is_some_and(|s| s.load(Ordering::Relaxed))
    }
}

/// When a trial stops.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Budget {
    /// Frames run and thrown away before measuring.
    pub warmup_frames: u64,
    /// Measured frames at least ...
    pub min_frames: u64,
    /// ... and measured seconds at least ...
    pub min_seconds: f64,
    /// ... unless this many seconds have passed (with at least one frame).
    pub max_seconds: f64,
}

impl Budget {
    /// Exactly `frames` measured frames, no warm-up, no time limits (for tests and checks).
    pub fn exact(frames: u64) -> Budget {
        Budget {
            warmup_frames: 0,
            min_frames: frames,
            min_seconds: 0.0,
            max_seconds: f64::INFINITY,
        }
    }

    fn done(&self, frames: u64, seconds: f64) -> bool {
        (frames >= self.min_frames && seconds >= self.min_seconds)
            || (frames >= 1 && seconds >= self.max_seconds)
    }
}

/// Why a loop did not finish.
#[derive(Debug, thiserror::Error)]
pub enum LoopError {
    /// A hand-off wait passed its timeout.
    #[error("{sync} hand-off in {mode} mode: {who} waited over {timeout:?}; cell aborted")]
    Stalled {
        /// The method's name.
        sync: &'static str,
        /// The mode's name.
        mode: &'static str,
        /// Which side was waiting.
        who: &'static str,
        /// The timeout that passed.
        timeout: Duration,
    },
    /// The helper thread panicked or could not be started.
    #[error("helper thread failed: {0}")]
    Helper(String),
    /// The spec is not runnable (e.g. `lookup` on too large a grid).
    #[error("{0}")]
    Spec(String),
    /// The stop flag was raised; the trial is incomplete.
    #[error("interrupted")]
    Interrupted,
}

/// The outcome of one loop: the measured frames and how the pins went.
#[derive(Clone, Debug)]
pub struct LoopRun {
    /// Measured frames.
    pub trial: Trial,
    /// Main thread's pin.
    pub main_pin: Pin,
    /// Helper's pin (every per-frame thread held in `spawn`); `None` in `serial`.
    pub helper_pin: Option<Pin>,
}

/// One frame as the helper leaves it in the slot.
struct Frame {
    index: u64,
    step_ns: u64,
    mesh: Mesh,
}

fn time_of(spec: &LoopSpec, frame: u64) -> f32 {
    (frame as f64 * spec.time_step) as f32
}

fn ns(d: Duration) -> u64 {
    d.as_nanos() as u64
}

/// Runs one loop on a fresh main thread (so the caller's own CPU mask is never changed) and
/// calls `observe(frame, render_buffer)` after every frame's copy, warm-up frames included.
pub fn run<F>(spec: &LoopSpec, budget: &Budget, observe: F) -> Result<LoopRun, LoopError>
where
    F: FnMut(u64, &Mesh) + Send,
{
    let ocean = Ocean::new(spec.grid, spec.waves.clone(), spec.normals, spec.kernel)
        .map_err(LoopError::Spec)?;
    std::thread::scope(|s| {
        std::thread::Builder::new()
            .name("ocean-main".into())
            .spawn_scoped(s, move || match (spec.mode, spec.threading) {
                (Mode::Serial, _) => serial(spec, budget, ocean, observe),
                (_, Threading::Pool) => pool(spec, budget, ocean, observe),
                (_, Threading::Spawn) => spawn_per_frame(spec, budget, ocean, observe),
            })
            .map_err(|e| LoopError::Helper(e.to_string()))?
            .join()
            .map_err(|_| LoopError::Helper("main loop thread panicked".into()))?
    })
}

/// Counts frames and decides when the measured part is over.
struct Clock<'a> {
    budget: &'a Budget,
    frame: u64,
    measured_ns: u64,
    records: Vec<FrameRecord>,
}

impl<'a> Clock<'a> {
    fn new(budget: &'a Budget) -> Self {
        Clock {
            budget,
            frame: 0,
            measured_ns: 0,
            records: Vec::with_capacity(budget.min_frames.min(1 << 20) as usize),
        }
    }

    /// Records a finished frame; returns true when the loop should stop.
    fn finish(&mut self, record: FrameRecord) -> bool {
        self.frame += 1;
        if self.frame <= self.budget.warmup_frames {
            return false;
        }
        self.measured_ns += record.total_ns;
        self.records.push(record);
        self.budget
            .done(self.records.len() as u64, self.measured_ns as f64 * 1e-9)
    }

    fn trial(self) -> Trial {
        Trial {
            frames: self.records,
        }
    }
}

fn serial<F: FnMut(u64, &Mesh)>(
    spec: &LoopSpec,
    budget: &Budget,
    mut ocean: Ocean,
    mut observe: F,
) -> Result<LoopRun, LoopError> {
    let main_pin = affinity::pin_current(spec.main_core);
    let mut mesh = Mesh::new(spec.grid);
    let mut render = Mesh::new(spec.grid);
    let mut clock = Clock::new(budget);
    loop {
        let k = clock.frame;
        let t0 = Instant::now();
        workload::run(spec.workload_iterations, k);
        let t1 = Instant::now();
        ocean.step(time_of(spec, k), &mut mesh);
        let t2 = Instant::now();
        render.copy_from(&mesh);
        let t3 = Instant::now();
        observe(k, &render);
        let stop = clock.finish(FrameRecord {
            total_ns: ns(t3 - t0),
            workload_ns: ns(t1 - t0),
            wait_ns: 0,
            copy_ns: ns(t3 - t2),
            step_ns: ns(t2 - t1),
        });
        if stop {
            break;
        }
        if spec.stopped() {
            return Err(LoopError::Interrupted);
        }
    }
    Ok(LoopRun {
        trial: clock.trial(),
        main_pin,
        helper_pin: None,
    })
}

/// The main thread's side of one threaded frame: workload, wait, copy, release.
fn consume<F: FnMut(u64, &Mesh)>(
    spec: &LoopSpec,
    k: u64,
    handoff: &dyn Handoff,
    slot: &Slot<Frame>,
    render: &mut Mesh,
    observe: &mut F,
) -> Result<FrameRecord, LoopError> {
    let t0 = Instant::now();
    workload::run(spec.workload_iterations, k);
    let t1 = Instant::now();
    handoff
        .wait_published(t1 + spec.timeout)
        .map_err(|_| stalled(spec, "the main thread (waiting for the mesh)"))?;
    let t2 = Instant::now();
    // SAFETY: the mesh is published and not yet released, so the helper is not writing.
    let frame = unsafe { slot.get() };
    render.copy_from(&frame.mesh);
    let (index, step_ns) = (frame.index, frame.step_ns);
    handoff.release();
    let t3 = Instant::now();
    if index != k {
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

fn stalled(spec: &LoopSpec, who: &'static str) -> LoopError {
    LoopError::Stalled {
        sync: spec.sync.name(),
        mode: spec.mode.name(),
        who,
        timeout: spec.timeout,
    }
}

/// The helper's side of one frame: compute frame k's mesh into the slot and publish it.
fn produce(spec: &LoopSpec, k: u64, ocean: &mut Ocean, slot: &Slot<Frame>, handoff: &dyn Handoff) {
    if spec.stall_at_frame == Some(k) {
        // A helper that never publishes again: the main thread's timeout must end the cell.
        loop {
            std::thread::park();
        }
    }
    // SAFETY: the slot is Empty (never published, or released by the main thread), so the main
    // thread is not reading it.
    let frame = unsafe { slot.get_mut() };
    let t0 = Instant::now();
    ocean.step(time_of(spec, k), &mut frame.mesh);
    frame.step_ns = ns(t0.elapsed());
    frame.index = k;
    handoff.publish();
}

fn pool<F: FnMut(u64, &Mesh)>(
    spec: &LoopSpec,
    budget: &Budget,
    mut ocean: Ocean,
    mut observe: F,
) -> Result<LoopRun, LoopError> {
    let main_pin = affinity::pin_current(spec.main_core);
    let handoff: Arc<dyn Handoff> = Arc::from(spec.sync.handoff());
    let slot = Arc::new(Slot::new(Frame {
        index: 0,
        step_ns: 0,
        mesh: Mesh::new(spec.grid),
    }));
    let helper = {
        let (handoff, slot, spec) = (Arc::clone(&handoff), Arc::clone(&slot), spec.clone());
        std::thread::Builder::new()
            .name("ocean-helper".into())
            .spawn(move || -> Result<Pin, LoopError> {
                let pin = affinity::pin_current(spec.helper_core);
                let mut k = 0;
                loop {
                    produce(&spec, k, &mut ocean, &slot, &*handoff);
                    match handoff.wait_released(Instant::now() + spec.timeout) {
                        Ok(Released::Next) => k += 1,
                        Ok(Released::Shutdown) => return Ok(pin),
                        Err(_) => return Err(stalled(&spec, "the helper (waiting for release)")),
                    }
                }
            })
            .map_err(|e| LoopError::Helper(e.to_string()))?
    };
    let mut render = Mesh::new(spec.grid);
    let mut clock = Clock::new(budget);
    let outcome = loop {
        match consume(
            spec,
            clock.frame,
            &*handoff,
            &slot,
            &mut render,
            &mut observe,
        ) {
            Ok(record) => {
                if clock.finish(record) {
                    break Ok(());
                }
                if spec.stopped() {
                    break Err(LoopError::Interrupted);
                }
            }
            Err(e) => break Err(e),
        }
    };
    handoff.shutdown();
    // A stalled helper may never return: leave it behind rather than hang the process.
    outcome?;
    let helper_pin = helper
        .join()
        .map_err(|_| LoopError::Helper("helper thread panicked".into()))??;
    Ok(LoopRun {
        trial: clock.trial(),
        main_pin,
        helper_pin: Some(helper_pin),
    })
}

fn spawn_per_frame<F: FnMut(u64, &Mesh)>(
    spec: &LoopSpec,
    budget: &Budget,
    ocean: Ocean,
    mut observe: F,
) -> Result<LoopRun, LoopError> {
    let main_pin = affinity::pin_current(spec.main_core);
    let handoff: Arc<dyn Handoff> = Arc::from(spec.sync.handoff());
    let slot = Arc::new(Slot::new(Frame {
        index: 0,
        step_ns: 0,
        mesh: Mesh::new(spec.grid),
    }));
    let mut ocean = Some(ocean);
    let mut helpers_held = true;
    let mut render = Mesh::new(spec.grid);
    let mut clock = Clock::new(budget);
    loop {
        let k = clock.frame;
        let t0 = Instant::now();
        let helper = {
            let (handoff, slot, spec) = (Arc::clone(&handoff), Arc::clone(&slot), spec.clone());
            let mut ocean = ocean
                .take()
                .expect("the ocean is returned by every joined helper");
            // The new thread inherits the main thread's mask, so it pins itself explicitly.
            std::thread::Builder::new()
                .name("ocean-helper".into())
                .spawn(move || {
                    let pin = affinity::pin_current(spec.helper_core);
                    produce(&spec, k, &mut ocean, &slot, &*handoff);
                    (ocean, pin)
                })
                .map_err(|e| LoopError::Helper(e.to_string()))?
        };
        let mut record = consume(spec, k, &*handoff, &slot, &mut render, &mut observe)?;
        let (back, pin) = helper
            .join()
            .map_err(|_| LoopError::Helper("helper thread panicked".into()))?;
        ocean = Some(back);
        helpers_held &= pin.held;
        // The frame includes creating and joining its thread, as the paper's first build did.
        record.total_ns = ns(t0.elapsed());
        if clock.finish(record) {
            break;
        }
        if spec.stopped() {
            return Err(LoopError::Interrupted);
        }
    }
    Ok(LoopRun {
        trial: clock.trial(),
        main_pin,
        helper_pin: Some(Pin {
            core: spec.helper_core,
            held: helpers_held,
        }),
    })
}
