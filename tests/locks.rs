//! Two runs at once and a failed write, as a user meets them: a second run into a results folder
//! in use is refused, a second run on cores in use waits (or is refused with `--no-wait`), and a
//! write that fails leaves no temporary file. Every test gives its processes a lock directory of
//! its own (OCEANBENCH_LOCK_DIR), so tests running in parallel never see each other's locks.

mod common;

use common::{assert_one_line_exit_2, assert_success, command_locked};
use oceanbench::doctor::{Report, Severity};
use oceanbench::results::Results;
use std::path::Path;
use std::process::{Child, Command, Output};
use std::time::{Duration, Instant};

/// A run on cores 0 and 1 that measures for a few seconds: long enough for a second process to
/// start while it holds its locks.
const LONG_RUN: &[&str] = &[
    "run",
    "--size",
    "8",
    "--frames",
    "2",
    "--seconds",
    "2",
    "--trials",
    "2",
    "--cores",
    "0,1",
];

/// A run on cores 0 and 1 that takes well under a second.
const SHORT_RUN: &[&str] = &[
    "run",
    "--size",
    "8",
    "--frames",
    "2",
    "--seconds",
    "0.01",
    "--trials",
    "1",
    "--cores",
    "0,1",
];

/// How long any process of these tests may take: a lock that never frees fails the test within
/// this, instead of hanging it.
const LIMIT: Duration = Duration::from_secs(20);

/// Runs `cmd` to its end, or kills it and fails once it has run for [`LIMIT`].
fn output(cmd: &mut Command) -> Output {
    finish(cmd.spawn().unwrap())
}

