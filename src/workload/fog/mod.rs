//! `fog`: the CPU Perlin fog of Intel's ocean-fog article as main-thread work. Every frame it
//! rebuilds an N³ gradient-noise volume over several octaves ([`noise`]), blurs it with the
//! article's separable Pascal's-triangle filter with wrap-around ([`blur`]), and computes the fog
//! coefficient of every vertex of the consumed mesh ([`coefficient`]). The article builds the
//! volume once; rebuilding it each frame makes it the per-frame load animated fog would be, and a
//! memory-heavy one where the synthetic workload is pure arithmetic. A level is the volume's
//! edge N (`{"volume": N}`); see docs/fog.md.

pub mod blur;
pub mod calibrate;
pub mod coefficient;
#[cfg(target_arch = "x86_64")]
mod gather;
pub mod noise;

use super::{
    whole_amount, Kind, LevelAt, MeshWork, Stopped, Work, WorkOutput, WorkSpec, WorkloadKind,
};
use crate::input::InputError;
use crate::machine::available_memory;
use crate::ocean::Mesh;
use crate::stats;
use coefficient::View;
use serde::{Deserialize, Serialize};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// Largest volume edge a level may ask for (512³ voxels, 512 MiB a buffer).
pub const MAX_VOLUME: u64 = 512;

/// Most octaves the noise may sum.
pub const MAX_OCTAVES: u32 = 8;

/// Allowed strides, in voxels per lattice cell.
pub const STRIDE: (f64, f64) = (0.25, 4096.0);

/// Narrowest blur.
pub const MIN_BLUR: u32 = 3;

/// Widest blur.
const MAX_BLUR: u32 = blur::MAX_WIDTH as u32;

/// Voxels the noise moves per frame along x, y and z: the fog drifting through the volume, so
/// that every frame's volume differs.
const DRIFT: [f64; 3] = [0.5, 0.25, 0.125];

/// Vertices given fog between two looks at the stop flag.
const CHUNK: usize = 1 << 14;

/// The fog's parameters (config key `fog`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FogParams {
    /// Octaves of noise summed into the volume, 1 to 8.
    pub octaves: u32,
    /// Each octave's lattice spacing in voxels (default 64, 32, 16, ...: halving per octave).
    pub strides: Option<Vec<f64>>,
    /// Each octave's weight (default proportional to its stride: the longer the stride, the
    /// heavier the octave, as the article has it). Normalised to sum to 1.
    pub weights: Option<Vec<f32>>,
    /// Fog density ρ, per patch width.
    pub density: f32,
    /// Taps of the blur along each axis: odd, 3 to 31.
    pub blur_width: u32,
    /// Seed of octave 0's permutation table; octave o uses seed + o (as the `noise` crate's
    /// fractals do).
    pub seed: u32,
}

impl Default for FogParams {
    fn default() -> Self {
        FogParams {
            octaves: 4,
            strides: None,
            weights: None,
            density: 4.0,
            blur_width: 5,
            seed: 0,
        }
    }
}

impl FogParams {
    /// Checks every field; the message names it and what is allowed.
    pub fn validate(&self) -> Result<(), InputError> {
        if !(1..=MAX_OCTAVES).contains(&self.octaves) {
            return Err(InputError(format!(
                "fog.octaves: must be 1 to {MAX_OCTAVES}, got {}",
                self.octaves
            )));
        }
        let count = |field: &str, len: usize| {
            if len == self.octaves as usize {
                Ok(())
            } else {
                Err(InputError(format!(
                    "fog.{field}: give one per octave ({} octaves), got {len}",
                    self.octaves
                )))
            }
        };
        if let Some(strides) = &self.strides {
            count("strides", strides.len())?;
            for (i, &s) in strides.iter().enumerate() {
                if !(s.is_finite() && (STRIDE.0..=STRIDE.1).contains(&s)) {
                    return Err(InputError(format!(
                        "fog.strides[{i}]: must be {} to {} voxels, got {s}",
                        STRIDE.0, STRIDE.1
                    )));
                }
            }
        }
        if let Some(weights) = &self.weights {
            count("weights", weights.len())?;
            for (i, &w) in weights.iter().enumerate() {
                if !(w.is_finite() && w >= 0.0) {
                    return Err(InputError(format!(
                        "fog.weights[{i}]: must be a finite number >= 0, got {w}"
                    )));
                }
            }
            if weights.iter().sum::<f32>() <= 0.0 {
                return Err(InputError(
                    "fog.weights: at least one must be above 0".into(),
                ));
            }
        }
        if !(self.density.is_finite() && self.density >= 0.0) {
            return Err(InputError(format!(
                "fog.density: must be a finite number >= 0, got {}",
                self.density
            )));
        }
        if !(MIN_BLUR..=MAX_BLUR).contains(&self.blur_width) || self.blur_width.is_multiple_of(2) {
            return Err(InputError(format!(
                "fog.blur_width: must be odd, {MIN_BLUR} to {MAX_BLUR}, got {}",
                self.blur_width
            )));
        }
        Ok(())
    }

