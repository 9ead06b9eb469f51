//! Why a trial was slow. The noise records see time taken away from a thread (run delay,
//! steal); they cannot see a core that runs slower (a busy SMT sibling in another guest, a lower
//! clock, a cache-hungry neighbour) nor a change of placement. Each trial therefore also carries
//! two speed canaries, work whose cost is known: the helper's step against the cell's other
//! trials, and the synthetic workload's time per iteration against its calibration; and the
//! cross-core round trip just before and after it. A trial well below its cell's median FPS is
//! put down to every cause whose evidence is there, or to none: unexplained.

use crate::stats;
use crate::summary::Breakdown;
use serde::{Deserialize, Serialize};

/// A canary this much slower than its reference says its core ran slower.
pub const CANARY_SLOWER: f64 = 0.10;

/// Round trips more than this many times apart are two placements (near and far), the sweep's
/// own rule.
pub const PLACEMENT_RATIO: f64 = crate::crosscore::PLACEMENT_CHANGE_RATIO;

/// The default share below the cell's median FPS that makes a trial slow, in percent.
pub const DEFAULT_THRESHOLD_PERCENT: f64 = 10.0;

crate::named! {
    /// What made a slow trial slow.
    pub enum Cause {
        /// Other tasks or the hypervisor took the threads' cores (run delay or steal over the
        /// noise threshold).
        TakenAway,
        /// The main thread's core ran the synthetic workload slower than its calibration.
        SlowMainCore,
        /// The helper's core ran the mesh step slower than in the cell's other trials.
        SlowHelperCore,
        /// The cross-core round trip around the trial says the threads moved between near and
        /// far cores.
        PlacementChange,
        /// None of the above: the evidence recorded does not say.
        Unexplained,
    }
}

/// What was measured around one trial, besides its frames.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TrialFacts {
    /// Frames ÷ seconds.
    pub fps: f64,
    /// The trial's mean per-frame breakdown.
    pub breakdown: Option<Breakdown>,
    /// Whether other tasks or the hypervisor took more than the noise threshold.
    pub taken_away: bool,
    /// The workload's nanoseconds per iteration in this trial ÷ its calibration in the row
    /// (synthetic workload above zero only).
    pub workload_ratio: Option<f64>,
    /// Median round trip just before and just after the trial (ns), when the threads have two
    /// cores.
    pub round_trip_ns: Option<[f64; 2]>,
}

/// One trial as results files keep it: its FPS and breakdown, its canaries and round trips, and
/// for a slow trial what made it slow.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrialRecord {
    /// Frames ÷ seconds.
    pub fps: f64,
    /// Mean per-frame breakdown of this trial.
    pub breakdown: Breakdown,
    /// The trial's mean step ÷ the median of the cell's trials' mean steps.
    pub step_ratio: Option<f64>,
    /// The workload's time per iteration ÷ its calibration in the row (synthetic, above zero).
    pub workload_ratio: Option<f64>,
    /// Median round trip before and after the trial (ns; two cores only; DP trials only
    /// before schema 6).
    pub round_trip_ns: Option<[f64; 2]>,
    /// Whether the noise records mark the trial (today's †).
    pub taken_away: bool,
    /// Present when the trial's FPS is more than the threshold below the cell's median.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub slow: Option<Slow>,
    /// Where its two cores sat, from its round trips against the run's (absent before
    /// schema 6, and without round trips).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub placement: Option<crate::placement::Class>,
}

/// How slow a slow trial was and why.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Slow {
    /// Percent below the cell's median trial FPS.
    pub below_median_percent: f64,
    /// Every cause whose evidence is there, or `unexplained` alone.
    pub causes: Vec<Cause>,
}

impl TrialRecord {
    /// Whether the trial is slow and nothing recorded says why.
    pub fn unexplained(&self) -> bool {
        self.slow
            .as_ref()
            .is_some_and(|s| s.causes == [Cause::Unexplained])
    }
}

