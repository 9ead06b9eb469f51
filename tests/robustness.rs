//! Random and malformed input never panics: configs, waves files and command lines either parse
//! or give one line naming what is wrong.

use clap::Parser;
use oceanbench::cli::{clap_line, Cli};
use oceanbench::config::SweepConfig;
use oceanbench::ocean::WaveSet;
use proptest::prelude::*;

const VALID: &str = r#"{"name": "p", "sizes": [8, 12], "workloads": [0, 1], "modes": ["serial", "up"],
 "sync": ["atomic"], "threading": ["pool"], "normals": ["analytic"], "kernel": ["reference"],
 "trials": 2, "min_frames": 5, "min_seconds": 0.1, "max_seconds": 1.0,
 "workload_levels": [{"micros": 0}, {"step_fraction": 0.5, "size": 40}],
 "waves": [{"amplitude": 1, "wavelength": 10, "speed": 2, "direction": [1, 0], "steepness": 2}]}"#;

fn one_line(e: &str) {
    assert!(!e.is_empty() && !e.contains('\n'), "{e:?}");
}

/// Replacement values that are wrong in type or range for most fields.
fn junk() -> impl Strategy<Value = String> {
    prop_oneof![
        Just("-1".to_string()),
        Just("0".to_string()),
        Just("1e308".to_string()),
        Just("null".to_string()),
        Just("\"\"".to_string()),
        Just("[]".to_string()),
        Just("{}".to_string()),
        Just("[\"tri\"]".to_string()),
        Just("[-3]".to_string()),
        Just("[99999]".to_string()),
        Just("true".to_string()),
        any::<i64>().prop_map(|v| v.to_string()),
        any::<f64>().prop_map(|v| format!("{v:?}")),
        "[a-z]{0,8}".prop_map(|s| format!("\"{s}\"")),
    ]
}

/// The fields a junk value replaces, one by one ("sizez" is a misspelt key).
const FIELDS: [&str; 24] = [
    "sizes",
    "workloads",
    "modes",
    "sync",
    "threading",
    "normals",
    "ocean",
    "kernel",
    "trials",
    "min_frames",
    "min_seconds",
    "max_seconds",
    "workload_levels",
    "waves",
    "name",
    "spacing",
    "time_step",
    "timeout_seconds",
    "cores",
    "warmup_frames",
    "camera",
    "slow_trial_percent",
    "workload_kind",
    "sizez",
];

/// The fixed junk values of [`junk`].
const FIXED_JUNK: [&str; 11] = [
    "-1",
    "0",
    "1e308",
    "null",
    "\"\"",
    "[]",
    "{}",
    "[\"tri\"]",
    "[-3]",
    "[99999]",
    "true",
];

/// `field` set to `value` in the valid config is either refused with one line naming the
/// field, or accepted as a config that reads back the same after being written out (from_json
/// has validated it already, so checking `validate()` again could not fail).
fn junk_is_refused_by_name_or_kept(field: &str, value: serde_json::Value) -> Result<(), String> {
    let mut obj: serde_json::Map<String, serde_json::Value> = serde_json::from_str(VALID).unwrap();
    obj.insert(field.to_string(), value.clone());
    let text = serde_json::to_string(&obj).unwrap();
    match SweepConfig::from_json(&text) {
        Ok(config) => {
            let again = SweepConfig::from_json(&serde_json::to_string(&config).unwrap());
            if again.as_ref().ok() != Some(&config) {
                return Err(format!(
                    "{field} = {value}: accepted but reads back as {again:?}"
                ));
            }
        }
        Err(e) => {
            let msg = e.to_string();
            one_line(&msg);
            if !msg.contains(field) {
                return Err(format!(
                    "{field} = {value}: the message does not name it: {msg}"
                ));
            }
        }
    }
    Ok(())
}

/// Every field with every fixed junk value, so no case is left to sampling.
#[test]
fn every_field_with_every_fixed_junk_value() {
    for field in FIELDS {
        for value in FIXED_JUNK {
            let value = serde_json::from_str(value).unwrap();
            junk_is_refused_by_name_or_kept(field, value).unwrap();
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]

    #[test]
    fn arbitrary_text_never_panics(text in ".{0,200}") {
        if let Err(e) = SweepConfig::from_json(&text) {
            one_line(&e.to_string());
        }
        if let Err(e) = WaveSet::from_json(&text) {
            one_line(&e.to_string());
        }
    }

    #[test]
    fn truncated_configs_never_panic(cut in 0usize..VALID.len()) {
        let text = &VALID[..cut];
        let e = SweepConfig::from_json(text).expect_err("a truncated config is invalid");
        one_line(&e.to_string());
    }

    #[test]
    fn one_field_replaced_by_junk_gives_one_line_or_a_valid_config(
        field in prop::sample::select(FIELDS.to_vec()),
        value in junk(),
    ) {
        let parsed: Result<serde_json::Value, _> = serde_json::from_str(&value);
        prop_assume!(parsed.is_ok());
        if let Err(why) = junk_is_refused_by_name_or_kept(field, parsed.unwrap()) {
            prop_assert!(false, "{}", why);
        }
    }

    #[test]
    fn random_command_lines_never_panic(
        words in prop::collection::vec(prop::sample::select(vec![
            "run", "sweep", "mesh", "chart", "compare", "latency", "--size", "--mode", "--sync",
            "--normals", "--ocean", "--kernel", "--workload", "--cores", "--frames", "--seconds", "--trials",
            "--out", "--by", "--baseline", "--threshold", "--format", "--time", "up", "dp",
            "spin", "0", "-1", "1,2,3", "x", "", "--", "--help-me", "1e9", "nan",
        ]), 0..8),
    ) {
        let mut argv = vec!["oceanbench"];
        argv.extend(words.iter().copied());
        if let Err(err) = Cli::try_parse_from(&argv) {
            one_line(&clap_line(&err));
        }
    }
}