    /// The octaves as the noise runs them: strides, weights and permutation tables.
    pub fn octaves(&self) -> Vec<noise::Octave> {
        (0..self.octaves as usize)
            .map(|o| {
                let stride = self
                    .strides
                    .as_ref()
                    .map_or(64.0 / f64::from(1u32 << o), |s| s[o]);
                noise::Octave {
                    stride,
                    weight: self
                        .weights
                        .as_ref()
                        .map_or(1.0 / (1u32 << o) as f32, |w| w[o]),
                    table: noise::permutation(self.seed.wrapping_add(o as u32)),
                }
            })
            .collect()
    }
}

/// Bytes the fog of volume edge `n` allocates: the volume and the blur's second buffer.
pub fn volume_bytes(n: u64) -> u64 {
    2 * n.pow(3) * std::mem::size_of::<f32>() as u64
}

/// Refuses a volume edge above [`MAX_VOLUME`] or one whose buffers would not fit in
/// `available` bytes of memory, naming `field` and how much it would need.
pub fn check_volume(field: &str, n: u64, available: Option<u64>) -> Result<(), InputError> {
    let need = || volume_bytes(n) >> 20;
    if n > MAX_VOLUME {
        return Err(InputError(format!(
            "{field}: must be 0 to {MAX_VOLUME} voxels per edge, got {n} (a {n}³ fog would need \
             {} MiB)",
            need()
        )));
    }
    match available {
        Some(avail) if volume_bytes(n) > avail => Err(InputError(format!(
            "{field}: a {n}³ fog volume needs {} MiB (two {n}³ f32 buffers) but only {} MiB is \
             available; allowed 0 to {MAX_VOLUME}",
            need(),
            avail >> 20
        ))),
        _ => Ok(()),
    }
}

/// What the fog recorded of its work over a loop: the volume, the octaves, and the median
/// time per frame of each part of the pass.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FogRecord {
    /// Volume edge N (N³ voxels).
    pub volume: u64,
    /// Octaves summed.
    pub octaves: u32,
    /// Median ms per frame rebuilding the noise volume.
    pub noise_ms: f64,
    /// Median ms per frame blurring it.
    pub blur_ms: f64,
    /// Median ms per frame computing the vertices' coefficients.
    pub coefficient_ms: f64,
}

impl FogRecord {
    /// The median of each time over several loops' records (the trials of a cell).
    pub fn median(records: &[FogRecord]) -> Option<FogRecord> {
        let first = records.first()?;
        let m =
            |f: fn(&FogRecord) -> f64| stats::median(&records.iter().map(f).collect::<Vec<_>>());
        Some(FogRecord {
            noise_ms: m(|r| r.noise_ms),
            blur_ms: m(|r| r.blur_ms),
            coefficient_ms: m(|r| r.coefficient_ms),
            ..first.clone()
        })
    }

    /// The record as results keep it, under the field names.
    pub fn keyed(&self) -> super::WorkRecord {
        super::WorkRecord::default()
            .with("volume", self.volume as f64)
            .with("octaves", f64::from(self.octaves))
            .with("noise_ms", self.noise_ms)
            .with("blur_ms", self.blur_ms)
            .with("coefficient_ms", self.coefficient_ms)
    }
}

/// The kind's name, and its config key.
pub(in crate::workload) const NAME: &str = "fog";

impl WorkloadKind {
    /// The ocean-fog article's CPU fog: a noise volume rebuilt and blurred each frame.
    pub const FOG: WorkloadKind = WorkloadKind(NAME);
}

/// The descriptor of the fog workload.
pub struct FogKind;

impl Kind for FogKind {
    type Params = FogParams;

    fn name(&self) -> &'static str {
        NAME
    }

    fn doc(&self) -> &'static str {
        "The ocean-fog article's CPU fog: rebuilds and blurs an N³ noise volume, then gives every \
         vertex of the consumed mesh its fog coefficient."
    }

    fn unit(&self) -> &'static str {
        Fog::UNIT
    }

    fn amount_text(&self, amount: &str) -> String {
        format!("{amount}³ voxels")
    }

    fn check_params(&self, params: &FogParams) -> Result<(), InputError> {
        params.validate()
    }

    fn check_amount(&self, field: &str, amount: f64) -> Result<(), InputError> {
        check_volume(field, whole_amount(field, amount)?, available_memory())
    }

    /// A level in volumes is timed by its own pass; µs (or a step fraction's µs) come to the
    /// edge whose pass takes that long, at most [`MAX_VOLUME`] (the start refuses levels beyond).
    /// Below the smallest pass (a 1³ volume and the mesh's vertices), the row runs that pass and
    /// records its µs, not the level's: the vertex coefficients alone can outlast the level.
    fn row_level(&self, params: &FogParams, at: &LevelAt, micros: f64, amount: u64) -> (f64, u64) {
        if at.given.is_some() {
            let cost = calibrate::measure(params, at.grid, at.camera, amount);
            return (if amount == 0 { 0.0 } else { cost.micros() }, amount);
        }
        match calibrate::volume_for(params, at.grid, at.camera, micros) {
            Ok((1, Some(cost))) if cost.micros() > micros => (cost.micros(), 1),
            Ok((edge, _)) => (micros, edge),
            Err(_) => (micros, MAX_VOLUME),
        }
    }

    /// A volume level's µs are its pass's; a level in µs the fog cannot reach within
    /// [`MAX_VOLUME`] is refused.
    fn start_level(&self, params: &FogParams, at: &LevelAt, micros: f64) -> Result<f64, String> {
        let n = at.grid.n;
        match at.given {
            Some(0) => Ok(micros),
            Some(volume) => Ok(calibrate::measure(params, at.grid, at.camera, volume).micros()),
            None => match calibrate::volume_for(params, at.grid, at.camera, micros) {
                Ok(_) => Ok(micros),
                Err(edge) => Err(format!(
                    "{micros:.0} µs of fog on the {n}×{n} mesh needs a volume of about {edge}³ \
                     on this machine; allowed up to {MAX_VOLUME}³ (fewer µs, or more octaves)"
                )),
            },
        }
    }

    fn build(&self, spec: &WorkSpec, params: &FogParams) -> Work {
        Work::on_mesh(Fog::new(spec, params))
    }
}

