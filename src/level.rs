//! A workload level as a config gives it (microseconds of one core's work, a fraction of a mesh
//! size's step, or an amount in a kind's unit), when fractions are resolved against the machine,
//! and how far a resolved level may drift before reports say so: plain values that configs,
//! results and reports share.

use crate::input::InputError;
use crate::ocean::Grid;
use crate::workload::{DynKind, WorkloadKind};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// Drift beyond which a row's yardstick is reported as having moved since the sweep started.
pub const DRIFT_WARNING: f64 = 0.10;

crate::named! {
    /// When `step_fraction` levels are resolved against the machine.
    pub enum Calibrate {
        /// Before every row, from the yardstick measured just before it (the default).
        Row,
        /// Once, at the start of the sweep.
        Once,
    }
}

/// One workload level: microseconds of one core's work, a fraction of a mesh size's step, or an
/// amount in the workload kind's own unit (`{"iterations": N}`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Level {
    /// Microseconds of one core's work.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub micros: Option<f64>,
    /// Fraction of the measured step time of mesh `size` (reference kernel, `neighbors` normals).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub step_fraction: Option<f64>,
    /// The mesh size whose step time `step_fraction` refers to.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub size: Option<usize>,
    /// An amount in a workload kind's own unit, keyed by the unit's name; any other key lands
    /// here too, so that validation can name it against the kinds' units.
    #[serde(flatten)]
    pub units: BTreeMap<String, f64>,
}

impl Level {
    /// A level of `micros` microseconds.
    pub fn micros(micros: f64) -> Level {
        Level {
            micros: Some(micros),
            step_fraction: None,
            size: None,
            units: BTreeMap::new(),
        }
    }

    /// A level of `fraction` × the step time of an N = `size` mesh.
    pub fn step_fraction(fraction: f64, size: usize) -> Level {
        Level {
            micros: None,
            step_fraction: Some(fraction),
            size: Some(size),
            units: BTreeMap::new(),
        }
    }

    /// A level of `amount` in a kind's `unit`.
    pub fn in_unit(unit: &str, amount: u64) -> Level {
        Level {
            micros: None,
            step_fraction: None,
            size: None,
            units: BTreeMap::from([(unit.to_string(), amount as f64)]),
        }
    }

    /// The level's unit and amount, when it is given in a kind's unit.
    pub fn amount(&self) -> Option<(&str, u64)> {
        self.units
            .iter()
            .next()
            .map(|(u, &a)| (u.as_str(), a as u64))
    }

    /// Checks the level's shape and, for `micros`, its bound: no more than `max_micros`; a level
    /// in a unit must be in the unit of every workload kind in `kinds`.
    pub(crate) fn validate(
        &self,
        index: usize,
        max_micros: f64,
        kinds: &[WorkloadKind],
    ) -> Result<(), InputError> {
        let field = format!("workload_levels[{index}]");
        let kinds: Vec<&dyn DynKind> = kinds.iter().map(|k| k.kind()).collect::<Result<_, _>>()?;
        let forms = || {
            let mut units: Vec<&str> = kinds.iter().map(|k| k.unit()).collect();
            units.dedup();
            let units: Vec<String> = units.iter().map(|u| format!("{{\"{u}\": N}}")).collect();
            format!(
                "give {{\"micros\": US}}, {{\"step_fraction\": F, \"size\": N}} or {}",
                units.join(" or ")
            )
        };
        if let Some((unit, &amount)) = self.units.iter().next() {
            let alone = self.units.len() == 1
                && self.micros.is_none()
                && self.step_fraction.is_none()
                && self.size.is_none();
            if let Some(kind) = kinds.iter().find(|k| k.unit() != unit) {
                return Err(InputError(format!(
                    "{field}: `{unit}` is not a unit of workload_kind `{}` (its unit is \
                     `{}`); {}",
                    kind.name(),
                    kind.unit(),
                    forms()
                )));
            }
            if !alone {
                return Err(InputError(format!("{field}: {}, one of them", forms())));
            }
            for kind in &kinds {
                kind.check_amount(&format!("{field}.{unit}"), amount)?;
            }
            return Ok(());
        }
        if let Some((kind, why)) = kinds
            .iter()
            .find_map(|k| k.no_time_levels().map(|why| (k, why)))
        {
            let (name, unit) = (kind.name(), kind.unit());
            return Err(InputError(format!(
                "{field}: workload_kind `{name}` takes its level in {unit}, {{\"{unit}\": N}}; microseconds and step fractions are not converted to {unit} ({why})"
            )));
        }
        match (self.micros, self.step_fraction, self.size) {
            (Some(us), None, None) if us.is_finite() && (0.0..=max_micros).contains(&us) => Ok(()),
            (Some(us), None, None) if us.is_finite() && us > max_micros => Err(InputError(
                too_much_work(&format!("{field}.micros"), us, max_micros),
            )),
            (Some(us), None, None) => Err(InputError(format!(
                "{field}.micros: must be a finite number >= 0, got {us}"
            ))),
            (None, Some(f), Some(size)) => {
                if !(f.is_finite() && f >= 0.0) {
                    return Err(InputError(format!(
                        "{field}.step_fraction: must be a finite number >= 0, got {f}"
                    )));
                }
                Grid::new(size, 1.0)
                    .map(|_| ())
                    .map_err(|e| InputError(format!("{field}.{e}")))
            }
            _ => Err(InputError(format!("{field}: {}", forms()))),
        }
    }
}

/// The message for a level of more work per frame than the bound.
pub fn too_much_work(field: &str, micros: f64, max_micros: f64) -> String {
    format!(
        "{field}: {micros} µs of work per frame is more than timeout_seconds allows \
         (a helper waiting that long for its slot gives the cell up); allowed 0 to {max_micros}, \
         or raise timeout_seconds"
    )
}
