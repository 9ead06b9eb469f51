//! What the integration tests share: the binary, run from the checkout or a folder of the test's.

#![allow(dead_code)]

use std::path::Path;
use std::process::{Command, Output};

/// Runs the binary with `args` in the checkout's top folder.
pub fn oceanbench(args: &[&str]) -> Output {
    oceanbench_in(Path::new(env!("CARGO_MANIFEST_DIR")), args)
}

/// Runs the binary with `args` in `dir`.
pub fn oceanbench_in(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_oceanbench"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("the binary runs")
}

/// Asserts exit status 2 and one stderr line holding every needle; returns the line.
pub fn assert_input_error(out: &Output, needles: &[&str]) -> String {
    let stderr = String::from_utf8_lossy(&out.stderr).trim_end().to_string();
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    for needle in needles {
        assert!(stderr.contains(needle), "{stderr:?} lacks {needle:?}");
    }
    assert!(!stderr.contains("panicked"), "{stderr}");
    stderr
}
