//! The game loops: `serial` (one thread does workload, mesh and copy) and threaded (a helper
//! computes frame k's mesh while the main thread runs frame k's workload, then hands it over).
//! With `helpers` > 1 the mesh's rows are split into bands, one persistent helper per band, each
//! with its own hand-off: the paper's future work, "do a portion of the grid on one thread, a
//! portion on another".

use crate::affinity::{self, Pin};
use crate::input::InputError;
use crate::measure::{FrameRecord, Trial};
use crate::ocean::{Grid, Kernel, Mesh, MeshRows, NormalMethod, Ocean, WaveSet};
use crate::sync::{Handoff, Released, Slot, SyncMethod};
use crate::workload;
use std::cell::UnsafeCell;
use std::ops::Range;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

crate::named! {
    /// Where the two threads run.
    pub enum Mode {
        /// One thread: workload, mesh step and copy in turn (the paper's non-threaded build).
        Serial,
        /// Main and helper threads pinned to the same core (uniprocessor).
        Up,
        /// Main and helper threads pinned to two different cores (dual processor).
        Dp,
    }
}

impl Mode {
    /// Distinct cores the mode needs.
    pub fn cores_needed(self) -> usize {
        match self {
            Mode::Dp => 2,
            _ => 1,
        }
    }
}

