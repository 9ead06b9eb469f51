//! `run`/`sweep --frame-log DIR`: each cell's last trial as a MangoHud log, read back as
//! FlightlessSomething and CapFrameX read it, and the refusals that keep earlier logs.

mod common;

use common::{
    assert_cell_provenance, assert_input_error, assert_run_provenance, assert_success,
    oceanbench_locked, write_file,
};
use oceanbench::findings::provenance;
use oceanbench::frame_log;
use oceanbench::results::Results;
use std::path::Path;

/// Line 1 and line 3 exactly as MangoHud a5e7dc7's src/logging.cpp (writeFileHeaders) writes
/// them, copied from its source rather than from this crate.
const MANGOHUD_SYSTEM_HEADER: &str = "os,cpu,gpu,ram,kernel,driver,cpuscheduler";
const MANGOHUD_COLUMNS: &str = "fps,frametime,cpu_load,cpu_power,gpu_load,cpu_temp,gpu_temp,\
gpu_core_clock,gpu_mem_clock,gpu_vram_used,gpu_power,ram_used,swap_used,process_rss,cpu_mhz,\
elapsed";

/// A log read back: the system values and each frame's 16 numbers.
struct Log {
    system: Vec<String>,
    rows: Vec<Vec<f64>>,
}

fn read_log(path: &Path) -> Log {
    let text = std::fs::read_to_string(path).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], MANGOHUD_SYSTEM_HEADER);
    assert_eq!(lines[2], MANGOHUD_COLUMNS);
    let system: Vec<String> = lines[1].split(',').map(str::to_string).collect();
    assert_eq!(system.len(), 7, "{}", lines[1]);
    let rows = lines[3..]
        .iter()
        .map(|l| {
            let fields: Vec<f64> = l.split(',').map(|f| f.parse().unwrap()).collect();
            assert_eq!(fields.len(), 16, "{l}");
            fields
        })
        .collect();
    Log { system, rows }
}

#[test]
fn a_run_logs_its_last_trial_frame_by_frame_in_mangohud_columns() {
    let dir = tempfile::tempdir().unwrap();
    let (logs, out) = (dir.path().join("logs"), dir.path().join("run"));
    let run = oceanbench_locked(
        dir.path(),
        &[
            "run",
            "--size",
            "16",
            "--mode",
            "dp",
            "--trials",
            "2",
            "--frames",
            "40",
            "--seconds",
            "0",
            "--frame-log",
            logs.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
    );
    assert_success(&run);
    let results = Results::load(&out).unwrap();
    let cell = &results.cells[0];
    let path = logs.join(frame_log::file_name(&cell.key));
    assert!(String::from_utf8_lossy(&run.stdout).contains(&path.display().to_string()));
    let log = read_log(&path);

    // What line 2 has no field for is beside the log: machine, commit, config, placement.
    let sidecar = provenance::sidecar(&path);
    assert_eq!(
        sidecar.file_name().unwrap().to_str().unwrap(),
        frame_log::file_name(&cell.key).replace(".csv", ".provenance.json")
    );
    let record = serde_json::from_str(&std::fs::read_to_string(&sidecar).unwrap()).unwrap();
    let p = assert_run_provenance(&record, &results);
    assert_eq!(p.placement.cells.len(), 1);
    assert_eq!(p.placement.cells[0].name, cell.key.label());
    assert_cell_provenance(&p.placement.cells[0], cell);
    assert_eq!(
        p.config.command, results.command,
        "the command line, recorded before the run"
    );

    assert_eq!(log.system[0], results.machine.os);
    assert_eq!(log.system[4], results.machine.kernel);
    assert!(log.system[3].parse::<u64>().unwrap() > 0, "RAM in kB");
    assert_eq!(
        [&log.system[2], &log.system[5]],
        ["", ""],
        "no GPU, no driver"
    );

    // One line per measured frame of the last trial, not of both.
    assert_eq!(log.rows.len(), 40);
    let (frametime, elapsed) = (1, 15);
    for pair in log.rows.windows(2) {
        assert!(pair[1][elapsed] > pair[0][elapsed], "elapsed rises");
    }
    let sum_ms: f64 = log.rows.iter().map(|r| r[frametime]).sum();
    let last_ns = log.rows.last().unwrap()[elapsed];
    assert!(
        (sum_ms * 1e6 - last_ns).abs() < 1e3,
        "{sum_ms} ms vs {last_ns} ns"
    );
    // The trial's wall time, from its FPS as results.json keeps it.
    let trial_seconds = 40.0 / cell.trials.last().unwrap().fps;
    assert!(
        (sum_ms * 1e-3 - trial_seconds).abs() < 1e-6 * trial_seconds.max(1.0),
        "{sum_ms} ms vs {trial_seconds} s"
    );
    for r in &log.rows {
        assert!(
            (r[0] - 1e3 / r[frametime]).abs() < 1e-3 * r[0].max(1.0),
            "fps"
        );
        assert!(
            r[2..15].iter().all(|&v| v == 0.0),
            "unmeasured columns hold 0"
        );
    }
}

#[test]
fn a_sweep_logs_every_cell_and_refuses_a_folder_holding_their_logs() {
    let dir = tempfile::tempdir().unwrap();
    let config = write_file(
        dir.path(),
        "tiny.json",
        r#"{"name": "tiny", "sizes": [8], "workloads": [0], "modes": ["serial", "dp"],
            "sync": ["atomic"], "trials": 1, "warmup_frames": 2, "min_frames": 25,
            "min_seconds": 0.0, "workload_levels": [{"micros": 0}]}"#,
    );
    let logs = dir.path().join("logs");
    let sweep = |out: &str| {
        let out = dir.path().join(out);
        let args = [
            "sweep",
            &config,
            "--out",
            out.to_str().unwrap(),
            "--quiet",
            "--no-charts",
            "--no-report",
            "--no-doctor",
            "--frame-log",
            logs.to_str().unwrap(),
        ];
        oceanbench_locked(dir.path(), &args)
    };
    assert_success(&sweep("first"));
    let results = Results::load(&dir.path().join("first")).unwrap();
    assert_eq!(results.cells.len(), 2);
    for cell in &results.cells {
        let path = logs.join(frame_log::file_name(&cell.key));
        let log = read_log(&path);
        assert_eq!(log.rows.len(), 25);
        // The last row's rewrite: the placement results.json ends with.
        let sidecar = std::fs::read_to_string(provenance::sidecar(&path)).unwrap();
        let p = assert_run_provenance(&serde_json::from_str(&sidecar).unwrap(), &results);
        assert_cell_provenance(&p.placement.cells[0], cell);
    }
    assert_eq!(
        std::fs::read_dir(&logs).unwrap().count(),
        4,
        "a log and its provenance per cell"
    );

    // Again into the same folder: refused before anything runs, the logs kept.
    let kept = logs.join(frame_log::file_name(&results.cells[0].key));
    let before = std::fs::read(&kept).unwrap();
    assert_input_error(&sweep("second"), &["--frame-log", "already exists"]);
    assert_eq!(std::fs::read(&kept).unwrap(), before);
    assert!(!dir.path().join("second").join("results.json").exists());
}

#[test]
fn a_frame_log_folder_that_is_a_file_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("taken");
    std::fs::write(&file, "kept").unwrap();
    let out = oceanbench_locked(
        dir.path(),
        &["run", "--size", "8", "--frame-log", file.to_str().unwrap()],
    );
    assert_input_error(&out, &["--frame-log", "cannot create"]);
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "kept");
}
