//! Every mode × threading × hand-off delivers the same meshes as the serial loop, each frame
//! exactly once and in order.

mod common;

use common::{describe, helper_cores, threaded_modes};
use oceanbench::affinity;
use oceanbench::camera::Camera;
use oceanbench::frame_loop::{self, Budget, Consume, LoopSpec, Mode, Threading};
use oceanbench::ocean::{Grid, GridKind, Kernel, Mesh, NormalMethod, OceanKind};
use oceanbench::sync::{Policy, SyncMethod};
use oceanbench::workload::{KindParams, WorkloadKind};
use std::time::Duration;

const FRAMES: u64 = 300;

fn spec(mode: Mode, sync: SyncMethod, threading: Threading, normals: NormalMethod) -> LoopSpec {
    LoopSpec {
        normals,
        threading,
        workload_amount: 50,
        ..common::loop_spec(mode, sync)
    }
}

/// Every frame the main thread received: its index and a full copy of the render buffer.
fn frames(spec: &LoopSpec) -> Vec<(u64, Mesh)> {
    let mut seen = Vec::new();
    let run = frame_loop::run(spec, &Budget::exact(FRAMES), |k, mesh| {
        seen.push((k, mesh.clone()))
    })
    .unwrap_or_else(|e| {
        panic!(
            "{:?} {:?} {:?} x{}: {e}",
            spec.mode,
            spec.sync,
            spec.threading,
            spec.helpers()
        )
    });
    assert_eq!(run.trial.frames.len() as u64, FRAMES);
    seen
}

#[test]
fn threaded_meshes_are_bit_identical_to_serial_each_frame_once_in_order() {
    for normals in [NormalMethod::Analytic, NormalMethod::Neighbors] {
        let serial = frames(&spec(
            Mode::Serial,
            SyncMethod::Atomic,
            Threading::Pool,
            normals,
        ));
        let indices: Vec<u64> = serial.iter().map(|(k, _)| *k).collect();
        assert_eq!(indices, (0..FRAMES).collect::<Vec<_>>());
        // The surface moves: consecutive frames differ.
        assert_ne!(serial[0].1.z, serial[1].1.z);
        for mode in threaded_modes() {
            for threading in [Threading::Pool, Threading::Spawn] {
                for sync in SyncMethod::of_policy(Policy::Fifo) {
                    let got = frames(&spec(mode, sync, threading, normals));
                    assert_eq!(got.len(), serial.len());
                    for ((k, mesh), (sk, smesh)) in got.iter().zip(&serial) {
                        assert_eq!(k, sk, "{mode:?} {sync:?} {threading:?}: frame order");
                        assert!(
                            mesh == smesh,
                            "{mode:?} {sync:?} {threading:?} {normals:?}: frame {k} differs"
                        );
                    }
                }
            }
        }
    }
}

/// Every depth (1 to MAX_DEPTH) × consumption × method × mode consumes the serial meshes, each frame once and in
/// order; with `read`, every mode reads the same meshes (equal checksums).
#[test]
fn pipelined_meshes_are_bit_identical_to_serial_for_every_depth_and_consumption() {
    const FEW: u64 = 40;
    let collect = |spec: &LoopSpec| {
        let mut seen = Vec::new();
        let run = frame_loop::run(spec, &Budget::exact(FEW), |k, mesh| {
            seen.push((k, mesh.clone()))
        })
        .unwrap_or_else(|e| {
            panic!(
                "{:?} {:?} d{} {:?}: {e}",
                spec.mode, spec.sync, spec.depth, spec.consume
            )
        });
        (seen, run)
    };
    for consume in [Consume::Copy, Consume::Read, Consume::Handle] {
        let mut serial_spec = spec(
            Mode::Serial,
            SyncMethod::Atomic,
            Threading::Pool,
            NormalMethod::Analytic,
        );
        serial_spec.consume = consume;
        let (serial, serial_run) = collect(&serial_spec);
        assert_eq!(
            serial_run.trial.checksum.is_some(),
            consume == Consume::Read
        );
        for mode in threaded_modes() {
            for sync in SyncMethod::of_policy(Policy::Fifo) {
                for depth in 1..=frame_loop::MAX_DEPTH {
                    let mut s = spec(mode, sync, Threading::Pool, NormalMethod::Analytic);
                    (s.depth, s.consume) = (depth, consume);
                    let (got, run) = collect(&s);
                    let what = format!("{mode:?} {sync:?} depth {depth} {consume:?}");
                    let indices: Vec<u64> = got.iter().map(|(k, _)| *k).collect();
                    assert_eq!(indices, (0..FEW).collect::<Vec<_>>(), "{what}");
                    for ((k, mesh), (_, smesh)) in got.iter().zip(&serial) {
                        assert!(mesh == smesh, "{what}: frame {k} differs");
                    }
                    assert_eq!(run.trial.checksum, serial_run.trial.checksum, "{what}");
                    for f in &run.trial.frames {
                        assert!(
                            f.age_frames < depth as u32,
                            "{what}: a frame aged {}",
                            f.age_frames
                        );
                    }
                }
            }
        }
    }
}

