//! The `helpers` dimension (helper threads the mesh's rows are split among) in configs and
//! results: swept for threaded cells, refused where it cannot run, and absent from old results
//! files (read as 1 for threaded cells, none for serial ones).

use oceanbench::config::SweepConfig;
use oceanbench::results::CellKey;
use oceanbench::sweep;

#[test]
fn old_cell_keys_without_helpers_load_as_one_helper() {
    let old = r#"{"size": 256, "workload": 2, "mode": "dp", "sync": "atomic",
        "threading": "pool", "normals": "neighbors", "kernel": "reference"}"#;
    let key: CellKey = serde_json::from_str(old).unwrap();
    assert_eq!(key.helpers, Some(1));
    assert_eq!(key.label(), "256 w2 dp atomic pool neighbors reference");
    let split = CellKey {
        helpers: Some(2),
        ..key
    };
    assert_eq!(
        split.label(),
        "256 w2 dp atomic pool h2 neighbors reference"
    );
}

#[test]
fn helpers_are_swept_for_threaded_modes_only() {
    let config = SweepConfig::from_json(
        r#"{"sizes": [64], "workloads": [0], "modes": ["serial", "up"], "sync": ["atomic"],
            "normals": ["analytic"], "helpers": [1, 2]}"#,
    )
    .unwrap();
    let helpers: Vec<Option<usize>> = sweep::cells(&config).iter().map(|k| k.helpers).collect();
    assert_eq!(helpers, [None, Some(1), Some(2)]);
}

#[test]
fn configs_that_cannot_split_are_refused_naming_helpers() {
    for bad in [
        r#"{"modes": ["up"], "normals": ["analytic"], "threading": ["spawn"], "helpers": [2]}"#,
        r#"{"modes": ["up"], "normals": ["neighbors"], "helpers": [1, 2]}"#,
        r#"{"modes": ["up"], "normals": ["analytic"], "helpers": [0]}"#,
    ] {
        let err = SweepConfig::from_json(bad).unwrap_err().to_string();
        assert!(err.starts_with("helpers:"), "{bad}: {err}");
    }
}
