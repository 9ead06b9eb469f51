//! Where the two measured cores sat relative to each other. On a shared VM the hypervisor moves
//! the two vCPUs between pairs of physical cores mid-run: near (two hardware threads of one
//! core, or two cores sharing a cache) or far (two cores on different dies), and the cache-line
//! round trip between them tells the two apart. A DP trial on near cores is a different
//! experiment from one on far cores, so every trial and balance probe is classified from the
//! round trips measured around it, against the run's own distribution of round trips: one
//! cluster (one placement throughout), or two (near and far).
//!
//! Everything here is plain data in, facts out: no measuring, no I/O.

use crate::crosscore::PLACEMENT_CHANGE_RATIO;
use crate::frame_loop::Mode;
use crate::results::{Cell, CellKey, Results};
use crate::slow_trials::TrialRecord;
use crate::stats;
use serde::{Deserialize, Serialize};

crate::named! {
    /// Where a trial (or probe) ran, from the round trips around it.
    pub enum Class {
        /// The run's round trips form one cluster: one placement throughout.
        One,
        /// The faster of the run's two clusters of round trips.
        Near,
        /// The slower of the two.
        Far,
        /// The round trips around it fell in different clusters: the cores moved during it.
        Moved,
    }
}

/// A run's round trips, as one cluster or two.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Split {
    /// Fastest and slowest round trip of the near cluster, or of the only one (ns).
    pub near_ns: [f64; 2],
    /// Round trips in it.
    pub near_count: usize,
    /// Fastest and slowest round trip of the far cluster, when there are two (ns).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub far_ns: Option<[f64; 2]>,
    /// Round trips in it.
    #[serde(default)]
    pub far_count: usize,
    /// Round trips in neither cluster (a ping-pong preempted while it was timed).
    #[serde(default)]
    pub outliers: usize,
}

/// A value belongs to a cluster when it lies within this factor of its span: half the gap
/// (in log terms) that separates two clusters.
fn margin() -> f64 {
    PLACEMENT_CHANGE_RATIO.sqrt()
}

impl Split {
    /// The clusters of `round_trips` (ns; non-positive and non-finite values are ignored):
    /// sorted values are cut wherever one is more than [`PLACEMENT_CHANGE_RATIO`] times the one
    /// before; groups of at least two values are clusters (every group when none is), and the
    /// two most populous are near and far. `None` without a round trip.
    pub fn of(round_trips: impl IntoIterator<Item = f64>) -> Option<Split> {
        let mut v: Vec<f64> = round_trips
            .into_iter()
            .filter(|x| x.is_finite() && *x > 0.0)
            .collect();
        v.sort_by(f64::total_cmp);
        let mut groups: Vec<&[f64]> = v
            .chunk_by(|a, b| b <= &(a * PLACEMENT_CHANGE_RATIO))
            .collect();
        if groups.is_empty() {
            return None;
        }
        if groups.iter().any(|g| g.len() >= 2) {
            groups.retain(|g| g.len() >= 2);
        }
        // The two most populous; among equals, the faster first (a stable sort keeps order).
        let mut ranked = groups.clone();
        ranked.sort_by_key(|g| std::cmp::Reverse(g.len()));
        ranked.truncate(2);
        ranked.sort_by(|a, b| a[0].total_cmp(&b[0]));
        let span = |g: &[f64]| [g[0], g[g.len() - 1]];
        let clustered: usize = ranked.iter().map(|g| g.len()).sum();
        Some(Split {
            near_ns: span(ranked[0]),
            near_count: ranked[0].len(),
            far_ns: ranked.get(1).map(|g| span(g)),
            far_count: ranked.get(1).map_or(0, |g| g.len()),
            outliers: v.len() - clustered,
        })
    }

    /// The split of every round trip a results file holds: around each trial, around each
    /// balance probe, before and after each search, and the run's own before, during and after.
    pub fn of_results(results: &Results) -> Option<Split> {
        Split::of(round_trips(results))
    }

    /// Whether the round trips form two clusters.
    pub fn two(&self) -> bool {
        self.far_ns.is_some()
    }