/// With several helpers each band has its own ring, and frame k is consumed when every band has
/// published it.
#[test]
fn split_meshes_run_ahead_too() {
    let serial = frames(&spec(
        Mode::Serial,
        SyncMethod::Atomic,
        Threading::Pool,
        NormalMethod::Analytic,
    ));
    for mode in threaded_modes() {
        for consume in [Consume::Read, Consume::Handle] {
            let mut s = spec(
                mode,
                SyncMethod::Condvar,
                Threading::Pool,
                NormalMethod::Analytic,
            );
            (s.depth, s.consume) = (2, consume);
            s.helper_cores = helper_cores(mode, 2);
            let got = frames(&s);
            for ((k, mesh), (_, smesh)) in got.iter().zip(&serial) {
                assert!(mesh == smesh, "{mode:?} {consume:?}: frame {k} differs");
            }
        }
    }
}

/// Frames tile the timeline: each runs from its start to the next one's, so a trial's frame
/// times add up exactly to its wall time, and the parts plus the remainder make the frame.
#[test]
fn frame_times_add_up_to_the_wall_time() {
    let mut all = vec![(Mode::Serial, Threading::Pool)];
    for mode in threaded_modes() {
        all.extend([(mode, Threading::Pool), (mode, Threading::Spawn)]);
    }
    for (mode, threading) in all {
        let s = spec(mode, SyncMethod::Atomic, threading, NormalMethod::Analytic);
        let budget = Budget {
            warmup_frames: 3,
            ..Budget::exact(25)
        };
        let trial = frame_loop::run(&s, &budget, |_, _| {}).unwrap().trial;
        let sum: u64 = trial.frames.iter().map(|f| f.total_ns).sum();
        assert_eq!(sum, trial.wall_ns, "{mode:?} {threading:?}");
        for f in &trial.frames {
            let main_parts = f.workload_ns + f.wait_ns + f.copy_ns + f.other_ns;
            let parts = if mode == Mode::Serial {
                main_parts + f.step_ns
            } else {
                main_parts
            };
            assert_eq!(parts, f.total_ns, "{mode:?} {threading:?}: {f:?}");
        }
    }
}

#[test]
fn depth_beyond_the_ring_or_with_spawn_is_refused() {
    for (threading, depth, needle) in [
        (Threading::Pool, 5, "1 to 4"),
        (Threading::Pool, 0, "1 to 4"),
        (Threading::Spawn, 2, "pool"),
    ] {
        let mut s = spec(
            Mode::Up,
            SyncMethod::Atomic,
            threading,
            NormalMethod::Analytic,
        );
        s.depth = depth;
        match frame_loop::run(&s, &Budget::exact(1), |_, _| {}) {
            Err(frame_loop::LoopError::Spec(e)) => {
                let e = e.to_string();
                assert!(e.starts_with("depth:") && e.contains(needle), "{e}");
            }
            other => panic!("expected a spec error, got {:?}", other.map(|_| ())),
        }
    }
}

