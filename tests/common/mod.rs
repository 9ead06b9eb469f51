//! What the integration tests share: the binary, run from the checkout or a folder of the test's;
//! the checks on its refusals; the committed fixture run; and frame-loop specs for this machine.

// Each test file is its own crate and uses a part of this module; the rest would warn there.
#![allow(dead_code)]

use oceanbench::affinity;
use oceanbench::camera::Camera;
use oceanbench::frame_loop::{self, Consume, LoopSpec, Mode, Threading};
use oceanbench::ocean::{Grid, GridKind, Kernel, NormalMethod, OceanKind, OceanParams};
use oceanbench::results::Results;
use oceanbench::sync::{Policy, SyncMethod};
use oceanbench::workload::{KindParams, WorkloadKind};
use std::ffi::OsStr;
use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::Duration;

/// The quick run committed as a fixture: a small sweep's results.json, a path and an argument.
pub const FIXTURE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/fixtures/quick-results.json"
);

/// The checkout's top folder.
pub fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The fixture run, loaded.
pub fn fixture() -> Results {
    Results::load(Path::new(FIXTURE)).expect("the fixture loads")
}

/// The fixture with five trials a cell, enough for a verdict: FPS times 0.99, 0.995, 1, 1.005, 1.01.
pub fn five_trials() -> Results {
    let mut r = fixture();
    for c in &mut r.cells {
        if let Some(s) = c.summary.as_mut() {
            let f = s.fps;
            s.fps_trials = [0.99, 0.995, 1.0, 1.005, 1.01].map(|k| f * k).to_vec();
        }
    }
    r
}

/// Writes `text` to `dir/name` and gives the path as a command-line argument.
pub fn write_file(dir: &Path, name: &str, text: &str) -> String {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path.to_string_lossy().into_owned()
}

/// The binary with `args`, in the checkout's top folder, for a test to set up further.
pub fn command(args: &[impl AsRef<OsStr>]) -> Command {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_oceanbench"));
    cmd.args(args).current_dir(root());
    cmd
}