/// The fog of one loop: its octaves, its buffers and the camera it looks from.
pub struct Fog {
    edge: usize,
    octaves: Vec<noise::Octave>,
    weights: Vec<f32>,
    view: View,
    volume: Vec<f32>,
    scratch: Vec<f32>,
    coefficients: Vec<f32>,
    /// ms of noise, blur and coefficients, per frame run.
    times: Vec<[f64; 3]>,
    frame: u64,
}

impl Fog {
    /// A fog level is the volume's edge.
    pub const UNIT: &'static str = "volume";

    /// The fog of `spec`: a `spec.amount`³ volume (none at 0), seen from the camera.
    pub fn new(spec: &WorkSpec, params: &FogParams) -> Fog {
        let edge = spec.amount as usize;
        let grid = spec.grid;
        let voxels = edge.pow(3);
        Fog {
            edge,
            octaves: params.octaves(),
            weights: blur::weights(params.blur_width as usize),
            view: View {
                eye: spec.camera.eye(grid),
                width: ((grid.n - 1) as f32 * grid.spacing).max(grid.spacing),
                density: params.density,
            },
            volume: vec![0.0; voxels],
            scratch: vec![0.0; voxels],
            coefficients: vec![1.0; if edge > 0 { grid.n * grid.n } else { 0 }],
            times: Vec::new(),
            frame: 0,
        }
    }

    /// The coefficient of every vertex from the last frame (empty at volume 0).
    pub fn coefficients(&self) -> &[f32] {
        &self.coefficients
    }

    /// The blurred volume of the last frame.
    pub fn volume(&self) -> &[f32] {
        &self.volume
    }

    /// The noise's sample positions in frame `k`.
    pub fn frame(k: u64) -> noise::Frame {
        noise::Frame {
            offset: DRIFT.map(|d| d * k as f64),
        }
    }
}

impl WorkOutput for Fog {
    fn digest(&self) -> u64 {
        super::fold_digest(
            self.frame,
            self.coefficients.iter().map(|v| u64::from(v.to_bits())),
        )
    }

    fn record(&self) -> Option<super::WorkRecord> {
        self.pass_record().map(|r| r.keyed())
    }
}

impl Fog {
    /// The loop's pass so far: the median time of each part per frame; `None` before a frame.
    pub fn pass_record(&self) -> Option<FogRecord> {
        let median = |p: usize| stats::median(&self.times.iter().map(|t| t[p]).collect::<Vec<_>>());
        (!self.times.is_empty()).then(|| FogRecord {
            volume: self.edge as u64,
            octaves: self.octaves.len() as u32,
            noise_ms: median(0),
            blur_ms: median(1),
            coefficient_ms: median(2),
        })
    }
}

impl MeshWork for Fog {
    fn run(&mut self, k: u64, mesh: &Mesh, stop: Option<&AtomicBool>) -> Result<(), Stopped> {
        self.frame = k;
        if self.edge == 0 {
            return Ok(());
        }
        let n = self.edge;
        let started = Instant::now();
        if !noise::fill(&mut self.volume, n, &self.octaves, &Fog::frame(k), stop) {
            return Err(Stopped);
        }
        let noised = Instant::now();
        if !blur::blur(&mut self.volume, &mut self.scratch, n, &self.weights, stop) {
            return Err(Stopped);
        }
        let blurred = Instant::now();
        let vertices = self.coefficients.len();
        for start in (0..vertices).step_by(CHUNK) {
            if stop.is_some_and(|s| s.load(Ordering::Relaxed)) {
                return Err(Stopped);
            }
            let range = start..(start + CHUNK).min(vertices);
            coefficient::fill(
                mesh,
                range.clone(),
                &self.volume,
                n,
                &self.view,
                &mut self.coefficients[range],
            );
        }
        let done = Instant::now();
        let ms = |a: Instant, b: Instant| (b - a).as_secs_f64() * 1e3;
        self.times
            .push([ms(started, noised), ms(noised, blurred), ms(blurred, done)]);
        Ok(())
    }
}

#[cfg(test)]
mod tests;
