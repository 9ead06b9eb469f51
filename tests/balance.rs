//! The balance search on a model machine: its curve, its bracket and bisection, noise, what
//! it does when the probes mix placements, and its errors. `oceanbench balance` end to end is
//! tests/balance_cli.rs.

use oceanbench::balance::{self, BalanceError, BalanceSettings, Probe, Testbed, UnitCost};
use oceanbench::cell::{Axes, CellKey, Dim, DimValue};
use oceanbench::frame_loop::{LoopError, Mode};
use oceanbench::measure::{FrameRecord, Trial};
use oceanbench::placement::Class;

/// A machine answered from a model instead of the scheduler: the helper's step is 100 µs on
/// near cores and 60 µs on far ones (unless it grows with the main thread's work), the
/// threads overlap perfectly in DP, and the round trip is 50 ns near and 400 ns far, the
/// placement changing at scripted round trips. So the search's
/// logic, and what it does with placements, is checked whatever else runs on the machine.
struct Model {
    /// Which round trip (counted from 0) is far.
    far: fn(usize) -> bool,
    /// Which round trips fall in no placement: each an outlier at least thrice any other.
    lost: fn(usize) -> bool,
    /// How far apart a DP cell's successive trials put the waits (µs): the main thread waits
    /// this much longer in one trial, the helper in the next, so a probe's mean difference of
    /// the waits is the model's own and its noise (two standard errors) is twice this.
    jitter_us: f64,
    /// At which workloads (µs) noise swaps the DP waits, so a probe reads the wrong side.
    swapped: fn(f64) -> bool,
    /// How much the helper's step grows per µs of main-thread work, as if they shared a cache.
    step_per_work: f64,
    calls: std::cell::Cell<usize>,
    is_far: std::cell::Cell<bool>,
    dp_trials: std::cell::Cell<usize>,
    trials: std::cell::Cell<usize>,
}

/// The model's iterations of synthetic work (ns).
const ITERATION_NS: f64 = 0.5;

/// Trials past which a search on the model has lost its way: a search of these tests runs
/// about a hundred.
const MAX_TRIALS: usize = 1000;

impl Model {
    fn new(far: fn(usize) -> bool) -> Model {
        Model {
            far,
            lost: |_| false,
            jitter_us: 0.0,
            swapped: |_| false,
            step_per_work: 0.0,
            calls: std::cell::Cell::new(0),
            is_far: std::cell::Cell::new(false),
            dp_trials: std::cell::Cell::new(0),
            trials: std::cell::Cell::new(0),
        }
    }

    /// One placement throughout, the waits jittered by `jitter_us`.
    fn noisy(jitter_us: f64) -> Model {
        Model {
            jitter_us,
            ..Model::new(|_| false)
        }
    }
}

impl Testbed for Model {
    fn trial(&self, key: &CellKey, amount: u64) -> Result<Trial, LoopError> {
        // Synthetic work is counted in iterations of half a nanosecond; a kind with its own
        // unit costs 2 ns a unit, so a search that read its amounts in the other's would land
        // elsewhere than the step.
        let unit_ns = if key.workload_kind.unit() == "iterations" {
            ITERATION_NS
        } else {
            2.0
        };
        let trials = self.trials.get() + 1;
        self.trials.set(trials);
        assert!(
            trials <= MAX_TRIALS,
            "{trials} trials: a search that does not end"
        );
        let w = amount as f64 * unit_ns / 1e3;
        let s = if self.is_far.get() { 60.0 } else { 100.0 } + self.step_per_work * w;
        let (frame, wait, helper_wait) = match key.mode {
            Mode::Serial => (w + s, 0.0, 0.0),
            Mode::Up => (w + s + 2.0, s, 0.0),
            _ => {
                let n = self.dp_trials.get();
                self.dp_trials.set(n + 1);
                let (main, helper) = if n.is_multiple_of(2) {
                    (self.jitter_us, 0.0)
                } else {
                    (0.0, self.jitter_us)
                };
                let (wait, helper_wait) = ((s - w).max(0.0) + main, (w - s).max(0.0) + helper);
                let (wait, helper_wait) = if (self.swapped)(w) {
                    (helper_wait, wait)
                } else {
                    (wait, helper_wait)
                };
                (w.max(s) + 5.0, wait, helper_wait)
            }
        };
        let ns = |us: f64| (us * 1e3) as u64;
        let frame = FrameRecord {
            total_ns: ns(frame),
            workload_ns: ns(w),
            wait_ns: ns(wait),
            helper_wait_ns: ns(helper_wait),
            step_ns: ns(s),
            ..FrameRecord::default()
        };
        Ok(Trial {
            frames: vec![frame; 20],
            wall_ns: 20 * ns(frame.total_ns as f64 / 1e3),
            checksum: None,
        })
    }

