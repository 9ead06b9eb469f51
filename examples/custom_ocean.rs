//! An ocean model defined outside the crate: one Gerstner wave (a trochoid, the building block of
//! most game oceans), with analytic normals, that several helpers can split by rows.
//!
//! `cargo run --release --example custom_ocean [OUT]` registers the model, runs a small sweep of
//! it through the library (40×40 and 128×128, workloads 0 and 2, serial, UP and DP, the atomic
//! hand-off) and writes the results folder, by default `results/custom-ocean-<UTC>`. The stock
//! binary, which knows nothing of Gerstner waves, then reads it: `oceanbench report OUT`,
//! `oceanbench chart OUT`, `oceanbench compare OUT OUT`.

use oceanbench::config::{InputError, SweepConfig};
use oceanbench::ocean::{
    self, Grid, Kernel, Mesh, MeshRows, Model, NormalMethod, OceanParams, Stepper,
};
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// Gravity, m/s².
const G: f32 = 9.81;

/// The model's config object, the key `gerstner` of a config.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
struct GerstnerParams {
    /// Crest height above the mean, in grid units.
    amplitude: f32,
    /// Crest to crest, in grid units.
    wavelength: f32,
    /// Direction of travel, in degrees from +x.
    direction_degrees: f32,
    /// 0: a sine; 1: sharp crests (the trochoid's loop begins above 1).
    steepness: f32,
}

impl Default for GerstnerParams {
    fn default() -> Self {
        GerstnerParams {
            amplitude: 0.8,
            wavelength: 12.0,
            direction_degrees: 30.0,
            steepness: 0.7,
        }
    }
}

/// The model: stateless; its per-run state is [`GerstnerStep`].
struct Gerstner;

impl Model for Gerstner {
    fn name(&self) -> &'static str {
        "gerstner"
    }

    fn doc(&self) -> &'static str {
        "One Gerstner wave: crests sharpened by moving vertices towards them."
    }

    fn default_params(&self) -> Option<serde_json::Value> {
        serde_json::to_value(GerstnerParams::default()).ok()
    }

    fn parse_params(
        &self,
        raw: &serde_json::Value,
        params: &mut OceanParams,
    ) -> Result<(), InputError> {
        let p: GerstnerParams = params.parse("gerstner", raw)?;
        if !(p.wavelength.is_finite() && p.wavelength > 0.0) {
            return Err(InputError(format!(
                "gerstner.wavelength: must be a finite number above 0, got {}",
                p.wavelength
            )));
        }
        if !(0.0..=1.0).contains(&p.steepness) {
            return Err(InputError(format!(
                "gerstner.steepness: must be 0 to 1 (above 1 the surface loops), got {}",
                p.steepness
            )));
        }
        Ok(())
    }

    fn kernels(&self) -> &'static [Kernel] {
        &[Kernel::Reference]
    }

    fn normals(&self) -> &'static [NormalMethod] {
        &[NormalMethod::Analytic]
    }

    /// Every vertex is a function of its own rest position and t.
    fn splits_into_rows(&self, _: NormalMethod) -> Result<(), InputError> {
        Ok(())
    }

    fn check(&self, _: usize, _: NormalMethod) -> Result<(), InputError> {
        Ok(())
    }

    fn yardstick(&self) -> (Kernel, NormalMethod) {
        (Kernel::Reference, NormalMethod::Analytic)
    }

    fn prepare(
        &self,
        grid: Grid,
        params: &OceanParams,
        _: NormalMethod,
        _: Kernel,
    ) -> Result<Box<dyn Stepper>, InputError> {
        let p = params.get::<GerstnerParams>();
        let k = std::f32::consts::TAU / p.wavelength;
        let (sin, cos) = p.direction_degrees.to_radians().sin_cos();
        Ok(Box::new(GerstnerStep {
            spacing: grid.spacing,
            amplitude: p.amplitude,
            k,
            omega: (G * k).sqrt(),
            direction: [cos, sin],
            // Q/(k·A) is the textbook's steepness: 1 makes the crests cusps.
            q: p.steepness / (k * p.amplitude).max(f32::EPSILON),
        }))
    }
}

/// One run's wave: its constants, from which every vertex follows.
#[derive(Clone, Debug)]
struct GerstnerStep {
    spacing: f32,
    amplitude: f32,
    k: f32,
    omega: f32,
    direction: [f32; 2],
    q: f32,
}

impl Stepper for GerstnerStep {
    fn step(&mut self, t: f32, mesh: &mut Mesh) {
        let n = mesh.grid.n;
        self.step_rows(t, mesh.rows_mut(0..n));
    }

    fn step_rows(&mut self, t: f32, rows: MeshRows<'_>) {
        let n = rows.grid.n;
        let [dx, dy] = self.direction;
        let (a, k, q) = (self.amplitude, self.k, self.q);
        for r in 0..rows.rows() {
            let y0 = (rows.first_row + r) as f32 * self.spacing;
            for j in 0..n {
                let v = r * n + j;
                let x0 = j as f32 * self.spacing;
                let (s, c) = (k * (dx * x0 + dy * y0) - self.omega * t).sin_cos();
                rows.x[v] = x0 + q * a * dx * c;
                rows.y[v] = y0 + q * a * dy * c;
                rows.z[v] = a * s;
                // GPU Gems 1, ch. 1, equation 12.
                let wa = k * a;
                let (nx, ny, nz) = (-dx * wa * c, -dy * wa * c, 1.0 - q * wa * s);
                let len = (nx * nx + ny * ny + nz * nz).sqrt();
                (rows.nx[v], rows.ny[v], rows.nz[v]) = (nx / len, ny / len, nz / len);
            }
        }
    }

    fn boxed_clone(&self) -> Box<dyn Stepper> {
        Box::new(self.clone())
    }
}

fn main() {
    if let Err(e) = run() {
        eprintln!("custom_ocean: {e}");
        std::process::exit(2);
    }
}

fn run() -> Result<(), Box<dyn std::error::Error>> {
    ocean::register(Gerstner)?;
    let config = SweepConfig::from_json(
        r#"{
            "name": "custom-ocean",
            "description": "one Gerstner wave, an ocean model registered by examples/custom_ocean.rs",
            "sizes": [40, 128],
            "ocean": ["gerstner"],
            "normals": ["analytic"],
            "workloads": [0, 2],
            "modes": ["serial", "up", "dp"],
            "sync": ["atomic"],
            "trials": 3,
            "min_seconds": 0.3,
            "gerstner": {"wavelength": 16.0}
        }"#,
    )?;
    let out = match std::env::args().nth(1) {
        Some(dir) => PathBuf::from(dir),
        None => {
            let stamp: String = oceanbench::sweep::utc_now()
                .chars()
                .filter(char::is_ascii_alphanumeric)
                .collect();
            PathBuf::from(format!("results/custom-ocean-{stamp}"))
        }
    };
    std::fs::create_dir_all(&out)?;
    let results = oceanbench::sweep::Sweep::prepare(config)?.run(&mut ());
    oceanbench::report::write_all(&out, &results)?;
    print!("{}", oceanbench::report::markdown::to_string(&results));
    println!("\nwritten: {}", out.display());
    Ok(())
}
