//! Workload kinds registered from outside the crate: configs name them like built-in ones, their
//! own checks answer bad input, sweeps run them, and results naming a kind this program never
//! registered still read back. Its own test binary: the registry is process-wide.

mod common;

use oceanbench::cell::Axes;
use oceanbench::config::{InputError, Level, SweepConfig};
use oceanbench::frame_loop::Mode;
use oceanbench::ocean::Mesh;
use oceanbench::results::Results;
use oceanbench::sweep::Sweep;
use oceanbench::workload::{
    self, fold_digest, whole_amount, Kind, MeshWork, Stopped, Work, WorkOutput, WorkSpec,
    WorkloadKind,
};
use serde::{Deserialize, Serialize};
use std::sync::atomic::AtomicBool;
use std::sync::Once;

/// The test kind's config object: how much each frame adds to its sum, 1 to 9.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
struct TallyParams {
    step: u32,
}

/// Sums the consumed mesh's heights `amount` times a frame, plus `step`.
struct Tally;

impl Kind for Tally {
    type Params = TallyParams;

    fn name(&self) -> &'static str {
        "tally"
    }

    fn unit(&self) -> &'static str {
        "passes"
    }

    fn check_params(&self, p: &TallyParams) -> Result<(), InputError> {
        if p.step > 9 {
            return Err(InputError(format!(
                "tally.step: must be 0 to 9, got {}",
                p.step
            )));
        }
        Ok(())
    }

    fn check_amount(&self, field: &str, amount: f64) -> Result<(), InputError> {
        match whole_amount(field, amount)? {
            n if n <= 50 => Ok(()),
            n => Err(InputError(format!(
                "{field}: must be 0 to 50 passes, got {n}"
            ))),
        }
    }

    fn no_time_levels(&self) -> Option<&'static str> {
        Some("tally has no per-pass calibration")
    }

    fn build(&self, spec: &WorkSpec, p: &TallyParams) -> Work {
        Work::on_mesh(TallyWork {
            passes: spec.amount,
            step: p.step,
            sum: 0,
        })
    }
}

struct TallyWork {
    passes: u64,
    step: u32,
    sum: u64,
}

impl WorkOutput for TallyWork {
    fn digest(&self) -> u64 {
        self.sum
    }
}

impl MeshWork for TallyWork {
    fn run(&mut self, k: u64, mesh: &Mesh, _: Option<&AtomicBool>) -> Result<(), Stopped> {
        for _ in 0..self.passes {
            self.sum = fold_digest(self.sum, mesh.z.iter().map(|z| u64::from(z.to_bits())));
        }
        self.sum = self.sum.wrapping_add(k * u64::from(self.step));
        Ok(())
    }
}

fn register() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        workload::register(Tally).unwrap();
    });
}

/// A config naming the test kind, with `extra` keys merged in.
fn config(extra: serde_json::Value) -> Result<SweepConfig, InputError> {
    let base = serde_json::json!({
        "sizes": [6],
        "workload_kind": ["tally"],
        "workload_levels": [{"passes": 0}, {"passes": 3}],
        "workloads": [0, 1],
        "modes": ["serial", "up"],
        "sync": ["atomic"],
        "trials": 1,
        "warmup_frames": 1,
        "min_frames": 3,
        "min_seconds": 0.0,
        "tally": {"step": 2}
    });
    common::config_with(base, extra)
}

#[test]
fn a_registered_kind_is_named_by_configs_flags_and_cells_like_a_built_in_one() {
    register();
    assert!(workload::names().contains(&"tally"));
    let config = config(serde_json::json!({})).unwrap();
    let tally = WorkloadKind::parse("tally").unwrap();
    assert_eq!(config.axes.workload_kind, vec![tally]);
    assert_eq!(tally.unit(), "passes");
    let params = config.kind_params(tally).unwrap();
    assert_eq!(params.json(), &serde_json::json!({"step": 2}));
    assert!(
        SweepConfig::keys().contains(&"tally".to_string()),
        "a default config lists the kind's object"
    );
}