    /// The class of one round trip; `None` for a value in neither cluster.
    pub fn class(&self, ns: f64) -> Option<Class> {
        let within = |[lo, hi]: [f64; 2]| ns >= lo / margin() && ns <= hi * margin();
        match self.far_ns {
            None => within(self.near_ns).then_some(Class::One),
            Some(far) if within(self.near_ns) => Some(Class::Near).filter(|_| !within(far)),
            Some(far) => within(far).then_some(Class::Far),
        }
    }

    /// The class of something measured between round trips `ns` (a trial's before and after, a
    /// probe's before every round and after the last): the one class all placed values share,
    /// [`Class::Moved`] when they differ, `None` when none is placed.
    pub fn class_of(&self, ns: &[f64]) -> Option<Class> {
        let mut classes = ns.iter().filter_map(|&x| self.class(x));
        let first = classes.next()?;
        Some(if classes.all(|c| c == first) {
            first
        } else {
            Class::Moved
        })
    }

    /// The round trips of `class`, fastest and slowest (ns).
    pub fn span(&self, class: Class) -> Option<[f64; 2]> {
        match class {
            Class::One | Class::Near => Some(self.near_ns),
            Class::Far => self.far_ns,
            Class::Moved => None,
        }
    }

    /// `one placement, 41-64 ns` or `near 41-64 ns, far 363-402 ns`.
    pub fn describe(&self) -> String {
        let ns = |[lo, hi]: [f64; 2]| {
            if (hi - lo).abs() < 0.5 {
                format!("{lo:.0} ns")
            } else {
                format!("{lo:.0}-{hi:.0} ns")
            }
        };
        match self.far_ns {
            None => format!("one placement, round trip {}", ns(self.near_ns)),
            Some(far) => format!(
                "two placements: near {} ({} round trips), far {} ({})",
                ns(self.near_ns),
                self.near_count,
                ns(far),
                self.far_count
            ),
        }
    }
}

/// Every round trip in `results`, in no particular order (ns).
pub fn round_trips(results: &Results) -> Vec<f64> {
    let mut out: Vec<f64> = results.round_trip.all().map(|r| r.median_ns).collect();
    for c in &results.cells {
        for t in c.trials.iter().chain(&c.set_aside) {
            out.extend(t.round_trip_ns.iter().flatten());
        }
    }
    for e in &results.balance {
        out.extend(&e.round_trip_ns);
        for p in &e.probes {
            out.extend(&p.round_trip_ns);
        }
    }
    out
}

/// Places every trial of `results` (kept and set aside) against the split of every round trip
/// the file holds, and records that split: what results.json says of placement. Reports place
/// trials the same way from the round trips, so files written before this existed read alike.
pub fn label(results: &mut Results) {
    let split = Split::of_results(results);
    for c in &mut results.cells {
        for t in c.trials.iter_mut().chain(c.set_aside.iter_mut()) {
            t.placement = split.as_ref().and_then(|s| trial_class(s, t));
        }
    }
    results.placement = split;
}

/// The class of a trial from the round trips around it.
pub fn trial_class(split: &Split, trial: &TrialRecord) -> Option<Class> {
    split.class_of(&trial.round_trip_ns.unwrap_or_default())
}

/// Whether trials of these classes mixed placements: some near and some far, or one that moved.
pub fn mixed(classes: &[Option<Class>]) -> bool {
    let has = |c: Class| classes.contains(&Some(c));
    (has(Class::Near) && has(Class::Far)) || has(Class::Moved)
}

/// When trials of these classes mixed placements, the placement that holds `trials` of them.
pub fn settled(classes: &[Option<Class>], trials: usize) -> Option<Class> {
    if !mixed(classes) {
        return None;
    }
    [Class::Near, Class::Far]
        .into_iter()
        .find(|&c| classes.iter().filter(|&&x| x == Some(c)).count() >= trials)
}

