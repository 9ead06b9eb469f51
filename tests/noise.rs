//! Measurements that stay valid on a noisy machine: per-row calibration, noise recorded per
//! trial, noisy trials re-run, verdicts that say when they rest on noisy trials, `doctor`, and
//! the bad input of each.

mod common;

use common::{assert_one_line_exit_2, oceanbench};
use oceanbench::affinity;
use oceanbench::calibrate::Calibrate;
use oceanbench::cell::Axes;
use oceanbench::config::{Level, SweepConfig};
use oceanbench::frame_loop::Mode;
use oceanbench::report::compare::{self, Metric};
use oceanbench::report::markdown;
use oceanbench::results::Results;
use oceanbench::sweep::Sweep;
use oceanbench::sync::SyncMethod;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

fn tiny(modes: Vec<Mode>, levels: Vec<Level>) -> SweepConfig {
    SweepConfig {
        name: "noise".into(),
        axes: Axes {
            sizes: vec![24],
            workloads: (0..levels.len()).collect(),
            modes,
            sync: vec![SyncMethod::Atomic],
            ..Axes::default()
        },
        trials: 2,
        warmup_frames: 2,
        min_frames: 10,
        min_seconds: 0.01,
        workload_levels: levels,
        ..SweepConfig::default()
    }
}

fn run(config: SweepConfig) -> Results {
    Sweep::prepare(config).unwrap().run(&mut ())
}

#[test]
fn step_fraction_levels_are_rederived_in_every_row_and_micros_stay() {
    let levels = vec![Level::micros(30.0), Level::step_fraction(0.5, 24)];
    let results = run(tiny(vec![Mode::Serial], levels.clone()));
    for cell in &results.cells {
        let cal = cell
            .calibration
            .as_ref()
            .expect("every cell records its calibration");
        assert_eq!(cal.calibrate, Calibrate::Row);
        assert!(cal.step_ms_at_start > 0.0 && cal.step_ms_in_row > 0.0);
        match cell.key.workload {
            0 => assert_eq!(cal.level_micros, 30.0, "micros levels stay as written"),
            _ => assert!(
                (cal.level_micros - 0.5 * cal.step_ms_in_row * 1e3).abs() < 1e-6,
                "0.5 × the step measured in the row: {cal:?}"
            ),
        }
    }
    let once = run(SweepConfig {
        calibrate: Calibrate::Once,
        ..tiny(vec![Mode::Serial], levels)
    });
    for cell in &once.cells {
        let cal = cell.calibration.as_ref().unwrap();
        assert_eq!(cal.calibrate, Calibrate::Once);
        assert_eq!(
            cal.level_micros, once.calibration.levels[cell.key.workload].micros,
            "once keeps the start's levels"
        );
    }
}

#[test]
fn every_trial_records_each_threads_scheduling_and_each_cores_steal() {
    let mut modes = vec![Mode::Serial, Mode::Up];
    if affinity::allowed_cores().len() > 1 {
        modes.push(Mode::Dp);
    }
    let results = run(tiny(modes, vec![Level::micros(0.0)]));
    for cell in &results.cells {
        let noise = cell.noise.as_ref().expect("noise is recorded");
        assert_eq!(noise.trials.len(), 2, "one record per kept trial");
        for trial in &noise.trials {
            let threads = if cell.key.is_serial() { 1 } else { 2 };
            assert_eq!(trial.threads.len(), threads, "{}", cell.key.label());
            assert!(trial.wall_ns > 0);
            assert!(trial.threads.iter().all(|t| t.cpu_ns <= trial.wall_ns * 2));
        }
    }
}

/// Spins on `core` until dropped: another task competing for the measured core.
struct Hog(Arc<AtomicBool>);

impl Hog {
    fn on(core: usize) -> Hog {
        let stop = Arc::new(AtomicBool::new(false));
        let flag = Arc::clone(&stop);
        std::thread::spawn(move || {
            affinity::pin_current(core);
            while !flag.load(Ordering::Relaxed) {
                std::hint::spin_loop();
            }
        });
        Hog(stop)
    }
}

impl Drop for Hog {
    fn drop(&mut self) {
        self.0.store(true, Ordering::Relaxed);
    }
}