#[test]
fn warmup_frames_are_run_but_not_measured() {
    let s = spec(
        Mode::Serial,
        SyncMethod::Atomic,
        Threading::Pool,
        NormalMethod::Analytic,
    );
    let mut observed = 0;
    let budget = Budget {
        warmup_frames: 7,
        ..Budget::exact(13)
    };
    let run = frame_loop::run(&s, &budget, |_, _| observed += 1).unwrap();
    assert_eq!(observed, 20);
    assert_eq!(run.trial.frames.len(), 13);
    assert!(run.main_pin.held, "pinning to an allowed core holds");
}

#[test]
fn pins_are_recorded_for_both_threads() {
    for mode in threaded_modes() {
        let s = spec(
            mode,
            SyncMethod::Condvar,
            Threading::Pool,
            NormalMethod::Analytic,
        );
        let run = frame_loop::run(&s, &Budget::exact(5), |_, _| {}).unwrap();
        assert_eq!(run.helper_pins.len(), 1, "threaded modes have a helper");
        assert_eq!(run.helper_pins[0].core, s.helper_cores[0]);
        assert!(run.pinned());
    }
}

/// Splitting the mesh's rows among helpers changes who computes a row, never its value: 2 and
/// 3 helpers (3 does not divide 9 rows evenly) give the serial meshes, each frame once in order,
/// with every hand-off and both kernels.
#[test]
fn split_meshes_are_bit_identical_to_serial_each_frame_once_in_order() {
    for kernel in [Kernel::Reference, Kernel::Fast] {
        let mut serial_spec = spec(
            Mode::Serial,
            SyncMethod::Atomic,
            Threading::Pool,
            NormalMethod::Analytic,
        );
        serial_spec.kernel = kernel;
        let serial = frames(&serial_spec);
        for mode in threaded_modes() {
            for sync in SyncMethod::of_policy(Policy::Fifo) {
                for helpers in [2, 3] {
                    let mut s = spec(mode, sync, Threading::Pool, NormalMethod::Analytic);
                    s.kernel = kernel;
                    s.helper_cores = helper_cores(mode, helpers);
                    let got = frames(&s);
                    let indices: Vec<u64> = got.iter().map(|(k, _)| *k).collect();
                    assert_eq!(indices, (0..FRAMES).collect::<Vec<_>>());
                    for ((k, mesh), (_, smesh)) in got.iter().zip(&serial) {
                        assert!(
                            mesh == smesh,
                            "{kernel:?} {mode:?} {sync:?} x{helpers}: frame {k} differs"
                        );
                    }
                }
            }
        }
    }
}

/// The FFT ocean's helpers split its row pass and its column pass by rows and meet at a barrier
/// between them: 1, 2 and 3 helpers (3 does not divide 16 rows evenly), at depth 1 and 2, give
/// the serial meshes bit for bit, each frame once in order.
#[test]
fn fft_meshes_are_bit_identical_in_every_mode_and_helper_count() {
    let fft = |mode, sync| {
        let mut s = spec(mode, sync, Threading::Pool, NormalMethod::Analytic);
        s.ocean = OceanKind::FFT;
        s.grid = Grid::new(16, 1.0).unwrap();
        s
    };
    let serial = frames(&fft(Mode::Serial, SyncMethod::Atomic));
    assert!(serial.windows(2).all(|w| w[0].1 != w[1].1), "the sea moves");
    for mode in threaded_modes() {
        for sync in [
            SyncMethod::Atomic,
            SyncMethod::Condvar,
            SyncMethod::Crossbeam,
        ] {
            for (helpers, depth) in [(1, 1), (2, 1), (3, 1), (2, 2)] {
                let mut s = fft(mode, sync);
                s.helper_cores = helper_cores(mode, helpers);
                s.depth = depth;
                let got = frames(&s);
                let indices: Vec<u64> = got.iter().map(|(k, _)| *k).collect();
                assert_eq!(indices, (0..FRAMES).collect::<Vec<_>>());
                for ((k, mesh), (_, want)) in got.iter().zip(&serial) {
                    assert!(
                        mesh == want,
                        "{mode:?} {sync:?} x{helpers} depth {depth}: frame {k} differs"
                    );
                }
            }
        }
    }
}

