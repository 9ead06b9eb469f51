//! `run --trace` and `sweep --trace`: the Chrome Trace Event JSON a viewer opens, parsed back.
//! Slices nest or follow each other on every thread, time runs forward, every flow binds to a
//! helper's step and the main thread's consume slice, the frame cap holds and the file says so;
//! bad flags exit 2 with one line and write nothing.

mod common;

use common::{
    assert_input_error, assert_run_provenance, assert_success, oceanbench_locked, write_file,
};
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::Path;

/// Slack for comparing times the file holds as µs with three decimals' worth of nanoseconds.
const EPS_US: f64 = 1e-3;

/// A tiny cell (8² unless `extra` gives a size) with `--trace FILE` and `extra` flags; the
/// parsed file.
fn traced_run(dir: &Path, extra: &[&str]) -> Value {
    let file = dir.join("t.json");
    let mut args = vec![
        "run",
        "--trials",
        "1",
        "--frames",
        "30",
        "--seconds",
        "0",
        "--trace",
        file.to_str().unwrap(),
        "--trace-frames",
        "20",
    ];
    if !extra.contains(&"--size") {
        args.extend(["--size", "8"]);
    }
    args.extend(extra);
    let out = oceanbench_locked(dir, &args);
    assert_success(&out);
    serde_json::from_str(&std::fs::read_to_string(&file).unwrap()).unwrap()
}

fn events<'a>(trace: &'a Value, ph: &str) -> Vec<&'a Value> {
    trace["traceEvents"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|e| e["ph"] == ph)
        .collect()
}

fn f(e: &Value, key: &str) -> f64 {
    e[key].as_f64().unwrap_or_else(|| panic!("{key} of {e}"))
}

/// The thread names by tid.
fn threads(trace: &Value) -> BTreeMap<u64, String> {
    events(trace, "M")
        .into_iter()
        .filter(|e| e["name"] == "thread_name")
        .map(|e| {
            (
                e["tid"].as_u64().unwrap(),
                e["args"]["name"].as_str().unwrap().to_string(),
            )
        })
        .collect()
}

/// Checks that on every thread the `X` slices nest or follow each other, and returns them by tid
/// in start order. The check is exact, in f64, on times shifted to the trace's first event, as
/// speedscope computes them: a slice that ends where the next starts must not end a rounding
/// error past it, or speedscope nests every later slice inside it.
fn slices_nest(trace: &Value) -> BTreeMap<u64, Vec<&Value>> {
    let origin = events(trace, "X")
        .iter()
        .map(|e| f(e, "ts"))
        .fold(f64::INFINITY, f64::min);
    let start = |e: &Value| f(e, "ts") - origin;
    let end = |e: &Value| start(e) + f(e, "dur");
    let mut by_tid: BTreeMap<u64, Vec<&Value>> = BTreeMap::new();
    for e in events(trace, "X") {
        assert!(f(e, "dur") >= 0.0, "{e}");
        by_tid
            .entry(e["tid"].as_u64().unwrap())
            .or_default()
            .push(e);
    }
    for (tid, slices) in &mut by_tid {
        slices.sort_by(|a, b| {
            (f(a, "ts"), -f(a, "dur"))
                .partial_cmp(&(f(b, "ts"), -f(b, "dur")))
                .unwrap()
        });
        let mut open: Vec<&Value> = Vec::new();
        for s in slices.iter() {
            while open.last().is_some_and(|p| end(p) <= start(s)) {
                open.pop();
            }
            if let Some(parent) = open.last() {
                assert!(
                    end(s) <= end(parent),
                    "tid {tid}: {s} overlaps {parent} without nesting in it"
                );
            }
            open.push(s);
        }
    }
    by_tid
}

/// The slice on `tid` named by `is` that starts at `ts`.
fn slice_at<'a>(
    slices: &BTreeMap<u64, Vec<&'a Value>>,
    tid: u64,
    ts: f64,
    is: impl Fn(&str) -> bool,
) -> Option<&'a Value> {
    slices.get(&tid)?.iter().copied().find(|s| {
        is(s["name"].as_str().unwrap())
            && f(s, "ts") <= ts + EPS_US
            && ts <= f(s, "ts") + f(s, "dur") + EPS_US
    })
}

/// Every `s` has one `f` of the same id, cat and name, with `bp` "e"; `s` lies in a step slice
/// of its thread with its cat, `f` in the main thread's consume slice with its cat, after it.
fn flows_bind(trace: &Value, slices: &BTreeMap<u64, Vec<&Value>>, step_tids: &[u64]) -> usize {
    let starts = events(trace, "s");
    let ends = events(trace, "f");
    assert_eq!(starts.len(), ends.len());
    let mut ids = std::collections::BTreeSet::new();
    for s in &starts {
        assert!(
            ids.insert(s["id"].as_u64().unwrap()),
            "one flow per mesh: {s}"
        );
        let matching: Vec<_> = ends
            .iter()
            .filter(|e| e["id"] == s["id"] && e["cat"] == s["cat"] && e["name"] == s["name"])
            .collect();
        assert_eq!(matching.len(), 1, "{s}");
        let end = matching[0];
        assert_eq!(end["bp"], "e");
        assert_eq!((&s["pid"], &end["pid"]), (&Value::from(1), &Value::from(1)));
        let tid = s["tid"].as_u64().unwrap();
        assert!(step_tids.contains(&tid), "{s}");
        let step = slice_at(slices, tid, f(s, "ts"), |n| n == "step").expect("s in a step");
        assert_eq!((&step["cat"], &step["pid"]), (&s["cat"], &s["pid"]));
        assert_eq!(end["tid"], 1, "{end}");
        let consume = slice_at(slices, 1, f(end, "ts"), |n| n.starts_with("consume"))
            .expect("f in a consume slice");
        assert_eq!(consume["cat"], end["cat"]);
        assert!(f(s, "ts") <= f(end, "ts"), "{s} after {end}");
    }
    starts.len()
}

