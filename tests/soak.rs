//! A bounded soak (ignored by default; `.ci/run` runs it): up to a million frames on a tiny mesh
//! for every hand-off method in UP and DP, checking every frame's sequence number.
//!
//! Run with `cargo test --release --test soak -- --ignored`. `spin` on one core pays a scheduler
//! tick per hand-off, so that run alone is capped at `MAX_SECONDS`; every other method must reach
//! the full count.

use oceanbench::affinity;
use oceanbench::frame_loop::{self, Budget, LoopSpec, Mode, Threading};
use oceanbench::ocean::{Grid, Kernel, NormalMethod, WaveSet};
use oceanbench::sync::SyncMethod;
use std::time::Duration;
use strum::VariantArray;

const FRAMES: u64 = 1_000_000;
const MAX_SECONDS: f64 = 20.0;

#[test]
#[ignore = "soak: about two minutes; run by .ci/run"]
fn a_million_frames_per_method_none_lost() {
    let cores = affinity::allowed_cores();
    let mut modes = vec![Mode::Up];
    if cores.len() > 1 {
        modes.push(Mode::Dp);
    }
    for mode in modes {
        for &sync in SyncMethod::VARIANTS {
            let spec = LoopSpec {
                grid: Grid::new(2, 1.0).unwrap(),
                waves: WaveSet::default(),
                normals: NormalMethod::Analytic,
                kernel: Kernel::Reference,
                mode,
                sync,
                threading: Threading::Pool,
                workload_iterations: 0,
                main_core: cores[0],
                helper_cores: frame_loop::helper_cores(
                    mode,
                    cores[0],
                    if mode == Mode::Dp { cores[1] } else { cores[0] },
                    1,
                ),
                time_step: 1.0 / 60.0,
                timeout: Duration::from_secs(10),
                stop: None,
                stall_at_frame: None,
            };
            // Only `spin` on one core is cut short by time; every other run must reach the count
            // however slow the machine is (the hand-off timeout still ends a stuck run).
            let spin_on_one_core = mode == Mode::Up && sync == SyncMethod::Spin;
            let budget = Budget {
                warmup_frames: 0,
                min_frames: FRAMES,
                min_seconds: 0.0,
                max_seconds: if spin_on_one_core {
                    MAX_SECONDS
                } else {
                    f64::INFINITY
                },
            };
            let mut expected = 0u64;
            let mut out_of_order = 0u64;
            let run = frame_loop::run(&spec, &budget, |k, _| {
                if k != expected {
                    out_of_order += 1;
                }
                expected = k + 1;
            })
            .unwrap_or_else(|e| panic!("{mode:?} {sync:?}: {e}"));
            let frames = run.trial.frames.len() as u64;
            eprintln!(
                "{mode:?} {sync:?}: {frames} frames in {:.1} s",
                run.trial.seconds()
            );
            assert_eq!(out_of_order, 0, "{mode:?} {sync:?}");
            assert_eq!(expected, frames, "{mode:?} {sync:?}: every frame seen once");
            if !spin_on_one_core {
                assert_eq!(frames, FRAMES, "{mode:?} {sync:?} reached the full count");
            }
        }
    }
}
