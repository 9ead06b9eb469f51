//! The fog's own calibration: what a volume edge costs on this machine, and which edge a level
//! in microseconds comes to. A pass is noise and blur over N³ voxels plus the coefficients of a
//! mesh's vertices, and its time per voxel changes with N as the volume outgrows the caches, so
//! the edge for a target is found by measuring: the time per voxel at a small probe volume
//! predicts an edge, the pass is measured there, and one secant step on N³ corrects it.

use super::{Fog, FogParams, FogRecord, MAX_VOLUME};
use crate::camera::Camera;
use crate::ocean::{Grid, Mesh};
use crate::workload::{MeshWork, WorkSpec, WorkloadKind};

/// The probe volume's edge: small enough to take well under a millisecond.
const PROBE: u64 = 32;

/// Frames timed per measurement (the median is kept), after one untimed frame.
const FRAMES: u64 = 5;

/// What one fog pass costs at one volume edge on one mesh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cost {
    /// Volume edge N.
    pub volume: u64,
    /// Median µs per frame of noise and blur (the part that grows with N³).
    pub volume_micros: f64,
    /// Median µs per frame of the vertices' coefficients (the part that does not).
    pub vertex_micros: f64,
}

impl Cost {
    /// The whole pass, in µs.
    pub fn micros(&self) -> f64 {
        self.volume_micros + self.vertex_micros
    }

    /// ns per voxel of the noise and blur.
    pub fn ns_per_voxel(&self) -> f64 {
        self.volume_micros * 1e3 / (self.volume as f64).powi(3)
    }
}

/// Measures the fog pass at `volume` on a still `grid` seen by `camera`, on the calling thread.
pub fn measure(params: &FogParams, grid: Grid, camera: Camera, volume: u64) -> Cost {
    let spec = WorkSpec {
        kind: WorkloadKind::FOG,
        amount: volume,
        grid,
        camera,
        spacing: grid.spacing,
        time_step: 1.0 / 60.0,
    };
    let mesh = Mesh::new(grid);
    let mut fog = Fog::new(&spec, params);
    let mut records = Vec::new();
    for k in 0..=FRAMES {
        fog.run(k, &mesh, None).expect("no stop flag was given");
        if k > 0 {
            if let Some(r) = fog.pass_record() {
                records.push(r);
            }
            fog.times.clear();
        }
    }
    let r = FogRecord::median(&records).unwrap_or(FogRecord {
        volume,
        octaves: params.octaves,
        noise_ms: 0.0,
        blur_ms: 0.0,
        coefficient_ms: 0.0,
    });
    Cost {
        volume,
        volume_micros: (r.noise_ms + r.blur_ms) * 1e3,
        vertex_micros: r.coefficient_ms * 1e3,
    }
}

/// The edge whose N³ voxels take `voxel_micros` at `cost`'s time per voxel (at least 1).
fn edge_for(voxel_micros: f64, cost: &Cost) -> f64 {
    (voxel_micros.max(0.0) * 1e3 / cost.ns_per_voxel().max(1e-6))
        .cbrt()
        .max(1.0)
}

/// The volume edge whose pass takes about `micros` on `grid`, and that pass's measured cost;
/// `Err` with the estimated edge when it is above [`MAX_VOLUME`]. 0 µs is volume 0 (no pass).
pub fn volume_for(
    params: &FogParams,
    grid: Grid,
    camera: Camera,
    micros: f64,
) -> Result<(u64, Option<Cost>), u64> {
    if micros <= 0.0 {
        return Ok((0, None));
    }
    let probe = measure(params, grid, camera, PROBE);
    let guess = edge_for(micros - probe.vertex_micros, &probe);
    if guess > MAX_VOLUME as f64 * 1.1 {
        return Err(guess.round() as u64);
    }
    let first = measure(
        params,
        grid,
        camera,
        guess.round().min(MAX_VOLUME as f64) as u64,
    );
    let edge = edge_for(micros - first.vertex_micros, &first).round() as u64;
    if edge > MAX_VOLUME {
        return Err(edge);
    }
    let cost = if edge == first.volume {
        first
    } else {
        measure(params, grid, camera, edge)
    };
    Ok((edge, Some(cost)))
}