    fn ns_per_iteration(&self) -> f64 {
        ITERATION_NS
    }

    fn round_trip(&self, _batches: usize) -> Option<f64> {
        let i = self.calls.get();
        self.calls.set(i + 1);
        if (self.lost)(i) {
            return Some(1e4 * 3f64.powi(i as i32));
        }
        self.is_far.set((self.far)(i));
        Some(if self.is_far.get() { 400.0 } else { 50.0 })
    }
}

fn dp_cell() -> CellKey {
    let axes = Axes {
        sizes: vec![16],
        modes: vec![Mode::Dp],
        ..Axes::default()
    };
    axes.cells().remove(0)
}

fn settings() -> BalanceSettings {
    BalanceSettings {
        tolerance_percent: 2.0,
        points: 6,
        range: [0.1, 10.0],
        trials: 2,
    }
}

#[test]
fn a_search_in_one_placement_finds_the_step() {
    let entry = balance::search(&Model::new(|_| false), &dp_cell(), &settings()).unwrap();
    let (lo, hi) = (
        entry.balance_us_low.unwrap(),
        entry.balance_us_high.unwrap(),
    );
    assert!(lo <= 100.0 && 100.0 <= hi, "[{lo}, {hi}]");
    assert!(hi - lo <= 2.0, "within the tolerance: [{lo}, {hi}]");
    assert_eq!(entry.placement, Some(Class::One));
    assert_eq!(entry.set_aside, 0);
    assert!(entry.note.is_none(), "{:?}", entry.note);
    assert_eq!(entry.placements.len(), 1);
    assert_eq!(entry.placements[0].balance_us, entry.balance_us);
    assert!((entry.fraction().unwrap() - 1.0).abs() < 0.02);
    for p in &entry.probes {
        assert_eq!(
            p.round_trip_ns.len(),
            3,
            "before each round and after the last"
        );
        assert_eq!(p.step_us, vec![100.0, 100.0], "S timed in every probe");
        assert_eq!(p.placement, Some(Class::One));
    }
}

#[test]
fn a_search_that_mixed_placements_sets_probes_aside_and_says_so() {
    // Round trip 0 is the search's before; probe k times 1+3k, 2+3k, 3+3k. The curve's fifth
    // probe (398 µs) runs far, the sixth (1000 µs) moves back to near in its second round.
    let entry = balance::search(
        &Model::new(|i| (13..=17).contains(&i)),
        &dp_cell(),
        &settings(),
    )
    .unwrap();
    let count = |c: Class| {
        entry
            .probes
            .iter()
            .filter(|p| p.placement == Some(c))
            .count()
    };
    assert_eq!((count(Class::Far), count(Class::Moved)), (1, 1));
    assert_eq!(entry.placement, Some(Class::Near));
    assert_eq!(entry.set_aside, 2);
    assert_eq!(
        entry.note.as_deref(),
        Some(&*format!(
            "probes mixed placements: 2 of {} set aside (1 far, 1 moved); the figures are the near probes' alone",
            entry.probes.len()
        ))
    );
    // The headline is the near probes' alone: their S, their bracket.
    let near = entry.headline().unwrap();
    assert_eq!(near.placement, Class::Near);
    assert_eq!(near.step_us, Some(100.0));
    let (lo, hi) = (
        entry.balance_us_low.unwrap(),
        entry.balance_us_high.unwrap(),
    );
    assert!(lo <= 100.0 && 100.0 <= hi, "[{lo}, {hi}]");
    // The ratios and the overhead are the near probe's nearest the balance, within a
    // microsecond or two of it: the model's figures there.
    let b = entry.balance_us.unwrap();
    assert_eq!(b, (lo + hi) / 2.0);
    let r = near.dp_over_serial.unwrap();
    let expected = (b + 100.0) / (b.max(100.0) + 5.0);
    assert!((r.value / expected - 1.0).abs() < 0.01, "{r:?} near {b} µs");
    assert_eq!(
        (
            entry.dp_over_serial_low,
            entry.dp_over_serial,
            entry.dp_over_serial_high
        ),
        (Some(r.low), Some(r.value), Some(r.high))
    );
    assert_eq!(entry.dp_over_up, near.dp_over_up);
    assert!(near.dp_over_up.is_some());
    let overhead = entry.overhead_percent.unwrap();
    assert!(
        (overhead - 100.0 * 5.0 / b.max(100.0)).abs() < 0.1,
        "{overhead}"
    );
    let far = entry
        .placements
        .iter()
        .find(|p| p.placement == Class::Far)
        .unwrap();
    assert_eq!((far.probes, far.step_us), (1, Some(60.0)));
    assert_eq!(far.balance_us, None, "one far probe brackets nothing");
    assert_eq!(far.round_trip_ns, [400.0, 400.0]);
}