/// A stop raised while the FFT ocean's helpers run their phases ends the loop as interrupted,
/// never as a helper stuck at the phase barrier (its shutdown breaks the barrier).
#[test]
fn a_stop_ends_fft_helpers_at_their_barrier() {
    for mode in threaded_modes() {
        for helpers in [2, 3] {
            let mut s = spec(
                mode,
                SyncMethod::Atomic,
                Threading::Pool,
                NormalMethod::Analytic,
            );
            s.ocean = OceanKind::FFT;
            s.grid = Grid::new(32, 1.0).unwrap();
            s.helper_cores = helper_cores(mode, helpers);
            let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
            s.stop = Some(stop.clone());
            let got = frame_loop::run(&s, &Budget::exact(1000), |k, _| {
                if k == 20 {
                    stop.store(true, std::sync::atomic::Ordering::Relaxed);
                }
            });
            assert!(
                matches!(got, Err(frame_loop::LoopError::Interrupted)),
                "{mode:?} x{helpers}: {:?}",
                got.map(|_| ())
            );
        }
    }
}

#[test]
fn every_helper_is_pinned_to_its_core() {
    let cores = affinity::allowed_cores();
    for mode in threaded_modes() {
        let mut s = spec(
            mode,
            SyncMethod::Condvar,
            Threading::Pool,
            NormalMethod::Analytic,
        );
        s.helper_cores = helper_cores(mode, 3);
        if mode == Mode::Dp {
            // Cycling from the helper core on wraps through every allowed core.
            assert_eq!(s.helper_cores[0], cores[1]);
            assert!(s.helper_cores.iter().all(|c| cores.contains(c)));
        } else {
            assert_eq!(s.helper_cores, [cores[0]; 3]);
        }
        let run = frame_loop::run(&s, &Budget::exact(5), |_, _| {}).unwrap();
        assert_eq!(run.helper_pins.len(), 3);
        for (k, pin) in run.helper_pins.iter().enumerate() {
            assert_eq!(pin.core, s.helper_cores[k]);
            assert!(pin.held, "helper {k} pinned to an allowed core holds");
        }
        assert!(run.pinned());
    }
}

#[test]
fn unsupported_helper_counts_are_refused_with_the_reason() {
    let refused = |threading, normals, helpers| {
        let mut s = spec(Mode::Up, SyncMethod::Atomic, threading, normals);
        s.helper_cores = helper_cores(Mode::Up, helpers);
        match frame_loop::run(&s, &Budget::exact(1), |_, _| {}) {
            Err(frame_loop::LoopError::Spec(e)) => e.to_string(),
            other => panic!("expected a spec error, got {:?}", other.map(|_| ())),
        }
    };
    let msg = refused(Threading::Spawn, NormalMethod::Analytic, 2);
    assert!(msg.contains("pool"), "{msg}");
    let msg = refused(Threading::Pool, NormalMethod::Neighbors, 2);
    assert!(msg.contains("analytic"), "{msg}");
    let msg = refused(Threading::Pool, NormalMethod::Analytic, 10);
    assert!(msg.contains("row"), "{msg}");
    let msg = refused(Threading::Pool, NormalMethod::Analytic, 0);
    assert!(msg.contains("1 to"), "{msg}");
}

/// A threaded spec whose helpers stop producing at `frame`, with a short hand-off timeout.
fn stalling(mode: Mode, threading: Threading, helpers: usize, frame: u64) -> LoopSpec {
    let mut s = spec(mode, SyncMethod::Atomic, threading, NormalMethod::Analytic);
    s.helper_cores = helper_cores(mode, helpers);
    s.stall_at_frame = Some(frame);
    s.timeout = Duration::from_millis(300);
    s
}

/// The stalled helper never returns, so a loop that joined it would never return either.
#[test]
fn a_helper_stalled_mid_trial_times_out_and_is_left_behind() {
    for mode in threaded_modes() {
        for (threading, helpers) in [
            (Threading::Pool, 1),
            (Threading::Pool, 2),
            (Threading::Spawn, 1),
        ] {
            let s = stalling(mode, threading, helpers, 2);
            let mut observed = 0;
            match frame_loop::run(&s, &Budget::exact(10), |_, _| observed += 1) {
                Err(frame_loop::LoopError::Stalled { who, .. }) => {
                    assert!(
                        who.contains("main thread"),
                        "{mode:?} {threading:?} x{helpers}: {who}"
                    )
                }
                other => panic!("{mode:?} {threading:?} x{helpers}: {:?}", other.map(|_| ())),
            }
            assert_eq!(observed, 2, "frames before the stall are delivered");
        }
    }
}