crate::named! {
    /// How the helper thread comes to exist.
    pub enum Threading {
        /// One persistent helper, created once (the paper's thread pool).
        Pool,
        /// A new helper thread every frame (the paper's first implementation).
        Spawn,
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
    /// Helper threads the mesh's rows are split among (1: the paper's single helper).
    pub helpers: usize,
    /// Helper k runs on `helper_cores[k % len]`; empty puts every helper on `helper_core`.
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
    /// The core helper `k` is pinned to.
    pub fn helper_core_of(&self, k: usize) -> usize {
        match self.helper_cores.len() {
            0 => self.helper_core,
            len => self.helper_cores[k % len],
        }
    }

    /// Checks what `helpers` > 1 needs: a persistent pool, analytic normals, a band per helper.
    pub fn check_helpers(&self) -> Result<(), InputError> {
        check_helpers(
            self.helpers,
            self.mode,
            self.threading,
            self.normals,
            self.grid.n,
        )
    }

    fn stopped(&self) -> bool {
        self.stop
            .as_ref()
            .is_some_and(|s| s.load(Ordering::Relaxed))
    }
}

/// Most helpers a loop may split the mesh among.
pub const MAX_HELPERS: usize = 64;

/// Refuses a helper count the loops cannot run, naming why; shared by configs, flags and
/// `run` so every entry point gives the same message.
pub fn check_helpers(
    helpers: usize,
    mode: Mode,
    threading: Threading,
    normals: NormalMethod,
    size: usize,
) -> Result<(), InputError> {
    if !(1..=MAX_HELPERS).contains(&helpers) {
        return Err(InputError(format!(
            "helpers: must be 1 to {MAX_HELPERS}, got {helpers}"
        )));
    }
    if helpers == 1 || mode == Mode::Serial {
        return Ok(());
    }
    if threading == Threading::Spawn {
        return Err(InputError(format!(
            "helpers: {helpers} helpers need threading `pool`; `spawn` starts one thread per \
             frame and is kept as the paper's single-helper first build"
        )));
    }
    if helpers > size {
        return Err(InputError(format!(
            "helpers: {helpers} helpers need at least one row each; size {size} has {size} rows"
        )));
    }
    Ocean::splits_into_rows(normals)
}

/// Helper cores cycling through the allowed cores from `first` on (wrapping past the main
/// core): in dp with the defaults on two cores, helper 0 gets core 1 and helper 1 core 0.
pub fn cycle_cores(first: usize, helpers: usize) -> Vec<usize> {
    let allowed = affinity::allowed_cores();
    let start = allowed.iter().position(|&c| c == first).unwrap_or(0);
    allowed
        .iter()
        .cycle()
        .skip(start)
        .take(helpers)
        .copied()
        .collect()
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
    #[error(transparent)]
    Spec(#[from] InputError),
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
    /// Helper's pin (every per-frame thread held in `spawn`, every helper held with several
    /// helpers; the core is helper 0's); `None` in `serial`.
    pub helper_pin: Option<Pin>,
    /// Every helper's pin, helper k at index k (empty in `serial`).
    pub helper_pins: Vec<Pin>,
}

/// What a helper leaves next to its band: which frame the band holds and how long it took.
#[derive(Default)]
struct Stamp {
    index: u64,
    step_ns: u64,
}

/// One helper's share of the frame: its rows, its hand-off and its stamp.
struct Part {
    rows: Range<usize>,
    handoff: Box<dyn Handoff>,
    stamp: Slot<Stamp>,
}

/// The one-frame slot: a mesh the helpers write band by band and the main thread copies whole,
/// with one hand-off per helper (so every sync method works unchanged for any helper count).
struct Shared {
    mesh: UnsafeCell<Mesh>,
    /// Base pointers of z, nx, ny, nz (and x, y), taken once while the mesh was uniquely owned,
    /// so helpers can make disjoint band slices without ever forming a `&mut Mesh` at once.
    base: [*mut f32; 6],
    parts: Vec<Part>,
}

// SAFETY: the mesh and stamps are only touched under the hand-off protocol: helper k writes its
// own rows (disjoint from every other helper's) and its stamp while its hand-off is Empty, the
// main thread reads them only after every hand-off is Full; each pair of sides is a
// release/acquire edge. The raw pointers point into the mesh's buffers, which are never resized.
unsafe impl Sync for Shared {}
// SAFETY: as above; the pointers are owned data of `mesh`, which moves with them.
unsafe impl Send for Shared {}

impl Shared {
    /// A slot for `spec`'s grid split evenly into `spec.helpers` bands of whole rows.
    fn new(spec: &LoopSpec) -> Shared {
        let mut mesh = Mesh::new(spec.grid);
        let base = [
            mesh.x.as_mut_ptr(),
            mesh.y.as_mut_ptr(),
            mesh.z.as_mut_ptr(),
            mesh.nx.as_mut_ptr(),
            mesh.ny.as_mut_ptr(),
            mesh.nz.as_mut_ptr(),
        ];
        let (n, h) = (spec.grid.n, spec.helpers.max(1));
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

    /// Helper k's band of the mesh.
    ///
    /// # Safety
    /// The caller is helper k and owns its part (its hand-off is Empty), and it is one of
    /// several helpers (a lone helper uses `whole`), so only disjoint bands are alive.
    #[allow(clippy::mut_from_ref)]
    unsafe fn band(&self, k: usize) -> MeshRows<'_> {
        let grid = self.mesh_grid();
        let rows = self.parts[k].rows.clone();
        let (start, len) = (rows.start * grid.n, rows.len() * grid.n);
        // SAFETY: `start + len` is within the mesh's N² elements; x and y are never written,
        // and z..nz rows of different helpers do not overlap (bands partition the rows).
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

    /// The whole mesh, for a lone helper (face normals need every row).
    ///
    /// # Safety
    /// The caller is the only helper and owns the slot (its hand-off is Empty).
    #[allow(clippy::mut_from_ref)]
    unsafe fn whole(&self) -> &mut Mesh {
        unsafe { &mut *self.mesh.get() }
    }

    /// The finished mesh.
    ///
    /// # Safety
    /// The caller is the main thread, every part is published and none released yet.
    unsafe fn finished(&self) -> &Mesh {
        unsafe { &*self.mesh.get() }
    }

    fn mesh_grid(&self) -> Grid {
        // SAFETY: `grid` is never written after construction, so reading it races with nothing.
        unsafe { (*self.mesh.get()).grid }
    }
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
    spec.check_helpers().map_err(LoopError::Spec)?;
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
        helper_pins: Vec::new(),
    })
}

/// The main thread's side of one threaded frame: workload, wait for every helper, copy,
/// release them all.
fn consume<F: FnMut(u64, &Mesh)>(
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
            .map_err(|_| stalled(spec, "the main thread (waiting for the mesh)"))?;
    }
    let t2 = Instant::now();
    // SAFETY: every part is published and not yet released, so no helper is writing.
    render.copy_from(unsafe { shared.finished() });
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

fn stalled(spec: &LoopSpec, who: &'static str) -> LoopError {
    LoopError::Stalled {
        sync: spec.sync.name(),
        mode: spec.mode.name(),
        who,
        timeout: spec.timeout,
    }
}

/// Helper `h`'s side of one frame: compute its rows of frame k into the slot and publish them.
fn produce(spec: &LoopSpec, k: u64, ocean: &mut Ocean, shared: &Shared, h: usize) {
    if spec.stall_at_frame == Some(k) {
        // A helper that never publishes again: the main thread's timeout must end the cell.
        loop {
            std::thread::park();
        }
    }
    let part = &shared.parts[h];
    let t = time_of(spec, k);
    let t0 = Instant::now();
    // SAFETY (both arms): part h is Empty (never published, or released by the main thread),
    // so the main thread is not reading it; other helpers only touch their own rows.
    if shared.parts.len() == 1 {
        ocean.step(t, unsafe { shared.whole() });
    } else {
        ocean.step_rows(t, unsafe { shared.band(h) });
    }
    // SAFETY: as above, the stamp belongs to helper h until it publishes.
    let stamp = unsafe { part.stamp.get_mut() };
    stamp.step_ns = ns(t0.elapsed());
    stamp.index = k;
    part.handoff.publish();
}

fn pool<F: FnMut(u64, &Mesh)>(
    spec: &LoopSpec,
    budget: &Budget,
    ocean: Ocean,
    mut observe: F,
) -> Result<LoopRun, LoopError> {
    let main_pin = affinity::pin_current(spec.main_core);
    let shared = Arc::new(Shared::new(spec));
    let mut helpers = Vec::with_capacity(shared.parts.len());
    // Each helper owns an `Ocean` of its own: the fast kernel keeps per-band tables in it.
    for h in 0..shared.parts.len() {
        let (mine, spec, mut ocean) = (Arc::clone(&shared), spec.clone(), ocean.clone());
        let helper = std::thread::Builder::new()
            .name(format!("ocean-helper-{h}"))
            .spawn(move || -> Result<Pin, LoopError> {
                let pin = affinity::pin_current(spec.helper_core_of(h));
                let handoff = &*mine.parts[h].handoff;
                let mut k = 0;
                loop {
                    produce(&spec, k, &mut ocean, &mine, h);
                    match handoff.wait_released(Instant::now() + spec.timeout) {
                        Ok(Released::Next) => k += 1,
                        Ok(Released::Shutdown) => return Ok(pin),
                        Err(_) => return Err(stalled(&spec, "the helper (waiting for release)")),
                    }
                }
            });
        match helper {
            Ok(helper) => helpers.push(helper),
            Err(e) => {
                // The helpers already started would wait for a release forever: stop them.
                for part in &shared.parts {
                    part.handoff.shutdown();
                }
                return Err(LoopError::Helper(e.to_string()));
            }
        }
    }
    let mut render = Mesh::new(spec.grid);
    let mut clock = Clock::new(budget);
    let outcome = loop {
        match consume(spec, clock.frame, &shared, &mut render, &mut observe) {
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
    for part in &shared.parts {
        part.handoff.shutdown();
    }
    // A stalled helper may never return: leave it behind rather than hang the process.
    outcome?;
    let mut helper_pins = Vec::with_capacity(helpers.len());
    for helper in helpers {
        helper_pins.push(
            helper
                .join()
                .map_err(|_| LoopError::Helper("helper thread panicked".into()))??,
        );
    }
    Ok(LoopRun {
        trial: clock.trial(),
        main_pin,
        helper_pin: Some(Pin {
            core: helper_pins[0].core,
            held: helper_pins.iter().all(|p| p.held),
        }),
        helper_pins,
    })
}

fn spawn_per_frame<F: FnMut(u64, &Mesh)>(
    spec: &LoopSpec,
    budget: &Budget,
    ocean: Ocean,
    mut observe: F,
) -> Result<LoopRun, LoopError> {
    let main_pin = affinity::pin_current(spec.main_core);
    let shared = Arc::new(Shared::new(spec));
    let mut ocean = Some(ocean);
    let mut helpers_held = true;
    let mut render = Mesh::new(spec.grid);
    let mut clock = Clock::new(budget);
    loop {
        let k = clock.frame;
        let t0 = Instant::now();
        let helper = {
            let (shared, spec) = (Arc::clone(&shared), spec.clone());
            let mut ocean = ocean
                .take()
                .expect("the ocean is returned by every joined helper");
            // The new thread inherits the main thread's mask, so it pins itself explicitly.
            std::thread::Builder::new()
                .name("ocean-helper".into())
                .spawn(move || {
                    let pin = affinity::pin_current(spec.helper_core);
                    produce(&spec, k, &mut ocean, &shared, 0);
                    (ocean, pin)
                })
                .map_err(|e| LoopError::Helper(e.to_string()))?
        };
        let mut record = consume(spec, k, &shared, &mut render, &mut observe)?;
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
    let helper_pin = Pin {
        core: spec.helper_core,
        held: helpers_held,
    };
    Ok(LoopRun {
        trial: clock.trial(),
        main_pin,
        helper_pin: Some(helper_pin),
        helper_pins: vec![helper_pin],
    })
}
