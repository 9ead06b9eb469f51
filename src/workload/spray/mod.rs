//! `spray`: the slides' particle system on the main thread. Every frame, on the mesh just
//! consumed, it integrates every particle of its pool under gravity and drag, kills those that
//! expired, left the patch or fell below the surface, and emits new ones where the surface
//! folds (the Jacobian J below a threshold), along the fold direction plus the surface's own
//! velocity. Its level is the pool's capacity in particles. See docs/spray.md.

mod pool;

pub use pool::{Pool, Step, Surface, BYTES_PER_PARTICLE};

use super::{Kind, MeshWork, Stopped, Work, WorkCounts, WorkOutput, WorkSpec, WorkloadKind};
use crate::input::InputError;
use crate::machine::available_memory;
use crate::ocean::{Grid, GridKind, Mesh, Model, OceanKind};
use crate::stats::SplitMix64;
use serde::{Deserialize, Serialize};
use std::sync::atomic::{AtomicBool, Ordering};

/// Gravity (m/s²): the FFT ocean's default, the metres its surface is in.
pub const GRAVITY: f32 = 9.81;

/// Most particles a pool may hold: its free list counts slots in `u32`.
pub const MAX_PARTICLES: u64 = u32::MAX as u64;

/// The slides' particle count: the pool `run --workload-kind spray` fills without `--amount`.
pub const DEFAULT_PARTICLES: f64 = 131_072.0;

/// Particles integrated or tested between two looks at the stop flag: tens of microseconds.
const CHUNK: usize = 1 << 14;

/// Most particles one frame may emit.
pub const MAX_EMISSION: u32 = 1 << 24;

/// The emission threshold's range (J is 1 where the surface is undisturbed).
pub const THRESHOLD_RANGE: (f64, f64) = (-100.0, 1.0);
/// Fastest launch speed (m/s).
pub const MAX_SPEED: f64 = 1000.0;
/// Longest lifetime (s).
pub const MAX_LIFETIME: f64 = 3600.0;
/// Strongest drag (per second).
pub const MAX_DRAG: f64 = 1000.0;

/// The spray's parameters: the config key `spray`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SprayParams {
    /// A vertex emits where its J is below this (1: the surface is not compressed at all).
    pub threshold: f64,
    /// Launch speed along the fold direction (m/s).
    pub speed: f64,
    /// Seconds a particle lives at most.
    pub lifetime: f64,
    /// Drag: the velocity decays as exp(−drag·t) (per second; 0: none).
    pub drag: f64,
    /// Most particles emitted per frame.
    pub emission_cap: u32,
    /// The jitter's seed.
    pub seed: u64,
}

impl Default for SprayParams {
    fn default() -> Self {
        SprayParams {
            threshold: 0.6,
            speed: 6.0,
            lifetime: 2.0,
            drag: 0.2,
            emission_cap: 4096,
            seed: 1,
        }
    }
}

impl SprayParams {
    /// Checks every field, naming it and what is allowed.
    pub fn validate(&self) -> Result<(), InputError> {
        let bad = |field: &str, allowed: &str, got: String| {
            Err(InputError(format!(
                "spray.{field}: must be {allowed}, got {got}"
            )))
        };
        let t = self.threshold;
        let (lo, hi) = THRESHOLD_RANGE;
        if !(t.is_finite() && (lo..=hi).contains(&t)) {
            return bad(
                "threshold",
                &format!("{lo} to {hi} (J is 1 where the surface is undisturbed)"),
                t.to_string(),
            );
        }
        if !(self.speed.is_finite() && (0.0..=MAX_SPEED).contains(&self.speed)) {
            return bad(
                "speed",
                &format!("0 to {MAX_SPEED} (m/s)"),
                self.speed.to_string(),
            );
        }
        if !(self.lifetime.is_finite() && self.lifetime > 0.0 && self.lifetime <= MAX_LIFETIME) {
            return bad(
                "lifetime",
                &format!("above 0 and at most {MAX_LIFETIME} (seconds)"),
                self.lifetime.to_string(),
            );
        }
        if !(self.drag.is_finite() && (0.0..=MAX_DRAG).contains(&self.drag)) {
            return bad(
                "drag",
                &format!("0 to {MAX_DRAG} (per second)"),
                self.drag.to_string(),
            );
        }
        if !(1..=MAX_EMISSION).contains(&self.emission_cap) {
            return bad(
                "emission_cap",
                &format!("1 to {MAX_EMISSION} (particles per frame)"),
                self.emission_cap.to_string(),
            );
        }
        Ok(())
    }
}

