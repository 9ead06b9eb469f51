//! Constants of the code that the docs quote, by name: a `const` block renders one, so a doc
//! that quotes a default or a threshold is checked against the code like any measured number.

use super::blocks::Block;
use crate::cell::Dim;
use crate::config::SweepConfig;
use std::path::Path;

/// Every constant a doc may quote: its name, what it is, and its value as docs write it.
pub fn all() -> Vec<(&'static str, &'static str, String)> {
    let config = SweepConfig::default();
    let fft_defaults = crate::ocean::phillips::FftParams::default();
    let balance_defaults = crate::balance::record::BalanceSettings::default();
    let list = |dim: Dim| {
        config
            .axes
            .values(dim)
            .iter()
            .map(|v| v.to_string())
            .collect::<Vec<_>>()
            .join(", ")
    };
    vec![
        (
            "default_sizes",
            "the default sweep's mesh sizes",
            list(Dim::Size),
        ),
        (
            "default_sync",
            "the default sweep's hand-off methods",
            list(Dim::Sync),
        ),
        (
            "default_trials",
            "trials per cell by default",
            config.trials.to_string(),
        ),
        (
            "spread_percent",
            "a cell's trial spread above which a number from it says so",
            format!("{}", crate::findings::SPREAD_PERCENT),
        ),
        (
            "flat_percent",
            "how far DP may move from its lowest level's FPS and still count as flat",
            format!("{}", crate::findings::FLAT_PERCENT),
        ),
        (
            "slow_trial_percent",
            "how far below its cell's median a trial counts as slow, by default",
            format!("{}", crate::slow_trials::DEFAULT_THRESHOLD_PERCENT),
        ),
        (
            "placement_change_ratio",
            "round trips further apart than this ratio are two placements",
            format!("{}", crate::crosscore::PLACEMENT_CHANGE_RATIO),
        ),
        (
            "compare_threshold_percent",
            "compare's default threshold",
            format!("{}", crate::report::compare::DEFAULT_THRESHOLD_PCT),
        ),
        (
            "compare_min_trials",
            "trials a side compare needs for a verdict",
            crate::report::compare::MIN_TRIALS.to_string(),
        ),
        (
            "max_depth",
            "the deepest run-ahead ring",
            crate::frame_loop::MAX_DEPTH.to_string(),
        ),
        (
            "max_helpers",
            "the most helper threads",
            crate::frame_loop::MAX_HELPERS.to_string(),
        ),
        (
            "schema_version",
            "the results.json layout this build writes",
            crate::results::SCHEMA_VERSION.to_string(),
        ),
        // fft (docs/fft-ocean.md, docs/balance.md):
        (
            "fft_strip_columns",
            "columns per strip of the FFT ocean's row pass",
            crate::ocean::fft::transform::STRIP.to_string(),
        ),
        (
            "fft_default_patch_metres",
            "the FFT ocean's default patch side L, in metres",
            format!("{}", fft_defaults.patch_metres),
        ),
        (
            "fft_default_wind_speed",
            "the FFT ocean's default wind speed V, in m/s",
            format!("{}", fft_defaults.wind_speed),
        ),
        (
            "fft_default_wind_direction_degrees",
            "the FFT ocean's default wind direction, in degrees from +x",
            format!("{}", fft_defaults.wind_direction_degrees),
        ),
        (
            "fft_default_amplitude",
            "the FFT ocean's default Phillips constant A",
            format!("{:e}", fft_defaults.amplitude),
        ),
        (
            "fft_default_cutoff_metres",
            "the FFT ocean's default cutoff l, in metres",
            format!("{}", fft_defaults.cutoff_metres),
        ),
        (
            "fft_default_choppiness",
            "the FFT ocean's default choppiness λ",
            format!("{}", fft_defaults.choppiness),
        ),
        (
            "fft_default_gravity",
            "the FFT ocean's default g, in m/s²",
            format!("{}", fft_defaults.gravity),
        ),
        (
            "fft_default_seed",
            "the FFT ocean's default seed",
            fft_defaults.seed.to_string(),
        ),
        (
            "fft_allowed_patch_metres",
            "the values of patch_metres a parameters file may give",
            fft_allowed("patch_metres"),
        ),
        (
            "fft_allowed_wind_speed",
            "the values of wind_speed a parameters file may give",
            fft_allowed("wind_speed"),
        ),
        (
            "fft_allowed_wind_direction_degrees",
            "the values of wind_direction_degrees a parameters file may give",
            fft_allowed("wind_direction_degrees"),
        ),
        (
            "fft_allowed_amplitude",
            "the values of amplitude a parameters file may give",
            fft_allowed("amplitude"),
        ),
        (
            "fft_allowed_cutoff_metres",
            "the values of cutoff_metres a parameters file may give",
            fft_allowed("cutoff_metres"),
        ),
        (
            "fft_allowed_choppiness",
            "the values of choppiness a parameters file may give",
            fft_allowed("choppiness"),
        ),
        (
            "fft_allowed_gravity",
            "the values of gravity a parameters file may give",
            fft_allowed("gravity"),
        ),
        (
            "fft_allowed_depth_metres",
            "the values of depth_metres a parameters file may give (besides null)",
            fft_allowed("depth_metres"),
        ),
        (
            "fft_finest_spacing_metres",
            "the default patch's vertex spacing at the FFT ocean's largest size, in metres",
            format!(
                "{:.2}",
                fft_defaults.patch_metres / crate::ocean::fft::size::MAX as f64
            ),
        ),
        (
            "balance_default_points",
            "points of a balance search's curve by default",
            balance_defaults.points.to_string(),
        ),
        (
            "balance_default_range_from",
            "where a balance search's range starts by default, as W ÷ S",
            format!("{}", balance_defaults.range[0]),
        ),
        (
            "balance_default_range_to",
            "where a balance search's range ends by default, as W ÷ S",
            format!("{}", balance_defaults.range[1]),
        ),
        (
            "balance_default_trials",
            "paired trials at every balance probe by default",
            balance_defaults.trials.to_string(),
        ),
        (
            "balance_default_tolerance_percent",
            "the bracket width, in % of the step, at which a balance search stops by default",
            format!("{}", balance_defaults.tolerance_percent),
        ),
    ]
}