/// Whether a cell whose trials have these classes needs another round: they mixed placements
/// and no placement holds `trials` of them yet.
pub fn needs_round(classes: &[Option<Class>], trials: usize) -> bool {
    mixed(classes) && settled(classes, trials).is_none()
}

/// Which trials a cell keeps: those of the placement that holds `trials` of them when they
/// mixed placements, else every one.
pub fn kept(classes: &[Option<Class>], trials: usize) -> Vec<bool> {
    match settled(classes, trials) {
        Some(class) => classes.iter().map(|&c| c == Some(class)).collect(),
        None => vec![true; classes.len()],
    }
}

/// A cell's trials in one class.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ClassTrials {
    /// The class.
    pub class: Class,
    /// Trials in it.
    pub trials: usize,
    /// Their mean FPS.
    pub fps: f64,
    /// Their median mean step (ms): the helper's in `dp`.
    pub step_ms: f64,
}

/// Where one cell's kept trials ran.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CellPlacement {
    /// The cell.
    pub key: CellKey,
    /// Each class its trials ran in, in the order near, far, one, moved.
    pub classes: Vec<ClassTrials>,
    /// Trials with no placed round trip.
    pub unplaced: usize,
}

impl CellPlacement {
    /// The cell's trials by class.
    pub fn of(cell: &Cell, split: &Split) -> CellPlacement {
        let classed: Vec<(Option<Class>, &TrialRecord)> = cell
            .trials
            .iter()
            .map(|t| (trial_class(split, t), t))
            .collect();
        let classes = [Class::Near, Class::Far, Class::One, Class::Moved]
            .into_iter()
            .filter_map(|class| {
                let of: Vec<&TrialRecord> = classed
                    .iter()
                    .filter(|(c, _)| *c == Some(class))
                    .map(|(_, t)| *t)
                    .collect();
                (!of.is_empty()).then(|| ClassTrials {
                    class,
                    trials: of.len(),
                    fps: stats::mean(&of.iter().map(|t| t.fps).collect::<Vec<_>>()),
                    step_ms: stats::median(
                        &of.iter().map(|t| t.breakdown.step_ms).collect::<Vec<_>>(),
                    ),
                })
            })
            .collect();
        CellPlacement {
            key: cell.key.clone(),
            classes,
            unplaced: classed.iter().filter(|(c, _)| c.is_none()).count(),
        }
    }

    /// Whether the kept trials ran in more than one placement (or moved during one): the
    /// tables' [`MIXED`] mark.
    pub fn mixed(&self) -> bool {
        let classes: Vec<Option<Class>> = self.classes.iter().map(|c| Some(c.class)).collect();
        mixed(&classes)
    }

    /// The trials of `class`, when there are any.
    pub fn get(&self, class: Class) -> Option<&ClassTrials> {
        self.classes.iter().find(|c| c.class == class)
    }

    /// The one class every placed trial shares, when they share one.
    pub fn only(&self) -> Option<Class> {
        match self.classes.as_slice() {
            [one] if one.class != Class::Moved => Some(one.class),
            _ => None,
        }
    }

    /// `near 1234 FPS (3), far 987 FPS (2)`.
    pub fn fps_line(&self) -> String {
        self.classes
            .iter()
            .map(|c| format!("{} {:.0} FPS ({})", c.class, c.fps, c.trials))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// Marks a cell whose kept trials ran in more than one placement.
pub const MIXED: &str = "§";

/// How a run's cells fell between the placements.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunPlacement {
    /// The run's round trips as one cluster or two; `None` when none was measured.
    pub split: Option<Split>,
    /// Every measured cell with a placed trial.
    pub cells: Vec<CellPlacement>,
}

impl RunPlacement {
    /// The placement of every cell of `results`.
    pub fn of(results: &Results) -> RunPlacement {
        let split = Split::of_results(results);
        let cells = split.as_ref().map_or_else(Vec::new, |s| {
            results
                .cells
                .iter()
                .map(|c| CellPlacement::of(c, s))
                .filter(|p| !p.classes.is_empty())
                .collect()
        });
        RunPlacement { split, cells }
    }

