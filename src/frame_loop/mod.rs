//! The game loops: `serial` (one thread does workload, mesh and copy) and threaded (a helper
//! computes frame k's mesh while the main thread runs frame k's workload, then hands it over),
//! with a persistent helper (`pool`) or a thread per frame (`spawn`). With `helpers` > 1 the
//! mesh's rows are split into bands, one persistent helper per band, each with its own
//! hand-off: the paper's future work, "do a portion of the grid on one thread, a portion on
//! another".
//!
//! One file per loop; `frames.rs` counts frames against the budget, and `slots.rs` holds the
//! shared mesh and the two sides of a threaded frame that touch it: every `unsafe` access to
//! the slot is there.

mod barrier;
mod consume;
mod frames;
mod latest;
mod pool;
mod serial;
mod slots;
mod spawn;
mod timeline;

pub use crate::cell::axes::{
    check_depth, check_helpers, check_policy, Mode, Threading, MAX_DEPTH, MAX_HELPERS,
};
pub use consume::{read, Consume, ReadPass};
pub use timeline::{HelperSpan, Timeline, TracedFrame};

use crate::affinity::{self, Pin};
use crate::camera::Camera;
use crate::input::InputError;
use crate::measure::Trial;
use crate::ocean::{Grid, GridKind, Kernel, Mesh, NormalMethod, OceanKind, OceanParams};
use crate::sched::{self, ThreadCounters, ThreadNoise, TrialNoise};
use crate::sync::{Policy, SyncMethod};
use crate::workload::{KindParams, Work, WorkRecord, WorkSpec, WorkloadKind};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Everything that defines one cell's loop.
#[derive(Clone, Debug)]
pub struct LoopSpec {
    /// The mesh grid.
    pub grid: Grid,
    /// Where its vertices lie: the regular patch, or projected from `camera`.
    pub grid_kind: GridKind,
    /// Which ocean model the helper computes.
    pub ocean: OceanKind,
    /// The models' parameters (the sines' waves, the FFT ocean's spectrum).
    pub params: OceanParams,
    /// How normals are computed.
    pub normals: NormalMethod,
    /// Which kernel fills the heights.
    pub kernel: Kernel,
    /// serial, up or dp.
    pub mode: Mode,
    /// Which frames the main thread consumes (ignored in `serial`).
    pub policy: Policy,
    /// The hand-off method (ignored in `serial`).
    pub sync: SyncMethod,
    /// Persistent or per-frame helper (ignored in `serial`).
    pub threading: Threading,
    /// What the main thread does each frame.
    pub workload_kind: WorkloadKind,
    /// The main thread's work per frame, in the kind's unit ([`crate::workload::Kind::unit`]).
    pub workload_amount: u64,
    /// The camera, for workloads that look at the mesh and for the projected grid.
    pub camera: Camera,
    /// The workload kind's parameters (its config object, parsed by the kind).
    pub work_params: KindParams,
    /// Mesh slots in the ring: frames the helper may finish before the main thread consumes
    /// the first of them (1: the paper's lockstep loop; ignored in `serial`).
    pub depth: usize,
    /// How the main thread consumes a mesh.
    pub consume: Consume,
    /// Core of the main thread.
    pub main_core: usize,
    /// Helper k's core, one per helper thread the mesh's rows are split among (one: the
    /// paper's single helper; none in `serial`). See [`helper_cores`].
    pub helper_cores: Vec<usize>,
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
    /// Helper threads: one per helper core.
    pub fn helpers(&self) -> usize {
        self.helper_cores.len()
    }

    /// Checks what the loop needs: the cell's rules ([`crate::cell::rules`]) and parameters of
    /// its workload kind.
    pub fn check(&self) -> Result<(), InputError> {
        if self.work_params.kind() != self.workload_kind {
            return Err(InputError(format!(
                "work_params: parameters of workload kind `{}` for a `{}` loop",
                self.work_params.kind(),
                self.workload_kind
            )));
        }
        let threaded = self.mode != Mode::Serial;
        crate::cell::rules::Runnable {
            size: self.grid.n,
            ocean: self.ocean,
            grid: self.grid_kind,
            normals: self.normals,
            kernel: self.kernel,
            workload_kind: self.workload_kind,
            mode: self.mode,
            policy: threaded.then_some(self.policy),
            sync: threaded.then_some(self.sync),
            threading: threaded.then_some(self.threading),
            helpers: threaded.then(|| self.helpers()),
            depth: threaded.then_some(self.depth),
        }
        .check()
        .map_err(|r| r.error())
    }

    /// A blank mesh with the fields the cell's model fills: every slot and render buffer.
    fn blank_mesh(&self) -> Mesh {
        self.ocean.model().mesh(self.grid)
    }

