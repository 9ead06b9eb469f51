//! Frame statistics on known frame times, and the workload's determinism.

use oceanbench::measure::{FrameRecord, Trial};
use oceanbench::stats::quantile;
use oceanbench::summary::Summary;
use oceanbench::workload;

fn trial(ms: &[u64]) -> Trial {
    Trial {
        frames: ms
            .iter()
            .map(|&m| FrameRecord {
                total_ns: m * 1_000_000,
                workload_ns: m * 250_000,
                wait_ns: m * 250_000,
                copy_ns: 0,
                step_ns: m * 500_000,
                ..FrameRecord::default()
            })
            .collect(),
        ..Trial::default()
    }
}

#[test]
fn summary_of_known_frame_times() {
    // 198 frames of 10 ms and 2 of 100 ms in one trial; 100 frames of 20 ms in another.
    let mut a = vec![10u64; 198];
    a.extend([100, 100]);
    let b = vec![20u64; 100];
    let s = Summary::of(&[trial(&a), trial(&b)]).unwrap();
    let seconds = (198.0 * 10.0 + 200.0 + 100.0 * 20.0) / 1000.0;
    assert!((s.fps - 300.0 / seconds).abs() < 1e-9);
    assert_eq!(s.fps_trials.len(), 2);
    assert!((s.fps_trials[0] - 200.0 / 2.18).abs() < 1e-9);
    assert!((s.fps_trials[1] - 50.0).abs() < 1e-9);
    assert_eq!(s.frame_time_ms.median, 10.0);
    assert_eq!(s.frame_time_ms.max, 100.0);
    // Nearest rank: the 297th of 300 sorted frames is a 20 ms frame.
    assert_eq!(s.frame_time_ms.p99, 20.0);
    // 1% low: the slowest 3 frames (100, 100, 20 ms) → 3 frames in 0.22 s.
    assert!((s.one_percent_low_fps - 3.0 / 0.22).abs() < 1e-9);
    assert!((s.breakdown.step_ms * 2.0 - s.frame_time_ms.mean).abs() < 1e-9);
    let q = |x: f64| s.frame_time_quantiles.iter().find(|p| p.q == x).unwrap().ms;
    assert_eq!(
        s.frame_time_quantiles.len(),
        oceanbench::summary::QUANTILES.len()
    );
    assert_eq!((q(0.0), q(0.5), q(0.99), q(1.0)), (10.0, 10.0, 20.0, 100.0));
    // 198 of 300 frames take 10 ms, the rest 20 or 100 ms: the 0.75 quantile is 20 ms.
    assert_eq!(q(0.75), 20.0);
    assert!(s
        .frame_time_quantiles
        .windows(2)
        .all(|w| w[0].ms <= w[1].ms));
    assert_eq!(s.frames, 300);
    assert!(s.fps_spread.min < s.fps_spread.max && s.fps_spread.stddev > 0.0);
}

#[test]
fn no_frames_no_summary() {
    assert!(Summary::of(&[]).is_none());
    assert!(Summary::of(&[Trial::default()]).is_none());
    assert!(quantile(&[], 0.5).is_nan());
}

#[test]
fn workload_is_deterministic_and_depends_on_its_inputs() {
    assert_eq!(workload::run(10_000, 3), workload::run(10_000, 3));
    assert_ne!(workload::run(10_000, 3), workload::run(10_001, 3));
    assert_ne!(workload::run(10_000, 3), workload::run(10_000, 4));
}

#[test]
fn calibration_turns_microseconds_into_iterations() {
    let c = workload::Calibration::measure(3);
    assert!(c.ns_per_iteration > 0.0 && c.ns_per_iteration.is_finite());
    assert_eq!(c.samples_ns_per_iteration.len(), 3);
    assert_eq!(c.iterations_for(0.0), 0);
    let a = c.iterations_for(100.0);
    let b = c.iterations_for(200.0);
    assert!(a > 0 && (b as f64 / a as f64 - 2.0).abs() < 0.01);
}
