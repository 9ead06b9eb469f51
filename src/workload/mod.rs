//! What the main thread does each frame while the helper computes the mesh, behind one trait:
//! the synthetic game work of the paper's study (a calibrated integer chain), `render`, which
//! transforms the mesh just consumed, `spray`, particles born at its folds, and `fog`, a noise
//! volume rebuilt and blurred each frame that gives every vertex its fog coefficient. A kind is
//! its own file or folder with one descriptor ([`Kind`]) and one line in the registry
//! (`kind::KINDS`); a library user registers more with [`register`].

pub mod fog;
mod kind;
mod render;
pub mod spray;
mod synthetic;

pub use crate::summary::work::{CountStats, WorkCounts, WorkRecord, WorkTrial, MAX_COUNTS};
pub use fog::{Fog, FogParams, FogRecord};
pub use kind::{
    kinds, lookup, names, register, whole_amount, DynKind, Kind, KindParams, LevelAt, WorkloadKind,
    MAX_AMOUNT,
};
pub use render::Render;
pub use spray::{Spray, SprayParams};
pub use synthetic::{run, run_unless, Calibration, Synthetic};

use crate::camera::Camera;
use crate::ocean::{Grid, Mesh};
use std::sync::atomic::AtomicBool;

/// The stop flag was raised before the frame's work was done.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Stopped;

/// What every kind's work says of itself after a frame.
pub trait WorkOutput: Send {
    /// A digest of what the last frame's work produced, to check that every mode, method and
    /// depth produces the same (not called while measuring).
    fn digest(&self) -> u64;

    /// What the last frame counted, for kinds that count something per frame.
    fn counts(&self) -> Option<WorkCounts> {
        None
    }

    /// What the work measured of itself over the loop, for the results (kinds that time their
    /// own parts; not called while measuring).
    fn record(&self) -> Option<WorkRecord> {
        None
    }
}

/// Work that runs before the wait for the mesh, overlapping the helper's step (the paper's
/// place).
pub trait FrameWork: WorkOutput {
    /// Frame `k`'s work. Looks at `stop` every hundred microseconds or so of work.
    fn run(&mut self, k: u64, stop: Option<&AtomicBool>) -> Result<(), Stopped>;
}

/// Work that runs on the mesh the frame consumed: after the consume step, before the mesh's
/// slot is released.
pub trait MeshWork: WorkOutput {
    /// Frame `k`'s work on `mesh`. Looks at `stop` every hundred microseconds or so of work.
    fn run(&mut self, k: u64, mesh: &Mesh, stop: Option<&AtomicBool>) -> Result<(), Stopped>;
}

/// A frame's worth of main-thread work, by where in the frame it runs.
pub enum Work {
    /// Before the wait for the mesh.
    BeforeWait(Box<dyn FrameWork>),
    /// On the consumed mesh.
    OnMesh(Box<dyn MeshWork>),
}

impl Work {
    /// Work run before the wait.
    pub fn before_wait(work: impl FrameWork + 'static) -> Work {
        Work::BeforeWait(Box::new(work))
    }

    /// Work run on the consumed mesh.
    pub fn on_mesh(work: impl MeshWork + 'static) -> Work {
        Work::OnMesh(Box::new(work))
    }

    /// Whether it reads the mesh the frame consumed.
    pub fn reads_mesh(&self) -> bool {
        matches!(self, Work::OnMesh(_))
    }

    /// What it says of itself.
    pub fn output(&self) -> &dyn WorkOutput {
        match self {
            Work::BeforeWait(w) => &**w,
            Work::OnMesh(w) => &**w,
        }
    }
}

/// Folds `values` into a digest from `seed`: what [`WorkOutput::digest`] implementations hash
/// with.
pub fn fold_digest(seed: u64, values: impl Iterator<Item = u64>) -> u64 {
    values.fold(seed, |h, v| {
        (h.rotate_left(5) ^ v).wrapping_mul(0x9E37_79B9_7F4A_7C15)
    })
}

/// What a kind's work is built from.
#[derive(Clone, Debug)]
pub struct WorkSpec {
    /// The kind.
    pub kind: WorkloadKind,
    /// The level in the kind's own unit ([`Kind::unit`]).
    pub amount: u64,
    /// The mesh grid the work may read.
    pub grid: Grid,
    /// The camera, for kinds that look at the mesh.
    pub camera: Camera,
    /// Rest spacing of the meshes' vertices (the ocean model's, in its units).
    pub spacing: f32,
    /// Simulated seconds between two frames' meshes.
    pub time_step: f32,
}