/// Refuses a particle count the pool cannot hold: `amount` must be a whole number from 1 to
/// [`MAX_PARTICLES`] whose pool fits in `available` bytes (when known). `field` names it.
pub fn check_particles(field: &str, amount: f64, available: Option<u64>) -> Result<(), InputError> {
    if !(amount.is_finite() && amount >= 1.0 && amount.fract() == 0.0) {
        return Err(InputError(format!(
            "{field}: must be a whole number of particles, 1 to {MAX_PARTICLES}, got {amount}"
        )));
    }
    let need = amount * BYTES_PER_PARTICLE as f64;
    if let Some(avail) = available.filter(|&a| need > a as f64) {
        return Err(InputError(format!(
            "{field}: {amount} particles need {:.0} MiB for the pool ({BYTES_PER_PARTICLE} bytes each) but only {} MiB is available",
            need / f64::from(1 << 20),
            avail >> 20
        )));
    }
    if amount > MAX_PARTICLES as f64 {
        return Err(InputError(format!(
            "{field}: must be 1 to {MAX_PARTICLES} particles, got {amount}"
        )));
    }
    Ok(())
}

/// Refuses an ocean model whose meshes carry no fold: spray is born where the surface folds.
pub fn check_ocean(ocean: &str, model: &dyn Model) -> Result<(), InputError> {
    let tiny = Grid::new(2, 1.0).expect("a valid grid");
    if model.mesh(tiny).has_fold() {
        return Ok(());
    }
    Err(InputError(format!(
        "workload_kind: spray needs the fft ocean's folds; the `{ocean}` ocean has none (J is 1 everywhere, nothing would be emitted): use ocean fft"
    )))
}

/// Refuses a grid other than the regular one: a particle finds the surface under it in the
/// rest-grid cell it is over, which a projected mesh does not have.
pub fn check_grid(grid: GridKind) -> Result<(), InputError> {
    if grid == GridKind::Regular {
        return Ok(());
    }
    Err(InputError(format!(
        "grid: spray finds the surface under each particle in the regular grid's cells; it runs on the `regular` grid, not `{}`",
        grid.name()
    )))
}

/// The kind's name, and its config key.
pub(in crate::workload) const NAME: &str = "spray";

impl WorkloadKind {
    /// The slides' spray: particles born where the consumed mesh folds.
    pub const SPRAY: WorkloadKind = WorkloadKind(NAME);
}

/// The descriptor of the spray workload.
pub struct SprayKind;

impl Kind for SprayKind {
    type Params = SprayParams;

    fn name(&self) -> &'static str {
        NAME
    }

    fn doc(&self) -> &'static str {
        "The slides' spray: a pool of particles born where the consumed mesh folds, flown under \
         gravity and drag, killed below the surface or when they expire."
    }

    fn unit(&self) -> &'static str {
        Spray::UNIT
    }

    fn check_params(&self, params: &SprayParams) -> Result<(), InputError> {
        params.validate()
    }

    fn check_amount(&self, field: &str, amount: f64) -> Result<(), InputError> {
        check_particles(field, amount, available_memory())
    }

    fn no_time_levels(&self) -> Option<&'static str> {
        Some("spray has no per-particle calibration")
    }

    fn default_amount(&self) -> Option<u64> {
        Some(DEFAULT_PARTICLES as u64)
    }

    fn check_surface(&self, ocean: OceanKind, grid: GridKind) -> Result<(), InputError> {
        check_ocean(ocean.name(), ocean.model())?;
        check_grid(grid)
    }

    fn build(&self, spec: &WorkSpec, params: &SprayParams) -> Work {
        Work::on_mesh(Spray::new(spec, *params))
    }
}

