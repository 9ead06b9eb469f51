//! What the integration tests share: the binary, run from the checkout or a folder of the test's;
//! the checks on its refusals; and the committed fixture run.

// Each test file is its own crate and uses a part of this module; the rest would warn there.
#![allow(dead_code)]

use oceanbench::results::Results;
use std::ffi::OsStr;
use std::path::Path;
use std::process::{Command, Output};

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

/// The binary with `args`, in the checkout's top folder, for a test to set up further.
pub fn command(args: &[impl AsRef<OsStr>]) -> Command {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_oceanbench"));
    cmd.args(args).current_dir(root());
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