/// A pool helper runs ahead into the frame after the last one (at depth 1, once the last frame
/// is released); if it stalls there, the loop must not wait for it forever: either the shutdown
/// reached it first, or the main thread gives up after the timeout and leaves it behind.
#[test]
fn a_helper_stalled_after_the_last_frame_is_left_behind() {
    for mode in threaded_modes() {
        for helpers in [1, 2] {
            for depth in 1..=frame_loop::MAX_DEPTH {
                // Whether the shutdown wins is a race: a few tries see both outcomes.
                for _ in 0..3 {
                    let mut s = stalling(mode, Threading::Pool, helpers, 3);
                    s.depth = depth;
                    let what = format!("{mode:?} x{helpers} depth {depth}");
                    match frame_loop::run(&s, &Budget::exact(3), |_, _| {}) {
                        Ok(run) => assert_eq!(run.trial.frames.len(), 3, "{what}"),
                        Err(frame_loop::LoopError::Stalled { who, .. }) => {
                            assert!(who.contains("helpers to stop"), "{what}: {who}")
                        }
                        Err(e) => panic!("{what}: {e}"),
                    }
                }
            }
        }
    }
}

/// Every loop shape ends with `Interrupted`, the pool's helpers shut down by its `Drop`.
#[test]
fn a_raised_stop_flag_interrupts_every_loop() {
    let mut loops = vec![(Mode::Serial, Threading::Pool, 1)];
    for mode in threaded_modes() {
        loops.extend([
            (mode, Threading::Pool, 1),
            (mode, Threading::Pool, 2),
            (mode, Threading::Spawn, 1),
        ]);
    }
    for (mode, threading, helpers) in loops {
        let mut s = spec(mode, SyncMethod::Condvar, threading, NormalMethod::Analytic);
        s.helper_cores = helper_cores(mode, helpers);
        s.stop = Some(std::sync::Arc::new(std::sync::atomic::AtomicBool::new(
            true,
        )));
        let mut observed = 0;
        let got = frame_loop::run(&s, &Budget::exact(10), |_, _| observed += 1);
        assert!(
            matches!(got, Err(frame_loop::LoopError::Interrupted)),
            "{mode:?} {threading:?} x{helpers}: {:?}",
            got.map(|_| ())
        );
        assert!(
            observed <= 1,
            "{mode:?} {threading:?} x{helpers}: no frame after the stop"
        );
    }
}

/// Under `latest`, every mesh the main thread takes is the surface at the frame index it was
/// computed for (bit for bit what a lone stepper of the cell's model gives at that time), and the indices never
/// decrease, whatever the helper dropped or the main thread took twice.
#[test]
fn latest_meshes_are_the_serial_mesh_of_their_index_and_indices_never_decrease() {
    for sync in SyncMethod::of_policy(Policy::Latest) {
        for mode in threaded_modes() {
            for consume in [Consume::Copy, Consume::Handle] {
                let mut s = spec(mode, sync, Threading::Pool, NormalMethod::Analytic);
                s.policy = Policy::Latest;
                s.consume = consume;
                let seen = frames(&s);
                let indices: Vec<u64> = seen.iter().map(|(k, _)| *k).collect();
                assert!(
                    indices.windows(2).all(|w| w[0] <= w[1]),
                    "{sync} {mode} {consume}: {indices:?}"
                );
                let model = s.ocean.model();
                let mut ocean = model
                    .prepare(s.grid, &s.params, s.normals, s.kernel)
                    .unwrap();
                let mut want = model.mesh(s.grid);
                for (k, mesh) in &seen {
                    ocean.step((*k as f64 * s.time_step) as f32, &mut want);
                    assert!(
                        mesh == &want,
                        "{sync} {mode} {consume}: the mesh taken for index {k} differs"
                    );
                }
            }
        }
    }
}

