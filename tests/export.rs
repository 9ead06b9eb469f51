//! `oceanbench export`: committed runs (old schemas included) as Bencher Metric Format, checked
//! against Bencher's published JSON schema, and as github-action-benchmark's list; bad input.

mod common;

use common::{
    assert_cell_provenance, assert_run_provenance, assert_success, oceanbench, refuses, root,
};
use oceanbench::results::Results;
use serde_json::Value;

/// Bencher's BMF JSON schema as https://bencher.dev/docs/reference/bencher-metric-format
/// publishes it (draft-07).
const BMF_SCHEMA: &str = r#"{
  "$id": "https://bencher.dev/bmf.json",
  "$schema": "http://json-schema.org/draft-07/schema",
  "type": "object",
  "patternProperties": {
    ".+": {
      "type": "object",
      "patternProperties": {
        ".+": {
          "type": "object",
          "properties": {
            "value": { "type": "number" },
            "lower_value": { "type": "number" },
            "upper_value": { "type": "number" }
          },
          "required": ["value"]
        }
      }
    }
  }
}"#;

/// Validates `value` against `schema`, for the draft-07 keywords the BMF schema uses (any other
/// keyword fails the test rather than pass unread); the errors found, each with its path.
fn validate(schema: &Value, value: &Value, path: &str, errors: &mut Vec<String>) {
    for (keyword, rule) in schema.as_object().unwrap() {
        match keyword.as_str() {
            "$id" | "$schema" => {}
            "type" => {
                let ok = match rule.as_str().unwrap() {
                    "object" => value.is_object(),
                    "number" => value.is_number(),
                    other => panic!("type {other} is not read here"),
                };
                if !ok {
                    errors.push(format!("{path}: not a {rule}"));
                }
            }
            "patternProperties" => {
                for (pattern, sub) in rule.as_object().unwrap() {
                    assert_eq!(pattern, ".+", "only the pattern `.+` is read here");
                    for (key, v) in value.as_object().into_iter().flatten() {
                        if key.is_empty() {
                            errors.push(format!("{path}: an empty key"));
                        }
                        validate(sub, v, &format!("{path}/{key}"), errors);
                    }
                }
            }
            "properties" => {
                for (key, sub) in rule.as_object().unwrap() {
                    if let Some(v) = value.get(key) {
                        validate(sub, v, &format!("{path}/{key}"), errors);
                    }
                }
            }
            "required" => {
                for key in rule.as_array().unwrap() {
                    if value.get(key.as_str().unwrap()).is_none() {
                        errors.push(format!("{path}: lacks {key}"));
                    }
                }
            }
            other => panic!("keyword {other} is not read here"),
        }
    }
}

/// A committed run from before schema versions were written (read through serde's aliases).
const OLD_RUN: &str = "results/figure-5-1-20261122T024939Z";

