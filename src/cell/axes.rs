//! The axes of a loop that are plain values: where the threads run, how helpers come to exist,
//! how the main thread consumes a mesh, and the checks that refuse what the loops cannot run.
//! They sit with the cell so that configs, the rules and the reports name them without
//! importing the engine that runs them.

use crate::input::InputError;
use crate::ocean::{Model, NormalMethod};
use crate::sync::{Policy, SyncMethod};

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

crate::named! {
    /// How the main thread consumes a mesh.
    pub enum Consume {
        /// Copy it into the main thread's render buffer (the paper's build).
        Copy,
        /// Read every vertex and normal once, in place: a bounding box and a checksum.
        Read,
        /// Take the slot and pass it on untouched; it goes back to the helper depth − 1 frames
        /// later (at depth 1, at the end of the frame), as frames in flight do. What this leaves
        /// out is the GPU's read of the buffer, which no CPU thread pays.
        Handle,
    }
}

/// Most mesh slots a ring may have.
pub const MAX_DEPTH: usize = 4;

/// Most helpers a loop may split the mesh among.
pub const MAX_HELPERS: usize = 64;

/// Refuses a run-ahead depth the loops cannot run: 1 to [`MAX_DEPTH`], and more than 1 only with a
/// persistent helper (a thread per frame is joined inside its frame, so it cannot run ahead).
pub fn check_depth(depth: usize, threading: Threading) -> Result<(), InputError> {
    if !(1..=MAX_DEPTH).contains(&depth) {
        return Err(InputError(format!(
            "depth: must be 1 to {MAX_DEPTH}, got {depth}"
        )));
    }
    if depth > 1 && threading == Threading::Spawn {
        return Err(InputError(format!(
            "depth: {depth} slots need threading `pool`; `spawn` joins its thread inside the frame, so it cannot run ahead"
        )));
    }
    Ok(())
}

/// Refuses a method the `policy` cannot hand over with, and what `latest` has no use for: it
/// runs one persistent helper that never waits, so a ring's depth, a second helper's band or
/// a thread per frame mean nothing to it.
pub fn check_policy(
    policy: Policy,
    sync: SyncMethod,
    depth: usize,
    helpers: usize,
    threading: Threading,
) -> Result<(), InputError> {
    if !sync.serves(policy) {
        let can: Vec<&str> = SyncMethod::of_policy(policy).map(|m| m.name()).collect();
        return Err(InputError(format!(
            "sync: `{sync}` cannot hand over under policy `{policy}`; the methods that can are {}",
            can.join(", ")
        )));
    }
    if policy == Policy::Latest {
        if depth != 1 {
            return Err(InputError(format!(
                "depth: {depth} has no meaning under policy `latest`, where the helper never waits for a slot; use depth 1"
            )));
        }
        if helpers != 1 {
            return Err(InputError(format!(
                "helpers: policy `latest` runs 1 helper, got {helpers}; bands of one frame would each need the others' mailbox"
            )));
        }
        if threading != Threading::Pool {
            return Err(InputError(format!(
                "threading: policy `latest` needs `pool`, got `{threading}`; a thread per frame cannot run ahead of the main thread"
            )));
        }
    }
    Ok(())
}

