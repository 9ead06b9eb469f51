//! results.json's `schema_version`: files from before it load as version 1, this build writes
//! its own, and a file from a newer build is refused with one line rather than misread.

mod common;

use common::{fixture, oceanbench, root, FIXTURE};
use oceanbench::results::{Results, SCHEMA_VERSION};

#[test]
fn files_without_a_version_load_as_version_1_and_every_committed_run_loads() {
    let text = std::fs::read_to_string(FIXTURE).unwrap();
    assert!(
        !text.contains("schema_version"),
        "the fixture predates the field"
    );
    assert_eq!(fixture().schema_version, 1);
    for dir in std::fs::read_dir(root().join("results")).unwrap() {
        let dir = dir.unwrap().path();
        if dir.join("results.json").exists() {
            let r = Results::load(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
            assert!(r.schema_version <= SCHEMA_VERSION);
        }
    }
}

#[test]
fn this_build_writes_its_version_and_refuses_a_newer_one() {
    let mut r = fixture();
    r.schema_version = SCHEMA_VERSION;
    let written = oceanbench::report::json::to_string(&r).unwrap();
    let json: serde_json::Value = serde_json::from_str(&written).unwrap();
    assert_eq!(json["schema_version"], SCHEMA_VERSION);

    let dir = tempfile::tempdir().unwrap();
    let newer = dir.path().join("results.json");
    let mut bumped = json.clone();
    bumped["schema_version"] = (SCHEMA_VERSION + 1).into();
    // A newer layout may change anything: drop a field this build needs, too.
    bumped.as_object_mut().unwrap().remove("cells");
    std::fs::write(&newer, bumped.to_string()).unwrap();
    let err = Results::load(&newer).unwrap_err().to_string();
    assert!(
        err.contains(&format!("schema version {}", SCHEMA_VERSION + 1)) && err.contains("newer"),
        "{err}"
    );
    let charts = dir.path().join("charts");
    let out = oceanbench(&[
        "chart",
        newer.to_str().unwrap(),
        "--out",
        charts.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
    assert!(stderr.contains("newer"), "{stderr}");
}

/// Schema 7 keyed a kind's counts and records; the committed spray and fog runs from before it
/// read back under the keys today's kinds write, with the values the files hold.
#[test]
fn counts_and_records_from_before_schema_7_read_back_keyed() {
    let spray = Results::load(&root().join("results/fft-spray-20261125T162607Z")).unwrap();
    assert!(spray.schema_version < 7);
    let raw: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(root().join("results/fft-spray-20261125T162607Z/results.json"))
            .unwrap(),
    )
    .unwrap();
    let (cell, raw_cell) = spray
        .cells
        .iter()
        .zip(raw["cells"].as_array().unwrap())
        .find(|(c, _)| {
            c.summary
                .as_ref()
                .is_some_and(|s| !s.work_trials.is_empty())
        })
        .expect("a spray cell with counts");
    let old = &raw_cell["particles"][0];
    let t = &cell.summary.as_ref().unwrap().work_trials[0];
    let keys: Vec<&str> = t.counts.iter().map(|c| c.key.as_str()).collect();
    assert_eq!(keys, ["live", "emitted", "recycled"]);
    let live = t.count("live").unwrap();
    assert_eq!(live.mean, old["live_mean"].as_f64().unwrap());
    assert_eq!(live.min, old["live_min"].as_u64());
    assert_eq!(live.max, old["live_max"].as_u64());
    let emitted = t.count("emitted").unwrap();
    assert_eq!(emitted.mean, old["emitted_per_frame"].as_f64().unwrap());
    assert_eq!((emitted.min, emitted.max), (None, None), "not in the file");
    assert_eq!(t.main_ms, old["main_ms"].as_f64().unwrap());

    let fog = Results::load(&root().join("results/fog-20261125T163342Z")).unwrap();
    let raw: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(root().join("results/fog-20261125T163342Z/results.json")).unwrap(),
    )
    .unwrap();
    let (cell, raw_cell) = fog
        .cells
        .iter()
        .zip(raw["cells"].as_array().unwrap())
        .find(|(c, _)| c.work.is_some())
        .expect("a fog cell with its record");
    let old = &raw_cell["work"]["fog"];
    let r = cell.work.as_ref().unwrap();
    let keys: Vec<&str> = r.iter().map(|(k, _)| k).collect();
    assert_eq!(
        keys,
        ["volume", "octaves", "noise_ms", "blur_ms", "coefficient_ms"]
    );
    for (k, v) in r.iter() {
        assert_eq!(Some(v), old[k].as_f64(), "{k}");
    }

    // Written again, both are in today's layout and read back the same.
    let mut again = spray.clone();
    again.cells.truncate(0);
    again.cells.push(cell.clone());
    let text = oceanbench::report::json::to_string(&again).unwrap();
    let written: serde_json::Value = serde_json::from_str(&text).unwrap();
    let work = written["cells"][0]["work"].as_object().unwrap();
    assert!(work.values().all(|v| v.is_number()), "flat: {work:?}");
    let back: Results = serde_json::from_str(&text).unwrap();
    assert_eq!(back.cells[0].work, cell.work);
}