/// The records of a cell's trials: canaries against the cell's medians, and each trial below
/// the median FPS by more than `threshold_percent` attributed.
pub fn attribute(facts: &[TrialFacts], threshold_percent: f64) -> Vec<TrialRecord> {
    let median_fps = stats::median(&facts.iter().map(|f| f.fps).collect::<Vec<_>>());
    let steps: Vec<f64> = facts
        .iter()
        .filter_map(|f| f.breakdown.as_ref().map(|b| b.step_ms))
        .filter(|&s| s > 0.0)
        .collect();
    let median_step = (!steps.is_empty()).then(|| stats::median(&steps));
    let trips: Vec<f64> = facts
        .iter()
        .filter_map(|f| f.round_trip_ns)
        .flatten()
        .filter(|&ns| ns > 0.0)
        .collect();
    let median_trip = (!trips.is_empty()).then(|| stats::median(&trips));
    // The workload canary's reference: its calibration, or the cell's typical trial when the
    // calibration itself ran slow (a busy machine while it was measured), so that one trial's
    // slower core still shows against its siblings.
    let ratios: Vec<f64> = facts.iter().filter_map(|f| f.workload_ratio).collect();
    let workload_reference = if ratios.is_empty() {
        1.0
    } else {
        stats::median(&ratios).min(1.0)
    };
    facts
        .iter()
        .filter_map(|f| {
            let breakdown = f.breakdown.clone()?;
            let step_ratio = median_step
                .filter(|_| breakdown.step_ms > 0.0)
                .map(|m| breakdown.step_ms / m);
            let below = 100.0 * (1.0 - f.fps / median_fps);
            let slow = (below > threshold_percent).then(|| {
                let mut causes = Vec::new();
                if f.taken_away {
                    causes.push(Cause::TakenAway);
                }
                if f.workload_ratio
                    .is_some_and(|r| r >= workload_reference * (1.0 + CANARY_SLOWER))
                {
                    causes.push(Cause::SlowMainCore);
                }
                if step_ratio.is_some_and(|r| r >= 1.0 + CANARY_SLOWER) {
                    causes.push(Cause::SlowHelperCore);
                }
                let moved = |ns: f64| {
                    median_trip.is_some_and(|m| ns > 0.0 && (ns / m).max(m / ns) > PLACEMENT_RATIO)
                };
                if f.round_trip_ns
                    .is_some_and(|t| t.iter().any(|&ns| moved(ns)))
                {
                    causes.push(Cause::PlacementChange);
                }
                if causes.is_empty() {
                    causes.push(Cause::Unexplained);
                }
                Slow {
                    below_median_percent: below,
                    causes,
                }
            });
            Some(TrialRecord {
                fps: f.fps,
                breakdown,
                step_ratio,
                workload_ratio: f.workload_ratio,
                round_trip_ns: f.round_trip_ns,
                taken_away: f.taken_away,
                slow,
                placement: None,
            })
        })
        .collect()
}

