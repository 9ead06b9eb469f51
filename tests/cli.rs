//! The binary as a user meets it: bad input exits 2 with one line, the mesh CSV, a tiny sweep's
//! files, and the shipped configs.

mod common;

use common::{assert_success, oceanbench, refuses, write_file, FIXTURE};
use oceanbench::config::SweepConfig;
use oceanbench::ocean::{FftParams, Grid, Kernel, NormalMethod, OceanKind, OceanParams, WaveSet};
use oceanbench::results::Results;
use std::path::Path;
use std::process::Command;

#[test]
fn bad_flags_exit_2_with_one_line() {
    refuses(&["run", "--mode", "tri"], &["--mode", "serial, up, dp"]);
    refuses(&["run", "--sync", "futexes"], &["--sync", "futex"]);
    refuses(&["run", "--normals", "x"], &["lookup, neighbors, analytic"]);
    refuses(&["run", "--ocean", "nope"], &["--ocean", "nope", "sines"]);
    refuses(&["run", "--size", "1"], &["--size:", "2 to"]);
    refuses(&["run", "--size", "abc"], &["--size"]);
    refuses(&["run", "--workload", "9"], &["--workload:", "0 to 3"]);
    refuses(&["run", "--trials", "0"], &["--trials:", "1 to 1000"]);
    // A negative number is a value out of range, not an unknown argument, and the error names
    // the flag typed, not the config key it sets.
    refuses(&["run", "--seconds", "-1"], &["--seconds:", ">= 0", "-1"]);
    refuses(
        &["run", "--max-seconds", "0"],
        &["--max-seconds:", ">= --seconds (1)"],
    );
    refuses(&["run", "--pitch", "400"], &["--pitch:", "at most 90"]);
    refuses(
        &["run", "--timeout", "-3"],
        &["--timeout:", "at most 86400"],
    );
    refuses(
        &["run", "--noise-threshold", "-4"],
        &["--noise-threshold:", "below 100"],
    );
    refuses(&["latency", "--samples", "0"], &["--samples", "1 to"]);
    refuses(&["run", "--cores", "0,999"], &["--cores:", "allowed"]);
    refuses(
        &["run", "--normals", "lookup", "--size", "300"],
        &["lookup"],
    );
    refuses(&["run", "--bogus"], &["--bogus"]);
    refuses(&["fly"], &["fly"]);
    refuses(
        &[
            "mesh",
            "--size",
            "4",
            "--time",
            "1",
            "--waves",
            "/nonexistent.json",
            "--out",
            "/tmp/x.csv",
        ],
        &["/nonexistent.json"],
    );
    let mesh = ["mesh", "--size", "4", "--time", "1", "--out", "/tmp/x.csv"];
    refuses(
        &[&mesh[..], &["--ocean", "nope"]].concat(),
        &["--ocean", "nope", "sines"],
    );
}