    fn stopped(&self) -> bool {
        self.stop
            .as_ref()
            .is_some_and(|s| s.load(Ordering::Relaxed))
    }

    /// What the main thread's work is built from.
    pub fn work_spec(&self) -> WorkSpec {
        WorkSpec {
            kind: self.workload_kind,
            amount: self.workload_amount,
            grid: self.grid,
            camera: self.camera,
            spacing: self.ocean.model().rest_spacing(self.grid, &self.params),
            time_step: self.time_step as f32,
        }
    }

    /// Frame k's work if it runs before the wait, so that it overlaps the helper's step;
    /// `Interrupted` when a stop request arrived meanwhile.
    fn work_before_wait(&self, work: &mut Work, k: u64) -> Result<(), LoopError> {
        let Work::BeforeWait(work) = work else {
            return Ok(());
        };
        work.run(k, self.stop.as_deref())
            .map_err(|_| LoopError::Interrupted)
    }

    /// Frame k's work if it runs on the mesh the frame consumed; how long it took.
    fn work_on_mesh(&self, work: &mut Work, k: u64, mesh: &Mesh) -> Result<Duration, LoopError> {
        let Work::OnMesh(work) = work else {
            return Ok(Duration::ZERO);
        };
        let started = Instant::now();
        work.run(k, mesh, self.stop.as_deref())
            .map_err(|_| LoopError::Interrupted)?;
        Ok(started.elapsed())
    }

    /// Fault injection: a helper that reaches `stall_at_frame` never publishes again, so the
    /// main thread's timeout must end the cell.
    fn stall_at(&self, frame: u64) {
        if self.stall_at_frame == Some(frame) {
            loop {
                std::thread::park();
            }
        }
    }

    fn time_of(&self, frame: u64) -> f32 {
        (frame as f64 * self.time_step) as f32
    }

    fn stalled(&self, who: &'static str) -> LoopError {
        LoopError::Stalled {
            sync: self.sync.name(),
            mode: self.mode.name(),
            who,
            timeout: self.timeout,
        }
    }
}