/// What a parameters file may give for the FFT ocean's number `key`, as the parameters table
/// writes it, found by asking the parameters' own check: `> 0`, `≥ 0` or `finite`.
fn fft_allowed(key: &str) -> String {
    let accepts = |v: f64| {
        crate::ocean::phillips::FftParams::from_json(&format!("{{\"{key}\": {v}}}")).is_ok()
    };
    match (accepts(-1.0), accepts(0.0), accepts(1.0)) {
        (true, true, true) => "finite".into(),
        (false, true, true) => "≥ 0".into(),
        (false, false, true) => "> 0".into(),
        other => format!("? ({key}: {other:?})"),
    }
}

/// The constant `name` as docs write it.
pub fn value(name: &str) -> Result<String, String> {
    let all = all();
    all.iter()
        .find(|(n, _, _)| *n == name)
        .map(|(_, _, v)| v.clone())
        .ok_or_else(|| {
            format!(
                "const: unknown name `{name}` (allowed: {})",
                all.iter()
                    .map(|(n, _, _)| *n)
                    .collect::<Vec<_>>()
                    .join(", ")
            )
        })
}

/// The value at `key` (a dotted path; list indexes as numbers) of the committed config named by
/// a `config` block's `file`, as docs write it: a list as `a, b, c`, a string without quotes.
pub fn config_value(root: &Path, block: &Block) -> Result<String, String> {
    let file = block
        .attr("file")
        .ok_or("`config` needs file=configs/NAME.json")?;
    let key = block.attr("key").ok_or("`config` needs key=PATH")?;
    let text = std::fs::read_to_string(root.join(file))
        .map_err(|e| format!("config file `{file}`: {e}"))?;
    let json: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| format!("config file `{file}`: {e}"))?;
    let mut at = &json;
    for part in key.split('.') {
        let next = match part.parse::<usize>() {
            Ok(i) => at.get(i),
            Err(_) => at.get(part),
        };
        at = next.ok_or_else(|| format!("config file `{file}` has no key `{key}`"))?;
    }
    let show = |v: &serde_json::Value| match v {
        serde_json::Value::String(s) => s.clone(),
        other => other.to_string(),
    };
    Ok(match at {
        serde_json::Value::Array(items) => items.iter().map(show).collect::<Vec<_>>().join(", "),
        other => show(other),
    })
}