fn export(run: &str, format: &str) -> Value {
    let out = oceanbench(&["export", run, "--format", format]);
    assert_success(&out);
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn bmf_of_a_committed_run_fits_bencher_schema_and_names_every_cell() {
    let results = Results::load(&root().join(OLD_RUN)).unwrap();
    let bmf = export(OLD_RUN, "bmf");
    let mut errors = Vec::new();
    validate(
        &serde_json::from_str(BMF_SCHEMA).unwrap(),
        &bmf,
        "",
        &mut errors,
    );
    assert!(errors.is_empty(), "{errors:?}");

    let benchmarks = bmf.as_object().unwrap();
    let measured: Vec<_> = results
        .cells
        .iter()
        .filter_map(|c| c.summary.as_ref())
        .collect();
    assert_eq!(
        benchmarks.len(),
        measured.len(),
        "one name per cell, none twice"
    );
    for (name, measures) in benchmarks {
        assert!(name.chars().count() <= 1024, "Bencher's name limit: {name}");
        for dim in [
            "size=",
            "workload_kind=",
            "level=",
            "mode=",
            "kernel=",
            "normals=",
        ] {
            assert!(name.contains(dim), "{name} lacks {dim}");
        }
        // The level as the config gives it: µs, or a fraction of a mesh's step (whose µs differ
        // from run to run, so a name holding them would too).
        assert!(
            name.contains("level=0 µs,") || name.contains(" step,"),
            "the level in its unit: {name}"
        );
        assert!(!name.contains("workload="), "no level index: {name}");
        let fps = &measures["fps"];
        let [v, lo, hi] = ["value", "lower_value", "upper_value"].map(|k| fps[k].as_f64().unwrap());
        assert!(lo <= v && v <= hi, "{name}: {lo} {v} {hi}");
    }
    // Every cell's FPS, under its name.
    let mut values: Vec<f64> = benchmarks
        .values()
        .map(|m| m["fps"]["value"].as_f64().unwrap())
        .collect();
    let mut expected: Vec<f64> = measured.iter().map(|s| s.fps).collect();
    values.sort_by(f64::total_cmp);
    expected.sort_by(f64::total_cmp);
    assert_eq!(values, expected);
}

#[test]
fn github_action_benchmark_lists_fps_with_string_range_and_extra() {
    let results = Results::load(&root().join(OLD_RUN)).unwrap();
    let list = export(OLD_RUN, "github-action-benchmark");
    let bmf = export(OLD_RUN, "bmf");
    let list = list.as_array().unwrap();
    assert_eq!(list.len(), bmf.as_object().unwrap().len());
    for bench in list {
        let keys: Vec<&str> = bench
            .as_object()
            .unwrap()
            .keys()
            .map(String::as_str)
            .collect();
        assert_eq!(keys, ["name", "unit", "value", "range", "extra"]);
        let name = bench["name"].as_str().unwrap();
        assert_eq!(bench["unit"], "FPS");
        assert_eq!(
            bench["value"], bmf[name]["fps"]["value"],
            "{name}: same name, same FPS"
        );
        assert!(bench["range"].is_string() && bench["extra"].is_string());
        let extra = bench["extra"].as_str().unwrap();
        assert!(extra.contains(&results.machine.cpu_model), "{extra}");
    }
}

/// `OLD_RUN` as `export` reads it: its trials placed against its round trips.
fn labelled_old_run() -> Results {
    let mut results = Results::load(&root().join(OLD_RUN)).unwrap();
    oceanbench::findings::placement::label(&mut results);
    results
}

#[test]
fn every_export_file_has_its_provenance_beside_it() {
    let results = labelled_old_run();
    let dir = tempfile::tempdir().unwrap();
    for format in ["bmf", "github-action-benchmark"] {
        let file = dir.path().join(format!("{format}.json"));
        let out = oceanbench(&[
            "export",
            OLD_RUN,
            "--format",
            format,
            "--out",
            file.to_str().unwrap(),
        ]);
        assert_success(&out);
        let sidecar = dir.path().join(format!("{format}.provenance.json"));
        let record: Value = serde_json::from_str(&std::fs::read_to_string(&sidecar).unwrap())
            .unwrap_or_else(|e| panic!("{}: {e}", sidecar.display()));
        let p = assert_run_provenance(&record, &results);
        // One entry per exported benchmark, under the name the export gives it.
        let names: Vec<String> = match format {
            "bmf" => export(OLD_RUN, "bmf")
                .as_object()
                .unwrap()
                .keys()
                .cloned()
                .collect(),
            _ => export(OLD_RUN, format)
                .as_array()
                .unwrap()
                .iter()
                .map(|b| b["name"].as_str().unwrap().to_string())
                .collect(),
        };
        let cells: Vec<&str> = p.placement.cells.iter().map(|c| c.name.as_str()).collect();
        assert_eq!(cells, names);
        let measured = results.cells.iter().filter(|c| c.summary.is_some());
        for (facts, cell) in p.placement.cells.iter().zip(measured) {
            assert_cell_provenance(facts, cell);
        }
    }
}

#[test]
fn bmf_to_standard_output_stays_pure_and_names_its_provenance_on_stderr() {
    let results = labelled_old_run();
    let out = oceanbench(&["export", OLD_RUN, "--format", "bmf"]);
    assert_success(&out);
    let bmf: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(bmf
        .as_object()
        .unwrap()
        .values()
        .all(|m| m.get("fps").is_some()));
    let stderr = String::from_utf8_lossy(&out.stderr);
    let line = stderr
        .lines()
        .find_map(|l| l.split_once("provenance").map(|_| l))
        .unwrap_or_else(|| panic!("no provenance on stderr: {stderr}"));
    let record: Value = serde_json::from_str(&line[line.find('{').unwrap()..]).unwrap();
    assert_run_provenance(&record, &results);
}

#[test]
fn github_action_benchmark_extra_carries_machine_commit_config_and_placement() {
    let results = labelled_old_run();
    let hash = oceanbench::findings::provenance::config_hash(&results);
    for bench in export(OLD_RUN, "github-action-benchmark")
        .as_array()
        .unwrap()
    {
        let extra = bench["extra"].as_str().unwrap();
        let name = bench["name"].as_str().unwrap();
        for needle in [
            results.machine.line(),
            results.machine.provenance_line(),
            format!("config {} (hash {hash})", results.config.name),
            format!("placement of {name}: "),
        ] {
            assert!(extra.contains(&needle), "{needle} not in {extra}");
        }
        if let Some(split) = &results.placement {
            assert!(extra.contains(&split.describe()), "{extra}");
        }
    }
}

#[test]
fn an_export_to_a_file_matches_standard_output() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("bmf.json");
    let out = oceanbench(&[
        "export",
        OLD_RUN,
        "--format",
        "bmf",
        "--out",
        file.to_str().unwrap(),
    ]);
    assert_success(&out);
    let written: Value = serde_json::from_str(&std::fs::read_to_string(&file).unwrap()).unwrap();
    assert_eq!(written, export(OLD_RUN, "bmf"));
}

#[test]
fn bad_exports_exit_2_with_one_line_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let kept = dir.path().join("kept.json");
    std::fs::write(&kept, "earlier").unwrap();
    let not_a_run = dir.path().to_str().unwrap();
    refuses(
        &["export", OLD_RUN, "--format", "csv"],
        &["--format", "bmf", "github-action-benchmark"],
    );
    refuses(
        &[
            "export",
            not_a_run,
            "--format",
            "bmf",
            "--out",
            kept.to_str().unwrap(),
        ],
        &["RUN:", "results.json"],
    );
    let missing = dir.path().join("no/such/folder/out.json");
    refuses(
        &[
            "export",
            OLD_RUN,
            "--format",
            "bmf",
            "--out",
            missing.to_str().unwrap(),
        ],
        &["--out", "no folder"],
    );
    assert_eq!(std::fs::read_to_string(&kept).unwrap(), "earlier");
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        1,
        "no export and no provenance beside it"
    );
}
