//! What every export says of where its numbers came from: the machine, the source (commit and
//! dirty flag), the config and where the two measured cores sat. One record for every format:
//! a format with room carries it inline (a trace's `otherData`, github-action-benchmark's
//! `extra`), one without (BMF, a MangoHud log) gets it in a `*.provenance.json` beside the file
//! (docs/exports.md).

use super::placement::{self as run_placement, CellPlacement};
use crate::machine::Machine;
use crate::placement::{Class, Split};
use crate::results::{Cell, Results};
use crate::stats;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Where an export's numbers came from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Provenance {
    /// When the run started (RFC 3339 UTC).
    pub started: String,
    /// The oceanbench version that measured the run.
    pub oceanbench_version: String,
    /// The machine measured on.
    pub machine: MachineFacts,
    /// The source measured.
    pub commit: CommitFacts,
    /// The config run.
    pub config: ConfigFacts,
    /// Where the two cores sat: over the run, and for each exported cell.
    pub placement: PlacementFacts,
}

/// The machine, as results.json records it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MachineFacts {
    /// The CPU model.
    pub cpu: String,
    /// Logical cores the OS reports.
    pub logical_cores: usize,
    /// Cores the run could use.
    pub allowed_cores: Vec<usize>,
    /// The OS's name and version.
    pub os: String,
    /// The kernel release.
    pub kernel: String,
    /// `release` or `debug`.
    pub build_profile: String,
    /// All of it on one line, as the reports print it.
    pub line: String,
}

/// The source a run measured.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CommitFacts {
    /// The commit, when the build came from a checkout.
    pub id: Option<String>,
    /// Whether tracked files had uncommitted changes; `null` when not recorded.
    pub dirty: Option<bool>,
    /// The hash of the uncommitted diff, when dirty.
    pub diff_hash: Option<String>,
    /// All of it on one line, as the reports print it.
    pub line: String,
}

/// The config a run ran.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ConfigFacts {
    /// The config's `name`.
    pub name: String,
    /// FNV-1a 64 of the config as results.json records it (compact JSON), 16 hex digits: two
    /// runs of one config share it whatever file or flags produced it.
    pub hash: String,
    /// The command line that started the run (the config file's path for a `sweep`), when
    /// recorded.
    pub command: Option<Vec<String>>,
}

/// Where the two measured cores sat.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PlacementFacts {
    /// The run's round trips as one cluster or two, as far as measured when the file was
    /// written; `null` when nothing ran across two cores.
    pub split: Option<Split>,
    /// The split, and how the trials fell, on one line.
    pub summary: Option<String>,
    /// Whether the OS lists the two cores as thread siblings (the guest's view in a VM).
    pub thread_siblings: Option<bool>,
    /// Each exported cell's trials.
    pub cells: Vec<CellFacts>,
}

/// Where one exported cell's trials ran.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CellFacts {
    /// The cell as the export names it.
    pub name: String,
    /// `near`, `far` or `one` when every placed trial ran there, `mixed` when they did not
    /// (or one moved), `unplaced` when no trial has a placed round trip.
    pub placement: String,
    /// Each kept trial's class and median round trip before and after it (ns).
    pub trials: Vec<TrialFacts>,
    /// Trials set aside because they ran in the other placement.
    pub set_aside: usize,
}

/// One trial's placement.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrialFacts {
    /// Its class against the run's round trips; `null` when not placed.
    pub class: Option<Class>,
    /// Median round trip before and after it (ns); `null` on one core.
    pub round_trip_ns: Option<[f64; 2]>,
}

impl Provenance {
    /// The provenance of `results` for an export of `cells` (each named as the export names
    /// it), placed against every round trip the results hold.
    pub fn of(results: &Results, cells: Vec<CellFacts>) -> Provenance {
        let split = run_placement::split(results);
        let summary = run_placement::RunPlacement {
            split: split.clone(),
            ..run_placement::RunPlacement::of(results)
        }
        .summary();
        Provenance::assemble(results, split, summary, cells)
    }