/// Refuses a helper count the loops cannot run, naming why: whether rows split with these
/// normals is the `model`'s to say. Shared by configs, flags and `run` so every entry point
/// gives the same message.
pub fn check_helpers(
    helpers: usize,
    mode: Mode,
    threading: Threading,
    model: &dyn Model,
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
    model.splits_into_rows(normals)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ocean::sines::Sines;

    /// The refusal's field, the text before its first colon ("depth", "helpers", ...).
    fn field<T>(r: Result<T, InputError>) -> Option<String> {
        r.err()
            .map(|e| e.0.split(':').next().unwrap_or_default().to_string())
    }

    #[test]
    fn two_cores_for_dp_one_otherwise() {
        assert_eq!(Mode::Dp.cores_needed(), 2);
        assert_eq!(Mode::Up.cores_needed(), 1);
        assert_eq!(Mode::Serial.cores_needed(), 1);
    }

    #[test]
    fn depth_is_1_to_the_most_and_above_1_only_with_a_pool() {
        let depth = Some("depth".to_string());
        assert_eq!(field(check_depth(0, Threading::Pool)), depth);
        for d in 1..=MAX_DEPTH {
            assert_eq!(check_depth(d, Threading::Pool), Ok(()), "depth {d}");
        }
        assert_eq!(field(check_depth(MAX_DEPTH + 1, Threading::Pool)), depth);
        assert_eq!(check_depth(1, Threading::Spawn), Ok(()));
        let err = check_depth(2, Threading::Spawn).unwrap_err().0;
        assert!(
            err.starts_with("depth: 2 slots need threading `pool`"),
            "{err}"
        );
    }

    #[test]
    fn latest_takes_one_pooled_helper_at_depth_1_and_fifo_anything() {
        let (pool, spawn) = (Threading::Pool, Threading::Spawn);
        let latest = |sync, depth, helpers, threading| {
            field(check_policy(
                Policy::Latest,
                sync,
                depth,
                helpers,
                threading,
            ))
        };
        assert_eq!(latest(SyncMethod::TripleBuffer, 1, 1, pool), None);
        assert_eq!(latest(SyncMethod::Atomic, 1, 1, pool), None);
        assert_eq!(
            latest(SyncMethod::Condvar, 1, 1, pool).as_deref(),
            Some("sync")
        );
        assert_eq!(
            latest(SyncMethod::Atomic, 2, 1, pool).as_deref(),
            Some("depth")
        );
        assert_eq!(
            latest(SyncMethod::Atomic, 1, 2, pool).as_deref(),
            Some("helpers")
        );
        assert_eq!(
            latest(SyncMethod::Atomic, 1, 1, spawn).as_deref(),
            Some("threading")
        );
        let fifo = |sync, depth, helpers, threading| {
            field(check_policy(Policy::Fifo, sync, depth, helpers, threading))
        };
        assert_eq!(fifo(SyncMethod::Condvar, 3, 2, spawn), None);
        assert_eq!(
            fifo(SyncMethod::TripleBuffer, 1, 1, pool).as_deref(),
            Some("sync")
        );
    }

    #[test]
    fn helpers_are_1_to_the_most_at_least_a_row_each_in_a_pool() {
        let (pool, spawn, a) = (Threading::Pool, Threading::Spawn, NormalMethod::Analytic);
        let helpers = |n, mode, threading, normals, size| {
            check_helpers(n, mode, threading, &Sines, normals, size)
        };
        let refused = Some("helpers".to_string());
        assert_eq!(field(helpers(0, Mode::Dp, pool, a, 64)), refused);
        assert_eq!(helpers(MAX_HELPERS, Mode::Dp, pool, a, MAX_HELPERS), Ok(()));
        assert_eq!(
            field(helpers(MAX_HELPERS + 1, Mode::Dp, pool, a, 128)),
            refused
        );
        // One row each: as many helpers as rows, not one more.
        assert_eq!(helpers(8, Mode::Up, pool, a, 8), Ok(()));
        let err = helpers(9, Mode::Up, pool, a, 8).unwrap_err().0;
        assert!(err.contains("need at least one row each"), "{err}");
        // One helper runs anywhere; serial runs no helper, so its count is not checked further.
        assert_eq!(helpers(1, Mode::Dp, spawn, NormalMethod::Lookup, 2), Ok(()));
        assert_eq!(
            helpers(4, Mode::Serial, spawn, NormalMethod::Lookup, 2),
            Ok(())
        );
        let err = helpers(2, Mode::Dp, spawn, a, 64).unwrap_err().0;
        assert!(err.contains("need threading `pool`"), "{err}");
        // Whether rows split with these normals is the model's to say.
        assert_eq!(
            field(helpers(2, Mode::Dp, pool, NormalMethod::Neighbors, 64)),
            refused
        );
    }
}