/// The main thread's frames: each holds its parts, in order, and frames run forward.
fn frames_hold_their_parts(slices: &BTreeMap<u64, Vec<&Value>>, parts: &[&str]) -> usize {
    let main = &slices[&1];
    let frames: Vec<&&Value> = main
        .iter()
        .filter(|s| s["name"].as_str().unwrap().starts_with("frame "))
        .collect();
    for pair in frames.windows(2) {
        assert!(f(pair[0], "ts") + f(pair[0], "dur") <= f(pair[1], "ts") + EPS_US);
    }
    for frame in &frames {
        let (start, end) = (f(frame, "ts"), f(frame, "ts") + f(frame, "dur"));
        let inside: Vec<&str> = main
            .iter()
            .filter(|s| !std::ptr::eq(**s, **frame))
            .filter(|s| f(s, "ts") >= start - EPS_US && f(s, "ts") + f(s, "dur") <= end + EPS_US)
            .map(|s| s["name"].as_str().unwrap())
            .collect();
        let named: Vec<&str> = inside
            .iter()
            .map(|n| {
                if n.starts_with("consume") {
                    "consume"
                } else {
                    n
                }
            })
            .filter(|n| *n != "workload on mesh")
            .collect();
        assert_eq!(named, parts, "{frame}");
    }
    frames.len()
}

#[test]
fn a_dp_trace_names_its_threads_nests_its_slices_and_binds_every_flow() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    let trace = traced_run(
        dir.path(),
        &["--mode", "dp", "--out", out.to_str().unwrap()],
    );
    // The run's provenance rides in otherData; the traced trial is placed by its own round trips.
    let results = oceanbench::results::Results::load(&out).unwrap();
    let p = assert_run_provenance(&trace["otherData"]["provenance"], &results);
    assert_eq!(p.config.command, results.command);
    let [traced] = p.placement.cells.as_slice() else {
        panic!("one traced cell: {:?}", p.placement.cells)
    };
    assert_eq!(traced.name, results.cells[0].key.label());
    assert!(traced.trials[0].round_trip_ns.is_some(), "{traced:?}");
    let names = threads(&trace);
    assert_eq!(names[&1], "main");
    assert_eq!(names[&2], "helper 0");
    assert!(events(&trace, "M")
        .iter()
        .any(|e| e["name"] == "process_name"));
    let meta = &trace["otherData"];
    assert_eq!(meta["frames_captured"], 20);
    assert_eq!(meta["frame_cap"], 20);
    assert!(meta["frames_measured"].as_u64().unwrap() >= 30, "{meta}");
    let slices = slices_nest(&trace);
    assert_eq!(
        frames_hold_their_parts(&slices, &["workload", "wait", "consume"]),
        20
    );
    let steps = slices[&2].iter().filter(|s| s["name"] == "step").count();
    assert_eq!(steps, 20, "a step per frame");
    assert_eq!(flows_bind(&trace, &slices, &[2]), 20);
    let ages = events(&trace, "C");
    assert_eq!(ages.len(), 20);
    assert!(ages
        .iter()
        .all(|c| c["name"] == "mesh age" && c["args"]["frames"].is_u64()));
}

#[test]
fn a_serial_trace_draws_the_step_on_the_main_thread() {
    let dir = tempfile::tempdir().unwrap();
    let trace = traced_run(dir.path(), &["--mode", "serial"]);
    assert_eq!(threads(&trace).into_values().collect::<Vec<_>>(), ["main"]);
    let slices = slices_nest(&trace);
    assert_eq!(
        frames_hold_their_parts(&slices, &["workload", "step", "consume"]),
        20
    );
    assert_eq!(flows_bind(&trace, &slices, &[1]), 20);
}

#[test]
fn a_latest_trace_draws_each_mesh_once_and_two_helpers_each_their_band() {
    let dir = tempfile::tempdir().unwrap();
    let trace = traced_run(dir.path(), &["--mode", "dp", "--policy", "latest"]);
    let slices = slices_nest(&trace);
    frames_hold_their_parts(&slices, &["workload", "wait", "consume"]);
    let flows = flows_bind(&trace, &slices, &[2]);
    assert!((1..=20).contains(&flows), "{flows}");

    let trace = traced_run(dir.path(), &["--mode", "dp", "--helpers", "2"]);
    let names = threads(&trace);
    assert_eq!(
        (names[&2].as_str(), names[&3].as_str()),
        ("helper 0", "helper 1")
    );
    let slices = slices_nest(&trace);
    for tid in [2, 3] {
        assert_eq!(
            slices[&tid].iter().filter(|s| s["name"] == "step").count(),
            20
        );
    }
    assert_eq!(flows_bind(&trace, &slices, &[2, 3]), 20);
}

