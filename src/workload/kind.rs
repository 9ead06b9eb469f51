//! A workload kind owns its knowledge behind one descriptor, [`Kind`]: its name and unit, its
//! config object, the surfaces it needs, how a level in µs or a step fraction comes to its own
//! unit, and how it builds a loop's work. The harness reaches kinds only through the registry
//! ([`lookup`], [`kinds`]): the built-in ones are always there, and a library user adds more
//! with [`register`] before parsing a config, which then names them like built-in ones.

use super::{Work, WorkSpec};
use crate::camera::Camera;
use crate::input::InputError;
use crate::ocean::{Grid, GridKind, OceanKind};
use crate::registry::{Entry, Registry};
use crate::suggest;
use serde::de::DeserializeOwned;
use serde::Serialize;
use std::any::Any;
use std::fmt;
use std::sync::Arc;

/// A workload kind's name, as configs, cells and results give it. Any name reads back from a
/// results file (one written by a binary that registered more kinds); configs and flags accept
/// only registered ones.
#[derive(Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct WorkloadKind(pub(in crate::workload) &'static str);

impl WorkloadKind {
    /// The paper's game work: a chain of integer mixing, before the wait for the mesh.
    pub const SYNTHETIC: WorkloadKind = WorkloadKind(super::synthetic::NAME);
    /// Transforms the consumed mesh into a vertex buffer, then spends the level as the cost of
    /// submitting the frame.
    pub const RENDER: WorkloadKind = WorkloadKind(super::render::NAME);

    /// The kind called `name`, registered or not (results name kinds other binaries ran).
    pub fn named(name: &str) -> WorkloadKind {
        WorkloadKind(KINDS.intern(name))
    }

    /// The registered kind called `text`, or an error listing the registered ones.
    pub fn parse(text: &str) -> Result<WorkloadKind, InputError> {
        lookup(text)
            .map(|k| WorkloadKind(k.name()))
            .ok_or_else(|| InputError(suggest::unknown("value", text, &names())))
    }

    /// The kind's name.
    pub fn name(self) -> &'static str {
        self.0
    }

    /// Its descriptor, when this binary registered it.
    pub fn kind(self) -> Result<&'static dyn DynKind, InputError> {
        lookup(self.0).ok_or_else(|| {
            InputError(format!(
                "workload_kind: `{}` is not registered in this program (registered: {})",
                self.0,
                names().join(", ")
            ))
        })
    }

    /// The unit its levels are counted in (an unregistered kind's is unknown here: results
    /// keep it per cell).
    pub fn unit(self) -> &'static str {
        self.kind().map_or("", |k| k.unit())
    }

    /// `amount` of its work as sentences, ticks and axes name it (`19³ voxels`, `N³ voxels`); a
    /// kind this program does not register reads `{amount} {unit}` with the unit its results
    /// recorded.
    pub fn amount_text(self, amount: &str, recorded_unit: &str) -> String {
        self.kind().map_or_else(
            |_| format!("{amount} {recorded_unit}"),
            |k| k.amount_text(amount),
        )
    }

    /// Refuses a surface the kind cannot work on, or a kind this program does not know.
    pub fn check_surface(self, ocean: OceanKind, grid: GridKind) -> Result<(), InputError> {
        self.kind()?.check_surface(ocean, grid)
    }
}

crate::registered_name!(WorkloadKind);

/// Where a level stands when a kind converts it: the mesh it will run on and the camera, and
/// the amount when the level was given in the kind's own unit.
#[derive(Clone, Copy, Debug)]
pub struct LevelAt {
    /// The mesh grid of the row (at the start: the sweep's largest).
    pub grid: Grid,
    /// The camera the sweep looks through.
    pub camera: Camera,
    /// The amount in the kind's unit, when the config gave the level that way.
    pub given: Option<u64>,
}

