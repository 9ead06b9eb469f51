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
