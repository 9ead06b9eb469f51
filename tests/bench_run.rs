//! Benchmark runs: `bench-record` reads only the criterion estimates written since its stamp,
//! a run reads back as written, and bad input exits 2 with one line.

mod common;

use common::{assert_one_line_exit_2, oceanbench};
use oceanbench::bench_run::{BenchEstimate, BenchRun, Throughput, SCHEMA_VERSION};
use oceanbench::machine::Machine;
use std::fs::File;
use std::path::Path;
use std::time::{Duration, SystemTime};

/// Writes criterion 0.5's two files for one benchmark under `root/<dir>/new/`, dated `when`.
fn fake_bench(root: &Path, dir: &str, full_id: &str, median: [f64; 3], when: SystemTime) {
    let new = root.join(dir).join("new");
    std::fs::create_dir_all(&new).unwrap();
    let estimate = |point: f64, lower: f64, upper: f64| {
        serde_json::json!({
            "confidence_interval": {
                "confidence_level": 0.95, "lower_bound": lower, "upper_bound": upper
            },
            "point_estimate": point,
            "standard_error": 1.0
        })
    };
    let [point, lower, upper] = median;
    let estimates = serde_json::json!({
        "mean": estimate(point + 5.0, lower + 5.0, upper + 5.0),
        "median": estimate(point, lower, upper),
        "median_abs_dev": estimate(2.0, 1.0, 3.0),
        "slope": null,
        "std_dev": estimate(3.0, 2.0, 4.0),
    });
    let (group, function) = full_id.split_once('/').unwrap();
    let benchmark = serde_json::json!({
        "group_id": group,
        "function_id": function,
        "value_str": null,
        "throughput": {"Elements": 65536},
        "full_id": full_id,
        "directory_name": dir,
        "title": full_id,
    });
    for (name, json) in [("estimates.json", estimates), ("benchmark.json", benchmark)] {
        let path = new.join(name);
        std::fs::write(&path, json.to_string()).unwrap();
        File::options()
            .write(true)
            .open(&path)
            .unwrap()
            .set_modified(when)
            .unwrap();
    }
    // What criterion keeps beside `new/`, which must not be read.
    std::fs::create_dir_all(root.join(dir).join("base")).unwrap();
    std::fs::copy(
        new.join("estimates.json"),
        root.join(dir).join("base/estimates.json"),
    )
    .unwrap();
}

/// A stamp file dated `when`.
fn stamp(path: &Path, when: SystemTime) -> String {
    File::create(path).unwrap().set_modified(when).unwrap();
    path.to_string_lossy().into_owned()
}

#[test]
fn bench_record_keeps_only_estimates_written_since_the_stamp() {
    let tmp = tempfile::tempdir().unwrap();
    let criterion = tmp.path().join("criterion");
    let now = SystemTime::now();
    let hour = Duration::from_secs(3600);
    fake_bench(
        &criterion,
        "heights/old",
        "heights/old",
        [9.0, 8.0, 10.0],
        now - 2 * hour,
    );
    fake_bench(
        &criterion,
        "heights/fused/256",
        "heights/fused/256",
        [1234.5, 1200.25, 1260.75],
        now,
    );
    let since = stamp(&tmp.path().join("stamp"), now - hour);
    let out = tmp.path().join("run");
    let args = [
        "bench-record",
        "kernels",
        "--criterion-dir",
        criterion.to_str().unwrap(),
        "--since",
        &since,
        "--out",
        out.to_str().unwrap(),
        "--",
        "scripts/bench-run.sh",
        "kernels",
        "heights",
    ];
    let output = oceanbench(&args);
    assert!(output.status.success(), "{output:?}");
    assert_eq!(
        String::from_utf8_lossy(&output.stdout).trim(),
        out.display().to_string()
    );

    let run = BenchRun::load(&out).unwrap();
    assert_eq!(run.schema_version, SCHEMA_VERSION);
    assert_eq!(run.name, "kernels");
    assert_eq!(run.command, ["scripts/bench-run.sh", "kernels", "heights"]);
    assert!(
        run.source.contains("95% bootstrap confidence"),
        "{}",
        run.source
    );
    assert_eq!(run.machine.cpu_model, Machine::current().cpu_model);
    assert_eq!(
        run.estimates,
        [BenchEstimate {
            id: "heights/fused/256".into(),
            unit: "ns".into(),
            value: 1234.5,
            lower: 1200.25,
            upper: 1260.75,
            throughput: Some(Throughput::Elements(65536)),
        }]
    );
    assert!(run.estimate("heights/old").is_none());

    // The folder is not written twice.
    assert_one_line_exit_2(&oceanbench(&args), &["already holds bench.json"]);
}

#[test]
fn a_run_reads_back_as_written() {
    let run = BenchRun {
        schema_version: SCHEMA_VERSION,
        name: "kernel_ratio".into(),
        started: "2026-11-27T12:00:00Z".into(),
        machine: Machine::current(),
        command: vec!["kernel_ratio".into(), "256".into()],
        source: "a test".into(),
        estimates: vec![
            BenchEstimate {
                id: "heights only/fused/256".into(),
                unit: "Mvertices/s".into(),
                value: 1179.1,
                lower: 0.1 + 0.2,
                upper: 1300.0,
                throughput: None,
            },
            BenchEstimate {
                id: "spray/update/4096".into(),
                unit: "ns".into(),
                value: 1.0,
                lower: 0.5,
                upper: 2.0,
                throughput: Some(Throughput::Bytes(114_688)),
            },
        ],
    };
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("bench-kernel_ratio-20261127T120000Z");
    run.write(&dir).unwrap();
    assert_eq!(BenchRun::load(&dir).unwrap(), run);
    assert_eq!(BenchRun::load(&dir.join("bench.json")).unwrap(), run);
    let text = std::fs::read_to_string(dir.join("bench.json")).unwrap();
    assert!(text.contains("\"bytes\": 114688"), "{text}");
    assert_eq!(run.estimate("spray/update/4096"), Some(&run.estimates[1]));
}

#[test]
fn bad_input_exits_2_with_one_line() {
    let tmp = tempfile::tempdir().unwrap();
    let criterion = tmp.path().join("criterion");
    let now = SystemTime::now();
    fake_bench(&criterion, "fft-512/x", "fft-512/x", [1.0, 0.5, 2.0], now);
    let later = stamp(&tmp.path().join("stamp"), now + Duration::from_secs(60));
    let out = tmp.path().join("run");
    let out = out.to_str().unwrap();
    let dir = criterion.to_str().unwrap();
    let record = |name, dir, since| {
        [
            "bench-record",
            name,
            "--criterion-dir",
            dir,
            "--since",
            since,
            "--out",
            out,
        ]
    };
    assert_one_line_exit_2(
        &oceanbench(&record("fft", dir, &later)),
        &["no criterion estimates"],
    );
    let missing = tmp.path().join("nowhere");
    assert_one_line_exit_2(
        &oceanbench(&record("fft", missing.to_str().unwrap(), &later)),
        &["--criterion-dir"],
    );
    assert_one_line_exit_2(
        &oceanbench(&record("fft", dir, missing.to_str().unwrap())),
        &["--since"],
    );
    assert_one_line_exit_2(&oceanbench(&record("../fft", dir, &later)), &["NAME"]);
    assert!(!Path::new(out).exists());
}