/// A workload kind as its author writes it: typed parameters, typed work. Every method but
/// [`Kind::name`], [`Kind::unit`] and [`Kind::build`] has a default that fits a kind whose level
/// is timed like the synthetic chain's.
pub trait Kind: Send + Sync + 'static {
    /// Its config object (the config key is the kind's name); `()` for a kind without one.
    type Params: Serialize + DeserializeOwned + Default + Clone + Send + Sync + 'static;

    /// Its name in configs, flags, cells and results.
    fn name(&self) -> &'static str;

    /// One line for `--help` and the docs.
    fn doc(&self) -> &'static str {
        ""
    }

    /// The unit a level is counted in.
    fn unit(&self) -> &'static str;

    /// `amount` (a number, or `N` for an axis) in words, for findings and charts.
    fn amount_text(&self, amount: &str) -> String {
        format!("{amount} {}", self.unit())
    }

    /// Refuses parameters it cannot run; the message names `kind.key`.
    fn check_params(&self, params: &Self::Params) -> Result<(), InputError> {
        let _ = params;
        Ok(())
    }

    /// Refuses an amount in its unit it cannot run; `field` names where it was given. By
    /// default any whole number 0 to [`MAX_AMOUNT`].
    fn check_amount(&self, field: &str, amount: f64) -> Result<(), InputError> {
        whole_amount(field, amount).map(|_| ())
    }

    /// Why levels in µs or step fractions cannot be converted to its unit, if they cannot.
    fn no_time_levels(&self) -> Option<&'static str> {
        None
    }

    /// The level in its unit that `run` and `balance` start from when none is given, for a kind
    /// whose levels cannot be given in time (spray: the slides' particle count).
    fn default_amount(&self) -> Option<u64> {
        None
    }

    /// Refuses an ocean model or grid it cannot work on.
    fn check_surface(&self, ocean: OceanKind, grid: GridKind) -> Result<(), InputError> {
        let _ = (ocean, grid);
        Ok(())
    }

    /// Whether its amount is iterations of the calibrated synthetic chain alone, so that a
    /// trial's workload time per iteration is a canary of the core's speed.
    fn is_calibrated_chain(&self) -> bool {
        false
    }

    /// A row's level as (µs, amount in its unit), from the generic conversion of µs to
    /// iterations of the synthetic chain (`micros`, `amount`); a kind with its own calibration
    /// measures here.
    fn row_level(
        &self,
        params: &Self::Params,
        at: &LevelAt,
        micros: f64,
        amount: u64,
    ) -> (f64, u64) {
        let _ = (params, at);
        (micros, amount)
    }

    /// A level's µs in the sweep's start record (on its largest mesh), or why the kind cannot
    /// reach it.
    fn start_level(&self, params: &Self::Params, at: &LevelAt, micros: f64) -> Result<f64, String> {
        let _ = (params, at);
        Ok(micros)
    }

    /// Builds its work for one loop, on the thread that will run it.
    fn build(&self, spec: &WorkSpec, params: &Self::Params) -> Work;
}

/// Largest amount a level may give in a kind's unit: a whole number an f64 holds exactly.
pub const MAX_AMOUNT: f64 = 9.0e15;

/// `amount` as a whole number 0 to [`MAX_AMOUNT`], or the error naming `field`.
pub fn whole_amount(field: &str, amount: f64) -> Result<u64, InputError> {
    if amount.is_finite() && (0.0..=MAX_AMOUNT).contains(&amount) && amount.fract() == 0.0 {
        Ok(amount as u64)
    } else {
        Err(InputError(format!(
            "{field}: must be a whole number 0 to {MAX_AMOUNT}, got {amount}"
        )))
    }
}

/// A kind's parsed parameters, for the kind that parsed them; they print as their JSON.
#[derive(Clone)]
pub struct KindParams {
    kind: &'static str,
    value: Arc<dyn Any + Send + Sync>,
    json: serde_json::Value,
}

impl KindParams {
    /// The kind they belong to.
    pub fn kind(&self) -> WorkloadKind {
        WorkloadKind(self.kind)
    }

    /// As the config gives them (defaults filled in).
    pub fn json(&self) -> &serde_json::Value {
        &self.json
    }

    /// `params` for `kind`, checked by it.
    pub fn new<K: Kind>(kind: &K, params: K::Params) -> Result<KindParams, InputError> {
        kind.check_params(&params)?;
        Ok(KindParams {
            kind: Kind::name(kind),
            json: serde_json::to_value(&params).unwrap_or_default(),
            value: Arc::new(params),
        })
    }

    /// The default parameters of a registered kind.
    pub fn default_for(kind: WorkloadKind) -> Result<KindParams, InputError> {
        kind.kind()?.params(None)
    }
}

impl fmt::Debug for KindParams {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.kind, self.json)
    }
}

impl PartialEq for KindParams {
    fn eq(&self, other: &Self) -> bool {
        self.kind == other.kind && self.json == other.json
    }
}

