//! Pinning threads to cores, and checking that the pin held.

use crate::input::InputError;
use serde::{Deserialize, Serialize};
use std::sync::OnceLock;

/// The cores this process may run on, read once from the first (unpinned) caller.
///
/// Threads that are pinned inherit their mask into threads they spawn, so the list is read before
/// any pinning happens and cached.
pub fn allowed_cores() -> &'static [usize] {
    static ALLOWED: OnceLock<Vec<usize>> = OnceLock::new();
    ALLOWED.get_or_init(|| {
        let mut ids: Vec<usize> = core_affinity::get_core_ids()
            .unwrap_or_default()
            .into_iter()
            .map(|c| c.id)
            .collect();
        ids.sort_unstable();
        ids
    })
}

/// What happened when a thread asked to be pinned.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Pin {
    /// The core asked for.
    pub core: usize,
    /// Whether the OS accepted the pin and the thread's mask is now exactly that core.
    pub held: bool,
}

/// Pins the calling thread to `core` and reads its mask back to see whether the pin held.
pub fn pin_current(core: usize) -> Pin {
    let accepted = core_affinity::set_for_current(core_affinity::CoreId { id: core });
    let now: Vec<usize> = core_affinity::get_core_ids()
        .unwrap_or_default()
        .into_iter()
        .map(|c| c.id)
        .collect();
    Pin {
        core,
        held: accepted && now == [core],
    }
}

/// Checks that each requested core is allowed, naming the allowed ones if not.
pub fn check_allowed(cores: &[usize]) -> Result<(), InputError> {
    let allowed = allowed_cores();
    match cores.iter().find(|c| !allowed.contains(c)) {
        Some(bad) => Err(InputError(format!(
            "cores: core {bad} is not allowed for this process; allowed cores: {}",
            list(allowed)
        ))),
        None => Ok(()),
    }
}

/// Comma-separated core ids.
pub fn list(cores: &[usize]) -> String {
    cores
        .iter()
        .map(|c| c.to_string())
        .collect::<Vec<_>>()
        .join(",")
}
