//! `spray` in the frame loops and at the command line: the same particles after the same frames
//! in every mode, method, helper count, consumption and depth; at depth > 1 and under `latest`
//! the spray flew over the meshes the results say it consumed; bad input exits 2 with one line.

use oceanbench::affinity;
use oceanbench::camera::Camera;
use oceanbench::frame_loop::{self, Budget, Consume, LoopSpec, Mode, Threading};
use oceanbench::ocean::{FftParams, Grid, Kernel, Mesh, NormalMethod, OceanKind, OceanParams};
use oceanbench::sync::{Policy, SyncMethod};
use oceanbench::workload::{SprayParams, WorkloadKind};
use std::process::{Command, Output};
use std::time::Duration;

const FRAMES: u64 = 30;

/// A steep FFT sea (choppiness 3: it folds at N = 32) with spray on the main thread.
fn spec(mode: Mode, sync: SyncMethod, helpers: usize) -> LoopSpec {
    let cores = affinity::allowed_cores();
    let helper = if mode == Mode::Dp { cores[1] } else { cores[0] };
    LoopSpec {
        grid: Grid::new(32, 1.0).unwrap(),
        ocean: OceanKind::Fft,
        params: OceanParams {
            fft: FftParams {
                choppiness: 3.0,
                ..FftParams::default()
            },
            ..OceanParams::default()
        },
        normals: NormalMethod::Analytic,
        kernel: Kernel::Reference,
        mode,
        policy: Policy::Fifo,
        sync,
        threading: Threading::Pool,
        workload_kind: WorkloadKind::Spray,
        workload_amount: 3_000,
        camera: Camera::default(),
        spray: SprayParams {
            emission_cap: 200,
            ..SprayParams::default()
        },
        depth: 1,
        consume: Consume::Copy,
        main_core: cores[0],
        helper_cores: frame_loop::helper_cores(mode, cores[0], helper, helpers),
        time_step: 1.0 / 60.0,
        timeout: Duration::from_secs(20),
        stop: None,
        stall_at_frame: None,
    }
}

fn modes() -> Vec<Mode> {
    if affinity::allowed_cores().len() >= 2 {
        vec![Mode::Up, Mode::Dp]
    } else {
        eprintln!("only one core allowed: dp is not exercised here");
        vec![Mode::Up]
    }
}