#[test]
fn a_search_that_moved_for_good_reports_each_placement() {
    // Near for the curve's first four probes, far from then on. The bisection's probes, all
    // far, are above the far balance (S 60 µs) and bracket nothing; the near probes bracket
    // the near one (S 100 µs), so the headline is theirs and every far probe is set aside.
    let entry = balance::search(&Model::new(|i| i >= 13), &dp_cell(), &settings()).unwrap();
    assert_eq!(entry.placement, Some(Class::Near));
    let near = entry.headline().unwrap();
    assert_eq!((near.probes, near.step_us), (4, Some(100.0)));
    let (lo, hi) = (
        entry.balance_us_low.unwrap(),
        entry.balance_us_high.unwrap(),
    );
    assert!(
        lo < 100.0 && 100.0 < hi,
        "the near probes bracket S near: [{lo}, {hi}]"
    );
    assert_eq!(entry.set_aside, entry.probes.len() - 4);
    let far = &entry.placements[1];
    assert_eq!((far.placement, far.balance_us), (Class::Far, None));
    assert!(
        entry
            .note
            .as_deref()
            .unwrap()
            .contains(&format!("set aside ({} far)", far.probes)),
        "{:?}",
        entry.note
    );
}

/// `a` within a thousandth of `e`: the model's times are whole nanoseconds.
fn close(a: f64, e: f64) -> bool {
    (a - e).abs() <= 1e-3 * e.abs()
}

/// The search's bracket, as measured.
fn bracket(entry: &balance::BalanceEntry) -> (f64, f64) {
    (
        entry.balance_us_low.unwrap(),
        entry.balance_us_high.unwrap(),
    )
}

#[test]
fn curve_probes_that_noise_crossed_still_bracket_the_balance() {
    // The curve's 63 µs probe reads as idling and its 158 µs probe as waiting: the bracket
    // is taken between them, either way round.
    let model = Model {
        swapped: |w| [63.096, 158.489].iter().any(|c| (w - c).abs() < 0.01),
        ..Model::new(|_| false)
    };
    let entry = balance::search(&model, &dp_cell(), &settings()).unwrap();
    let (lo, hi) = bracket(&entry);
    assert!(lo <= 100.0 && 100.0 <= hi && hi - lo <= 2.0, "[{lo}, {hi}]");
}

#[test]
fn the_curve_spans_the_range_and_the_figures_come_from_the_probe_at_the_balance() {
    let entry = balance::search(&Model::new(|_| false), &dp_cell(), &settings()).unwrap();
    assert_eq!(entry.step_us, 100.0);
    // Six points from a tenth of the step to ten steps, evenly spaced on a log scale.
    for i in 0..6 {
        let w = 10.0 * 100f64.powf(i as f64 / 5.0);
        assert!(
            entry.probes.iter().any(|p| close(p.workload_us, w)),
            "no curve probe at {w} µs"
        );
    }
    assert!(entry
        .probes
        .windows(2)
        .all(|p| p[0].workload_us <= p[1].workload_us));
    let (lo, hi) = bracket(&entry);
    let b = entry.balance_us.unwrap();
    assert_eq!(b, (lo + hi) / 2.0);
    assert!(
        entry.probes.iter().any(|p| p.workload_us == b),
        "a probe at the balance"
    );
    // There the model's DP frame is max(W, S) + 5 µs, its serial twin's W + S and its UP
    // twin's W + S + 2; trials that do not vary give an interval of the ratio alone.
    let dp = b.max(100.0) + 5.0;
    let over_serial = entry.dp_over_serial.unwrap();
    assert!(close(over_serial, (b + 100.0) / dp), "{over_serial}");
    assert_eq!(entry.dp_over_serial_low, Some(over_serial));
    assert_eq!(entry.dp_over_serial_high, Some(over_serial));
    let over_up = entry.dp_over_up.unwrap();
    assert!(close(over_up.value, (b + 102.0) / dp), "{over_up:?}");
    let overhead = entry.overhead_percent.unwrap();
    assert!(close(overhead, 100.0 * 5.0 / b.max(100.0)), "{overhead}");
    assert_eq!(
        entry.unit_cost, None,
        "synthetic work is counted in iterations"
    );
    assert_eq!(
        entry.round_trip_ns,
        [50.0, 50.0],
        "before and after the search"
    );
}