/// Waits for `child`, or kills it and fails once it has run for [`LIMIT`].
fn finish(mut child: Child) -> Output {
    let deadline = Instant::now() + LIMIT;
    while child.try_wait().unwrap().is_none() {
        if Instant::now() > deadline {
            let _ = child.kill();
            let out = child.wait_with_output().unwrap();
            panic!(
                "still running after {LIMIT:?} (a lock that never frees?): {}",
                stderr(&out)
            );
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

fn with(base: &[&str], more: &[&str]) -> Vec<String> {
    base.iter().chain(more).map(|s| s.to_string()).collect()
}

fn strs(v: &[String]) -> Vec<&str> {
    v.iter().map(String::as_str).collect()
}

/// Waits until `child` has written its pid into the lock file at `path`, so it holds the lock.
fn wait_for_holder(child: &mut Child, path: &Path) {
    let pid = format!("pid {}:", child.id());
    let deadline = Instant::now() + LIMIT;
    loop {
        if std::fs::read_to_string(path).is_ok_and(|t| t.starts_with(&pid)) {
            return;
        }
        if let Some(status) = child.try_wait().unwrap() {
            panic!(
                "the first run ended ({status}) before it held {}",
                path.display()
            );
        }
        assert!(Instant::now() < deadline, "{} never held", path.display());
        std::thread::sleep(Duration::from_millis(20));
    }
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// Asserts exit 2 with one stderr line naming `pid` and every needle.
fn assert_refused(out: &Output, pid: u32, needles: &[&str]) {
    let err = assert_one_line_exit_2(out, needles);
    assert!(
        err.contains(&format!("pid {pid}:")),
        "{err:?} names no holder"
    );
}

fn lock_files(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .map(|entries| {
            entries
                .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
                .filter(|n| n.ends_with(".lock"))
                .collect()
        })
        .unwrap_or_default()
}

#[test]
fn a_second_run_into_a_folder_in_use_is_refused_and_the_first_completes() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let out_arg = out.to_string_lossy().into_owned();
    let (first_locks, second_locks) = (tmp.path().join("locks-1"), tmp.path().join("locks-2"));
    let mut first = command_locked(&first_locks, &strs(&with(LONG_RUN, &["--out", &out_arg])))
        .spawn()
        .unwrap();
    wait_for_holder(&mut first, &out.join(".oceanbench.lock"));

    // Its own core locks: only the folder's lock can stop it.
    let second = output(&mut command_locked(
        &second_locks,
        &strs(&with(SHORT_RUN, &["--out", &out_arg])),
    ));
    assert_refused(&second, first.id(), &["--out", &out_arg]);

    let first = finish(first);
    assert_success(&first);
    let results = Results::load(&out.join("results.json")).unwrap();
    assert!(results.finished.is_some());
    assert_eq!(results.cells.len(), 1);
    assert!(results.cells[0].summary.is_some(), "{:?}", results.cells[0]);
    assert_eq!(
        results.cells[0].summary.as_ref().unwrap().fps_trials.len(),
        2
    );
    assert!(lock_files(&out).is_empty(), "{:?}", lock_files(&out));
    assert!(lock_files(&first_locks).is_empty());
}

#[test]
fn a_run_on_cores_in_use_is_refused_with_no_wait_and_doctor_names_the_holder() {
    let tmp = tempfile::tempdir().unwrap();
    let locks = tmp.path().join("locks");
    let mut first = command_locked(&locks, LONG_RUN).spawn().unwrap();
    wait_for_holder(&mut first, &locks.join("core-1.lock"));

    let second = output(&mut command_locked(
        &locks,
        &strs(&with(SHORT_RUN, &["--no-wait"])),
    ));
    assert_refused(&second, first.id(), &["--no-wait", "core"]);

    let doctor = output(&mut command_locked(
        &locks,
        &["doctor", "--cores", "0,1", "--seconds", "0.1", "--json"],
    ));
    assert_success(&doctor);
    let report: Report = serde_json::from_slice(&doctor.stdout).unwrap();
    let held: Vec<_> = report
        .findings
        .iter()
        .filter(|f| f.check == "locks")
        .collect();
    assert_eq!(held.len(), 2, "{held:?}");
    for f in held {
        assert_eq!(f.severity, Severity::Warn, "{f:?}");
        assert!(f.finding.contains(&format!("pid {}:", first.id())), "{f:?}");
    }

    let first = finish(first);
    assert_success(&first);
    assert!(lock_files(&locks).is_empty(), "{:?}", lock_files(&locks));
}

#[test]
fn a_run_on_cores_in_use_waits_for_them_saying_so_once() {
    let tmp = tempfile::tempdir().unwrap();
    let locks = tmp.path().join("locks");
    let mut first = command_locked(&locks, LONG_RUN).spawn().unwrap();
    wait_for_holder(&mut first, &locks.join("core-0.lock"));
    let pid = first.id();

    let second = output(&mut command_locked(&locks, SHORT_RUN));
    let err = stderr(&second);
    assert_success(&second);
    let waits: Vec<&str> = err.lines().filter(|l| l.contains("waiting")).collect();
    assert_eq!(waits.len(), 1, "{err}");
    assert!(waits[0].contains(&format!("pid {pid}:")), "{err}");

    let first = finish(first);
    assert_success(&first);
    let doctor = output(&mut command_locked(
        &locks,
        &["doctor", "--cores", "0,1", "--seconds", "0.1", "--json"],
    ));
    let report: Report = serde_json::from_slice(&doctor.stdout).unwrap();
    assert!(report
        .findings
        .iter()
        .filter(|f| f.check == "locks")
        .all(|f| f.severity == Severity::Ok));
    assert!(lock_files(&locks).is_empty(), "{:?}", lock_files(&locks));
}

#[test]
fn a_failed_write_leaves_no_temporary_file() {
    use std::os::unix::process::CommandExt;
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let out_arg = out.to_string_lossy().into_owned();
    let mut cmd = command_locked(
        &tmp.path().join("locks"),
        &strs(&with(SHORT_RUN, &["--out", &out_arg])),
    );
    // A full disk, without a mount: files may grow to 2 KiB (the lock file fits, results.json
    // does not), and past that a write fails with EFBIG instead of raising SIGXFSZ.
    // SAFETY: setrlimit and signal are async-signal-safe system calls.
    unsafe {
        cmd.pre_exec(|| {
            let limit = libc::rlimit {
                rlim_cur: 2048,
                rlim_max: 2048,
            };
            if libc::setrlimit(libc::RLIMIT_FSIZE, &limit) != 0
                || libc::signal(libc::SIGXFSZ, libc::SIG_IGN) == libc::SIG_ERR
            {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        });
    }
    let run = output(&mut cmd);
    let err = stderr(&run);
    assert_eq!(run.status.code(), Some(1), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(err.contains("results.json"), "{err}");
    let left: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(left.is_empty(), "{left:?}");
}

#[test]
fn resume_and_balance_take_the_folder_lock_too() {
    let tmp = tempfile::tempdir().unwrap();
    let locks = tmp.path().join("locks");
    let out = tmp.path().join("out");
    let out_arg = out.to_string_lossy().into_owned();
    let written = output(&mut command_locked(
        &locks,
        &strs(&with(SHORT_RUN, &["--out", &out_arg])),
    ));
    assert_success(&written);

    // This test process is the holder: a second process must see the lock whoever took it.
    let held = oceanbench::lock::out_dir(&out).unwrap();
    let resume = output(&mut command_locked(
        &locks,
        &["sweep", "--resume", &out_arg, "--no-wait"],
    ));
    assert_refused(&resume, std::process::id(), &["--resume", &out_arg]);
    let balance = output(&mut command_locked(
        &locks,
        &["balance", "--size", "8", "--out", &out_arg],
    ));
    assert_refused(&balance, std::process::id(), &["--out", &out_arg]);
    drop(held);
    assert!(lock_files(&out).is_empty(), "{:?}", lock_files(&out));
}
