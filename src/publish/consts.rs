//! Constants of the code that the docs quote, by name: a `const` block renders one, so a doc
//! that quotes a default or a threshold is checked against the code like any measured number.

use super::blocks::Block;
use crate::cell::Dim;
use crate::config::SweepConfig;
use std::path::Path;

/// Every constant a doc may quote: its name, what it is, and its value as docs write it.
pub fn all() -> Vec<(&'static str, &'static str, String)> {
    let config = SweepConfig::default();
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
    ]
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