    /// The cell of `key`, if its trials were placed.
    pub fn cell(&self, key: &CellKey) -> Option<&CellPlacement> {
        self.cells.iter().find(|c| &c.key == key)
    }

    /// The cells that mixed placements.
    pub fn mixed(&self) -> impl Iterator<Item = &CellPlacement> {
        self.cells.iter().filter(|c| c.mixed())
    }

    /// Trials per class over every cell, in the order near, far, one, moved.
    pub fn trials(&self) -> Vec<(Class, usize)> {
        [Class::Near, Class::Far, Class::One, Class::Moved]
            .into_iter()
            .map(|class| {
                let n = self
                    .cells
                    .iter()
                    .filter_map(|c| c.get(class))
                    .map(|c| c.trials)
                    .sum();
                (class, n)
            })
            .filter(|&(_, n)| n > 0)
            .collect()
    }

    /// One line: the split and how the trials and cells fell; `None` without round trips.
    pub fn summary(&self) -> Option<String> {
        let split = self.split.as_ref()?;
        let trials: Vec<String> = self
            .trials()
            .iter()
            .map(|(c, n)| format!("{n} {c}"))
            .collect();
        let mixed = self.mixed().count();
        let trials = if trials.is_empty() {
            String::new()
        } else {
            format!("; trials: {}", trials.join(", "))
        };
        let mixed = if split.two() {
            format!(
                "; {mixed} of {} cells mixed placements ({MIXED} in the tables)",
                self.cells.len()
            )
        } else {
            String::new()
        };
        Some(format!("{}{trials}{mixed}", split.describe()))
    }
}

/// DP beside its serial twin within one placement.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Side {
    /// The placement.
    pub class: Class,
    /// DP trials in it, over every DP cell.
    pub dp_trials: usize,
    /// Geometric mean over the DP cells with trials in it of their DP ÷ serial there.
    pub dp_over_serial: Option<f64>,
    /// Median over the same cells of their helper's median step there (ms).
    pub step_ms: Option<f64>,
}

/// One DP cell that ran in both placements.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Contrast {
    /// The DP cell.
    pub key: CellKey,
    /// Its DP ÷ serial near and far.
    pub dp_over_serial: [Option<f64>; 2],
    /// Its helper's median step near and far (ms).
    pub step_ms: [f64; 2],
}

/// The per-run finding: does DP behave differently on the two placements?
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Finding {
    /// What the run shows, in one sentence.
    pub sentence: String,
    /// The run's round trips.
    pub split: Split,
    /// Per placement, DP ÷ serial and the helper's step.
    pub sides: Vec<Side>,
    /// The DP cells that ran in both placements, each against itself.
    pub contrasts: Vec<Contrast>,
    /// Geometric mean over [`Finding::contrasts`] of far ÷ near DP ÷ serial.
    pub dp_over_serial_far_over_near: Option<f64>,
    /// Geometric mean over the same of far ÷ near step.
    pub step_far_over_near: Option<f64>,
    /// Whether the serial twins' trials were placed too (runs from before placement was
    /// classified measured round trips around DP trials only; their serial FPS is then the
    /// twin's over every trial).
    pub serial_placed: bool,
}

fn geomean(values: &[f64]) -> Option<f64> {
    let v: Vec<f64> = values
        .iter()
        .copied()
        .filter(|x| x.is_finite() && *x > 0.0)
        .collect();
    (!v.is_empty()).then(|| (v.iter().map(|x| x.ln()).sum::<f64>() / v.len() as f64).exp())
}