    /// The provenance of a trial of cell `label` exported as it ends, before its cell is in
    /// `results` (a trace): placed by the round trips `around` it against every round trip
    /// measured so far, these two included.
    pub fn of_trial(results: &Results, label: String, around: Option<[f64; 2]>) -> Provenance {
        let trips = run_placement::round_trips(results);
        let split = Split::of(trips.into_iter().chain(around.into_iter().flatten()));
        let class = split
            .as_ref()
            .zip(around)
            .and_then(|(s, ns)| s.class_of(&ns));
        let cell = CellFacts {
            name: label,
            placement: match class {
                None => "unplaced".to_string(),
                Some(Class::Moved) => "mixed".to_string(),
                Some(c) => c.to_string(),
            },
            trials: vec![TrialFacts {
                class,
                round_trip_ns: around,
            }],
            set_aside: 0,
        };
        let summary = split.as_ref().map(Split::describe);
        Provenance::assemble(results, split, summary, vec![cell])
    }

    /// The one place every export's provenance is put together, so no format carries less.
    fn assemble(
        results: &Results,
        split: Option<Split>,
        summary: Option<String>,
        cells: Vec<CellFacts>,
    ) -> Provenance {
        let m: &Machine = &results.machine;
        Provenance {
            started: results.started.clone(),
            oceanbench_version: m.oceanbench_version.clone(),
            machine: MachineFacts {
                cpu: m.cpu_model.clone(),
                logical_cores: m.logical_cores,
                allowed_cores: m.allowed_cores.clone(),
                os: m.os.clone(),
                kernel: m.kernel.clone(),
                build_profile: m.build_profile.clone(),
                line: m.line(),
            },
            commit: CommitFacts {
                id: m.git_commit.clone(),
                dirty: m.git_dirty,
                diff_hash: m.git_diff_hash.clone(),
                line: m.provenance_line(),
            },
            config: ConfigFacts {
                name: results.config.name.clone(),
                hash: config_hash(results),
                command: results.command.clone(),
            },
            placement: PlacementFacts {
                split,
                summary,
                thread_siblings: results.round_trip.thread_siblings,
                cells,
            },
        }
    }

    /// The run's part as text, one fact per line: machine, commit, config and the run's
    /// placement (for a format whose only room is free text; each cell's is [`CellFacts::line`]).
    pub fn run_lines(&self) -> Vec<String> {
        let mut out = vec![
            format!(
                "machine: {}, kernel {}",
                self.machine.line, self.machine.kernel
            ),
            self.commit.line.clone(),
            format!(
                "config {} (hash {}), started {}",
                self.config.name, self.config.hash, self.started
            ),
        ];
        if let Some(summary) = &self.placement.summary {
            out.push(format!("placement: {summary}"));
        }
        out
    }
}

impl CellFacts {
    /// The placement of `cell`'s kept trials by their labels, named `name`.
    pub fn of(name: String, cell: &Cell) -> CellFacts {
        let p = CellPlacement::of(cell);
        let placement = if p.classes.is_empty() {
            "unplaced".to_string()
        } else if let Some(class) = p.only() {
            class.to_string()
        } else {
            "mixed".to_string()
        };
        CellFacts {
            name,
            placement,
            trials: cell
                .trials
                .iter()
                .map(|t| TrialFacts {
                    class: t.placement,
                    round_trip_ns: t.round_trip_ns,
                })
                .collect(),
            set_aside: cell.set_aside.len(),
        }
    }

    /// `placement of NAME: near, round trips 41-64 ns over 3 trial(s)`.
    pub fn line(&self) -> String {
        let ns: Vec<f64> = self
            .trials
            .iter()
            .flat_map(|t| t.round_trip_ns)
            .flatten()
            .collect();
        let round_trips = match (
            ns.iter().copied().reduce(f64::min),
            ns.iter().copied().reduce(f64::max),
        ) {
            (Some(lo), Some(hi)) => format!(", round trips {lo:.0}-{hi:.0} ns"),
            _ => String::new(),
        };
        let set_aside = match self.set_aside {
            0 => String::new(),
            n => format!(", {n} set aside"),
        };
        format!(
            "placement of {}: {}{round_trips} over {} trial(s){set_aside}",
            self.name,
            self.placement,
            self.trials.len()
        )
    }
}