#[test]
fn an_up_search_runs_the_curve_and_says_why_it_has_no_balance() {
    let key = dp_cell().with(Dim::Mode, Mode::Up.value()).unwrap();
    let entry = balance::search(&Model::new(|_| false), &key, &settings()).unwrap();
    assert_eq!(
        entry.note.as_deref(),
        Some("one core runs both threads: the main thread always waits, so there is no balance point")
    );
    assert_eq!(entry.probes.len(), 6, "the curve alone");
    assert!(entry
        .probes
        .iter()
        .all(|p| p.up_fps.is_empty() && p.serial_fps.len() == 2));
    assert_eq!(
        (entry.balance_us, entry.dp_over_serial, entry.dp_over_up),
        (None, None, None)
    );
    assert_eq!(entry.placement, Some(Class::One));
    let one = entry.headline().unwrap();
    assert_eq!((one.probes, one.step_us), (6, Some(100.0)));
    assert_eq!((one.balance_us, one.dp_over_serial), (None, None));
}

#[test]
fn a_kind_with_its_own_unit_is_searched_in_it() {
    let mut json = serde_json::to_value(dp_cell()).unwrap();
    json["workload_kind"] = "spray".into();
    json["ocean"] = "fft".into();
    json["normals"] = "analytic".into();
    let key: CellKey = serde_json::from_value(json).unwrap();
    let unit = key.workload_kind.unit();
    assert_ne!(unit, "iterations");
    let entry = balance::search(&Model::new(|_| false), &key, &settings()).unwrap();
    assert_eq!(
        entry.unit_cost,
        Some(UnitCost {
            unit: unit.into(),
            ns: 2.0
        })
    );
    let (lo, hi) = bracket(&entry);
    assert!(lo <= 100.0 && 100.0 <= hi && hi - lo <= 2.0, "[{lo}, {hi}]");
    let b = entry.balance_us.unwrap();
    assert_eq!(
        entry.balance_amount(),
        Some(((b * 1e3 / 2.0).round() as u64, unit))
    );
}

/// A machine whose every trial fails with `.0`.
struct Failing(fn() -> LoopError);

impl Testbed for Failing {
    fn trial(&self, _key: &CellKey, _amount: u64) -> Result<Trial, LoopError> {
        Err((self.0)())
    }

    fn ns_per_iteration(&self) -> f64 {
        1.0
    }

    fn round_trip(&self, _batches: usize) -> Option<f64> {
        None
    }
}

#[test]
fn a_failed_trial_ends_the_search_naming_the_cell_and_a_stop_request_says_interrupted() {
    let key = dp_cell();
    match balance::search(&Failing(|| LoopError::Interrupted), &key, &settings()) {
        Err(BalanceError::Interrupted) => {}
        other => panic!("{other:?}"),
    }
    match balance::search(
        &Failing(|| LoopError::Helper("it panicked".into())),
        &key,
        &settings(),
    ) {
        Err(e @ BalanceError::Loop { .. }) => assert_eq!(
            e.to_string(),
            format!("{}: helper thread failed: it panicked", key.label())
        ),
        other => panic!("{other:?}"),
    }
}