/// The descriptor as the harness holds it: [`Kind`] with its parameters behind [`KindParams`].
/// Every [`Kind`] is one.
pub trait DynKind: Send + Sync {
    /// See [`Kind::name`].
    fn name(&self) -> &'static str;
    /// See [`Kind::doc`].
    fn doc(&self) -> &'static str;
    /// See [`Kind::unit`].
    fn unit(&self) -> &'static str;
    /// See [`Kind::amount_text`].
    fn amount_text(&self, amount: &str) -> String;
    /// Its default config object, `None` for a kind without parameters.
    fn default_params(&self) -> Option<serde_json::Value>;
    /// Parses and checks its config object (the defaults when `raw` is `None`).
    fn params(&self, raw: Option<&serde_json::Value>) -> Result<KindParams, InputError>;
    /// Checks an amount in its unit, `field` naming where it was given.
    fn check_amount(&self, field: &str, amount: f64) -> Result<(), InputError>;
    /// See [`Kind::no_time_levels`].
    fn no_time_levels(&self) -> Option<&'static str>;
    /// See [`Kind::default_amount`].
    fn default_amount(&self) -> Option<u64>;
    /// See [`Kind::check_surface`].
    fn check_surface(&self, ocean: OceanKind, grid: GridKind) -> Result<(), InputError>;
    /// See [`Kind::is_calibrated_chain`].
    fn is_calibrated_chain(&self) -> bool;
    /// See [`Kind::row_level`].
    fn row_level(&self, params: &KindParams, at: &LevelAt, micros: f64, amount: u64) -> (f64, u64);
    /// See [`Kind::start_level`].
    fn start_level(&self, params: &KindParams, at: &LevelAt, micros: f64) -> Result<f64, String>;
    /// See [`Kind::build`].
    fn build(&self, spec: &WorkSpec, params: &KindParams) -> Work;
}

impl<K: Kind> DynKind for K {
    fn name(&self) -> &'static str {
        Kind::name(self)
    }

    fn doc(&self) -> &'static str {
        Kind::doc(self)
    }

    fn unit(&self) -> &'static str {
        Kind::unit(self)
    }

    fn amount_text(&self, amount: &str) -> String {
        Kind::amount_text(self, amount)
    }

    fn default_params(&self) -> Option<serde_json::Value> {
        serde_json::to_value(K::Params::default())
            .ok()
            .filter(|v| !v.is_null())
    }

    fn params(&self, raw: Option<&serde_json::Value>) -> Result<KindParams, InputError> {
        let name = Kind::name(self);
        let params: K::Params = match raw {
            None => K::Params::default(),
            Some(raw) => serde_path_to_error::deserialize(raw.clone()).map_err(|e| {
                let path = e.path().to_string();
                let msg = suggest::with_suggestion(&e.into_inner().to_string());
                match path.as_str() {
                    "." | "" => InputError(format!("{name}: {msg}")),
                    _ => InputError(format!("{name}.{path}: {msg}")),
                }
            })?,
        };
        KindParams::new(self, params)
    }

    fn check_amount(&self, field: &str, amount: f64) -> Result<(), InputError> {
        Kind::check_amount(self, field, amount)
    }

    fn no_time_levels(&self) -> Option<&'static str> {
        Kind::no_time_levels(self)
    }

    fn default_amount(&self) -> Option<u64> {
        Kind::default_amount(self)
    }

    fn check_surface(&self, ocean: OceanKind, grid: GridKind) -> Result<(), InputError> {
        Kind::check_surface(self, ocean, grid)
    }

    fn is_calibrated_chain(&self) -> bool {
        Kind::is_calibrated_chain(self)
    }

    fn row_level(&self, params: &KindParams, at: &LevelAt, micros: f64, amount: u64) -> (f64, u64) {
        Kind::row_level(self, typed::<K>(params), at, micros, amount)
    }

    fn start_level(&self, params: &KindParams, at: &LevelAt, micros: f64) -> Result<f64, String> {
        Kind::start_level(self, typed::<K>(params), at, micros)
    }

    fn build(&self, spec: &WorkSpec, params: &KindParams) -> Work {
        Kind::build(self, spec, typed::<K>(params))
    }
}

/// `params` as kind `K`'s own type. [`crate::frame_loop::LoopSpec::check`] refuses parameters
/// of another kind before anything is built, so a mismatch here is a bug in the caller.
fn typed<K: Kind>(params: &KindParams) -> &K::Params {
    params.value.downcast_ref().unwrap_or_else(|| {
        panic!(
            "parameters of kind `{}` handed to {}",
            params.kind,
            std::any::type_name::<K>()
        )
    })
}

impl Entry for dyn DynKind {
    fn entry_name(&self) -> &'static str {
        self.name()
    }
}

/// The built-in kinds, in the order `--help` lists them, then the registered ones.
static KINDS: Registry<dyn DynKind> = Registry::new(
    "workload kind",
    &[
        &super::synthetic::SyntheticKind,
        &super::render::RenderKind,
        &super::spray::SprayKind,
        &super::fog::FogKind,
    ],
);

/// Registers a kind for this process: configs, flags and sweeps then know it by name. Refuses
/// a name already taken.
pub fn register<K: Kind>(kind: K) -> Result<WorkloadKind, InputError> {
    KINDS.register(Box::leak(Box::new(kind))).map(WorkloadKind)
}

/// Every registered kind, the built-in ones first.
pub fn kinds() -> Vec<&'static dyn DynKind> {
    KINDS.all()
}

/// The registered kind called `name`.
pub fn lookup(name: &str) -> Option<&'static dyn DynKind> {
    KINDS.lookup(name)
}

/// Every registered kind's name.
pub fn names() -> Vec<&'static str> {
    KINDS.names()
}
