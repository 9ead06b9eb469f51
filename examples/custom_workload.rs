//! A workload kind defined outside the crate: buoyancy, the CPU work games do with an ocean.
//! N floating bodies each sample the consumed surface under their hull points, feel the
//! buoyancy of the part under water and the weight of the rest, and move for one frame.
//!
//! `cargo run --release --example custom_workload [OUT]` registers the kind, runs a small sweep
//! of it through the library (40×40 and 128×128, 0 and 20,000 bodies, UP and DP, the atomic
//! hand-off) and writes the results folder, by default `results/custom-workload-<UTC>`. The
//! stock binary, which knows nothing of buoyancy, then reads it:
//! `oceanbench report OUT`, `oceanbench chart OUT`, `oceanbench compare OUT OUT`.

use oceanbench::config::{InputError, SweepConfig};
use oceanbench::ocean::Mesh;
use oceanbench::workload::{
    self, fold_digest, whole_amount, Kind, MeshWork, Stopped, Work, WorkCounts, WorkOutput,
    WorkSpec,
};
use serde::{Deserialize, Serialize};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};

/// Most bodies a level may float.
const MAX_BODIES: u64 = 1_000_000;

/// The kind's config object, the key `buoyancy` of a config.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
struct BuoyancyParams {
    /// Points under each hull where the surface is sampled, 1 to 64.
    hull_points: u32,
    /// Half the hull's width, in grid cells.
    hull_radius: f32,
    /// Where the bodies start.
    seed: u64,
}

impl Default for BuoyancyParams {
    fn default() -> Self {
        BuoyancyParams {
            hull_points: 8,
            hull_radius: 1.5,
            seed: 7,
        }
    }
}

/// The descriptor: everything the harness needs to know of the kind.
struct Buoyancy;

impl Kind for Buoyancy {
    type Params = BuoyancyParams;

    fn name(&self) -> &'static str {
        "buoyancy"
    }

    fn doc(&self) -> &'static str {
        "Floating bodies sample the consumed surface under their hulls and move for a frame."
    }

    fn unit(&self) -> &'static str {
        "bodies"
    }

    fn check_params(&self, p: &BuoyancyParams) -> Result<(), InputError> {
        if !(1..=64).contains(&p.hull_points) {
            return Err(InputError(format!(
                "buoyancy.hull_points: must be 1 to 64, got {}",
                p.hull_points
            )));
        }
        if !(p.hull_radius.is_finite() && p.hull_radius > 0.0 && p.hull_radius <= 16.0) {
            return Err(InputError(format!(
                "buoyancy.hull_radius: must be above 0 and at most 16 (grid cells), got {}",
                p.hull_radius
            )));
        }
        Ok(())
    }

    fn check_amount(&self, field: &str, amount: f64) -> Result<(), InputError> {
        match whole_amount(field, amount)? {
            n if n <= MAX_BODIES => Ok(()),
            n => Err(InputError(format!(
                "{field}: must be 0 to {MAX_BODIES} bodies, got {n}"
            ))),
        }
    }

    fn no_time_levels(&self) -> Option<&'static str> {
        Some("buoyancy has no per-body calibration")
    }

    fn build(&self, spec: &WorkSpec, params: &BuoyancyParams) -> Work {
        Work::on_mesh(Floating::new(spec, params))
    }
}

/// One body: where it floats on the grid (in cells), its height and vertical speed.
#[derive(Clone, Copy)]
struct Body {
    u: f32,
    v: f32,
    z: f32,
    speed: f32,
}

/// The bodies of one loop and the hull's sample points around a body's centre.
struct Floating {
    bodies: Vec<Body>,
    hull: Vec<(f32, f32)>,
    dt: f32,
    counts: WorkCounts,
}

/// What the bodies count each frame: those more than half under the surface, and those whose
/// hull no wave touched (airborne on a crest's far side).
const COUNTS: [&str; 2] = ["swamped", "airborne"];

