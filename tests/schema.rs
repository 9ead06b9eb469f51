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