#[test]
fn a_second_kind_of_the_same_name_is_refused() {
    register();
    let e = workload::register(Tally).unwrap_err();
    assert!(e.0.contains("`tally` is registered already"), "{e}");
    let e = workload::register(SpraySquatter).unwrap_err();
    assert!(e.0.contains("`spray` is registered already"), "{e}");
}

/// A kind that takes a built-in kind's name.
struct SpraySquatter;

impl Kind for SpraySquatter {
    type Params = ();
    fn name(&self) -> &'static str {
        "spray"
    }
    fn unit(&self) -> &'static str {
        "drops"
    }
    fn build(&self, spec: &WorkSpec, _: &()) -> Work {
        Tally.build(spec, &TallyParams::default())
    }
}

#[test]
fn bad_input_for_a_registered_kind_gets_its_own_one_line_message() {
    register();
    let cases = [
        (
            serde_json::json!({"tally": {"step": 2, "bogus": 1}}),
            "tally.bogus: unknown field `bogus`",
        ),
        (
            serde_json::json!({"tally": {"step": 12}}),
            "tally.step: must be 0 to 9, got 12",
        ),
        (
            serde_json::json!({"workload_levels": [{"passes": 0}, {"passes": 70}]}),
            "workload_levels[1].passes: must be 0 to 50 passes, got 70",
        ),
        (
            serde_json::json!({"workload_levels": [{"passes": 0}, {"micros": 5.0}]}),
            "workload_levels[1]: workload_kind `tally` takes its level in passes, {\"passes\": N}; \
             microseconds and step fractions are not converted to passes (tally has no per-pass \
             calibration)",
        ),
        (
            serde_json::json!({"workload_kind": ["tallie"]}),
            "workload_kind[0]: unknown value `tallie`; did you mean `tally`?",
        ),
    ];
    for (extra, expected) in cases {
        let e = config(extra.clone()).unwrap_err().0;
        assert!(e.contains(expected), "{extra}: {e}");
        assert!(!e.contains('\n'), "one line: {e}");
    }
    let e = config(serde_json::json!({"workload_kind": ["nope"]}))
        .unwrap_err()
        .0;
    assert!(
        e.contains("synthetic") && e.contains("fog") && e.contains("tally"),
        "the registered kinds are listed: {e}"
    );
}

#[test]
fn a_sweep_runs_a_registered_kind_and_its_results_name_it() {
    register();
    let results = Sweep::prepare(config(serde_json::json!({})).unwrap())
        .unwrap()
        .run(&mut ());
    assert_eq!(results.cells.len(), 4, "serial and up, two levels");
    for cell in &results.cells {
        assert_eq!(cell.key.workload_kind.name(), "tally");
        assert_eq!(cell.workload_unit.as_deref(), Some("passes"));
        assert!(cell.error.is_none(), "{:?}", cell.error);
        assert!(cell.summary.is_some());
    }
    assert_eq!(
        results
            .cells
            .iter()
            .map(|c| c.workload_amount)
            .collect::<Vec<_>>(),
        [Some(0), Some(0), Some(3), Some(3)]
    );
}

#[test]
fn results_naming_a_kind_nobody_registered_read_back_unchanged() {
    register();
    let config = SweepConfig {
        axes: Axes {
            sizes: vec![6],
            workloads: vec![0],
            modes: vec![Mode::Serial],
            ..Axes::default()
        },
        trials: 1,
        warmup_frames: 1,
        min_frames: 2,
        min_seconds: 0.0,
        workload_levels: vec![Level::micros(0.0)],
        ..SweepConfig::default()
    };
    let results = Sweep::prepare(config).unwrap().run(&mut ());
    let text = serde_json::to_string(&results)
        .unwrap()
        .replace(
            "\"workload_kind\":\"synthetic\"",
            "\"workload_kind\":\"never-registered\"",
        )
        .replace(
            "\"workload_kind\":[\"synthetic\"]",
            "\"workload_kind\":[\"never-registered\"]",
        );
    assert!(text.contains("never-registered"));
    let read: Results = serde_json::from_str(&text).unwrap();
    assert_eq!(read.cells[0].key.workload_kind.name(), "never-registered");
    assert!(read.cells[0].key.workload_kind.kind().is_err());
    assert_eq!(
        serde_json::to_string(&read).unwrap(),
        text,
        "it writes back as read"
    );
}