/// The policy's refusals, one line naming the field: a method that cannot serve the policy
/// (with the list of those that can), and what `latest` has no use for.
#[test]
fn latest_refuses_fifo_methods_depth_helpers_and_spawn() {
    let base = || {
        let mut s = spec(
            Mode::Up,
            SyncMethod::Atomic,
            Threading::Pool,
            NormalMethod::Analytic,
        );
        s.policy = Policy::Latest;
        s
    };
    let refused = |s: LoopSpec| s.check().unwrap_err().to_string();
    let mut s = base();
    s.sync = SyncMethod::Condvar;
    let e = refused(s);
    assert!(
        e.starts_with("sync: `condvar`") && e.contains("atomic, triple-buffer"),
        "{e}"
    );
    let mut s = spec(
        Mode::Up,
        SyncMethod::TripleBuffer,
        Threading::Pool,
        NormalMethod::Analytic,
    );
    s.policy = Policy::Fifo;
    assert!(refused(s).starts_with("sync: `triple-buffer`"));
    let mut s = base();
    s.depth = 2;
    assert!(refused(s).starts_with("depth: 2"));
    let mut s = base();
    s.helper_cores = helper_cores(Mode::Up, 2);
    assert!(refused(s).starts_with("helpers: "));
    let mut s = base();
    s.threading = Threading::Spawn;
    assert!(refused(s).starts_with("threading: "));
    assert!(base().check().is_ok());
}

/// Under `latest` the main thread makes progress whichever side is slow: the loop ends within
/// its budget, and the indices it takes never decrease and do advance. A slow helper makes the
/// main thread show a mesh again; a slow main thread makes the helper drop meshes.
#[test]
fn latest_makes_progress_with_a_slow_helper_and_with_a_slow_main_thread() {
    let budget = Budget {
        warmup_frames: 0,
        min_frames: 10,
        min_seconds: 0.2,
        max_seconds: 30.0,
    };
    for sync in SyncMethod::of_policy(Policy::Latest) {
        for mode in threaded_modes() {
            // (helper's grid, main's workload iterations): a 96×96 mesh with neighbour
            // normals against next to no work, and a 9×9 mesh against a long chain.
            for (n, iterations, slow) in [(96, 50, "helper"), (9, 300_000, "main")] {
                let mut s = spec(mode, sync, Threading::Pool, NormalMethod::Neighbors);
                s.policy = Policy::Latest;
                s.grid = Grid::new(n, 0.75).unwrap();
                s.workload_amount = iterations;
                let (done, finished) = std::sync::mpsc::channel();
                std::thread::spawn(move || {
                    let mut indices = Vec::new();
                    let run = frame_loop::run(&s, &budget, |k, _| indices.push(k));
                    let _ = done.send((run.map(|r| r.trial.frames.len()), indices));
                });
                let what = format!("{sync} {mode} slow {slow}");
                let (run, indices) = finished
                    .recv_timeout(Duration::from_secs(120))
                    .unwrap_or_else(|_| panic!("{what}: the loop never ended"));
                let frames = run.unwrap_or_else(|e| panic!("{what}: {e}"));
                assert!(frames >= 10, "{what}: {frames} frames");
                assert!(
                    indices.windows(2).all(|w| w[0] <= w[1]),
                    "{what}: an index went back"
                );
                let distinct = indices.windows(2).filter(|w| w[0] < w[1]).count() + 1;
                assert!(
                    distinct >= 2,
                    "{what}: the main thread took only frame {} in {} frames",
                    indices[0],
                    indices.len()
                );
            }
        }
    }
}