#[test]
fn a_split_step_draws_its_phases_inside_each_helpers_step() {
    let dir = tempfile::tempdir().unwrap();
    let trace = traced_run(
        dir.path(),
        &[
            "--mode",
            "dp",
            "--helpers",
            "2",
            "--ocean",
            "fft",
            "--size",
            "16",
        ],
    );
    let slices = slices_nest(&trace);
    for tid in [2, 3] {
        let on = &slices[&tid];
        for step in on.iter().filter(|s| s["name"] == "step") {
            let (from, to) = (f(step, "ts"), f(step, "ts") + f(step, "dur"));
            let phases: Vec<&str> = on
                .iter()
                .filter(|s| s["name"].as_str().unwrap().starts_with("phase "))
                .filter(|s| f(s, "ts") >= from - EPS_US && f(s, "ts") + f(s, "dur") <= to + EPS_US)
                .map(|s| s["name"].as_str().unwrap())
                .collect();
            assert_eq!(phases, ["phase 0", "phase 1"], "{step}");
        }
    }
    assert_eq!(flows_bind(&trace, &slices, &[2, 3]), 20);
}

#[test]
fn a_sweep_traces_the_cells_its_filter_chooses() {
    let dir = tempfile::tempdir().unwrap();
    let config = write_file(
        dir.path(),
        "tiny.json",
        r#"{"name": "tiny", "sizes": [8], "workloads": [0], "sync": ["atomic", "condvar"],
            "trials": 2, "warmup_frames": 2, "min_frames": 5, "min_seconds": 0.0,
            "workload_levels": [{"micros": 0}]}"#,
    );
    let traces = dir.path().join("traces");
    let out = oceanbench_locked(
        dir.path(),
        &[
            "sweep",
            &config,
            "--out",
            dir.path().join("run").to_str().unwrap(),
            "--quiet",
            "--no-charts",
            "--no-report",
            "--no-doctor",
            "--trace",
            traces.to_str().unwrap(),
            "--trace-cells",
            "mode=dp,sync=condvar",
            "--trace-frames",
            "3",
        ],
    );
    assert_success(&out);
    let files: Vec<String> = std::fs::read_dir(&traces)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(files.len(), 1, "{files:?}");
    assert!(
        files[0].contains("dp") && files[0].contains("condvar"),
        "{files:?}"
    );
    let trace: Value =
        serde_json::from_str(&std::fs::read_to_string(traces.join(&files[0])).unwrap()).unwrap();
    assert_eq!(trace["otherData"]["frames_captured"], 3);
    assert_eq!(trace["otherData"]["frames_measured"], 5);
}

#[test]
fn bad_trace_flags_exit_2_with_one_line_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("out");
    let file = dir.path().join("t.json");
    let run = |extra: &[&str], needles: &[&str]| {
        let mut args = vec!["run", "--size", "8", "--out", out_dir.to_str().unwrap()];
        args.extend(extra);
        assert_input_error(&oceanbench_locked(dir.path(), &args), needles);
        assert!(
            !out_dir.exists() && !file.exists(),
            "{extra:?} wrote something"
        );
    };
    let missing = dir.path().join("no/such/folder/t.json");
    run(
        &["--trace", missing.to_str().unwrap()],
        &["--trace", "does not exist"],
    );
    run(
        &["--trace", dir.path().to_str().unwrap()],
        &["--trace", "is a folder"],
    );
    for n in ["0", "-3", "100001"] {
        run(
            &["--trace", file.to_str().unwrap(), "--trace-frames", n],
            &["--trace-frames", "1 to 100000", n],
        );
    }
    run(&["--trace-frames", "5"], &["--trace"]);
    run(
        &["--trace", file.to_str().unwrap(), "--mode", "up,dp"],
        &["--trace", "2 cells", "sweep --trace DIR"],
    );
    let sweep = |filter: &str, needles: &[&str]| {
        let traces = dir.path().join("traces");
        let args = [
            "sweep",
            "configs/quick.json",
            "--out",
            out_dir.to_str().unwrap(),
            "--trace",
            traces.to_str().unwrap(),
            "--trace-cells",
            filter,
        ];
        assert_input_error(&oceanbench_locked(dir.path(), &args), needles);
        assert!(
            !out_dir.exists() && !traces.exists(),
            "{filter} wrote something"
        );
    };
    sweep("flavour=dp", &["--trace-cells", "flavour", "mode"]);
    sweep("mode=tri", &["--trace-cells", "mode=tri"]);
    sweep("size", &["--trace-cells", "DIM=VALUE"]);
    sweep("size=12", &["--trace-cells", "chooses none"]);
}
