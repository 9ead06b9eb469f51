//! A run's placement: every trial labelled against the split of the run's round trips, each
//! cell's trials by placement, and the per-run finding (does DP behave differently on the two
//! placements?). Results in, facts out.

use crate::cell::Mode;
use crate::placement::{mixed, Class, Split};
use crate::results::{Cell, CellKey, Results};
use crate::slow_trials::TrialRecord;
use crate::stats;
use serde::{Deserialize, Serialize};

/// The split of every round trip a results file holds: around each trial, around each balance
/// probe, before and after each search, and the run's own before, during and after.
pub fn split(results: &Results) -> Option<Split> {
    Split::of(round_trips(results))
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
/// the file holds, and records that split. The sweep calls it before every write; a reader of
/// a file from before schema 6 calls it after loading, so its trials are placed from whatever
/// round trips it holds (its DP trials') as a new file's are. Everything else here reads the
/// labels.
pub fn label(results: &mut Results) {
    let split = split(results);
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
    /// The cell's kept trials by their labels ([`label`]).
    pub fn of(cell: &Cell) -> CellPlacement {
        let classed: Vec<(Option<Class>, &TrialRecord)> =
            cell.trials.iter().map(|t| (t.placement, t)).collect();
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

    /// Whether the kept trials ran in more than one placement (or moved during one).
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

/// How a run's cells fell between the placements.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunPlacement {
    /// The run's round trips as one cluster or two; `None` when none was measured.
    pub split: Option<Split>,
    /// Every measured cell with a placed trial.
    pub cells: Vec<CellPlacement>,
}

impl RunPlacement {
    /// The placement of every cell of `results`, from its labels ([`label`]).
    pub fn of(results: &Results) -> RunPlacement {
        let cells = results
            .cells
            .iter()
            .map(CellPlacement::of)
            .filter(|p| !p.classes.is_empty())
            .collect();
        RunPlacement {
            split: results.placement.clone(),
            cells,
        }
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
        let trials = self.trials();
        let total: usize = trials.iter().map(|t| t.1).sum();
        let trials = match trials.as_slice() {
            [] => String::new(),
            [(Class::One, n)] => format!("; every one of the {n} placed trials ran in it"),
            _ => {
                let each: Vec<String> = trials.iter().map(|(c, n)| format!("{n} {c}")).collect();
                format!("; {total} placed trials: {}", each.join(", "))
            }
        };
        let mixed = if split.two() {
            format!(
                "; {} of {} cells with placed trials mixed placements",
                self.mixed().count(),
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
    /// The DP cells the figures below are over: those that ran in both placements when any
    /// did (each then against itself), else every DP cell with trials in this one.
    pub cells: usize,
    /// Geometric mean over those cells of their DP ÷ serial in this placement.
    pub dp_over_serial: Option<f64>,
    /// Median over the same cells of their helper's median step in it (ms).
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
    /// Whether the serial twins' trials were placed too (runs from before schema 6 measured
    /// round trips around DP trials only; their serial FPS is then the twin's over every trial).
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

/// The finding of `results` (labelled, see [`label`]): per placement, DP ÷ serial (each DP cell
/// against its serial twin's trials in the same placement) and the helper's step; and for the
/// DP cells that ran in both, far against near. `None` when the run has no placed DP trial.
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
    let classes = if split.two() {
        vec![Class::Near, Class::Far]
    } else {
        vec![Class::One]
    };
    let paired =
        |c: &&&CellPlacement| contrasts.is_empty() || contrasts.iter().any(|x| x.key == c.key);
    let sides: Vec<Side> = classes
        .iter()
        .map(|&class| {
            let there: Vec<&&CellPlacement> =
                dp.iter().filter(|c| c.get(class).is_some()).collect();
            let basis: Vec<&&CellPlacement> = there.iter().copied().filter(paired).collect();
            let ratios: Vec<f64> = basis.iter().filter_map(|c| over(c, class)).collect();
            let steps: Vec<f64> = basis
                .iter()
                .filter_map(|c| c.get(class))
                .map(|t| t.step_ms)
                .collect();
            Side {
                class,
                dp_trials: there
                    .iter()
                    .filter_map(|c| c.get(class))
                    .map(|t| t.trials)
                    .sum(),
                cells: basis.len(),
                dp_over_serial: geomean(&ratios),
                step_ms: (!steps.is_empty()).then(|| stats::median(&steps)),
            }
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
    let mut finding = Finding {
        sentence: String::new(),
        split,
        sides,
        contrasts,
        dp_over_serial_far_over_near,
        step_far_over_near,
        serial_placed,
    };
    finding.sentence = sentence(&finding);
    Some(finding)
}

fn sentence(f: &Finding) -> String {
    let num = |v: Option<f64>, digits: usize| v.map_or("–".into(), |v| format!("{v:.digits$}"));
    let serial = if f.serial_placed {
        ""
    } else {
        " Serial trials were not placed in this run: each DP ÷ serial is against its serial twin's every trial."
    };
    if !f.split.two() {
        let s = &f.sides[0];
        return format!(
            "Every round trip fell in one placement ({}): DP ÷ serial {} and the helper's step {} ms over its {} DP trials; the run cannot say whether DP behaves differently on another placement.{serial}",
            f.split.describe().trim_start_matches("one placement, "),
            num(s.dp_over_serial, 2),
            num(s.step_ms, 3),
            s.dp_trials
        );
    }
    let [near, far] = [&f.sides[0], &f.sides[1]];
    let span = |c: Class| {
        let [lo, hi] = f.split.span(c).unwrap_or([f64::NAN; 2]);
        format!("{lo:.0}-{hi:.0} ns")
    };
    let head = format!(
        "Two placements: near {} ({} DP trials) and far {} ({})",
        span(Class::Near),
        near.dp_trials,
        span(Class::Far),
        far.dp_trials
    );
    let figures = format!(
        "DP ÷ serial was {} near and {} far, the helper's step {} ms near and {} ms far",
        num(near.dp_over_serial, 2),
        num(far.dp_over_serial, 2),
        num(near.step_ms, 3),
        num(far.step_ms, 3)
    );
    if f.contrasts.is_empty() {
        format!(
            "{head}. No DP cell ran in both, so the two come from different cells ({} near, {} far): {figures}.{serial}",
            near.cells, far.cells
        )
    } else {
        format!(
            "{head}. Over the {} DP cell(s) that ran in both, {figures} (far ÷ near {} and {}).{serial}",
            f.contrasts.len(),
            num(f.dp_over_serial_far_over_near, 2),
            num(f.step_far_over_near, 2)
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cell::{Dim, DimValue, Threading, Value};
    use crate::ocean::{Kernel, NormalMethod};
    use crate::sync::SyncMethod;

    fn key(size: usize) -> CellKey {
        CellKey::from_fn(|dim| match dim {
            Dim::Size => Some(Value::Count(size)),
            Dim::Workload => Some(Value::Count(0)),
            Dim::Mode => Some(Mode::Dp.value()),
            Dim::Sync => Some(SyncMethod::Atomic.value()),
            Dim::Threading => Some(Threading::Pool.value()),
            Dim::Normals => Some(NormalMethod::Neighbors.value()),
            Dim::Kernel => Some(Kernel::Reference.value()),
            _ => None,
        })
        .expect("a whole key")
    }

    fn cell(size: usize, classes: &[(Class, usize, f64)]) -> CellPlacement {
        CellPlacement {
            key: key(size),
            classes: classes
                .iter()
                .map(|&(class, trials, fps)| ClassTrials {
                    class,
                    trials,
                    fps,
                    step_ms: 1.0,
                })
                .collect(),
            unplaced: 0,
        }
    }

    fn split(two: bool) -> Split {
        let far = if two { vec![400.0, 410.0] } else { vec![] };
        Split::of([100.0, 110.0].into_iter().chain(far)).expect("round trips")
    }

    #[test]
    fn a_cell_has_one_class_only_when_its_trials_share_one_that_is_no_move() {
        assert_eq!(cell(40, &[(Class::Near, 3, 1.0)]).only(), Some(Class::Near));
        assert_eq!(cell(40, &[(Class::Moved, 3, 1.0)]).only(), None);
        let both = cell(40, &[(Class::Near, 2, 1.0), (Class::Far, 1, 1.0)]);
        assert_eq!(both.only(), None);
        assert_eq!(both.fps_line(), "near 1 FPS (2), far 1 FPS (1)");
        let line = cell(40, &[(Class::Near, 3, 1234.4), (Class::Far, 2, 986.6)]).fps_line();
        assert_eq!(line, "near 1234 FPS (3), far 987 FPS (2)");
    }

    #[test]
    fn a_run_counts_trials_per_class_and_names_its_mixed_cells() {
        let run = RunPlacement {
            split: Some(split(true)),
            cells: vec![
                cell(40, &[(Class::Near, 3, 1.0)]),
                cell(96, &[(Class::Near, 2, 1.0), (Class::Far, 1, 1.0)]),
            ],
        };
        assert_eq!(run.trials(), [(Class::Near, 5), (Class::Far, 1)]);
        let mixed: Vec<&CellKey> = run.mixed().map(|c| &c.key).collect();
        assert_eq!(mixed, [&key(96)]);
        let summary = run.summary().expect("a split");
        assert!(
            summary.ends_with("; 6 placed trials: 5 near, 1 far; 1 of 2 cells with placed trials mixed placements"),
            "{summary}"
        );
    }

    #[test]
    fn a_run_in_one_placement_or_with_no_placed_trial_says_so() {
        let one = RunPlacement {
            split: Some(split(false)),
            cells: vec![cell(40, &[(Class::One, 4, 1.0)])],
        };
        let summary = one.summary().expect("a split");
        assert!(
            summary.ends_with("; every one of the 4 placed trials ran in it"),
            "{summary}"
        );
        let none = RunPlacement {
            split: Some(split(false)),
            cells: vec![],
        };
        assert_eq!(none.trials(), []);
        assert_eq!(none.summary(), Some(split(false).describe()));
        let unmeasured = RunPlacement {
            split: None,
            cells: vec![],
        };
        assert_eq!(unmeasured.summary(), None);
    }

    #[test]
    fn the_geometric_mean_skips_what_has_no_logarithm() {
        assert_eq!(geomean(&[1.0, 4.0]), Some(2.0));
        assert_eq!(
            geomean(&[2.0, 0.0, -1.0, f64::INFINITY, f64::NAN, 8.0]),
            Some(4.0)
        );
        assert_eq!(geomean(&[0.0, f64::NAN]), None);
    }
}
