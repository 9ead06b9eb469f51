//! What the main thread does while the helper computes the mesh: the synthetic game work of
//! the paper's study (a calibrated integer chain), with room for workloads that use the mesh.

mod synthetic;

pub use synthetic::{run, run_unless, Calibration};