/// The spray's state for one loop: the pool, the vertices folding in the last consumed mesh
/// and where they were, the jitter's generator, and the last frame's counts.
pub struct Spray {
    params: SprayParams,
    pool: Pool,
    step: Step,
    /// Rest spacing of the consumed meshes (metres).
    spacing: f32,
    /// Simulated seconds between two meshes.
    time_step: f32,
    /// This frame's folding vertices, in index order (capacity: every vertex).
    candidates: Vec<u32>,
    /// The last consumed mesh's folding vertices, in index order ...
    previous: Vec<u32>,
    /// ... and their positions then.
    previous_at: Vec<[f32; 3]>,
    /// The mesh frame `previous` comes from.
    previous_frame: Option<u64>,
    rng: SplitMix64,
    counts: WorkCounts,
    frame: u64,
}

impl Spray {
    /// A spray level counts the particles of the pool.
    pub const UNIT: &'static str = "particles";

    /// An empty pool of `spec.amount` particles and the buffers for `spec.grid`'s meshes.
    pub fn new(spec: &WorkSpec, p: SprayParams) -> Spray {
        let dt = spec.time_step;
        let vertices = spec.grid.vertices();
        Spray {
            params: p,
            pool: Pool::new(spec.amount as usize),
            step: Step {
                dt,
                gravity_dt: GRAVITY * dt,
                keep: (-(p.drag as f32) * dt).exp(),
            },
            spacing: spec.spacing,
            time_step: dt,
            candidates: Vec::with_capacity(vertices),
            previous: Vec::with_capacity(vertices),
            previous_at: Vec::with_capacity(vertices),
            previous_frame: None,
            rng: SplitMix64(p.seed),
            counts: WorkCounts::new(&COUNTS, &[0; 3]),
            frame: 0,
        }
    }

    /// The particles.
    pub fn pool(&self) -> &Pool {
        &self.pool
    }

    /// The mesh frame the last run consumed.
    pub fn surface_frame(&self) -> Option<u64> {
        self.previous_frame
    }

    /// Uniform in [−0.5, 0.5).
    fn jitter(&mut self) -> f32 {
        (self.rng.next_u64() >> 40) as f32 / (1u64 << 24) as f32 - 0.5
    }

    /// Where vertex `v` moved since the last consumed mesh, per second: zero when it was not
    /// folding then (its position was not kept) or no time passed.
    fn surface_velocity(&self, v: u32, at: [f32; 3], k: u64) -> [f32; 3] {
        let Some(seconds) = self
            .previous_frame
            .filter(|&p| k > p)
            .map(|p| (k - p) as f32 * self.time_step)
            .filter(|&s| s > 0.0)
        else {
            return [0.0; 3];
        };
        match self.previous.binary_search(&v) {
            Ok(i) => {
                let was = self.previous_at[i];
                std::array::from_fn(|c| (at[c] - was[c]) / seconds)
            }
            Err(_) => [0.0; 3],
        }
    }

    /// Emits up to the cap (and the free slots) at this frame's folding vertices, from a random
    /// one on in index order, wrapping round (a vertex emits again when the cap exceeds them).
    fn emit(&mut self, mesh: &Mesh, k: u64) -> u32 {
        let threshold = self.params.threshold as f32;
        self.candidates.clear();
        self.candidates.extend(
            mesh.fold
                .iter()
                .enumerate()
                .filter(|(_, &j)| j < threshold)
                .map(|(v, _)| v as u32),
        );
        let count = self.candidates.len();
        let budget = (self.params.emission_cap as usize).min(self.pool.free.len());
        if count == 0 {
            return 0;
        }
        let speed = self.params.speed as f32;
        let start = self.rng.below(count);
        for e in 0..budget {
            let v = self.candidates[(start + e) % count];
            let i = v as usize;
            let at = [mesh.x[i], mesh.y[i], mesh.z[i]];
            let surface = self.surface_velocity(v, at, k);
            // Along the fold direction and as far up (45°), each component jittered by ±10 %
            // of the speed; born within half a cell of the vertex.
            let launch = [mesh.fold_dx[i], mesh.fold_dy[i], 1.0];
            let v3: [f32; 3] = std::array::from_fn(|c| {
                surface[c]
                    + speed * (launch[c] * std::f32::consts::FRAC_1_SQRT_2 + 0.2 * self.jitter())
            });
            let p = [
                at[0] + self.spacing * self.jitter(),
                at[1] + self.spacing * self.jitter(),
                at[2],
            ];
            self.pool.spawn(p, v3);
        }
        budget as u32
    }

