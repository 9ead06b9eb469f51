//! Whether a cell can run: the one place that decides, for configs (every crossed cell), the
//! CLI and library callers (a [`crate::frame_loop::LoopSpec`] before its loop starts) alike.
//!
//! A refusal is of one of two sorts. A combination the loops cannot run (a kernel the model does
//! not offer, spray on the sines, a method of the other policy) is left out of a sweep's product,
//! which says so when a listed value vanishes ([`crate::cell::Axes::check_coverage`]); a value
//! out of range for the cell (more helpers than rows, `lookup` on a huge mesh) is refused with
//! its field.

use super::axes::{check_depth, check_helpers, check_policy, Mode, Threading};
use super::check_offers;
use crate::input::InputError;
use crate::ocean::{GridKind, Kernel, NormalMethod, OceanKind};
use crate::sync::{Policy, SyncMethod};
use crate::workload::WorkloadKind;

/// The values of a cell the rules read; serial cells have no hand-off values.
#[derive(Clone, Copy, Debug)]
pub struct Runnable {
    /// Mesh size N.
    pub size: usize,
    /// The ocean model.
    pub ocean: OceanKind,
    /// The grid its vertices lie on.
    pub grid: GridKind,
    /// How normals are computed.
    pub normals: NormalMethod,
    /// Which kernel fills the heights.
    pub kernel: Kernel,
    /// The main thread's work.
    pub workload_kind: WorkloadKind,
    /// serial, up or dp.
    pub mode: Mode,
    /// The frame policy (threaded cells).
    pub policy: Option<Policy>,
    /// The hand-off method (threaded cells).
    pub sync: Option<SyncMethod>,
    /// Persistent or per-frame helpers (threaded cells).
    pub threading: Option<Threading>,
    /// Helper threads (threaded cells).
    pub helpers: Option<usize>,
    /// Ring depth (threaded cells).
    pub depth: Option<usize>,
}

/// Why a cell cannot run.
#[derive(Clone, Debug, PartialEq)]
pub enum Refusal {
    /// A combination the loops cannot run: a sweep leaves such cells out.
    Combination(InputError),
    /// A value out of range for the cell: refused with its field.
    Value(InputError),
}

impl Refusal {
    /// The one-line message.
    pub fn error(self) -> InputError {
        match self {
            Refusal::Combination(e) | Refusal::Value(e) => e,
        }
    }
}

impl Runnable {
    /// The combinations the loops can run: what the model offers, the surface the work needs,
    /// the grid's normals, and the policy's methods and shape.
    pub fn combination(&self) -> Result<(), InputError> {
        let model = self.ocean.model();
        check_offers(self.ocean, model, self.kernel, self.normals)?;
        self.workload_kind.check_surface(self.ocean, self.grid)?;
        crate::projected::check(self.grid, self.ocean.name(), model, self.normals)?;
        match (
            self.policy,
            self.sync,
            self.depth,
            self.helpers,
            self.threading,
        ) {
            (Some(policy), Some(sync), Some(depth), Some(helpers), Some(threading)) => {
                check_policy(policy, sync, depth, helpers, threading)
            }
            _ => Ok(()),
        }
    }

    /// The values the cell's model and threads accept: a helper count the threading, size and
    /// model can split into, a depth the threading allows, the model's own limits.
    pub fn values(&self) -> Result<(), InputError> {
        let model = self.ocean.model();
        if let (Some(helpers), Some(threading)) = (self.helpers, self.threading) {
            check_helpers(
                helpers,
                self.mode,
                threading,
                model,
                self.normals,
                self.size,
            )?;
            check_depth(self.depth.unwrap_or(1), threading)?;
        }
        model.check(self.size, self.normals)
    }

    /// Both, combinations first.
    pub fn check(&self) -> Result<(), Refusal> {
        self.combination().map_err(Refusal::Combination)?;
        self.values().map_err(Refusal::Value)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A threaded UP cell on the sines, its hand-off values given.
    fn threaded(policy: Policy, sync: SyncMethod, depth: usize) -> Runnable {
        Runnable {
            size: 16,
            ocean: OceanKind::SINES,
            grid: GridKind::Regular,
            normals: NormalMethod::Analytic,
            kernel: Kernel::Reference,
            workload_kind: WorkloadKind::SYNTHETIC,
            mode: Mode::Up,
            policy: Some(policy),
            sync: Some(sync),
            threading: Some(Threading::Pool),
            helpers: Some(1),
            depth: Some(depth),
        }
    }

    #[test]
    fn a_threaded_cell_is_a_combination_only_if_its_policy_takes_its_hand_off() {
        let fine = threaded(Policy::Latest, SyncMethod::TripleBuffer, 1);
        assert_eq!(fine.check(), Ok(()));
        let wrong_method = threaded(Policy::Latest, SyncMethod::Condvar, 1);
        assert!(
            matches!(wrong_method.check(), Err(Refusal::Combination(e)) if e.0.starts_with("sync:")),
            "{:?}",
            wrong_method.check()
        );
        let deep = threaded(Policy::Latest, SyncMethod::Atomic, 2);
        assert!(matches!(deep.combination(), Err(e) if e.0.starts_with("depth:")));
        // A serial cell has no hand-off to check.
        let serial = Runnable {
            mode: Mode::Serial,
            policy: None,
            sync: None,
            threading: None,
            helpers: None,
            depth: None,
            ..wrong_method
        };
        assert_eq!(serial.check(), Ok(()));
    }

    #[test]
    fn a_value_out_of_range_is_refused_as_a_value_not_a_combination() {
        let too_many = Runnable {
            helpers: Some(17),
            ..threaded(Policy::Fifo, SyncMethod::Atomic, 1)
        };
        assert!(
            matches!(too_many.check(), Err(Refusal::Value(e)) if e.0.starts_with("helpers:")),
            "{:?}",
            too_many.check()
        );
        let e = too_many.check().unwrap_err().error();
        assert!(e.0.contains("at least one row each"), "{}", e.0);
    }
}
