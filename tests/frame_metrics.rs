//! The CapFrameX-named frame-time metrics on sequences computed by hand: one frame, all-equal
//! frames, ties at the percentile, a long tail; and the order their definitions imply on any
//! sequence.

use oceanbench::summary::FrameMetrics;
use proptest::prelude::*;

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-9 * b.abs().max(1.0)
}

fn metrics(ms: &[f64]) -> FrameMetrics {
    FrameMetrics::of(ms).expect("frames")
}

#[test]
fn no_frames_no_metrics() {
    assert!(FrameMetrics::of(&[]).is_none());
}

#[test]
fn a_single_frame_is_every_figure() {
    let m = metrics(&[10.0]);
    for fps in [
        m.p1_fps,
        m.one_percent_low_average_fps,
        m.one_percent_low_integral_fps,
        m.p0_1_fps,
        m.point_one_percent_low_average_fps,
        m.point_one_percent_low_integral_fps,
    ] {
        assert!(close(fps, 100.0), "{m:?}");
    }
    assert_eq!(m.stutter_time_percent, 0.0);
}

#[test]
fn equal_frames_agree_and_never_stutter() {
    let m = metrics(&[5.0; 200]);
    assert!(close(m.p1_fps, 200.0) && close(m.one_percent_low_average_fps, 200.0));
    assert!(close(m.one_percent_low_integral_fps, 200.0) && close(m.p0_1_fps, 200.0));
    assert_eq!(m.stutter_time_percent, 0.0);
}

/// 99 frames of 10 ms and one of 100 ms. The 99th percentile (nearest rank: the 99th of 100) is
/// 10 ms, tied with 98 others, so every frame is "at or above" it: the 1 % low average is
/// 1000 ÷ 10.9 ms. The slowest frame alone is over 1 % of the 1090 ms, so the integral is 10
/// FPS. It stutters (100 > 2.5 × 10.9 ms) for 100 of 1090 ms.
#[test]
fn ties_at_the_percentile_and_one_long_frame() {
    let mut ms = vec![10.0; 99];
    ms.push(100.0);
    let m = metrics(&ms);
    assert!(close(m.p1_fps, 100.0), "{m:?}");
    assert!(close(m.one_percent_low_average_fps, 1000.0 / 10.9), "{m:?}");
    assert!(close(m.one_percent_low_integral_fps, 10.0), "{m:?}");
    assert!(
        close(m.stutter_time_percent, 100.0 * 100.0 / 1090.0),
        "{m:?}"
    );
}

/// 990 frames of 10 ms and 10 of 50 ms (10,400 ms in all). P1 is 100 FPS (the 990th frame is
/// 10 ms), P0.1 20 FPS (the 999th is 50 ms); the 0.1 % low average is the ten 50 ms frames; the
/// integral reaches 1 % (104 ms) at the third 50 ms frame and 0.1 % at the first; the 50 ms
/// frames are above 2.5 × 10.4 ms and take 500 ms.
#[test]
fn a_long_tail() {
    let mut ms = vec![10.0; 990];
    ms.extend([50.0; 10]);
    ms.reverse();
    let m = metrics(&ms);
    assert!(close(m.p1_fps, 100.0), "{m:?}");
    assert!(close(m.p0_1_fps, 20.0), "{m:?}");
    assert!(close(m.one_percent_low_average_fps, 1000.0 / 10.4), "{m:?}");
    assert!(close(m.point_one_percent_low_average_fps, 20.0), "{m:?}");
    assert!(close(m.one_percent_low_integral_fps, 20.0), "{m:?}");
    assert!(close(m.point_one_percent_low_integral_fps, 20.0), "{m:?}");
    assert!(close(m.stutter_time_percent, 500.0 / 104.0), "{m:?}");
}

proptest! {
    /// In frame time, the 1 % low average and the 1 % low integral are each at least as slow as
    /// P1 (the slowest 1 % of frames hold at least 1 % of the time), and the 0.1 % figures at
    /// least as slow as the 1 % ones.
    #[test]
    fn lows_are_never_faster_than_their_percentile(ms in prop::collection::vec(0.1f64..100.0, 1..3000)) {
        let m = metrics(&ms);
        prop_assert!(m.one_percent_low_average_fps <= m.p1_fps * (1.0 + 1e-12));
        prop_assert!(m.one_percent_low_integral_fps <= m.p1_fps * (1.0 + 1e-12));
        prop_assert!(m.p0_1_fps <= m.p1_fps);
        prop_assert!(m.point_one_percent_low_integral_fps <= m.one_percent_low_integral_fps);
        prop_assert!((0.0..=100.0).contains(&m.stutter_time_percent));
    }
}