/// `render` reads the consumed mesh after the consume step: in every mode, depth, consumption,
/// method and helper count its vertex buffer after the last frame is serial's, bit for bit (a
/// slot released before render read it would let the helper overwrite it mid-read); under
/// `latest` it runs and draws one of the meshes the helper finished.
#[test]
fn render_draws_the_same_vertex_buffer_in_every_mode_depth_consumption_method_and_helpers() {
    const FEW: u64 = 24;
    let analytic = |mode, sync, threading| {
        let mut s = spec(mode, sync, threading, NormalMethod::Analytic);
        (s.workload_kind, s.workload_amount) = (WorkloadKind::RENDER, 100);
        s.work_params = KindParams::default_for(WorkloadKind::RENDER).unwrap();
        s.grid = Grid::new(24, 0.75).unwrap();
        s
    };
    let serial = || analytic(Mode::Serial, SyncMethod::Atomic, Threading::Pool);
    // The digest of the buffer after `frames` frames, the last mesh index shown, and the cell.
    let render = |s: LoopSpec, frames: u64| {
        let what = describe(&s);
        let mut last = None;
        let run = frame_loop::run(&s, &Budget::exact(frames), |k, _| last = Some(k))
            .unwrap_or_else(|e| panic!("{what}: {e}"));
        assert!(
            run.trial.frames.iter().all(|f| f.workload_ns > 0),
            "{what}: render's time is the frame's workload"
        );
        (run.work_digest, last.expect("frames were shown"), what)
    };
    let (expect, _, _) = render(serial(), FEW);
    let mut slower = serial();
    slower.time_step *= 2.0;
    assert_ne!(render(slower, FEW).0, expect, "the buffer follows the mesh");
    for mode in threaded_modes() {
        for consume in [Consume::Copy, Consume::Read, Consume::Handle] {
            let mut cells = Vec::new();
            for depth in 1..=frame_loop::MAX_DEPTH {
                for sync in SyncMethod::of_policy(Policy::Fifo) {
                    cells.push((analytic(mode, sync, Threading::Pool), depth, 1));
                }
            }
            cells.push((analytic(mode, SyncMethod::Atomic, Threading::Spawn), 1, 1));
            cells.push((analytic(mode, SyncMethod::Condvar, Threading::Pool), 2, 3));
            for (mut s, depth, helpers) in cells {
                (s.depth, s.consume) = (depth, consume);
                s.helper_cores = helper_cores(mode, helpers);
                let (digest, _, what) = render(s, FEW);
                assert_eq!(digest, expect, "{what}");
            }
        }
        for sync in SyncMethod::of_policy(Policy::Latest) {
            let mut s = analytic(mode, sync, Threading::Pool);
            s.policy = Policy::Latest;
            let (digest, last, what) = render(s, FEW);
            // The serial loop run up to the mesh `latest` showed last draws the same buffer.
            let (drawn, _, _) = render(serial(), last + 1);
            assert_eq!(digest, drawn, "{what}: the buffer of mesh {last}");
        }
    }
}