/// The spray's digest after the frames, and the mesh frame each frame consumed.
fn fly(s: &LoopSpec) -> (u64, Vec<u64>) {
    let what = format!(
        "{:?} {:?} {:?} d{} {:?} h{}",
        s.mode,
        s.policy,
        s.sync,
        s.depth,
        s.consume,
        s.helpers()
    );
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
    let mut work = WorkloadKind::work(&s.work_spec());
    let mut mesh: Mesh = model.mesh(s.grid);
    for &k in indices {
        ocean.step((k as f64 * s.time_step) as f32, &mut mesh);
        work.run(k, Some(&mesh), None).unwrap();
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
    calmer.spray.speed = 3.0;
    assert_ne!(fly(&calmer).0, expect, "the digest sees the particles");
    for consume in [Consume::Copy, Consume::Read, Consume::Handle] {
        let mut s = serial.clone();
        s.consume = consume;
        assert_eq!(fly(&s).0, expect, "serial {consume:?}");
        for mode in modes() {
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
    for mode in modes() {
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

fn oceanbench(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_oceanbench"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("the binary runs")
}

/// Asserts exit status 2 and a single stderr line containing every `needle`.
fn assert_input_error(args: &[&str], needles: &[&str]) {
    let out = oceanbench(args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
    assert_eq!(stderr.trim_end().lines().count(), 1, "{args:?}: {stderr}");
    for needle in needles {
        assert!(
            stderr.contains(needle),
            "{args:?}: {stderr:?} lacks {needle:?}"
        );
    }
    assert!(!stderr.contains("panicked"), "{stderr}");
}

const SPRAY: [&str; 5] = ["run", "--workload-kind", "spray", "--ocean", "fft"];

#[test]
fn bad_particle_counts_exit_2_with_one_line_and_keep_what_was_written() {
    let dir = tempfile::tempdir().unwrap();
    let kept = dir.path().join("results.json");
    std::fs::write(&kept, "{\"earlier\": true}").unwrap();
    let out = dir.path().to_string_lossy().into_owned();
    for (particles, needles) in [
        ("0", vec!["--particles", "1 to 4294967295", "got 0"]),
        ("-5", vec!["--particles", "1 to 4294967295", "got -5"]),
        ("2.5", vec!["--particles", "whole number"]),
        ("1e12", vec!["--particles", "MiB for the pool", "available"]),
    ] {
        let mut args = SPRAY.to_vec();
        args.extend(["--particles", particles, "--out", &out]);
        assert_input_error(&args, &needles);
    }
    assert_eq!(
        std::fs::read_to_string(&kept).unwrap(),
        "{\"earlier\": true}"
    );
    assert_input_error(
        &["run", "--particles", "1000"],
        &["--particles", "--workload-kind spray"],
    );
    assert_input_error(
        &["run", "--workload-kind", "spray", "--ocean", "sines"],
        &["spray needs the fft ocean's folds", "sines"],
    );
}

#[test]
fn bad_spray_configs_exit_2_naming_the_field() {
    let dir = tempfile::tempdir().unwrap();
    let config = |extra: &str, levels: &str| {
        let path = dir.path().join("spray.json");
        let text = format!(
            r#"{{"sizes": [16], "modes": ["serial"], "ocean": ["fft"], "normals": ["analytic"],
                "workload_kind": ["spray"], "workloads": [0], "workload_levels": [{levels}]{extra}}}"#
        );
        std::fs::write(&path, text).unwrap();
        path.to_string_lossy().into_owned()
    };
    let good = r#"{"particles": 1000}"#;
    for (extra, levels, needles) in [
        (
            r#", "spray": {"threshold": 1.5}"#,
            good,
            vec!["spray.threshold", "-100 to 1", "1.5"],
        ),
        (
            r#", "spray": {"lifetime": -1}"#,
            good,
            vec!["spray.lifetime", "above 0"],
        ),
        (
            r#", "spray": {"speed": -3}"#,
            good,
            vec!["spray.speed", "0 to 1000"],
        ),
        (
            r#", "spray": {"sped": 3}"#,
            good,
            vec!["spray", "unknown field `sped`", "speed"],
        ),
        (
            "",
            r#"{"particles": 0}"#,
            vec!["workload_levels[0].particles", "1 to"],
        ),
        (
            "",
            r#"{"particles": -2}"#,
            vec!["workload_levels[0].particles", "1 to"],
        ),
        (
            "",
            r#"{"particles": 1e13}"#,
            vec!["workload_levels[0].particles", "MiB for the pool"],
        ),
        (
            "",
            r#"{"micros": 100}"#,
            vec!["workload_levels[0]", "particles", "not converted"],
        ),
        (
            "",
            r#"{"iterations": 100}"#,
            vec!["workload_levels[0]", "`iterations` is not a unit"],
        ),
        (
            r#", "ocean": ["sines"]"#,
            good,
            vec!["spray needs the fft ocean's folds"],
        ),
    ] {
        let path = config(extra, levels);
        let extra_ocean = extra.contains("\"ocean\"");
        let path = if extra_ocean {
            let text = std::fs::read_to_string(&path)
                .unwrap()
                .replace(r#""ocean": ["fft"], "#, "");
            std::fs::write(&path, text).unwrap();
            path
        } else {
            path
        };
        assert_input_error(&["sweep", &path, "--out", "/nonexistent/never"], &needles);
    }
}

#[test]
fn a_sweep_over_both_oceans_skips_the_spray_cells_on_sines_and_says_so_once() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("both.json");
    std::fs::write(
        &config,
        r#"{"sizes": [16], "modes": ["serial"], "ocean": ["sines", "fft"],
            "normals": ["analytic"], "workload_kind": ["spray"], "workloads": [0],
            "workload_levels": [{"particles": 500}], "trials": 1, "warmup_frames": 0,
            "min_frames": 3, "min_seconds": 0, "calibrate": "once"}"#,
    )
    .unwrap();
    let out = dir.path().join("out");
    let run = oceanbench(&[
        "sweep",
        &config.to_string_lossy(),
        "--out",
        &out.to_string_lossy(),
        "--no-charts",
        "--no-doctor",
        "--quiet",
    ]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{stderr}");
    let note = "spray cells on the sines ocean skipped: spray needs the fft ocean's folds";
    assert_eq!(stderr.matches(note).count(), 1, "{stderr}");
    let results = oceanbench::results::Results::load(&out.join("results.json")).unwrap();
    let oceans: Vec<OceanKind> = results.cells.iter().map(|c| c.key.ocean).collect();
    assert_eq!(oceans, [OceanKind::Fft]);
    let particles = &results.cells[0].summary.as_ref().unwrap().particles;
    assert_eq!(particles.len(), 1, "one trial's counts");
    assert!(particles[0].live_max <= 500);
}