/// FNV-1a 64 of `results`' config as results.json records it, 16 hex digits.
pub fn config_hash(results: &Results) -> String {
    let json = serde_json::to_string(&results.config).unwrap_or_default();
    format!("{:016x}", stats::seed_from(&json))
}

/// The provenance file beside export `path`: `bmf.json` gives `bmf.provenance.json`.
pub fn sidecar(path: &Path) -> PathBuf {
    path.with_extension("provenance.json")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cell_line_names_its_placement_round_trips_and_set_aside_trials() {
        let trial = |ns: [f64; 2]| TrialFacts {
            class: Some(Class::Near),
            round_trip_ns: Some(ns),
        };
        let cell = CellFacts {
            name: "size=16, mode=dp".into(),
            placement: "near".into(),
            trials: vec![trial([41.0, 52.0]), trial([64.0, 45.0])],
            set_aside: 1,
        };
        assert_eq!(
            cell.line(),
            "placement of size=16, mode=dp: near, round trips 41-64 ns over 2 trial(s), 1 set aside"
        );
    }

    fn quick() -> Results {
        serde_json::from_str(include_str!(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/tests/fixtures/quick-results.json"
        )))
        .unwrap()
    }

    #[test]
    fn a_run_s_placement_is_split_from_its_round_trips_not_taken_from_the_file() {
        // The fixture predates recorded splits: the provenance splits its round trips itself,
        // and says what a file that recorded that split would.
        let unrecorded = quick();
        assert_eq!(unrecorded.placement, None);
        let split = run_placement::split(&unrecorded);
        assert!(split.is_some(), "the fixture has round trips");
        let recorded = Results {
            placement: split.clone(),
            ..unrecorded.clone()
        };
        let (a, b) = (
            Provenance::of(&unrecorded, Vec::new()),
            Provenance::of(&recorded, Vec::new()),
        );
        assert_eq!(a.placement.split, split);
        assert!(a.placement.summary.is_some());
        assert_eq!(a.placement, b.placement);
        // A stale recorded split does not win over the round trips either.
        let stale = Results {
            placement: Split::of([20.0, 21.0, 22.0, 900.0, 910.0, 920.0]),
            ..recorded
        };
        assert_ne!(stale.placement, split);
        assert_eq!(Provenance::of(&stale, Vec::new()).placement, b.placement);
    }

    #[test]
    fn a_config_hash_is_sixteen_hex_digits_of_the_config_alone() {
        let results = quick();
        let hash = config_hash(&results);
        assert_eq!(hash.len(), 16, "{hash}");
        assert!(hash
            .chars()
            .all(|c| c.is_ascii_hexdigit() && !c.is_ascii_uppercase()));
        // The cells and the machine are not the config.
        let other_run = Results {
            cells: Vec::new(),
            started: "2020-01-01T00:00:00Z".into(),
            ..results.clone()
        };
        assert_eq!(config_hash(&other_run), hash);
        let mut renamed = results.clone();
        renamed.config.name.push('2');
        assert_ne!(config_hash(&renamed), hash);
        let mut longer = results;
        longer.config.trials += 1;
        assert_ne!(config_hash(&longer), hash);
        assert_eq!(
            Provenance::of(&longer, Vec::new()).config.hash,
            config_hash(&longer)
        );
    }

    #[test]
    fn a_trial_that_moved_is_mixed_and_one_without_round_trips_unplaced() {
        let mut results: Results = serde_json::from_str(include_str!(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/tests/fixtures/quick-results.json"
        )))
        .unwrap();
        // Two clusters, near and far; a trial whose round trips straddle them moved.
        results.round_trip.before = None;
        results.round_trip.during.clear();
        results.round_trip.after = None;
        results.cells.clear();
        results.balance.clear();
        let near_far = Provenance::of_trial(&results, "c".into(), Some([50.0, 400.0]));
        assert_eq!(near_far.placement.cells[0].placement, "mixed");
        assert!(near_far.placement.split.as_ref().is_some_and(Split::two));
        let none = Provenance::of_trial(&results, "c".into(), None);
        assert_eq!(none.placement.cells[0].placement, "unplaced");
        assert_eq!(none.placement.split, None);
    }
}