/// The projected grid, with a camera on a path so that every frame's vertices move: every mode,
/// method, helper count (1-3), depth and consumption, a helper per frame, and `latest`, give the
/// serial meshes bit for bit, with either kernel.
#[test]
fn projected_meshes_are_bit_identical_in_every_mode_method_depth_and_helper_count() {
    const FEW: u64 = 24;
    let projected = |mode, sync, threading| {
        let mut s = spec(mode, sync, threading, NormalMethod::Analytic);
        s.grid_kind = GridKind::Projected;
        s.camera = Camera {
            height: Some(5.0),
            pitch_degrees: 20.0,
            path: Some(oceanbench::camera::CameraPath {
                radius: 3.0,
                period_seconds: 0.25,
            }),
            ..Camera::default()
        };
        s
    };
    let collect = |s: &LoopSpec| {
        let mut seen = Vec::new();
        frame_loop::run(s, &Budget::exact(FEW), |k, mesh| {
            seen.push((k, mesh.clone()))
        })
        .unwrap_or_else(|e| panic!("{:?} {:?} x{}: {e}", s.mode, s.sync, s.helpers()));
        seen
    };
    let consumes = [Consume::Copy, Consume::Read, Consume::Handle];
    for (ocean, kernel, n) in [
        (OceanKind::SINES, Kernel::Reference, 9),
        (OceanKind::SINES, Kernel::Fast, 9),
        (OceanKind::FFT, Kernel::Reference, 16),
        (OceanKind::FFT, Kernel::Fast, 16),
    ] {
        let grid = Grid::new(n, 0.75).unwrap();
        let mut serial = projected(Mode::Serial, SyncMethod::Atomic, Threading::Pool);
        (serial.kernel, serial.ocean, serial.grid) = (kernel, ocean, grid);
        let serial = collect(&serial);
        assert_ne!(serial[0].1.x, serial[1].1.x, "the grid follows the camera");
        let mut runs = 0;
        for mode in threaded_modes() {
            for (m, sync) in SyncMethod::of_policy(Policy::Fifo).enumerate() {
                for helpers in 1..=3 {
                    let mut s = projected(mode, sync, Threading::Pool);
                    (s.kernel, s.ocean, s.grid) = (kernel, ocean, grid);
                    s.helper_cores = helper_cores(mode, helpers);
                    s.depth = 1 + (m + helpers) % frame_loop::MAX_DEPTH;
                    s.consume = consumes[(m + helpers) % consumes.len()];
                    let what = format!(
                        "{ocean:?} {kernel:?} {mode:?} {sync:?} x{helpers} d{} {:?}",
                        s.depth, s.consume
                    );
                    let got = collect(&s);
                    let indices: Vec<u64> = got.iter().map(|(k, _)| *k).collect();
                    assert_eq!(indices, (0..FEW).collect::<Vec<_>>(), "{what}");
                    for ((k, mesh), (_, smesh)) in got.iter().zip(&serial) {
                        assert!(mesh == smesh, "{what}: frame {k} differs");
                    }
                    runs += 1;
                }
            }
            let mut s = projected(mode, SyncMethod::Atomic, Threading::Spawn);
            (s.kernel, s.ocean, s.grid) = (kernel, ocean, grid);
            assert!(collect(&s) == serial, "{kernel:?} {mode:?} spawn");
            for sync in SyncMethod::of_policy(Policy::Latest) {
                let mut s = projected(mode, sync, Threading::Pool);
                (s.kernel, s.ocean, s.grid, s.policy) = (kernel, ocean, grid, Policy::Latest);
                let mut stepper = oceanbench::projected::stepper(
                    s.grid_kind,
                    s.ocean.model(),
                    s.grid,
                    &s.params,
                    s.normals,
                    s.kernel,
                    s.camera,
                )
                .unwrap();
                let mut want = s.ocean.model().mesh(s.grid);
                for (k, mesh) in collect(&s) {
                    stepper.step((k as f64 * s.time_step) as f32, &mut want);
                    assert!(
                        mesh == want,
                        "{kernel:?} {mode:?} latest {sync:?}: frame {k}"
                    );
                }
            }
        }
        assert!(runs > 0);
    }
}

/// `fog` gives the same coefficients to every vertex of the consumed mesh in every mode,
/// depth, consumption and method (it reads the mesh like `render`), and records its pass.
#[test]
fn fog_fields_are_the_same_in_every_mode_depth_consumption_and_method() {
    const FEW: u64 = 12;
    let fog = |mode, sync| {
        let mut s = spec(mode, sync, Threading::Pool, NormalMethod::Analytic);
        (s.workload_kind, s.workload_amount) = (WorkloadKind::FOG, 10);
        s.work_params = KindParams::default_for(WorkloadKind::FOG).unwrap();
        s.grid = Grid::new(16, 0.75).unwrap();
        s
    };
    let field = |s: LoopSpec| {
        let what = format!("{:?} {:?} d{} {:?}", s.mode, s.sync, s.depth, s.consume);
        let run = frame_loop::run(&s, &Budget::exact(FEW), |_, _| {})
            .unwrap_or_else(|e| panic!("{what}: {e}"));
        let Some(r) = run.work_record else {
            panic!("{what}: fog records its pass")
        };
        assert_eq!(r.get("volume"), Some(10.0), "{what}");
        (run.work_digest, what)
    };
    let (expect, _) = field(fog(Mode::Serial, SyncMethod::Atomic));
    let mut slower = fog(Mode::Serial, SyncMethod::Atomic);
    slower.time_step *= 2.0;
    assert_ne!(field(slower).0, expect, "the fog follows the mesh");
    for mode in threaded_modes() {
        for consume in [Consume::Copy, Consume::Read, Consume::Handle] {
            for (sync, depth) in [(SyncMethod::Atomic, 1), (SyncMethod::Condvar, 2)] {
                let mut s = fog(mode, sync);
                (s.depth, s.consume) = (depth, consume);
                let (digest, what) = field(s);
                assert_eq!(digest, expect, "{what}");
            }
        }
    }
}