impl Floating {
    fn new(spec: &WorkSpec, p: &BuoyancyParams) -> Floating {
        let edge = (spec.grid.n - 1) as f32;
        let mut state = p.seed | 1;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        let bodies = (0..spec.amount)
            .map(|_| Body {
                u: next() * edge,
                v: next() * edge,
                z: 0.0,
                speed: 0.0,
            })
            .collect();
        let hull = (0..p.hull_points)
            .map(|i| {
                let a = i as f32 / p.hull_points as f32 * std::f32::consts::TAU;
                (p.hull_radius * a.cos(), p.hull_radius * a.sin())
            })
            .collect();
        Floating {
            bodies,
            hull,
            dt: spec.time_step,
            counts: WorkCounts::new(&COUNTS, &[0, 0]),
        }
    }
}

/// The surface height at grid point (u, v), bilinear between the four vertices around it
/// (clamped to the patch).
fn height(mesh: &Mesh, u: f32, v: f32) -> f32 {
    let n = mesh.grid.n;
    let edge = (n - 1) as f32;
    let (u, v) = (u.clamp(0.0, edge), v.clamp(0.0, edge));
    let (i, j) = ((u as usize).min(n - 2), (v as usize).min(n - 2));
    let (fu, fv) = (u - i as f32, v - j as f32);
    let z = |i: usize, j: usize| mesh.z[j * n + i];
    let bottom = z(i, j) * (1.0 - fu) + z(i + 1, j) * fu;
    let top = z(i, j + 1) * (1.0 - fu) + z(i + 1, j + 1) * fu;
    bottom * (1.0 - fv) + top * fv
}

impl WorkOutput for Floating {
    fn digest(&self) -> u64 {
        fold_digest(1, self.bodies.iter().map(|b| u64::from(b.z.to_bits())))
    }

    fn counts(&self) -> Option<WorkCounts> {
        Some(self.counts)
    }
}

impl MeshWork for Floating {
    fn run(&mut self, _k: u64, mesh: &Mesh, stop: Option<&AtomicBool>) -> Result<(), Stopped> {
        let share = 1.0 / self.hull.len() as f32;
        let (mut swamped, mut airborne) = (0, 0);
        for (b, body) in self.bodies.iter_mut().enumerate() {
            if b % 4096 == 0 && stop.is_some_and(|s| s.load(Ordering::Relaxed)) {
                return Err(Stopped);
            }
            let submerged: f32 = self
                .hull
                .iter()
                .map(|&(du, dv)| (height(mesh, body.u + du, body.v + dv) - body.z).clamp(0.0, 1.0))
                .sum::<f32>()
                * share;
            swamped += u64::from(submerged > 0.5);
            airborne += u64::from(submerged == 0.0);
            // Half submerged floats still: buoyancy 2g at full depth against g of weight,
            // with some damping.
            let accel = 9.81 * (2.0 * submerged - 1.0) - 0.8 * body.speed;
            body.speed += accel * self.dt;
            body.z += body.speed * self.dt;
        }
        self.counts = WorkCounts::new(&COUNTS, &[swamped, airborne]);
        Ok(())
    }
}

fn main() {
    if let Err(e) = run() {
        eprintln!("custom_workload: {e}");
        std::process::exit(2);
    }
}

fn run() -> Result<(), Box<dyn std::error::Error>> {
    workload::register(Buoyancy)?;
    let config = SweepConfig::from_json(
        r#"{
            "name": "custom-workload",
            "description": "buoyancy, a workload kind registered by examples/custom_workload.rs",
            "sizes": [40, 128],
            "workload_kind": ["buoyancy"],
            "workload_levels": [{"bodies": 0}, {"bodies": 20000}],
            "workloads": [0, 1],
            "modes": ["up", "dp"],
            "sync": ["atomic"],
            "trials": 3,
            "min_seconds": 0.3,
            "buoyancy": {"hull_points": 8}
        }"#,
    )?;
    let out = match std::env::args().nth(1) {
        Some(dir) => PathBuf::from(dir),
        None => {
            let stamp: String = oceanbench::sweep::utc_now()
                .chars()
                .filter(char::is_ascii_alphanumeric)
                .collect();
            PathBuf::from(format!("results/custom-workload-{stamp}"))
        }
    };
    std::fs::create_dir_all(&out)?;
    let results = oceanbench::sweep::Sweep::prepare(config)?.run(&mut ());
    oceanbench::report::write_all(&out, &results)?;
    print!("{}", oceanbench::report::markdown::to_string(&results));
    println!("\nwritten: {}", out.display());
    Ok(())
}