/// The finding of `results`: per placement, DP ÷ serial (each DP cell against its serial twin's
/// trials in the same placement) and the helper's step; and for the DP cells that ran in both,
/// far against near. `None` when the run has no placed DP trial.
pub fn finding(results: &Results) -> Option<Finding> {
    let run = RunPlacement::of(results);
    let split = run.split.clone()?;
    let dp: Vec<&CellPlacement> = run
        .cells
        .iter()
        .filter(|c| c.key.mode == Mode::Dp)
        .collect();
    if dp.is_empty() {
        return None;
    }
    let serial_of = |key: &CellKey| -> Option<&Cell> {
        results.cell(&key.with(
            crate::cell::Dim::Mode,
            crate::cell::DimValue::value(Mode::Serial),
        )?)
    };
    let serial_placed = dp
        .iter()
        .filter_map(|c| serial_of(&c.key))
        .any(|s| run.cell(&s.key).is_some());
    // The serial twin's FPS in `class`: its trials there when they were placed, else all.
    let serial_fps = |key: &CellKey, class: Class| -> Option<f64> {
        let twin = serial_of(key)?;
        match run.cell(&twin.key) {
            Some(p) => p.get(class).map(|t| t.fps),
            None if serial_placed => None,
            None => twin.summary.as_ref().map(|s| stats::mean(&s.fps_trials)),
        }
    };
    let over = |c: &CellPlacement, class: Class| -> Option<f64> {
        Some(c.get(class)?.fps / serial_fps(&c.key, class)?)
    };
    let classes = if split.two() {
        vec![Class::Near, Class::Far]
    } else {
        vec![Class::One]
    };
    let sides: Vec<Side> = classes
        .iter()
        .map(|&class| {
            let of: Vec<&&CellPlacement> = dp.iter().filter(|c| c.get(class).is_some()).collect();
            let ratios: Vec<f64> = of.iter().filter_map(|c| over(c, class)).collect();
            let steps: Vec<f64> = of
                .iter()
                .filter_map(|c| c.get(class))
                .map(|t| t.step_ms)
                .collect();
            Side {
                class,
                dp_trials: of
                    .iter()
                    .filter_map(|c| c.get(class))
                    .map(|t| t.trials)
                    .sum(),
                dp_over_serial: geomean(&ratios),
                step_ms: (!steps.is_empty()).then(|| stats::median(&steps)),
            }
        })
        .collect();
    let contrasts: Vec<Contrast> = dp
        .iter()
        .filter_map(|c| {
            let (near, far) = (c.get(Class::Near)?, c.get(Class::Far)?);
            Some(Contrast {
                key: c.key.clone(),
                dp_over_serial: [over(c, Class::Near), over(c, Class::Far)],
                step_ms: [near.step_ms, far.step_ms],
            })
        })
        .collect();
    let ratio_of = |f: fn(&Contrast) -> Option<f64>| {
        geomean(&contrasts.iter().filter_map(f).collect::<Vec<_>>())
    };
    let dp_over_serial_far_over_near = ratio_of(|c| match c.dp_over_serial {
        [Some(n), Some(f)] => Some(f / n),
        _ => None,
    });
    let step_far_over_near = ratio_of(|c| Some(c.step_ms[1] / c.step_ms[0]));
    let sentence = sentence(
        &split,
        &sides,
        contrasts.len(),
        dp_over_serial_far_over_near,
        step_far_over_near,
        serial_placed,
    );
    Some(Finding {
        sentence,
        split,
        sides,
        contrasts,
        dp_over_serial_far_over_near,
        step_far_over_near,
        serial_placed,
    })
}

