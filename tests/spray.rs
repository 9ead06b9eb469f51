//! `spray` in the frame loops: the same particles after the same frames in every mode, method,
//! helper count, consumption and depth; at depth > 1 and under `latest` the spray flew over the
//! meshes the results say it consumed. Its command-line input is tested in `tests/cli.rs`.

mod common;

use common::{describe, helper_cores, threaded_modes};
use oceanbench::frame_loop::{self, Budget, Consume, LoopSpec, Mode};
use oceanbench::ocean::{FftParams, Grid, Mesh, OceanKind, OceanParams};
use oceanbench::sync::{Policy, SyncMethod};
use oceanbench::workload::spray::SprayKind;
use oceanbench::workload::{KindParams, SprayParams, Work, WorkloadKind};

const FRAMES: u64 = 30;

/// `params` with a cap of 200 particles a frame, so that the pool turns over in a short loop.
fn spray_params(params: SprayParams) -> KindParams {
    KindParams::new(
        &SprayKind,
        SprayParams {
            emission_cap: 200,
            ..params
        },
    )
    .unwrap()
}

/// A steep FFT sea (choppiness 3: it folds at N = 32) with spray on the main thread.
fn spec(mode: Mode, sync: SyncMethod, helpers: usize) -> LoopSpec {
    LoopSpec {
        grid: Grid::new(32, 1.0).unwrap(),
        ocean: OceanKind::FFT,
        params: OceanParams::default().with(FftParams {
            choppiness: 3.0,
            ..FftParams::default()
        }),
        workload_kind: WorkloadKind::SPRAY,
        workload_amount: 3_000,
        work_params: spray_params(SprayParams::default()),
        helper_cores: helper_cores(mode, helpers),
        ..common::loop_spec(mode, sync)
    }
}

/// The spray's digest after the frames, and the mesh frame each frame consumed.
fn fly(s: &LoopSpec) -> (u64, Vec<u64>) {
    let what = describe(s);
    let run = frame_loop::run(s, &Budget::exact(FRAMES), |_, _| {})
        .unwrap_or_else(|e| panic!("{what}: {e}"));
    let frames = &run.trial.frames;
    assert_eq!(frames.len() as u64, FRAMES, "{what}");
    assert!(
        frames.iter().all(|f| f.work_counts.is_some()),
        "{what}: every frame counts its particles"
    );
    (
        run.work_digest,
        frames.iter().map(|f| f.mesh_frame).collect(),
    )
}

/// The spray flown outside any loop over the meshes of `indices`, in order: what a loop that
/// consumed those meshes must have produced.
fn replay(s: &LoopSpec, indices: &[u64]) -> u64 {
    let model = s.ocean.model();
    let mut ocean = model
        .prepare(s.grid, &s.params, s.normals, s.kernel)
        .unwrap();
    let Work::OnMesh(mut work) = WorkloadKind::SPRAY
        .kind()
        .unwrap()
        .build(&s.work_spec(), &s.work_params)
    else {
        panic!("spray runs on the consumed mesh")
    };
    let mut mesh: Mesh = model.mesh(s.grid);
    for &k in indices {
        ocean.step((k as f64 * s.time_step) as f32, &mut mesh);
        work.run(k, &mesh, None).unwrap();
    }
    work.digest()
}

#[test]
fn every_mode_method_helper_count_and_consumption_flies_the_same_particles_at_depth_1() {
    let serial = spec(Mode::Serial, SyncMethod::Atomic, 1);
    let (expect, indices) = fly(&serial);
    assert_eq!(indices, (0..FRAMES).collect::<Vec<_>>());
    assert_eq!(replay(&serial, &indices), expect);
    let mut calmer = serial.clone();
    calmer.work_params = spray_params(SprayParams {
        speed: 3.0,
        ..SprayParams::default()
    });
    assert_ne!(fly(&calmer).0, expect, "the digest sees the particles");
    for consume in [Consume::Copy, Consume::Read, Consume::Handle] {
        let mut s = serial.clone();
        s.consume = consume;
        assert_eq!(fly(&s).0, expect, "serial {consume:?}");
        for mode in threaded_modes() {
            for sync in SyncMethod::of_policy(Policy::Fifo) {
                let mut s = spec(mode, sync, 1);
                s.consume = consume;
                assert_eq!(fly(&s).0, expect, "{mode:?} {sync:?} {consume:?}");
            }
            for helpers in [2, 3] {
                let mut s = spec(mode, SyncMethod::Atomic, helpers);
                s.consume = consume;
                assert_eq!(fly(&s).0, expect, "{mode:?} h{helpers} {consume:?}");
            }
        }
    }
}

/// Run-ahead changes which mesh is newest, not which one a `fifo` frame consumes: the spray at
/// depth 2-4 flies over meshes 0, 1, 2, ... as the records say (and as serial does), however
/// many the helper had finished beyond them. Under `latest` it flies over whichever meshes the
/// records name, repeats and skips included.
#[test]
fn the_spray_flies_over_the_meshes_the_records_say_it_consumed() {
    let (serial, _) = fly(&spec(Mode::Serial, SyncMethod::Atomic, 1));
    for mode in threaded_modes() {
        for (sync, depth) in [
            (SyncMethod::Atomic, 2),
            (SyncMethod::Condvar, 3),
            (SyncMethod::Atomic, 4),
        ] {
            for consume in [Consume::Copy, Consume::Handle] {
                let mut s = spec(mode, sync, 1);
                (s.depth, s.consume) = (depth, consume);
                let (digest, indices) = fly(&s);
                let what = format!("{mode:?} {sync:?} d{depth} {consume:?}");
                assert_eq!(indices, (0..FRAMES).collect::<Vec<_>>(), "{what}");
                assert_eq!(digest, replay(&s, &indices), "{what}");
                assert_eq!(digest, serial, "{what}");
            }
        }
        for sync in SyncMethod::of_policy(Policy::Latest) {
            let mut s = spec(mode, sync, 1);
            s.policy = Policy::Latest;
            let (digest, indices) = fly(&s);
            assert!(indices.windows(2).all(|w| w[0] <= w[1]), "{indices:?}");
            assert_eq!(digest, replay(&s, &indices), "{mode:?} latest {sync:?}");
        }
    }
}

#[test]
fn a_library_caller_cannot_run_spray_where_a_config_could_not() {
    // The loop asks the same rules a config does (cell::rules), so spray on the sines, which
    // have no folds, is refused before a frame runs rather than flying nothing.
    let mut s = spec(Mode::Serial, SyncMethod::Atomic, 1);
    s.ocean = OceanKind::SINES;
    s.params = OceanParams::default();
    let e = frame_loop::run(&s, &Budget::exact(FRAMES), |_, _| {})
        .expect_err("spray on the sines is refused")
        .to_string();
    assert!(e.contains("spray needs the fft ocean's folds"), "{e}");
    let mut s = spec(Mode::Dp, SyncMethod::Atomic, 1);
    s.work_params = KindParams::default_for(WorkloadKind::SYNTHETIC).unwrap();
    let e = frame_loop::run(&s, &Budget::exact(FRAMES), |_, _| {})
        .expect_err("another kind's parameters are refused")
        .to_string();
    assert!(
        e.contains("parameters of workload kind `synthetic` for a `spray` loop"),
        "{e}"
    );
}
