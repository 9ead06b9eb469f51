//! Stops that always stop: one SIGTERM ends a frame of a minute's work at once, with status 130,
//! and a sweep keeps the rows it finished.

mod common;

use oceanbench::results::Results;
use std::path::Path;
use std::process::{Child, Stdio};
use std::time::{Duration, Instant};

fn start(args: &[&str]) -> Child {
    common::command(args)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("the binary starts")
}

/// Whether the process is inside a frame: its frame loop runs on a thread named `ocean-main`.
fn in_a_frame(child: &Child) -> bool {
    let tasks = format!("/proc/{}/task", child.id());
    std::fs::read_dir(tasks).is_ok_and(|dir| {
        dir.flatten().any(|t| {
            std::fs::read_to_string(t.path().join("comm")).is_ok_and(|c| c.trim() == "ocean-main")
        })
    })
}

fn wait_for(what: &str, mut ready: impl FnMut() -> bool) {
    let start = Instant::now();
    while !ready() {
        assert!(start.elapsed() < Duration::from_secs(60), "never {what}");
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Sends one SIGTERM and returns how long the process took to exit, and its status.
fn terminate(mut child: Child) -> (Duration, Option<i32>) {
    // SAFETY: kill only sends a signal to the child's pid, which is still ours (not reaped).
    assert_eq!(unsafe { libc::kill(child.id() as i32, libc::SIGTERM) }, 0);
    let sent = Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            return (sent.elapsed(), status.code());
        }
        if sent.elapsed() > Duration::from_secs(20) {
            let _ = child.kill();
            panic!("still running 20 s after SIGTERM");
        }
        std::thread::sleep(Duration::from_millis(10));
    }
}

#[test]
fn one_sigterm_ends_a_minute_long_frame_at_once() {
    let child = start(&[
        "run",
        "--size",
        "8",
        "--mode",
        "up",
        "--workload-micros",
        "60e6",
        "--timeout",
        "120",
        "--frames",
        "1",
        "--seconds",
        "0",
        "--trials",
        "1",
    ]);
    wait_for("in a frame", || in_a_frame(&child));
    std::thread::sleep(Duration::from_millis(200));
    let (took, status) = terminate(child);
    assert_eq!(status, Some(130));
    assert!(took < Duration::from_secs(2), "took {took:?}");
}

#[test]
fn an_interrupted_sweep_keeps_the_rows_it_finished() {
    let dir = tempfile::tempdir().unwrap();
    let config = common::write_file(
        dir.path(),
        "stop.json",
        r#"{"sizes": [8], "workloads": [0, 1], "modes": ["serial"], "trials": 1,
            "warmup_frames": 1, "min_frames": 3, "min_seconds": 0, "timeout_seconds": 120,
            "workload_levels": [{"micros": 0}, {"micros": 60000000}]}"#,
    );
    let out = dir.path().join("out");
    let child = start(&[
        "sweep",
        &config,
        "--out",
        out.to_str().unwrap(),
        "--quiet",
        "--no-charts",
        "--no-doctor",
    ]);
    let results = out.join("results.json");
    wait_for("a finished row", || Path::new(&results).exists());
    wait_for("in the second row's frame", || in_a_frame(&child));
    std::thread::sleep(Duration::from_millis(200));
    let (took, status) = terminate(child);
    assert_eq!(status, Some(130));
    assert!(took < Duration::from_secs(2), "took {took:?}");
    let kept = Results::load(&results).unwrap();
    assert_eq!(kept.cells.len(), 1, "the first row is kept");
    assert_eq!(kept.cells[0].key.workload, 0);
    assert!(kept.finished.is_none());
}