    /// Keeps this frame's folding vertices and their positions for the next frame's surface
    /// velocity.
    fn remember(&mut self, mesh: &Mesh, k: u64) {
        std::mem::swap(&mut self.previous, &mut self.candidates);
        self.previous_at.clear();
        self.previous_at.extend(
            self.previous
                .iter()
                .map(|&v| [mesh.x[v as usize], mesh.y[v as usize], mesh.z[v as usize]]),
        );
        self.previous_frame = Some(k);
    }

    /// One frame on `mesh` (consumed for frame `k`), the integration through the SIMD loop or,
    /// with `plain`, the plain one.
    fn frame(
        &mut self,
        k: u64,
        mesh: &Mesh,
        stop: Option<&AtomicBool>,
        plain: bool,
    ) -> Result<(), Stopped> {
        assert!(mesh.has_fold(), "spray reads the fold of an fft mesh");
        let capacity = self.pool.capacity();
        let stopped = || stop.is_some_and(|s| s.load(Ordering::Relaxed));
        for start in (0..capacity).step_by(CHUNK) {
            if stopped() {
                return Err(Stopped);
            }
            let range = start..(start + CHUNK).min(capacity);
            if plain {
                self.pool.integrate_plain(self.step, range);
            } else {
                self.pool.integrate(self.step, range);
            }
        }
        let surface = Surface::of(mesh, self.spacing);
        let lifetime = self.params.lifetime as f32;
        let mut recycled = 0;
        for start in (0..capacity).step_by(CHUNK) {
            if stopped() {
                return Err(Stopped);
            }
            recycled += self
                .pool
                .kill(&surface, lifetime, start..(start + CHUNK).min(capacity));
        }
        let emitted = self.emit(mesh, k);
        self.remember(mesh, k);
        self.counts = WorkCounts::new(
            &COUNTS,
            &[self.pool.live() as u64, emitted.into(), recycled.into()],
        );
        self.frame = k;
        Ok(())
    }

    /// One frame as [`MeshWork::run`] does it, with the plain integration loop: the reference the
    /// SIMD loop is checked against.
    pub fn run_plain(&mut self, k: u64, mesh: &Mesh) {
        self.frame(k, mesh, None, true)
            .expect("no stop flag, no stop");
    }
}

/// What spray counts each frame: particles live after it, born in it, and killed in it (their
/// slots freed for reuse).
pub const COUNTS: [&str; 3] = ["live", "emitted", "recycled"];

impl WorkOutput for Spray {
    fn digest(&self) -> u64 {
        let p = &self.pool;
        let bits = p
            .floats()
            .into_iter()
            .flat_map(|a| a.iter().map(|v| u64::from(v.to_bits())))
            .chain(p.alive.iter().map(|&a| u64::from(a)))
            .chain(p.free.iter().map(|&f| u64::from(f)));
        super::fold_digest(self.frame ^ self.rng.0, bits)
    }

    fn counts(&self) -> Option<WorkCounts> {
        Some(self.counts)
    }
}

impl MeshWork for Spray {
    fn run(&mut self, k: u64, mesh: &Mesh, stop: Option<&AtomicBool>) -> Result<(), Stopped> {
        self.frame(k, mesh, stop, false)
    }
}

#[cfg(test)]
mod tests;
