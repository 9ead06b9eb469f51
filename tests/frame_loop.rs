//! Every mode × threading × hand-off delivers the same meshes as the serial loop, each frame
//! exactly once and in order.

use oceanbench::affinity;
use oceanbench::frame_loop::{self, Budget, LoopSpec, Mode, Threading};
use oceanbench::ocean::{Grid, Kernel, Mesh, NormalMethod, WaveSet};
use oceanbench::sync::SyncMethod;
use std::time::Duration;
use strum::VariantArray;

const FRAMES: u64 = 300;

fn spec(mode: Mode, sync: SyncMethod, threading: Threading, normals: NormalMethod) -> LoopSpec {
    let cores = affinity::allowed_cores();
    LoopSpec {
        grid: Grid::new(9, 0.75).unwrap(),
        waves: WaveSet::default(),
        normals,
        kernel: Kernel::Reference,
        mode,
        sync,
        threading,
        workload_iterations: 50,
        main_core: cores[0],
        helper_cores: with_helpers(mode, 1),
        time_step: 1.0 / 60.0,
        timeout: Duration::from_secs(20),
        stop: None,
        stall_at_frame: None,
    }
}

/// The cores of `helpers` helpers in `mode`, from the second allowed core on in dp.
fn with_helpers(mode: Mode, helpers: usize) -> Vec<usize> {
    let cores = affinity::allowed_cores();
    let helper = if mode == Mode::Dp { cores[1] } else { cores[0] };
    frame_loop::helper_cores(mode, cores[0], helper, helpers)
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

fn modes() -> Vec<Mode> {
    if affinity::allowed_cores().len() >= 2 {
        vec![Mode::Up, Mode::Dp]
    } else {
        eprintln!("only one core allowed: dp is not exercised here");
        vec![Mode::Up]
    }
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
        for mode in modes() {
            for threading in [Threading::Pool, Threading::Spawn] {
                for &sync in SyncMethod::VARIANTS {
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
    for mode in modes() {
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
        for mode in modes() {
            for &sync in SyncMethod::VARIANTS {
                for helpers in [2, 3] {
                    let mut s = spec(mode, sync, Threading::Pool, NormalMethod::Analytic);
                    s.kernel = kernel;
                    s.helper_cores = with_helpers(mode, helpers);
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

#[test]
fn every_helper_is_pinned_to_its_core() {
    let cores = affinity::allowed_cores();
    for mode in modes() {
        let mut s = spec(
            mode,
            SyncMethod::Condvar,
            Threading::Pool,
            NormalMethod::Analytic,
        );
        s.helper_cores = with_helpers(mode, 3);
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
        s.helper_cores = with_helpers(Mode::Up, helpers);
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
