//! Ocean models registered from outside the crate: configs name them like built-in ones, their
//! own checks answer bad input, sweeps run them, and results naming a model this program never
//! registered still read back. Its own test binary: the registry is process-wide.

mod common;

use oceanbench::config::{InputError, SweepConfig};
use oceanbench::ocean::{
    self, Grid, Kernel, Mesh, MeshRows, Model, NormalMethod, OceanKind, OceanParams, Stepper,
};
use oceanbench::results::Results;
use oceanbench::sweep::Sweep;
use serde::{Deserialize, Serialize};
use std::sync::Once;

/// The test model's config object: the sea's height, -10 to 10.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
struct LevelParams {
    height: f32,
}

/// A still sea at a set height.
struct Still;

impl Model for Still {
    fn name(&self) -> &'static str {
        "still"
    }
    fn default_params(&self) -> Option<serde_json::Value> {
        serde_json::to_value(LevelParams::default()).ok()
    }
    fn parse_params(
        &self,
        raw: &serde_json::Value,
        params: &mut OceanParams,
    ) -> Result<(), InputError> {
        let p: LevelParams = params.parse("still", raw)?;
        if !(-10.0..=10.0).contains(&p.height) {
            return Err(InputError(format!(
                "still.height: must be -10 to 10, got {}",
                p.height
            )));
        }
        Ok(())
    }
    fn kernels(&self) -> &'static [Kernel] {
        &[Kernel::Reference]
    }
    fn normals(&self) -> &'static [NormalMethod] {
        &[NormalMethod::Analytic]
    }
    fn splits_into_rows(&self, _: NormalMethod) -> Result<(), InputError> {
        Ok(())
    }
    fn check(&self, _: usize, _: NormalMethod) -> Result<(), InputError> {
        Ok(())
    }
    fn yardstick(&self) -> (Kernel, NormalMethod) {
        (Kernel::Reference, NormalMethod::Analytic)
    }
    fn prepare(
        &self,
        _: Grid,
        params: &OceanParams,
        _: NormalMethod,
        _: Kernel,
    ) -> Result<Box<dyn Stepper>, InputError> {
        Ok(Box::new(StillStep(params.get::<LevelParams>().height)))
    }
}

#[derive(Clone, Debug)]
struct StillStep(f32);

impl Stepper for StillStep {
    fn step(&mut self, t: f32, mesh: &mut Mesh) {
        let n = mesh.grid.n;
        self.step_rows(t, mesh.rows_mut(0..n));
    }
    fn step_rows(&mut self, _: f32, rows: MeshRows<'_>) {
        rows.z.fill(self.0);
        rows.nz.fill(1.0);
    }
    fn boxed_clone(&self) -> Box<dyn Stepper> {
        Box::new(self.clone())
    }
}

fn register() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        ocean::register(Still).unwrap();
    });
}

/// A config naming the test model, with `extra` keys merged in.
fn config(extra: serde_json::Value) -> Result<SweepConfig, InputError> {
    let base = serde_json::json!({
        "sizes": [6],
        "ocean": ["still"],
        "normals": ["analytic"],
        "workload_levels": [{"micros": 0.0}],
        "workloads": [0],
        "modes": ["serial", "up"],
        "sync": ["atomic"],
        "trials": 1,
        "warmup_frames": 1,
        "min_frames": 3,
        "min_seconds": 0.0,
        "still": {"height": 2.5}
    });
    common::config_with(base, extra)
}

#[test]
fn a_registered_model_is_named_by_configs_and_reads_its_own_object() {
    register();
    assert!(ocean::names().contains(&"still"));
    let config = config(serde_json::json!({})).unwrap();
    assert_eq!(config.axes.ocean, vec![OceanKind::parse("still").unwrap()]);
    let params = config.ocean_params().unwrap();
    assert_eq!(params.get::<LevelParams>(), LevelParams { height: 2.5 });
    let e = ocean::register(Still).unwrap_err();
    assert!(e.0.contains("`still` is registered already"), "{e}");
}

#[test]
fn bad_input_for_a_registered_model_gets_its_own_one_line_message() {
    register();
    let cases = [
        (
            serde_json::json!({"still": {"height": 1.0, "bogus": 1}}),
            "still.bogus: unknown field `bogus`",
        ),
        (
            serde_json::json!({"still": {"height": 12.0}}),
            "still.height: must be -10 to 10, got 12",
        ),
        (
            serde_json::json!({"ocean": ["stil"]}),
            "ocean[0]: unknown value `stil`; did you mean `still`?",
        ),
    ];
    for (extra, expected) in cases {
        let e = config(extra.clone()).unwrap_err().0;
        assert!(e.contains(expected), "{extra}: {e}");
        assert!(!e.contains('\n'), "one line: {e}");
    }
}

#[test]
fn a_sweep_runs_a_registered_model_on_the_helper() {
    register();
    let results = Sweep::prepare(config(serde_json::json!({})).unwrap())
        .unwrap()
        .run(&mut ());
    assert_eq!(results.cells.len(), 2, "serial and up");
    for cell in &results.cells {
        assert_eq!(cell.key.ocean.name(), "still");
        assert!(cell.error.is_none(), "{:?}", cell.error);
        assert!(cell.summary.is_some());
    }
    let text = serde_json::to_string(&results)
        .unwrap()
        .replace("\"ocean\":\"still\"", "\"ocean\":\"never-registered\"");
    let read: Results = serde_json::from_str(&text).unwrap();
    assert_eq!(read.cells[0].key.ocean.name(), "never-registered");
    assert!(read.cells[0]
        .key
        .ocean
        .model()
        .check(6, NormalMethod::Analytic)
        .is_err());
}

/// A config that names no normals runs each listed model's own (`neighbors` for the sines,
/// the paper's; `analytic` for the FFT ocean, its spectral slopes); normals a config names are
/// kept.
#[test]
fn a_config_without_normals_takes_each_models_own() {
    use oceanbench::config::SweepConfig;
    use oceanbench::ocean::NormalMethod;
    let normals = |json: &str| SweepConfig::from_json(json).unwrap().axes.normals;
    assert_eq!(normals(r#"{"sizes": [64]}"#), [NormalMethod::Neighbors]);
    assert_eq!(
        normals(r#"{"sizes": [64], "ocean": ["fft"]}"#),
        [NormalMethod::Analytic]
    );
    assert_eq!(
        normals(r#"{"sizes": [64], "ocean": ["sines", "fft"]}"#),
        [NormalMethod::Neighbors, NormalMethod::Analytic]
    );
    assert_eq!(
        normals(r#"{"sizes": [64], "ocean": ["fft"], "normals": ["neighbors"]}"#),
        [NormalMethod::Neighbors]
    );
}