/// The binary with `args` and its per-core locks under `lock_dir`, so that tests running on the
/// same cores at once never wait on each other's locks; stdout and stderr are piped, for a child
/// that is spawned and read later as for one that is run to its end.
pub fn command_locked(lock_dir: &Path, args: &[impl AsRef<OsStr>]) -> Command {
    let mut cmd = command(args);
    cmd.env(oceanbench::lock::DIR_ENV, lock_dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    cmd
}

/// Runs the binary with `args` in the checkout's top folder.
pub fn oceanbench(args: &[impl AsRef<OsStr>]) -> Output {
    command(args).output().expect("the binary runs")
}

/// Runs the binary with `args` in `dir`.
pub fn oceanbench_in(dir: &Path, args: &[impl AsRef<OsStr>]) -> Output {
    command(args)
        .current_dir(dir)
        .output()
        .expect("the binary runs")
}

/// Runs the binary with `args` in the checkout's top folder, its per-core locks under
/// `lock_dir` ([`command_locked`]).
pub fn oceanbench_locked(lock_dir: &Path, args: &[impl AsRef<OsStr>]) -> Output {
    command_locked(lock_dir, args)
        .output()
        .expect("the binary runs")
}

/// Asserts the command succeeded, showing what it printed if not.
#[track_caller]
pub fn assert_success(out: &Output) {
    assert!(
        out.status.success(),
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Asserts exit status 2 and one stderr line holding every needle; returns the stderr.
#[track_caller]
pub fn assert_one_line_exit_2(out: &Output, needles: &[&str]) -> String {
    let stderr = String::from_utf8_lossy(&out.stderr).trim_end().to_string();
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    for needle in needles {
        assert!(stderr.contains(needle), "{stderr:?} lacks {needle:?}");
    }
    stderr
}

/// [`assert_one_line_exit_2`], and the line is no panic's; returns the line.
#[track_caller]
pub fn assert_input_error(out: &Output, needles: &[&str]) -> String {
    let stderr = assert_one_line_exit_2(out, needles);
    assert!(!stderr.contains("panicked"), "{stderr}");
    stderr
}

/// Runs the binary with `args` in the checkout and asserts [`assert_input_error`] of it.
#[track_caller]
pub fn refuses(args: &[&str], needles: &[&str]) -> String {
    assert_input_error(&oceanbench(args), needles)
}

/// The threaded modes this machine can run: DP needs a second allowed core.
pub fn threaded_modes() -> Vec<Mode> {
    if affinity::allowed_cores().len() >= 2 {
        vec![Mode::Up, Mode::Dp]
    } else {
        eprintln!("only one core allowed: dp is not exercised here");
        vec![Mode::Up]
    }
}

/// The cores of `helpers` helpers in `mode`: the main thread's core, or the second one in DP.
pub fn helper_cores(mode: Mode, helpers: usize) -> Vec<usize> {
    let cores = affinity::allowed_cores();
    let helper = if mode == Mode::Dp { cores[1] } else { cores[0] };
    frame_loop::helper_cores(mode, cores[0], helper, helpers)
}

/// A one-helper, depth-1 loop of a small sines sea with no workload: tests set what they vary.
pub fn loop_spec(mode: Mode, sync: SyncMethod) -> LoopSpec {
    LoopSpec {
        grid: Grid::new(9, 0.75).unwrap(),
        grid_kind: GridKind::Regular,
        ocean: OceanKind::SINES,
        params: OceanParams::default(),
        normals: NormalMethod::Analytic,
        kernel: Kernel::Reference,
        mode,
        policy: Policy::Fifo,
        sync,
        threading: Threading::Pool,
        workload_kind: WorkloadKind::SYNTHETIC,
        workload_amount: 0,
        camera: Camera::default(),
        work_params: KindParams::default_for(WorkloadKind::SYNTHETIC).unwrap(),
        depth: 1,
        consume: Consume::Copy,
        main_core: affinity::allowed_cores()[0],
        helper_cores: helper_cores(mode, 1),
        time_step: 1.0 / 60.0,
        timeout: Duration::from_secs(20),
        stop: None,
        stall_at_frame: None,
    }
}

/// The loop's cell in a line, for failure messages.
pub fn describe(s: &LoopSpec) -> String {
    format!(
        "{:?} {:?} {:?} d{} {:?} h{}",
        s.mode,
        s.policy,
        s.sync,
        s.depth,
        s.consume,
        s.helpers()
    )
}

/// A tiny config for a kind or model a test registers: `base` with the keys of `extra` replaced,
/// parsed and validated as a config file is.
pub fn config_with(
    base: serde_json::Value,
    extra: serde_json::Value,
) -> Result<oceanbench::config::SweepConfig, oceanbench::config::InputError> {
    let mut value = base;
    for (k, v) in extra.as_object().expect("extra keys are an object") {
        value[k] = v.clone();
    }
    oceanbench::config::SweepConfig::from_json(&value.to_string())
}

/// An export's provenance record (a sidecar, or a trace's `otherData.provenance`), checked
/// against the run it came from: every field present (the parse has no defaults), the machine,
/// the commit and its dirty flag, the config's name and hash, and the run's placement split when
/// the run crossed two cores. The record, for the caller's checks of its cells.
pub fn assert_run_provenance(
    record: &serde_json::Value,
    results: &Results,
) -> oceanbench::findings::provenance::Provenance {
    let p: oceanbench::findings::provenance::Provenance = serde_json::from_value(record.clone())
        .unwrap_or_else(|e| panic!("a provenance record lacks a field: {e}\n{record:#}"));
    let m = &results.machine;
    assert_eq!(p.machine.cpu, m.cpu_model);
    assert_eq!(p.machine.logical_cores, m.logical_cores);
    assert_eq!(p.machine.line, m.line());
    assert_eq!(p.commit.id, m.git_commit);
    assert_eq!(p.commit.dirty, m.git_dirty);
    assert_eq!(p.commit.line, m.provenance_line());
    assert_eq!(p.config.name, results.config.name);
    assert_eq!(
        p.config.hash,
        oceanbench::findings::provenance::config_hash(results),
        "the hash of the config results.json records"
    );
    assert_eq!(p.started, results.started);
    if results.round_trip.before.is_some() {
        assert!(p.placement.split.is_some() && p.placement.summary.is_some());
    }
    p
}

/// A provenance record's cell against the results' cell: its placement word and each kept
/// trial's class and round trips.
pub fn assert_cell_provenance(
    facts: &oceanbench::findings::provenance::CellFacts,
    cell: &oceanbench::results::Cell,
) {
    let trials: Vec<_> = cell
        .trials
        .iter()
        .map(|t| (t.placement, t.round_trip_ns))
        .collect();
    let recorded: Vec<_> = facts
        .trials
        .iter()
        .map(|t| (t.class, t.round_trip_ns))
        .collect();
    assert_eq!(recorded, trials, "{}", facts.name);
    assert_eq!(facts.set_aside, cell.set_aside.len());
    let words = ["near", "far", "one", "mixed", "unplaced"];
    assert!(
        words.contains(&facts.placement.as_str()),
        "{}",
        facts.placement
    );
}