#[test]
fn a_probe_within_noise_narrows_the_bracket_or_says_what_stopped_it() {
    // Waits 0.4 µs apart: the noise, 0.8 µs, is within half the 2 µs tolerance. The
    // bisection's probe at 100.35 µs cannot tell the side, and narrows [98.9, 101.8] to the
    // model's balance give or take the noise: [99.2, 100.8].
    let entry = balance::search(&Model::noisy(0.4), &dp_cell(), &settings()).unwrap();
    let (lo, hi) = bracket(&entry);
    assert!(close(lo, 99.2) && close(hi, 100.8), "[{lo}, {hi}]");
    assert_eq!(entry.note, None);
    // 1 µs apart: noise 2 µs, over half the tolerance, and under twice it. The first probe
    // it hides (98.9 µs) ends the search at 100 ± 2 µs, and the note says why.
    let entry = balance::search(&Model::noisy(1.0), &dp_cell(), &settings()).unwrap();
    let (lo, hi) = bracket(&entry);
    assert!(close(lo, 98.0) && close(hi, 102.0), "[{lo}, {hi}]");
    assert_eq!(
        entry.note.as_deref(),
        Some(
            "noise (±2 µs in the waits at 99 µs) prevents a bracket narrower than 4.0% of the step"
        )
    );
    // 5 µs apart: noise 10 µs, over half the tolerance. The first probe it hides (98.9 µs)
    // ends the search at 100 ± 10 µs, and the note says why.
    let entry = balance::search(&Model::noisy(5.0), &dp_cell(), &settings()).unwrap();
    let (lo, hi) = bracket(&entry);
    assert!(close(lo, 90.0) && close(hi, 110.0), "[{lo}, {hi}]");
    assert_eq!(
        entry.note.as_deref(),
        Some("noise (±10 µs in the waits at 99 µs) prevents a bracket narrower than 20.0% of the step")
    );
}

#[test]
fn a_probe_in_no_placement_is_set_aside_and_counted() {
    // The curve's fifth probe (398 µs) has round trips 13 to 15, each far from any other.
    let model = Model {
        lost: |i| (13..=15).contains(&i),
        ..Model::new(|_| false)
    };
    let entry = balance::search(&model, &dp_cell(), &settings()).unwrap();
    let lost: Vec<f64> = entry
        .probes
        .iter()
        .filter(|p| p.placement.is_none())
        .map(|p| p.workload_us)
        .collect();
    assert_eq!(lost.len(), 1);
    assert!(close(lost[0], 398.107), "{lost:?}");
    assert_eq!((entry.placement, entry.set_aside), (Some(Class::One), 1));
    assert_eq!(
        entry.note.as_deref(),
        Some(&*format!(
            "probes mixed placements: 1 of {} set aside (1 unplaced); the figures are the one probes' alone",
            entry.probes.len()
        ))
    );
    let (lo, hi) = bracket(&entry);
    assert!(lo <= 100.0 && 100.0 <= hi && hi - lo <= 2.0, "[{lo}, {hi}]");
}

#[test]
fn a_placement_takes_the_step_at_its_balance_or_else_its_probes_median() {
    // The helper's step grows by 1 µs per 100 µs of main-thread work, so the balance, where
    // W = S(W), is 101.01 µs, and the step is read at the probe there, not at the median
    // probe: of a curve of twelve points from 50 µs to 10 ms, ten lie above the balance.
    let model = Model {
        step_per_work: 0.01,
        ..Model::new(|_| false)
    };
    let wide = BalanceSettings {
        points: 12,
        range: [0.5, 100.0],
        ..settings()
    };
    let entry = balance::search(&model, &dp_cell(), &wide).unwrap();
    let (lo, hi) = bracket(&entry);
    assert!(lo <= 101.01 && 101.01 <= hi, "[{lo}, {hi}]");
    let b = entry.balance_us.unwrap();
    let at = entry.probes.iter().find(|p| p.workload_us == b).unwrap();
    assert_eq!(entry.headline().unwrap().step_us, at.step());

    // Placed: the curve's last three probes (158, 398 and 1000 µs, round trips 10 to 18) and
    // the search's first round trip. Above the balance all, they bracket none, so the search
    // has no balance to report: the step is their median (the 398 µs probe's), the ratio the
    // probe's nearest the search's step (158 µs).
    let step = |w: f64| 100.0 + w / 100.0;
    let model = Model {
        lost: |i| (1..=9).contains(&i) || i >= 19,
        step_per_work: 0.01,
        ..Model::new(|_| false)
    };
    let entry = balance::search(&model, &dp_cell(), &settings()).unwrap();
    let n = entry.probes.len();
    assert_eq!(
        (entry.placement, entry.set_aside),
        (Some(Class::One), n - 3)
    );
    assert_eq!(
        entry.note.as_deref(),
        Some(&*format!(
            "probes mixed placements: {} of {n} set aside ({} unplaced); the figures are the one probes' alone, which bracket no balance point",
            n - 3,
            n - 3
        ))
    );
    let one = entry.headline().unwrap();
    assert!(close(one.step_us.unwrap(), step(398.107)), "{one:?}");
    assert_eq!(
        (
            entry.balance_us,
            entry.balance_us_low,
            entry.balance_us_high
        ),
        (None, None, None)
    );
    let w = 158.489;
    let over_serial = entry.dp_over_serial.unwrap();
    assert!(
        close(over_serial, (w + step(w)) / (w + 5.0)),
        "{over_serial}"
    );

    // Two placed (398 and 1000 µs): the overhead is the middle one's, the second of two.
    let model = Model {
        lost: |i| (1..=12).contains(&i) || i >= 19,
        step_per_work: 0.01,
        ..Model::new(|_| false)
    };
    let entry = balance::search(&model, &dp_cell(), &settings()).unwrap();
    assert_eq!(entry.set_aside, entry.probes.len() - 2);
    let overhead = entry.overhead_percent.unwrap();
    assert!(
        close(overhead, 0.5),
        "a 1005 µs frame for 1000 µs of work: {overhead}"
    );
}