fn sentence(
    split: &Split,
    sides: &[Side],
    paired: usize,
    over: Option<f64>,
    step: Option<f64>,
    serial_placed: bool,
) -> String {
    let num = |v: Option<f64>, digits: usize| v.map_or("–".into(), |v| format!("{v:.digits$}"));
    if !split.two() {
        let s = &sides[0];
        return format!(
            "Every round trip fell in one placement ({}): DP ÷ serial {} and the helper's step {} ms over {} DP trials; the run cannot say whether DP behaves differently on another placement.",
            split.describe().trim_start_matches("one placement, "),
            num(s.dp_over_serial, 2),
            num(s.step_ms, 3),
            s.dp_trials
        );
    }
    let side = |s: &Side| {
        let span = split.span(s.class).unwrap_or([f64::NAN; 2]);
        format!(
            "{} ({:.0}-{:.0} ns, {} DP trials): DP ÷ serial {}, helper's step {} ms",
            s.class,
            span[0],
            span[1],
            s.dp_trials,
            num(s.dp_over_serial, 2),
            num(s.step_ms, 3)
        )
    };
    let sides: Vec<String> = sides.iter().map(side).collect();
    let paired = if paired == 0 {
        "no DP cell ran in both, so each placement's figures come from different cells".into()
    } else {
        format!(
            "over the {paired} DP cell(s) that ran in both, far ÷ near is {} for DP ÷ serial and {} for the step",
            num(over, 2),
            num(step, 2)
        )
    };
    let serial = if serial_placed {
        ""
    } else {
        " (serial trials were not placed in this run: each DP figure is against its serial twin's every trial)"
    };
    format!("Two placements. {}; {paired}{serial}.", sides.join("; "))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_cluster_is_one_placement() {
        let s = Split::of([50.0, 52.0, 61.0, 48.0]).unwrap();
        assert!(!s.two());
        assert_eq!(s.near_ns, [48.0, 61.0]);
        assert_eq!(s.class(55.0), Some(Class::One));
        assert_eq!(
            s.class(5_000.0),
            None,
            "a preempted ping-pong is no placement"
        );
        assert_eq!(s.class_of(&[50.0, 60.0]), Some(Class::One));
        assert!(s
            .describe()
            .starts_with("one placement, round trip 48-61 ns"));
    }

    #[test]
    fn two_clusters_are_near_and_far() {
        let s = Split::of([41.0, 64.0, 50.0, 363.0, 402.0, 390.0, 52.0]).unwrap();
        assert_eq!(s.near_ns, [41.0, 64.0]);
        assert_eq!(s.far_ns, Some([363.0, 402.0]));
        assert_eq!((s.near_count, s.far_count, s.outliers), (4, 3, 0));
        assert_eq!(s.class(45.0), Some(Class::Near));
        assert_eq!(s.class(380.0), Some(Class::Far));
        assert_eq!(s.class_of(&[45.0, 380.0]), Some(Class::Moved));
        assert_eq!(
            s.class_of(&[45.0, 9_000.0]),
            Some(Class::Near),
            "an outlier says nothing"
        );
        assert_eq!(s.class_of(&[]), None);
    }

    #[test]
    fn a_lone_outlier_is_not_a_cluster() {
        let s = Split::of([50.0, 52.0, 55.0, 4_000.0]).unwrap();
        assert!(!s.two());
        assert_eq!(s.outliers, 1);
        // Two values alone, far apart, are two placements.
        let s = Split::of([50.0, 400.0]).unwrap();
        assert!(s.two());
        assert_eq!(Split::of([f64::NAN, 0.0]), None);
    }

    #[test]
    fn a_mixed_cell_keeps_the_placement_that_reached_its_trials() {
        let (n, f, m) = (Some(Class::Near), Some(Class::Far), Some(Class::Moved));
        assert!(!mixed(&[n, n, None]));
        assert!(mixed(&[n, f]) && mixed(&[n, m]));
        // Three trials: near, far, near. Not settled: it needs a round.
        assert!(needs_round(&[n, f, n], 3));
        assert_eq!(settled(&[n, f, n], 3), None);
        assert_eq!(
            kept(&[n, f, n], 3),
            [true; 3],
            "unsettled: every trial kept"
        );
        // A fourth, near: near holds three, the far one is set aside.
        assert_eq!(settled(&[n, f, n, n], 3), Some(Class::Near));
        assert!(!needs_round(&[n, f, n, n], 3));
        assert_eq!(kept(&[n, f, n, n], 3), [true, false, true, true]);
        // One placement throughout needs nothing.
        assert!(!needs_round(&[f, f], 3));
        assert_eq!(kept(&[f, f], 3), [true, true]);
    }

    #[test]
    fn a_ratio_just_under_the_rule_is_one_cluster() {
        let s = Split::of([100.0, 199.0]).unwrap();
        assert!(!s.two());
        let s = Split::of([100.0, 201.0, 100.0, 201.0]).unwrap();
        assert!(s.two());
    }
}