/// The cores of `helpers` helper threads: none in `serial`; in `up` they share the main core;
/// in `dp` they cycle through the allowed cores from `helper_core` on, wrapping past the main
/// core (on two cores with the defaults, helper 0 gets core 1 and helper 1 core 0).
pub fn helper_cores(
    mode: Mode,
    main_core: usize,
    helper_core: usize,
    helpers: usize,
) -> Vec<usize> {
    match mode {
        Mode::Serial => Vec::new(),
        Mode::Up => vec![main_core; helpers],
        Mode::Dp => {
            let allowed = affinity::allowed_cores();
            let start = allowed.iter().position(|&c| c == helper_core).unwrap_or(0);
            allowed
                .iter()
                .cycle()
                .skip(start)
                .take(helpers)
                .copied()
                .collect()
        }
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

    fn met(&self, frames: u64, seconds: f64) -> bool {
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
    #[error(transparent)]
    Spec(#[from] InputError),
    /// The stop flag was raised; the trial is incomplete.
    #[error("interrupted")]
    Interrupted,
}

/// The outcome of one loop: the measured frames, how the pins went and what disturbed it.
#[derive(Clone, Debug)]
pub struct LoopRun {
    /// Measured frames.
    pub trial: Trial,
    /// Main thread's pin.
    pub main_pin: Pin,
    /// Every helper's pin, helper k at index k (empty in `serial`; in `spawn`, the per-frame
    /// threads together: held only if every one held).
    pub helper_pins: Vec<Pin>,
    /// The digest of what the main thread's work produced in the last frame.
    pub work_digest: u64,
    /// What the main thread's work recorded of itself ([`crate::workload::WorkOutput::record`]).
    pub work_record: Option<WorkRecord>,
    /// Each thread's run delay and preemptions, and each core's steal, during the loop.
    pub noise: TrialNoise,
    /// The first measured frames' timeline, when [`run_traced`] asked for one.
    pub timeline: Option<Timeline>,
}

/// What a loop measured, before the work's digest and record join it in [`run`].
pub(crate) struct Measured {
    trial: Trial,
    main_pin: Pin,
    helper_pins: Vec<Pin>,
    noise: TrialNoise,
    timeline: Option<Timeline>,
}

impl LoopRun {
    /// The loop's outcome: what it measured, and what its work says of itself.
    fn of(measured: Measured, work: &Work) -> LoopRun {
        let output = work.output();
        LoopRun {
            trial: measured.trial,
            main_pin: measured.main_pin,
            helper_pins: measured.helper_pins,
            work_digest: output.digest(),
            work_record: output.record(),
            noise: measured.noise,
            timeline: measured.timeline,
        }
    }

    /// Whether every pin of the loop held.
    pub fn pinned(&self) -> bool {
        self.main_pin.held && self.helper_pins.iter().all(|p| p.held)
    }
}

/// A thread's scheduler counters from its start: what it suffered is read when it ends.
#[derive(Clone, Copy)]
struct ThreadWatch {
    core: usize,
    start: Option<ThreadCounters>,
}

impl ThreadWatch {
    /// Starts watching the calling thread, pinned to `core`.
    fn start(core: usize) -> ThreadWatch {
        ThreadWatch {
            core,
            start: ThreadCounters::now(),
        }
    }

    /// What the calling thread suffered since `start`, named `thread`.
    fn stop(self, thread: String) -> ThreadNoise {
        let delta = match (ThreadCounters::now(), self.start) {
            (Some(end), Some(start)) => end.since(start),
            _ => ThreadCounters::default(),
        };
        ThreadNoise {
            thread,
            core: self.core,
            cpu_ns: delta.cpu_ns,
            run_delay_ns: delta.run_delay_ns,
            involuntary_switches: delta.involuntary_switches,
        }
    }
}

/// The wall clock and the pinned cores' steal over a whole loop.
struct CoreWatch {
    started: Instant,
    cores: Vec<usize>,
    steal: Option<Vec<u64>>,
}

impl CoreWatch {
    fn start(spec: &LoopSpec) -> CoreWatch {
        let mut cores = vec![spec.main_core];
        cores.extend(&spec.helper_cores);
        cores.sort_unstable();
        cores.dedup();
        CoreWatch {
            started: Instant::now(),
            steal: sched::steal_ns(&cores),
            cores,
        }
    }

    fn stop(self, threads: Vec<ThreadNoise>) -> TrialNoise {
        let steal_ns = match (sched::steal_ns(&self.cores), self.steal) {
            (Some(end), Some(start)) => self
                .cores
                .iter()
                .zip(end.iter().zip(start))
                .map(|(&c, (e, s))| (c, e.saturating_sub(s)))
                .collect(),
            _ => Vec::new(),
        };
        TrialNoise {
            wall_ns: self.started.elapsed().as_nanos() as u64,
            threads,
            steal_ns,
        }
    }
}

/// Runs one loop on a fresh main thread (so the caller's own CPU mask is never changed) and
/// calls `observe(index, mesh)` after every frame's consumption, warm-up frames included, with
/// the mesh as consumed (the render buffer under `copy`) and the frame index it was computed
/// for: under `fifo` the frame's own, under `latest` the newest the helper had finished, so
/// indices may repeat or skip but never decrease.
pub fn run<F>(spec: &LoopSpec, budget: &Budget, observe: F) -> Result<LoopRun, LoopError>
where
    F: FnMut(u64, &Mesh) + Send,
{
    run_traced(spec, budget, None, observe)
}

/// [`run`], keeping with `trace` the timeline of that many first measured frames in
/// [`LoopRun::timeline`] (from the instants the loop reads anyway; see [`Timeline`]).
pub fn run_traced<F>(
    spec: &LoopSpec,
    budget: &Budget,
    trace: Option<usize>,
    observe: F,
) -> Result<LoopRun, LoopError>
where
    F: FnMut(u64, &Mesh) + Send,
{
    spec.check()?;
    let ocean = crate::projected::stepper(
        spec.grid_kind,
        spec.ocean.model(),
        spec.grid,
        &spec.params,
        spec.normals,
        spec.kernel,
        spec.camera,
    )?;
    std::thread::scope(|s| {
        std::thread::Builder::new()
            .name("ocean-main".into())
            .spawn_scoped(s, move || {
                // Built on the main thread, which alone touches it: a kind's buffers are then
                // in that thread's memory.
                let mut work = spec
                    .workload_kind
                    .kind()?
                    .build(&spec.work_spec(), &spec.work_params);
                let work = &mut work;
                let measured = match (spec.mode, spec.threading) {
                    (Mode::Serial, _) => serial::run(spec, budget, trace, ocean, work, observe),
                    _ if spec.policy == Policy::Latest => {
                        latest::run(spec, budget, trace, ocean, work, observe)
                    }
                    (_, Threading::Pool) => pool::run(spec, budget, trace, ocean, work, observe),
                    (_, Threading::Spawn) => spawn::run(spec, budget, trace, ocean, work, observe),
                }?;
                Ok(LoopRun::of(measured, work))
            })
            .map_err(|e| LoopError::Helper(e.to_string()))?
            .join()
            .map_err(|_| LoopError::Helper("main loop thread panicked".into()))?
    })
}