#[test]
fn a_range_without_a_balance_point_says_which_side_and_suggests_one() {
    // On the model: up to a third of the step the main thread always waits for the mesh, and
    // from three steps up the helper always idles.
    let cell = dp_cell();
    for (range, side, suggested) in [
        ([0.02, 0.3], "top of the range", "\"range\": [0.02, 3]"),
        ([3.0, 10.0], "bottom of the range", "\"range\": [0.3, 10]"),
    ] {
        let settings = BalanceSettings {
            range,
            ..settings()
        };
        let Err(balance::BalanceError::Input(e)) =
            balance::search(&Model::new(|_| false), &cell, &settings)
        else {
            panic!("{range:?} holds no balance point");
        };
        assert!(e.0.contains(side) && e.0.contains(suggested), "{e}");
    }
}

/// A probe at `workload_us` whose trials' waits differ by `signs` (main's wait less the
/// helper's, µs): positive below the balance, negative above it.
fn probe(workload_us: f64, signs: [f64; 2]) -> Probe {
    Probe {
        workload_us,
        fps: vec![100.0; 2],
        serial_fps: vec![80.0; 2],
        up_fps: Vec::new(),
        main_wait_us: signs.iter().map(|s| 100.0 + s).collect(),
        helper_wait_us: vec![100.0; 2],
        frame_ms: 0.2,
        step_us: Vec::new(),
        round_trip_ns: Vec::new(),
        placement: None,
    }
}

fn bracket_of(probes: &[Probe]) -> Option<(f64, f64)> {
    balance::bracket_of(&probes.iter().collect::<Vec<_>>())
}

#[test]
fn measured_probes_bracket_the_balance_narrowed_by_a_noisy_probe_inside_it() {
    let waits = probe(50.0, [50.0, 50.0]);
    let idles = probe(150.0, [-50.0, -50.0]);
    assert_eq!(
        bracket_of(&[idles.clone(), waits.clone()]),
        Some((50.0, 150.0))
    );
    // Every probe on one side brackets nothing.
    assert_eq!(
        bracket_of(&[waits.clone(), probe(80.0, [20.0, 20.0])]),
        None
    );
    assert_eq!(
        bracket_of(&[idles.clone(), probe(120.0, [-20.0, -20.0])]),
        None
    );
    // Noise crossed them: the main thread waited at 120 µs but not at 80.
    assert_eq!(
        bracket_of(&[
            waits.clone(),
            probe(80.0, [-20.0, -20.0]),
            probe(120.0, [20.0, 20.0])
        ]),
        Some((80.0, 120.0))
    );

    // Within noise at 95 µs: waits differ by 4 µs on average, give or take 12 (two standard
    // errors of 10 and -2), so the balance lies within 99 ± 12 µs.
    let inside = probe(95.0, [10.0, -2.0]);
    assert_eq!(
        bracket_of(&[waits.clone(), idles.clone(), inside.clone()]),
        Some((87.0, 111.0))
    );
    // A probe with no noise whose waits are equal puts the balance at its workload.
    assert_eq!(
        bracket_of(&[waits.clone(), idles.clone(), probe(100.0, [0.0, 0.0])]),
        Some((100.0, 100.0))
    );
    // Probes within noise at or outside the bracket's ends leave it alone, though their
    // windows (± 16 µs) reach into it.
    let noisy = |w: f64| probe(w, [8.0, -8.0]);
    assert_eq!(
        bracket_of(&[waits.clone(), idles.clone(), noisy(150.0)]),
        Some((50.0, 150.0))
    );
    assert_eq!(
        bracket_of(&[
            noisy(45.0),
            noisy(50.0),
            waits,
            inside,
            idles,
            noisy(150.0),
            noisy(155.0)
        ]),
        Some((87.0, 111.0))
    );
}