#[test]
fn bad_configs_exit_2_naming_the_field() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        (r#"{"sizez": [40]}"#, vec!["sizez", "sizes"]),
        (r#"{"modes": ["up", "tri"]}"#, vec!["modes[1]", "serial"]),
        (r#"{"workloads": [7]}"#, vec!["workloads", "7"]),
        (r#"{"sizes": [1]}"#, vec!["sizes", "2 to"]),
        (r#"{"sizes": []}"#, vec!["sizes", "at least one"]),
        (r#"{"trials": -1}"#, vec!["trials"]),
        (
            r#"{"min_seconds": 5, "max_seconds": 1}"#,
            vec!["max_seconds"],
        ),
        (
            r#"{"workloads": [0], "workload_levels": [{"micros": -5}]}"#,
            vec!["workload_levels[0].micros"],
        ),
        (
            r#"{"workloads": [0], "workload_levels": [{"step_fraction": 1}]}"#,
            vec!["workload_levels[0]"],
        ),
        (
            r#"{"waves": [{"amplitude": 1, "wavelength": 0, "speed": 1, "direction": [1, 0], "steepness": 2}]}"#,
            vec!["waves[0].wavelength"],
        ),
        (r#"{"sync": ["atomic", "atomic"]}"#, vec!["sync", "twice"]),
        (
            r#"{"ocean": ["fourier"]}"#,
            vec!["ocean[0]", "fourier", "sines, fft"],
        ),
        (r#"{"ocean": ["sines", "sines"]}"#, vec!["ocean", "twice"]),
        (
            r#"{"workload_kind": ["synthetic", "clouds"]}"#,
            vec!["workload_kind[1]", "synthetic, render, spray, fog"],
        ),
        (
            r#"{"workload_kind": ["fog"], "workloads": [0], "workload_levels": [{"volume": 600}]}"#,
            vec!["workload_levels[0].volume", "0 to 512", "1647 MiB"],
        ),
        (
            r#"{"workload_kind": ["fog"], "workloads": [0], "workload_levels": [{"volume": 8.5}]}"#,
            vec!["workload_levels[0].volume", "whole number"],
        ),
        (r#"{"fog": {"octaves": 0}}"#, vec!["fog.octaves", "1 to 8"]),
        (r#"{"fog": {"octaves": 9}}"#, vec!["fog.octaves", "1 to 8"]),
        (r#"{"fog": {"density": -0.1}}"#, vec!["fog.density", ">= 0"]),
        (
            r#"{"fog": {"blur_width": 4}}"#,
            vec!["fog.blur_width", "odd, 3 to 31"],
        ),
        (
            r#"{"fog": {"blur_width": 1}}"#,
            vec!["fog.blur_width", "odd, 3 to 31"],
        ),
        (
            r#"{"fog": {"thickness": 2}}"#,
            vec!["fog", "thickness", "octaves"],
        ),
        (
            r#"{"workloads": [0], "workload_levels": [{"particles": 100}]}"#,
            vec![
                "workload_levels[0]",
                "`particles` is not a unit",
                "iterations",
            ],
        ),
        (
            r#"{"workloads": [0], "workload_levels": [{"iterations": 100, "micros": 5}]}"#,
            vec!["workload_levels[0]", "one of them"],
        ),
        (
            r#"{"workloads": [0], "workload_levels": [{"iterations": 2.5}]}"#,
            vec!["workload_levels[0].iterations", "whole number"],
        ),
        (
            r#"{"camera": {"pitch_degrees": 0}}"#,
            vec!["camera.pitch_degrees", "above 0 and at most 90"],
        ),
        (
            r#"{"camera": {"fov_degrees": 200}}"#,
            vec!["camera.fov_degrees", "above 0 and below 180"],
        ),
        (r#"{"camera": {"aspect": -1}}"#, vec!["camera.aspect"]),
        (r#"{"camera": {"height": 0}}"#, vec!["camera.height"]),
        (
            r#"{"camera": {"zoom": 2}}"#,
            vec!["camera.zoom", "pitch_degrees"],
        ),
        (r#"{"cores": [0, 0]}"#, vec!["cores", "two different"]),
        (r#"[1, 2]"#, vec!["must be a JSON object"]),
        (r#"{"sizes": [40"#, vec!["not valid JSON"]),
    ];
    for (i, (text, needles)) in cases.iter().enumerate() {
        let path = write_file(dir.path(), &format!("bad{i}.json"), text);
        let out = dir.path().join(format!("out{i}"));
        refuses(&["sweep", &path, "--out", out.to_str().unwrap()], needles);
        assert!(
            !out.join("results.json").exists(),
            "nothing is written for a bad config"
        );
    }
    refuses(
        &["sweep", "/nonexistent/config.json"],
        &["/nonexistent/config.json"],
    );
}

#[test]
fn a_config_with_several_errors_lists_them_all_one_line_each() {
    let dir = tempfile::tempdir().unwrap();
    let path = write_file(
        dir.path(),
        "several.json",
        r#"{"trials": 0, "spacing": -1, "workloads": [7], "camera": {"height": 0}, "cores": [0, 0]}"#,
    );
    let out_dir = dir.path().join("out");
    let out = oceanbench(&["sweep", &path, "--out", out_dir.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    let lines: Vec<&str> = stderr.lines().collect();
    let fields = [
        "spacing:",
        "workloads: 7",
        "trials:",
        "camera.height",
        "cores:",
    ];
    assert_eq!(lines.len(), fields.len(), "one line per error: {stderr}");
    for field in fields {
        let line = lines.iter().find(|l| l.contains(field));
        let line = line.unwrap_or_else(|| panic!("no line names {field}: {stderr}"));
        assert!(line.starts_with(&format!("oceanbench: {path}: ")), "{line}");
    }
    assert!(!out_dir.exists(), "nothing is written for a bad config");

    let unknown = write_file(
        dir.path(),
        "unknown.json",
        r#"{"sizez": [40], "modes": ["tri"], "wavez": []}"#,
    );
    let out = oceanbench(&["sweep", &unknown]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    for needle in ["`sizez`", "modes[0]", "`wavez`"] {
        assert!(stderr.contains(needle), "{needle} missing: {stderr}");
    }
    assert_eq!(stderr.lines().count(), 3, "{stderr}");
}

/// Runs `oceanbench mesh` with `args`, its CSV written in `dir`: the header and the rows.
fn mesh_csv<T: std::str::FromStr>(dir: &Path, args: &[&str]) -> (String, Vec<Vec<T>>)
where
    T::Err: std::fmt::Debug,
{
    let csv = dir.join("mesh.csv");
    let out = oceanbench(&[&["mesh"], args, &["--out", csv.to_str().unwrap()]].concat());
    assert_success(&out);
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap_or_default().to_string();
    let rows = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    (header, rows)
}

#[test]
fn mesh_csv_has_one_row_per_vertex_and_matches_the_equations() {
    let dir = tempfile::tempdir().unwrap();
    let waves = write_file(
        dir.path(),
        "waves.json",
        r#"{"waves": [
            {"amplitude": 0.7, "wavelength": 9.0, "speed": 1.5, "direction": [1.0, 2.0], "steepness": 2.5},
            {"amplitude": 0.3, "wavelength": 4.0, "speed": 0.5, "direction": [-1.0, 0.3], "steepness": 1.0, "enabled": true},
            {"amplitude": 5.0, "wavelength": 3.0, "speed": 0.5, "direction": [0.0, 1.0], "steepness": 1.0, "enabled": false}
        ]}"#,
    );
    let (header, rows) = mesh_csv::<f64>(
        dir.path(),
        &[
            "--size",
            "12",
            "--time",
            "3.5",
            "--spacing",
            "0.5",
            "--waves",
            &waves,
        ],
    );
    let set = WaveSet::load(Path::new(&waves)).unwrap();
    assert_eq!(header, "i,j,x,y,z,nx,ny,nz");
    assert_eq!(rows.len(), 144);
    for r in &rows {
        let (i, j, x, y) = (r[0], r[1], r[2], r[3]);
        assert_eq!((x, y), (j * 0.5, i * 0.5));
        assert!((r[4] - set.height_f64(x, y, 3.5)).abs() < 1e-4);
        let n = set.normal_f64(x, y, 3.5);
        for c in 0..3 {
            assert!((r[5 + c] - n[c]).abs() < 1e-4, "{r:?} vs {n:?}");
        }
    }
}

#[test]
fn fft_bad_input_exits_2_with_one_line_and_keeps_the_output_file() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("kept.csv");
    std::fs::write(&out, "kept").unwrap();
    let out = out.to_str().unwrap();
    let mesh = |size: &'static str| {
        [
            "mesh", "--ocean", "fft", "--time", "1", "--size", size, "--out", out,
        ]
    };
    for (size, nearest) in [
        ("97", "96, 100"),
        ("33", "32, 36"),
        ("98", "96, 100"),
        ("0", "16"),
        ("8", "16"),
        ("5000", "4096"),
    ] {
        refuses(&mesh(size), &["size", "2, 3 and 5", nearest]);
    }
    refuses(
        &[&mesh("64")[..], &["--normals", "lookup"]].concat(),
        &["normals", "analytic", "neighbors"],
    );
    // The fft ocean offers both kernels: a kernel that is no kernel is refused with them.
    refuses(
        &[&mesh("64")[..], &["--kernel", "turbo"]].concat(),
        &["kernel", "reference", "fast"],
    );
    let params = |name: &str, text: &str| write_file(dir.path(), name, text);
    for (text, field) in [
        (r#"{"wind_speed": -1}"#, "wind_speed"),
        (r#"{"amplitude": -1e-8}"#, "amplitude"),
        (r#"{"patch_metres": -100}"#, "patch_metres"),
        (r#"{"patch_metres": 0}"#, "patch_metres"),
        (r#"{"choppiness": -0.5}"#, "choppiness"),
        (r#"{"depth_metres": 0}"#, "depth_metres"),
        (r#"{"wind_sped": 10}"#, "wind_speed"),
        (r#"{"seed": "x"}"#, "seed"),
        ("[1]", "fft_params"),
    ] {
        let file = params("p.json", text);
        refuses(
            &[&mesh("64")[..], &["--fft-params", &file]].concat(),
            &[field],
        );
        refuses(
            &[
                "run",
                "--ocean",
                "fft",
                "--size",
                "64",
                "--fft-params",
                &file,
            ],
            &[field],
        );
    }
    refuses(
        &[&mesh("64")[..], &["--fft-params", "/nonexistent/p.json"]].concat(),
        &["/nonexistent/p.json"],
    );
    assert_eq!(std::fs::read_to_string(out).unwrap(), "kept");

    refuses(
        &["run", "--ocean", "fft", "--size", "97"],
        &["size", "96, 100"],
    );
    refuses(
        &[
            "run",
            "--ocean",
            "fft",
            "--normals",
            "lookup",
            "--size",
            "64",
        ],
        &["normals", "lookup"],
    );
    refuses(
        &[
            "run",
            "--ocean",
            "fft",
            "--normals",
            "neighbors",
            "--helpers",
            "2",
            "--size",
            "64",
        ],
        &["helpers", "analytic", "neighbors"],
    );
    let config = params(
        "c.json",
        r#"{"ocean": ["fft"], "sizes": [64], "fft_params": "missing.json"}"#,
    );
    refuses(&["sweep", &config], &["fft_params", "missing.json"]);
}

#[test]
fn fft_mesh_csv_has_the_fold_column_and_the_model_s_surface() {
    let dir = tempfile::tempdir().unwrap();
    let params = write_file(
        dir.path(),
        "p.json",
        r#"{"patch_metres": 200, "wind_speed": 15, "amplitude": 1e-6, "choppiness": 1.2}"#,
    );
    let (header, rows) = mesh_csv::<f32>(
        dir.path(),
        &[
            "--ocean",
            "fft",
            "--size",
            "16",
            "--time",
            "2.5",
            "--fft-params",
            &params,
        ],
    );
    assert_eq!(header, "i,j,x,y,z,nx,ny,nz,fold");
    assert_eq!(rows.len(), 256);

    let fft = FftParams::load(Path::new(&params)).unwrap();
    let grid = Grid::new(16, 1.0).unwrap();
    let model = OceanKind::FFT.model();
    let mut mesh = model.mesh(grid);
    model
        .prepare(
            grid,
            &OceanParams::default().with(fft),
            NormalMethod::Analytic,
            Kernel::Reference,
        )
        .unwrap()
        .step(2.5, &mut mesh);
    for (v, r) in rows.iter().enumerate() {
        assert_eq!((r[0] as usize, r[1] as usize), (v / 16, v % 16));
        let want = [
            mesh.x[v], mesh.y[v], mesh.z[v], mesh.nx[v], mesh.ny[v], mesh.nz[v],
        ];
        assert_eq!(&r[2..8], &want[..], "vertex {v}");
        assert_eq!(r[8], mesh.fold[v], "vertex {v}");
    }
    let spacing = 200.0 / 16.0;
    assert!(
        rows.iter().any(|r| (r[2] - r[1] * spacing).abs() > 0.01),
        "x is displaced"
    );
}

#[test]
fn a_tiny_sweep_writes_json_csv_and_markdown() {
    let dir = tempfile::tempdir().unwrap();
    let config = write_file(
        dir.path(),
        "tiny.json",
        r#"{"name": "tiny", "sizes": [8, 12], "workloads": [0, 1], "sync": ["atomic", "condvar"],
            "trials": 2, "warmup_frames": 2, "min_frames": 5, "min_seconds": 0.0,
            "workload_levels": [{"micros": 0}, {"micros": 20}]}"#,
    );
    let out = dir.path().join("run");
    let status = oceanbench(&["sweep", &config, "--out", out.to_str().unwrap(), "--quiet"]);
    let stdout = String::from_utf8_lossy(&status.stdout);
    assert_success(&status);
    assert!(stdout.contains("| mesh | workload | serial | UP | DP | DP÷UP | DP÷serial |"));
    let results = Results::load(&out).unwrap();
    // 2 sizes × 2 workloads × (serial + 2 methods × (up + dp)).
    assert_eq!(results.cells.len(), 2 * 2 * 5);
    assert!(results.finished.is_some());
    for cell in &results.cells {
        let s = cell.summary.as_ref().expect("every cell measured");
        assert_eq!(s.fps_trials.len(), 2);
        assert_eq!(s.frames, 10);
        assert!(s.fps > 0.0 && s.frame_time_ms.p99 >= s.frame_time_ms.median);
    }
    assert_eq!(results.calibration.levels[1].micros, 20.0);
    assert!(results.calibration.levels[1].iterations > 0);
    let csv = std::fs::read_to_string(out.join("results.csv")).unwrap();
    assert_eq!(csv.lines().count(), 21);
    let md = std::fs::read_to_string(out.join("results.md")).unwrap();
    assert!(md.contains("12×12") && md.contains("condvar"));
    // A second sweep into the same directory is refused and keeps the first results whole.
    let before = std::fs::read(out.join("results.json")).unwrap();
    refuses(
        &["sweep", &config, "--out", out.to_str().unwrap()],
        &["already holds"],
    );
    assert_eq!(std::fs::read(out.join("results.json")).unwrap(), before);
}

#[test]
fn shipped_configs_are_valid_and_figure_5_1_is_the_default() {
    let root = common::root().join("configs");
    let figure = SweepConfig::load(&root.join("figure-5-1.json")).unwrap();
    let default = SweepConfig::default();
    assert_eq!(
        SweepConfig {
            description: String::new(),
            ..figure
        },
        default
    );
    for name in [
        "quick.json",
        "sync-primitives.json",
        "ci.json",
        "figure-5-1-fast.json",
        "figure-5-1-fft.json",
        "fft-scaling.json",
    ] {
        SweepConfig::load(&root.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
    }
}

#[test]
fn help_shows_examples() {
    let out = oceanbench(&["--help"]);
    assert_success(&out);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("Examples:") && text.contains("oceanbench sweep"));
}

#[test]
fn sigterm_keeps_finished_cells_and_prints_the_resume_command() {
    let dir = tempfile::tempdir().unwrap();
    let config = write_file(
        dir.path(),
        "long.json",
        r#"{"name": "long", "sizes": [8, 9, 10, 11, 12, 13, 14, 15], "workloads": [0],
            "sync": ["atomic"], "trials": 1, "warmup_frames": 0, "min_frames": 1,
            "min_seconds": 0.15, "workload_levels": [{"micros": 0}]}"#,
    );
    let out = dir.path().join("run");
    let child = common::command(&["sweep", &config, "--out", out.to_str().unwrap(), "--quiet"])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let json = out.join("results.json");
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(60);
    while !json.exists() && std::time::Instant::now() < deadline {
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    assert!(
        json.exists(),
        "the first row is written as soon as it finishes"
    );
    let kill = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let output = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(130), "{stderr}");
    assert!(stderr.contains("--resume"), "{stderr}");
    let kept = Results::load(&out).unwrap();
    assert!(kept.finished.is_none());
    assert!(!kept.cells.is_empty() && kept.cells.len() < 24);
    let resumed = oceanbench(&[
        "sweep",
        "--resume",
        out.to_str().unwrap(),
        "--quiet",
        "--no-charts",
    ]);
    assert_success(&resumed);
    let done = Results::load(&out).unwrap();
    assert_eq!(done.cells.len(), 8 * 3);
    assert!(done.finished.is_some());
    // A trial's placement is relative to the whole run's round trips, so the resumed run's
    // may relabel the kept cells' trials; everything measured stays as it was.
    let unplaced = |cells: &[oceanbench::results::Cell]| {
        let mut cells = cells.to_vec();
        for t in cells.iter_mut().flat_map(|c| c.trials.iter_mut()) {
            t.placement = None;
        }
        cells
    };
    assert_eq!(
        unplaced(&done.cells[..kept.cells.len()]),
        unplaced(&kept.cells)
    );
    // A config that differs from the recorded one is refused.
    let other = write_file(
        dir.path(),
        "other.json",
        r#"{"name": "long", "sizes": [8]}"#,
    );
    refuses(
        &["sweep", &other, "--resume", out.to_str().unwrap()],
        &["differs", "sizes"],
    );
}

#[test]
fn latency_lists_the_floor_and_every_method_on_each_placement() {
    let dir = tempfile::tempdir().unwrap();
    let run_dir = dir.path().join("run");
    let json = dir.path().join("copy.json");
    let out = oceanbench(&[
        "latency",
        "--samples",
        "40",
        "--repeats",
        "2",
        "--out",
        run_dir.to_str().unwrap(),
        "--json",
        json.to_str().unwrap(),
    ]);
    assert_success(&out);
    let text = String::from_utf8_lossy(&out.stdout);
    let file = std::fs::read_to_string(run_dir.join("latency.json")).unwrap();
    assert_eq!(file, std::fs::read_to_string(&json).unwrap());
    let run: serde_json::Value = serde_json::from_str(&file).unwrap();
    assert_eq!(run["schema_version"], 1);
    assert_eq!(run["repeats"], 2);
    assert!(
        run["machine"]["cpu_model"].is_string(),
        "the machine is recorded"
    );
    assert!(run["started"].as_str().unwrap().ends_with('Z'));
    let rows = run["rows"].as_array().unwrap();
    let two_cores = oceanbench::affinity::allowed_cores().len() > 1;
    use oceanbench::sync::{Policy, SyncMethod};
    let methods: Vec<String> = SyncMethod::of_policy(Policy::Fifo)
        .map(|m| m.name().to_string())
        .chain(SyncMethod::of_policy(Policy::Latest).map(|m| format!("{m} latest")))
        .collect();
    let expected = if two_cores {
        2 * methods.len() + 1
    } else {
        methods.len()
    };
    assert_eq!(rows.len(), expected);
    for method in methods {
        let n = rows.iter().filter(|r| r["method"] == method).count();
        assert_eq!(n, if two_cores { 2 } else { 1 }, "{method}");
        assert!(text.contains(&method));
    }
    if two_cores {
        assert!(text.contains("ping-pong"));
    }
    for row in rows {
        let repeats = row["repeats"].as_array().unwrap();
        assert_eq!(repeats.len(), 2, "{row}");
        for r in repeats {
            assert_eq!(r["method"], row["method"]);
            let (median, p99) = (
                r["median_ns"].as_f64().unwrap(),
                r["p99_ns"].as_f64().unwrap(),
            );
            assert!(median > 0.0 && p99 >= median, "{r}");
            assert!(r["samples"].as_u64().unwrap() > 0);
            if r["method"] != "ping-pong" && cfg!(target_os = "linux") {
                assert!(r["cpu_ns"].as_f64().unwrap() > 0.0, "{r}");
            }
        }
    }
    refuses(&["latency", "--samples", "0"], &["--samples"]);
    refuses(&["latency", "--repeats", "0"], &["--repeats", "1 to 100"]);
    // A folder already holding a run is refused before anything is measured.
    refuses(
        &["latency", "--out", run_dir.to_str().unwrap()],
        &["--out", "already holds latency.json"],
    );
    assert_eq!(
        std::fs::read_to_string(run_dir.join("latency.json")).unwrap(),
        file
    );
}

/// Two latency runs compare method by method over their repeats, and report draws a page of
/// each; a run from before repeats were kept loads but earns no verdict.
#[test]
fn latency_runs_are_compared_and_reported_like_sweeps() {
    let dir = tempfile::tempdir().unwrap();
    let run = |name: &str| {
        let path = dir.path().join(name);
        let args = ["latency", "--samples", "20", "--repeats", "5", "--out"];
        assert_success(&oceanbench(
            &[&args[..], &[path.to_str().unwrap()]].concat(),
        ));
        path.to_str().unwrap().to_string()
    };
    let (a, b) = (run("a"), run("b"));
    let out = oceanbench(&["compare", &a, &b, "--format", "json"]);
    assert!(matches!(out.status.code(), Some(0 | 1)), "{out:?}");
    let c: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(c["metric"], "round-trip");
    let rows = std::fs::read_to_string(Path::new(&a).join("latency.json")).unwrap();
    let rows = serde_json::from_str::<serde_json::Value>(&rows).unwrap()["rows"]
        .as_array()
        .unwrap()
        .len();
    let changes = c["changes"].as_array().unwrap();
    assert_eq!(changes.len(), rows, "every method on every placement");
    for ch in changes {
        assert_eq!(ch["base_trials"], 5);
        assert_eq!(ch["new_trials"], 5);
        assert_ne!(ch["verdict"], "too-few-trials", "{ch}");
        assert!(ch["label"].as_str().unwrap().contains(" on "), "{ch}");
    }
    let page = dir.path().join("page.html");
    assert_success(&oceanbench(&[
        "report",
        &b,
        "--baseline",
        &a,
        "--out",
        page.to_str().unwrap(),
    ]));
    let html = std::fs::read_to_string(&page).unwrap();
    for needle in [
        "id=\"verdict-baseline\"",
        "id=\"chart-round-trips\"",
        "Round trip per method",
        "atomic",
        "CPU",
    ] {
        assert!(html.contains(needle), "{needle}");
    }
    // The committed run from before: one repeat per row, no machine.
    let old = "results/latency-20261125T085346Z";
    let out = oceanbench(&["compare", old, &b, "--format", "json"]);
    assert_success(&out);
    let c: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(c["changes"]
        .as_array()
        .unwrap()
        .iter()
        .all(|ch| ch["verdict"] == "too-few-trials"));
    assert!(c["warnings"][0]
        .as_str()
        .unwrap()
        .contains("records no machine"));
    refuses(&["compare", &a, FIXTURE], &["latency run", "not"]);
    refuses(&["compare", FIXTURE, &a], &["latency run", "not"]);
    refuses(
        &["compare", &a, &b, "--metric", "wait-cpu"],
        &["--metric", "round trip"],
    );
    refuses(
        &["compare", FIXTURE, FIXTURE, "--metric", "round-trip"],
        &["--metric", "latency"],
    );
    refuses(&["chart", &a, FIXTURE], &["latency run", "alone"]);
    refuses(
        &["chart", &a, "--sync", "atomic"],
        &["--sync", "every method"],
    );
}

/// `chart` on a latency run draws its round trips, every method on each core pair, into the
/// run's folder or `--out`, as PNG and SVG.
#[test]
fn chart_draws_a_latency_runs_round_trips() {
    let dir = tempfile::tempdir().unwrap();
    let out = oceanbench(&[
        "chart",
        "results/latency-20261127T193624Z",
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    assert_success(&out);
    for ext in ["png", "svg"] {
        assert!(
            dir.path().join(format!("round-trips.{ext}")).exists(),
            "{ext}"
        );
    }
    let svg = std::fs::read_to_string(dir.path().join("round-trips.svg")).unwrap();
    for needle in [
        "median of 5 repeat(s)",
        "cores 0,0: both threads on one core",
        "cores 0,1: one core each",
        "cross-core floor (ping-pong)",
        "round trip (log scale)",
        "triple-buffer latest",
        "µs",
    ] {
        assert!(svg.contains(needle), "{needle}");
    }
}

#[test]
fn compare_exits_0_unchanged_1_regressed_2_bad_input() {
    let fixture = FIXTURE;
    let same = oceanbench(&["compare", fixture, fixture, "--format", "markdown"]);
    assert_eq!(same.status.code(), Some(0));
    assert!(String::from_utf8_lossy(&same.stdout).contains("0 regressed"));
    let dir = tempfile::tempdir().unwrap();
    // The fixture's two trials a cell are too few for a verdict: give both sides five.
    let five = common::five_trials();
    let five_path = dir.path().join("five.json");
    std::fs::write(&five_path, serde_json::to_string(&five).unwrap()).unwrap();
    let two_trials = fixture;
    let fixture = five_path.to_str().unwrap();
    let mut slower = five.clone();
    let cell = slower
        .cells
        .iter_mut()
        .find(|c| c.summary.is_some())
        .unwrap();
    let label = cell.key.label();
    let s = cell.summary.as_mut().unwrap();
    s.fps /= 2.0;
    s.fps_trials.iter_mut().for_each(|f| *f /= 2.0);
    let path = dir.path().join("slower.json");
    std::fs::write(&path, serde_json::to_string(&slower).unwrap()).unwrap();
    let out = oceanbench(&["compare", fixture, path.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stdout).contains(&label));
    let mut slower_two = Results::load(Path::new(two_trials)).unwrap();
    for c in slower_two
        .cells
        .iter_mut()
        .filter_map(|c| c.summary.as_mut())
    {
        c.fps /= 2.0;
        c.fps_trials.iter_mut().for_each(|f| *f /= 2.0);
    }
    let path_two = dir.path().join("slower-two.json");
    std::fs::write(&path_two, serde_json::to_string(&slower_two).unwrap()).unwrap();
    let out = oceanbench(&["compare", two_trials, path_two.to_str().unwrap()]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "two trials a side never fail CI"
    );
    assert!(String::from_utf8_lossy(&out.stdout).contains("too few trials"));
    refuses(
        &["compare", fixture, "/nonexistent.json"],
        &["/nonexistent.json"],
    );
    refuses(
        &["compare", fixture, fixture, "--threshold=-3"],
        &["--threshold"],
    );
    refuses(&["compare", fixture], &["--by"]);
    let notes = write_file(dir.path(), "notes.json", r#"{"hello": 1}"#);
    refuses(
        &["compare", &notes, fixture],
        &["not an oceanbench results file"],
    );
}

#[test]
fn chart_redraws_from_a_results_file_and_refuses_bad_paths() {
    let dir = tempfile::tempdir().unwrap();
    let out = oceanbench(&[
        "chart",
        FIXTURE,
        "--out",
        dir.path().to_str().unwrap(),
        "--format",
        "svg",
    ]);
    assert_success(&out);
    // The fixture's slices are its methods and helper threadings: every chart is drawn per
    // slice, those that lay the methods out per threading.
    for name in [
        "figure-5-1-sync-atomic-threading-pool",
        "relative-sync-condvar-std-threading-spawn",
        "sync-threading-pool",
        "frame-times-threading-spawn",
        "breakdown-threading-pool",
    ] {
        assert!(dir.path().join(format!("{name}.svg")).exists(), "{name}");
    }
    refuses(
        &["chart", "/nonexistent/results"],
        &["/nonexistent/results"],
    );
    let notes = write_file(dir.path(), "notes.json", "[1, 2, 3]");
    refuses(&["chart", &notes], &["not an oceanbench results file"]);
    refuses(&["chart", FIXTURE, "--format", "gif"], &["png, svg"]);
}

/// A chart filter no cell has, and `balance --workload` (the search sets the workload), are
/// refused with the values that would work.
#[test]
fn filters_that_would_draw_nothing_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    refuses(
        &["chart", FIXTURE, "--sync", "flume", "--out", out],
        &["--sync", "flume", "atomic", "condvar-std"],
    );
    assert!(
        std::fs::read_dir(dir.path()).unwrap().next().is_none(),
        "no empty chart written"
    );
    refuses(&["balance", "--workload", "2"], &["--workload", "--range"]);
}

/// A trial cut short by the time cap says so on stderr instead of capping --frames silently.
#[test]
fn frames_cut_short_by_the_time_cap_are_named() {
    let out = oceanbench(&[
        "run",
        "--size",
        "16",
        "--mode",
        "serial",
        "--frames",
        "100000000",
        "--seconds",
        "0.01",
        "--max-seconds",
        "0.05",
        "--trials",
        "1",
    ]);
    assert_eq!(out.status.code(), Some(0), "{out:?}");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("fewer than --frames 100000000") && err.contains("--max-seconds 0.05"),
        "{err}"
    );
}

// `spray`: bad input and a sweep over both oceans (docs/spray.md).

const SPRAY: [&str; 5] = ["run", "--workload-kind", "spray", "--ocean", "fft"];

#[test]
fn bad_particle_counts_exit_2_with_one_line_and_keep_what_was_written() {
    let dir = tempfile::tempdir().unwrap();
    let kept = dir.path().join("results.json");
    std::fs::write(&kept, "{\"earlier\": true}").unwrap();
    let out = dir.path().to_string_lossy().into_owned();
    for (flag, particles, needles) in [
        (
            "--amount",
            "0",
            vec!["--amount", "1 to 4294967295", "got 0"],
        ),
        (
            "--particles",
            "-5",
            vec!["--amount", "1 to 4294967295", "got -5"],
        ),
        ("--amount", "2.5", vec!["--amount", "whole number"]),
        (
            "--amount",
            "1e12",
            vec!["--amount", "MiB for the pool", "available"],
        ),
    ] {
        let mut args = SPRAY.to_vec();
        args.extend([flag, particles, "--out", &out]);
        refuses(&args, &needles);
    }
    assert_eq!(
        std::fs::read_to_string(&kept).unwrap(),
        "{\"earlier\": true}"
    );
    let mut micros = SPRAY.to_vec();
    micros.extend(["--workload-micros", "100"]);
    refuses(
        &micros,
        &[
            "--workload-micros",
            "no per-particle calibration",
            "--amount N",
        ],
    );
    refuses(
        &["run", "--amount", "1000", "--workload-micros", "5"],
        &["--amount", "--workload-micros"],
    );
    refuses(
        &["run", "--workload-kind", "spray", "--ocean", "sines"],
        &["spray needs the fft ocean's folds", "sines"],
    );
}

#[test]
fn bad_spray_configs_exit_2_naming_the_field() {
    let dir = tempfile::tempdir().unwrap();
    let config = |extra: &str, levels: &str| {
        let text = format!(
            r#"{{"sizes": [16], "modes": ["serial"], "ocean": ["fft"], "normals": ["analytic"],
                "workload_kind": ["spray"], "workloads": [0], "workload_levels": [{levels}]{extra}}}"#
        );
        write_file(dir.path(), "spray.json", &text)
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
        refuses(&["sweep", &path, "--out", "/nonexistent/never"], &needles);
    }
}

#[test]
fn a_sweep_over_both_oceans_skips_the_spray_cells_on_sines_and_says_so_once() {
    let dir = tempfile::tempdir().unwrap();
    let config = write_file(
        dir.path(),
        "both.json",
        r#"{"sizes": [16], "modes": ["serial"], "ocean": ["sines", "fft"],
            "normals": ["analytic"], "workload_kind": ["spray"], "workloads": [0],
            "workload_levels": [{"particles": 500}], "trials": 1, "warmup_frames": 0,
            "min_frames": 3, "min_seconds": 0, "calibrate": "once"}"#,
    );
    let out = dir.path().join("out");
    let run = oceanbench(&[
        "sweep",
        &config,
        "--out",
        &out.to_string_lossy(),
        "--no-charts",
        "--no-doctor",
        "--quiet",
    ]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{stderr}");
    let note = "spray cells skipped: workload_kind: spray needs the fft ocean's folds";
    assert_eq!(stderr.matches(note).count(), 1, "{stderr}");
    let results = Results::load(&out.join("results.json")).unwrap();
    let oceans: Vec<OceanKind> = results.cells.iter().map(|c| c.key.ocean).collect();
    assert_eq!(oceans, [OceanKind::FFT]);
    let trials = &results.cells[0].summary.as_ref().unwrap().work_trials;
    assert_eq!(trials.len(), 1, "one trial's counts");
    let keys: Vec<&str> = trials[0].counts.iter().map(|c| c.key.as_str()).collect();
    assert_eq!(keys, ["live", "emitted", "recycled"]);
    let live = trials[0].count("live").unwrap();
    assert!(live.max.unwrap() <= 500 && live.min <= live.max);
}

/// `run --amount N` gives the level in the kind's own unit, whatever the kind.
#[test]
fn run_takes_a_level_in_the_kinds_own_unit() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("amount");
    let status = oceanbench(&[
        "run",
        "--size",
        "8",
        "--mode",
        "serial",
        "--amount",
        "1234",
        "--frames",
        "3",
        "--seconds",
        "0",
        "--trials",
        "1",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_success(&status);
    let results = Results::load(&out).unwrap();
    let cell = &results.cells[0];
    assert_eq!(
        (cell.workload_unit(), cell.workload_amount()),
        ("iterations", 1234)
    );
}

/// An output folder that does not exist and a negative threshold are bad input: one line
/// naming the flag, exit 2, before anything is read or written.
#[test]
fn report_and_compare_refuse_a_missing_out_folder_and_a_negative_threshold() {
    refuses(
        &["report", common::FIXTURE, "--out", "/nonexistent/x.html"],
        &["--out", "/nonexistent", "no folder"],
    );
    for command in ["report", "compare"] {
        refuses(
            &[command, common::FIXTURE, "--threshold", "-5"],
            &["--threshold", "finite percentage >= 0", "got -5"],
        );
    }
}

/// `run --grid projected` and `run --helpers 2` name no normals: they run with the first
/// method their cells can use, and say so, rather than refuse the default nobody gave.
#[test]
fn run_fits_the_normals_nobody_gave_to_the_cells_asked_for() {
    for (flag, value) in [("--grid", "projected"), ("--helpers", "2")] {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("fit");
        let run = oceanbench(&[
            "run",
            flag,
            value,
            "--size",
            "16",
            "--frames",
            "3",
            "--seconds",
            "0",
            "--trials",
            "1",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert_success(&run);
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert!(
            stderr.contains("--normals analytic: the default (neighbors) cannot run these cells"),
            "{flag}: {stderr}"
        );
        let results = Results::load(&out).unwrap();
        assert_eq!(
            results.cells[0].key.normals,
            NormalMethod::Analytic,
            "{flag}"
        );
    }
    // Given normals are kept, and refused when the cells cannot use them.
    refuses(
        &["run", "--grid", "projected", "--normals", "neighbors"],
        &["neighbors"],
    );
}

#[test]
fn a_config_naming_no_normals_gets_normals_its_cells_can_run() {
    for (key, value) in [("grid", r#"["projected"]"#), ("helpers", "[2]")] {
        let text = format!(r#"{{"sizes": [16], "ocean": ["sines"], "{key}": {value}}}"#);
        let config = SweepConfig::from_json(&text).unwrap();
        assert_eq!(config.axes.normals, vec![NormalMethod::Analytic], "{key}");
        assert_eq!(config.notes.len(), 1, "said once: {:?}", config.notes);
        assert!(config.notes[0].contains("the default (neighbors) cannot run these cells"));
        // Named normals the cells cannot use are still refused.
        let named = format!(r#"{{"sizes": [16], "normals": ["neighbors"], "{key}": {value}}}"#);
        let e = SweepConfig::from_json(&named).unwrap_err().to_string();
        assert!(e.contains("neighbors"), "{e}");
    }
    // A config the defaults fit says nothing.
    let plain = SweepConfig::from_json(r#"{"sizes": [16]}"#).unwrap();
    assert!(plain.notes.is_empty());
    assert_eq!(plain.axes.normals, vec![NormalMethod::Neighbors]);
}

#[test]
fn completions_and_man_pages_cover_every_command() {
    use clap::CommandFactory;
    let cli = oceanbench::cli::Cli::command();
    let commands: Vec<String> = cli
        .get_subcommands()
        .map(|c| c.get_name().to_string())
        .collect();
    for shell in ["bash", "zsh", "fish"] {
        let out = oceanbench(&["completions", shell]);
        assert_success(&out);
        let script = String::from_utf8_lossy(&out.stdout);
        for name in &commands {
            assert!(script.contains(name.as_str()), "{shell}: no {name}");
        }
        assert!(script.contains("--baseline"), "{shell}: flags completed");
    }
    let out = oceanbench(&["man"]);
    assert_success(&out);
    let page = String::from_utf8_lossy(&out.stdout);
    assert!(
        page.starts_with(".ie") && page.contains(".TH oceanbench 1"),
        "{page}"
    );
    for name in &commands {
        assert!(page.contains(&format!("oceanbench\\-{}(1)", name.replace('-', "\\-"))));
    }

    let dir = tempfile::tempdir().unwrap();
    assert_success(&oceanbench(&["man", "--out", dir.path().to_str().unwrap()]));
    for name in &commands {
        let file = dir.path().join(format!("oceanbench-{name}.1"));
        let text = std::fs::read_to_string(&file).unwrap();
        assert!(text.contains(".SH SYNOPSIS"), "{}", file.display());
    }
    refuses(&["completions", "tcsh"], &["tcsh", "bash, elvish, fish"]);
    refuses(
        &["man", "--out", "/nonexistent/man1"],
        &["--out", "/nonexistent/man1"],
    );
}

/// A sweep examines the machine (the doctor) on the cores it runs on, each once, and keeps the
/// report in results.json; `--no-doctor` leaves it out.
#[test]
fn the_doctor_examines_the_sweeps_cores_unless_told_not_to() {
    let dir = tempfile::tempdir().unwrap();
    let config = write_file(
        dir.path(),
        "tiny.json",
        r#"{"sizes": [8], "modes": ["serial"], "workloads": [0], "trials": 1,
            "warmup_frames": 0, "min_frames": 3, "min_seconds": 0, "calibrate": "once"}"#,
    );
    for (flags, examined) in [(&[][..], true), (&["--no-doctor"][..], false)] {
        let out = dir.path().join(format!("out{}", flags.len()));
        let mut args = vec![
            "sweep".to_string(),
            config.clone(),
            "--out".into(),
            out.to_string_lossy().into_owned(),
            "--no-charts".into(),
            "--quiet".into(),
        ];
        args.extend(flags.iter().map(|f| f.to_string()));
        assert_success(&oceanbench(&args));
        let results = Results::load(&out.join("results.json")).unwrap();
        let Some(doctor) = &results.doctor else {
            assert!(!examined, "{flags:?}: no doctor's report");
            continue;
        };
        assert!(examined, "{flags:?}: a doctor's report");
        let [main, helper] = results.config.placement().unwrap();
        let mut cores = vec![main, helper];
        cores.dedup();
        assert_eq!(doctor.cores, cores);
    }
}
