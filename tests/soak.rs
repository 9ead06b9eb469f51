//! A bounded soak (ignored by default; `.ci/run` runs it): up to a million frames on a tiny mesh
//! for every FIFO hand-off method in UP and DP at depth 1, and a quarter million at depths 2
//! and 3, each with the consumption that holds slots longest at that depth, checking every
//! frame's sequence number.
//!
//! Run with `cargo test --release --test soak -- --ignored`. A run stops at its count or after
//! `MAX_SECONDS`, whichever comes first, so that the methods that sleep on every hand-off (a
//! VM's wake-up is about 50 µs) and `spin` on one core (a scheduler tick per hand-off) keep the
//! whole soak within CI's budget; every method is still soaked for at least `MIN_FRAMES`.

mod common;

use oceanbench::frame_loop::{self, Budget, Consume, LoopSpec, Mode};
use oceanbench::ocean::Grid;
use oceanbench::sync::{Policy, SyncMethod};
use std::time::Duration;

/// Frames per run at depths 1, 2 and 3.
const FRAMES: [u64; 3] = [1_000_000, 250_000, 250_000];
const MAX_SECONDS: f64 = 8.0;
/// The least every method must be soaked for, `spin` on one core aside (it may manage far
/// fewer).
const MIN_FRAMES: u64 = 50_000;

#[test]
#[ignore = "soak: about six minutes; run by .ci/run"]
fn a_million_frames_per_method_none_lost() {
    let modes = common::threaded_modes();
    for (depth, frames_wanted) in (1..).zip(FRAMES) {
        for mode in modes.iter().copied() {
            for sync in SyncMethod::of_policy(Policy::Fifo) {
                let spec = LoopSpec {
                    grid: Grid::new(2, 1.0).unwrap(),
                    depth,
                    consume: if depth == 1 {
                        Consume::Copy
                    } else {
                        Consume::Handle
                    },
                    timeout: Duration::from_secs(10),
                    ..common::loop_spec(mode, sync)
                };
                let spin_on_one_core = mode == Mode::Up && sync == SyncMethod::Spin;
                let what = format!("{mode:?} {sync:?} depth {depth}");
                // A run cut short by the time cap before `MIN_FRAMES` (a machine busy with other
                // work) is followed by fresh loops until the soak has seen that many frames.
                let least = if spin_on_one_core {
                    1
                } else {
                    MIN_FRAMES.min(frames_wanted)
                };
                let mut seen = 0u64;
                while seen < least {
                    let budget = Budget {
                        warmup_frames: 0,
                        min_frames: frames_wanted - seen,
                        min_seconds: 0.0,
                        max_seconds: MAX_SECONDS,
                    };
                    let mut expected = 0u64;
                    let mut out_of_order = 0u64;
                    let run = frame_loop::run(&spec, &budget, |k, _| {
                        if k != expected {
                            out_of_order += 1;
                        }
                        expected = k + 1;
                    })
                    .unwrap_or_else(|e| panic!("{what}: {e}"));
                    let frames = run.trial.frames.len() as u64;
                    eprintln!("{what}: {frames} frames in {:.1} s", run.trial.seconds());
                    assert_eq!(out_of_order, 0, "{what}");
                    assert_eq!(expected, frames, "{what}: every frame seen once");
                    seen += frames;
                }
            }
        }
    }
}