/// Refuses a slow-trial threshold outside (0, 100) percent.
pub fn check_threshold(percent: f64) -> Result<(), crate::input::InputError> {
    if percent > 0.0 && percent < 100.0 {
        Ok(())
    } else {
        Err(crate::input::InputError(format!(
            "slow_trial_percent: must be above 0 and below 100, got {percent}"
        )))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn breakdown(step_ms: f64) -> Breakdown {
        Breakdown {
            workload_ms: 1.0,
            wait_ms: 0.0,
            wait_cpu_ms: 0.0,
            copy_ms: 0.1,
            step_ms,
            other_ms: 0.0,
            helper_wait_ms: 0.0,
            helper_wait_cpu_ms: 0.0,
        }
    }

    /// Five trials at 100 FPS, step 1 ms, canary 1.0, round trips of 120 ns.
    fn quiet() -> Vec<TrialFacts> {
        (0..5)
            .map(|_| TrialFacts {
                fps: 100.0,
                breakdown: Some(breakdown(1.0)),
                taken_away: false,
                workload_ratio: Some(1.0),
                round_trip_ns: Some([120.0, 125.0]),
            })
            .collect()
    }

    fn causes(facts: &[TrialFacts], trial: usize) -> Option<Vec<Cause>> {
        attribute(facts, 10.0)[trial]
            .slow
            .as_ref()
            .map(|s| s.causes.clone())
    }

    #[test]
    fn a_quiet_cell_has_no_slow_trial() {
        let records = attribute(&quiet(), 10.0);
        assert_eq!(records.len(), 5);
        assert!(records.iter().all(|r| r.slow.is_none()));
        assert_eq!(records[0].step_ratio, Some(1.0));
    }

    #[test]
    fn each_injected_cause_is_named() {
        let slow = |f: &mut TrialFacts| f.fps = 60.0;
        let mut taken = quiet();
        slow(&mut taken[2]);
        taken[2].taken_away = true;
        assert_eq!(causes(&taken, 2), Some(vec![Cause::TakenAway]));

        let mut main = quiet();
        slow(&mut main[1]);
        main[1].workload_ratio = Some(1.25);
        assert_eq!(causes(&main, 1), Some(vec![Cause::SlowMainCore]));

        let mut helper = quiet();
        slow(&mut helper[4]);
        helper[4].breakdown = Some(breakdown(1.3));
        assert_eq!(causes(&helper, 4), Some(vec![Cause::SlowHelperCore]));

        let mut moved = quiet();
        slow(&mut moved[0]);
        moved[0].round_trip_ns = Some([120.0, 900.0]);
        assert_eq!(causes(&moved, 0), Some(vec![Cause::PlacementChange]));

        let mut none = quiet();
        slow(&mut none[3]);
        assert_eq!(causes(&none, 3), Some(vec![Cause::Unexplained]));
        assert!(attribute(&none, 10.0)[3].unexplained());

        let mut both = quiet();
        slow(&mut both[3]);
        both[3].taken_away = true;
        both[3].breakdown = Some(breakdown(2.0));
        assert_eq!(
            causes(&both, 3),
            Some(vec![Cause::TakenAway, Cause::SlowHelperCore])
        );
    }

    #[test]
    fn the_step_ratio_is_against_the_cells_median_step() {
        // Steps of 4 ms, not 1, so a ratio taken the wrong way round (step × median) shows.
        let mut facts = quiet();
        for f in &mut facts {
            f.breakdown = Some(breakdown(4.0));
        }
        facts[1].fps = 60.0;
        assert_eq!(attribute(&facts, 10.0)[1].step_ratio, Some(1.0));
        assert_eq!(causes(&facts, 1), Some(vec![Cause::Unexplained]));
        facts[1].breakdown = Some(breakdown(5.2));
        let ratio = attribute(&facts, 10.0)[1].step_ratio.unwrap();
        assert!((ratio - 1.3).abs() < 1e-9, "{ratio}");
        assert_eq!(causes(&facts, 1), Some(vec![Cause::SlowHelperCore]));
    }

    #[test]
    fn a_trial_with_no_step_or_round_trip_counts_in_no_median_and_gets_no_ratio() {
        // Steps 0, 0, 1, 2, 2: the median of the measured ones is 2 (with the zeros, 1).
        let mut facts = quiet();
        for (f, step) in facts.iter_mut().zip([0.0, 0.0, 1.0, 2.0, 2.0]) {
            f.breakdown = Some(breakdown(step));
        }
        let records = attribute(&facts, 10.0);
        assert_eq!(records[3].step_ratio, Some(1.0));
        assert_eq!(records[0].step_ratio, None, "no step, no ratio");
        // Six unmeasured round trips of ten: the median of the measured ones is 120 ns (the
        // lower middle), so a slow trial at 120-125 ns stayed where it was (with the zeros the
        // median is 0).
        let mut facts = quiet();
        for f in &mut facts[..3] {
            f.round_trip_ns = Some([0.0, 0.0]);
        }
        facts[3].fps = 60.0;
        assert_eq!(causes(&facts, 3), Some(vec![Cause::Unexplained]));
        // Nor did a slow trial whose own round trip went unmeasured.
        facts[3].round_trip_ns = Some([0.0, 120.0]);
        assert_eq!(causes(&facts, 3), Some(vec![Cause::Unexplained]));
    }

    #[test]
    fn a_calibration_that_ran_slow_does_not_hide_a_slowed_trial() {
        let mut facts = quiet();
        for f in &mut facts {
            f.workload_ratio = Some(0.5);
        }
        facts[2].fps = 70.0;
        facts[2].workload_ratio = Some(0.6);
        assert_eq!(causes(&facts, 2), Some(vec![Cause::SlowMainCore]));
        facts[2].workload_ratio = Some(0.54);
        assert_eq!(causes(&facts, 2), Some(vec![Cause::Unexplained]));
    }

    #[test]
    fn the_threshold_and_the_canary_margin_are_edges() {
        let mut facts = quiet();
        facts[0].fps = 90.5;
        assert_eq!(causes(&facts, 0), None, "9.5 % below is not slow at 10 %");
        facts[0].fps = 89.5;
        facts[0].workload_ratio = Some(1.09);
        assert_eq!(causes(&facts, 0), Some(vec![Cause::Unexplained]));
        facts[0].workload_ratio = Some(1.11);
        assert_eq!(causes(&facts, 0), Some(vec![Cause::SlowMainCore]));
        let r = &attribute(&facts, 10.0)[0];
        assert!((r.slow.as_ref().unwrap().below_median_percent - 10.5).abs() < 1e-9);
        // Exactly the threshold below is not slow: slow is more than the threshold below
        // (50 FPS under a median of 100 is 50 % below, exact in binary).
        let mut half = quiet();
        half[0].fps = 50.0;
        assert!(attribute(&half, 50.0)[0].slow.is_none());
        assert!(attribute(&half, 49.0)[0].slow.is_some());
        // A round trip 1.9x the median is the same placement.
        facts[0].workload_ratio = Some(1.0);
        facts[0].round_trip_ns = Some([228.0, 120.0]);
        assert_eq!(causes(&facts, 0), Some(vec![Cause::Unexplained]));
        // Exactly 2x the median (120 ns, the lower middle of ten) is still the same placement,
        // as the sweep's rule has it; a little more is a move.
        facts[0].round_trip_ns = Some([240.0, 120.0]);
        assert_eq!(causes(&facts, 0), Some(vec![Cause::Unexplained]));
        facts[0].round_trip_ns = Some([241.0, 120.0]);
        assert_eq!(causes(&facts, 0), Some(vec![Cause::PlacementChange]));
    }

    #[test]
    fn thresholds_outside_0_to_100_are_refused() {
        for bad in [0.0, -1.0, 100.0, f64::NAN] {
            let e = check_threshold(bad).unwrap_err().0;
            assert!(e.starts_with("slow_trial_percent: must be above 0"), "{e}");
        }
        check_threshold(10.0).unwrap();
    }
}