#[test]
fn a_hog_on_the_measured_core_makes_trials_noisy_and_they_are_retried() {
    let main = affinity::allowed_cores()[0];
    let config = SweepConfig {
        retry_noisy: 1,
        min_seconds: 0.2,
        cores: Some(vec![main]),
        ..tiny(vec![Mode::Serial], vec![Level::micros(200.0)])
    };
    let results = {
        let _hog = Hog::on(main);
        run(config)
    };
    let cell = &results.cells[0];
    let noise = cell.noise.as_ref().unwrap();
    // The hog takes about half the core when the machine is idle and more of it is taken when
    // it is not; the behaviour is that the share crosses the noise threshold, whatever the load.
    assert!(
        noise.preempted_percent() > noise.threshold_percent,
        "a spinning thread on the same core is seen: {noise:?}"
    );
    assert_eq!(noise.noisy_trials(), 2, "every kept trial is noisy");
    assert_eq!(noise.retries, 2, "each was retried once before it was kept");
    let md = markdown::to_string(&results);
    assert!(md.contains("†") && md.contains(&cell.key.label()), "{md}");
    let c = compare::between(&results, &results, 5.0, Metric::Fps);
    assert!(c.changes.iter().all(|c| c.noisy));
    assert!(c.to_text().contains("† rests on trials"));
}

#[test]
fn bad_noise_settings_exit_2_with_one_line_naming_the_field() {
    for (args, needle) in [
        (vec!["run", "--noise-threshold", "0"], "--noise-threshold:"),
        (
            vec!["run", "--noise-threshold", "100"],
            "--noise-threshold:",
        ),
        (vec!["run", "--retry-noisy", "11"], "--retry-noisy:"),
        (vec!["run", "--calibrate", "never"], "row, once"),
        (vec!["doctor", "--seconds", "0"], "--seconds"),
    ] {
        assert_one_line_exit_2(&oceanbench(&args), &[needle]);
    }
    for (text, needle) in [
        (
            r#"{"noise_threshold_percent": -1}"#,
            "noise_threshold_percent",
        ),
        (r#"{"retry_noisy": 20}"#, "retry_noisy"),
        (r#"{"calibrate": "sometimes"}"#, "row, once"),
    ] {
        let err = SweepConfig::from_json(text).unwrap_err().to_string();
        assert!(err.contains(needle), "{text}: {err}");
    }
}

#[test]
fn doctor_reports_one_line_per_finding_and_json_for_machines() {
    let out = oceanbench(&["doctor", "--seconds", "0.2"]);
    assert_eq!(out.status.code(), Some(0));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.lines().last().unwrap().starts_with("doctor: "),
        "{text}"
    );
    for check in ["isolation", "virtualization", "pinning", "threads"] {
        assert!(text.contains(&format!(" {check}: ")), "{check} in {text}");
    }
    let out = oceanbench(&["doctor", "--seconds", "0.2", "--json"]);
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
    assert!(report["findings"].as_array().is_some_and(|f| !f.is_empty()));
    assert!(report["missing"].is_array());
}

/// A step_fraction level is a fraction of the cell's own ocean's yardstick step: the sines' for
/// sines rows, the FFT ocean's for fft rows, both measured at the start and again in each row.
#[test]
fn step_fraction_levels_follow_each_oceans_own_yardstick() {
    use oceanbench::ocean::OceanKind;
    let mut config = tiny(vec![Mode::Serial], vec![Level::step_fraction(0.5, 32)]);
    config.axes.sizes = vec![32];
    config.axes.ocean = vec![OceanKind::SINES, OceanKind::FFT];
    config.axes.normals = vec![oceanbench::ocean::NormalMethod::Analytic];
    let results = run(config);
    let start = results.calibration.start.as_ref().unwrap();
    let (sines, fft) = (
        start.step_for(OceanKind::SINES, 32).unwrap(),
        start.step_for(OceanKind::FFT, 32).unwrap(),
    );
    assert!(sines > 0.0 && fft > 0.0);
    assert_eq!(results.cells.len(), 2);
    for cell in &results.cells {
        let cal = cell.calibration.as_ref().unwrap();
        assert!(
            (cal.level_micros - 0.5 * cal.step_ms_in_row * 1e3).abs() < 1e-6,
            "{}: {cal:?}",
            cell.key.label()
        );
        let at_start = start.step_for(cell.key.ocean, 32).unwrap();
        assert_eq!(cal.step_ms_at_start, at_start, "{}", cell.key.label());
    }
    let err = SweepConfig::from_json(
        r#"{"ocean": ["fft"], "sizes": [32], "normals": ["analytic"], "workloads": [0],
            "workload_levels": [{"step_fraction": 0.5, "size": 97}]}"#,
    )
    .unwrap_err()
    .to_string();
    assert!(
        err.contains("workload_levels[0].size: 97") && err.contains("fft"),
        "{err}"
    );
}
