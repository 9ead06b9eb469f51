//! Frame timelines as Chrome Trace Event JSON (`run --trace FILE`, `sweep --trace DIR`), which
//! Perfetto, chrome://tracing, speedscope and Tracy's `import-chrome` open: which cells are
//! traced, where their files go, and each file's events (docs/trace.md describes them).

use crate::cell::{CellKey, Dim, Value};
use crate::frame_loop::{Consume, Timeline, TracedFrame};
use crate::input::InputError;
use serde_json::{json, Value as Json};
use std::path::{Path, PathBuf};

/// Frames a trace keeps when `--trace-frames` is not given.
pub const DEFAULT_FRAMES: u64 = 1000;
/// The most frames `--trace-frames` allows (a few kB of JSON per frame).
pub const MAX_FRAMES: u64 = 100_000;

/// The process id every event carries: one process per file.
const PID: u64 = 1;
/// The main thread's id; helper k's is `HELPER_TID + k`.
const MAIN_TID: u64 = 1;
const HELPER_TID: u64 = 2;
/// The category of the slices a flow binds to, and of the flows: a mesh's step and consume.
pub const MESH_CAT: &str = "mesh";
/// The flows' name.
pub const FLOW_NAME: &str = "mesh hand-off";

/// Where the traces go: one file (`run`), or a folder of one file per traced cell (`sweep`).
#[derive(Clone, Debug, PartialEq)]
pub enum Target {
    /// `run --trace FILE`.
    File(PathBuf),
    /// `sweep --trace DIR`.
    Dir(PathBuf),
}

/// The cells `--trace-cells` chooses: each listed dimension must have one of its listed values.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CellFilter(Vec<(Dim, Vec<Value>)>);

impl CellFilter {
    /// Parses `dim=value` items (a dimension named twice takes either value), e.g.
    /// `mode=dp`, `size=40`, `size=96`.
    pub fn parse(items: &[String]) -> Result<CellFilter, InputError> {
        let mut out: Vec<(Dim, Vec<Value>)> = Vec::new();
        for item in items {
            let (name, value) = item.split_once('=').ok_or_else(|| {
                InputError(format!(
                    "--trace-cells: `{item}` is not DIM=VALUE (e.g. mode=dp,size=40)"
                ))
            })?;
            let name = name.trim().replace('-', "_");
            let dim = Dim::ALL
                .iter()
                .copied()
                .find(|d| d.name() == name)
                .ok_or_else(|| {
                    let dims: Vec<&str> = Dim::ALL.iter().map(|d| d.name()).collect();
                    InputError(format!(
                        "--trace-cells: `{item}`: no dimension `{name}`; one of {}",
                        dims.join(", ")
                    ))
                })?;
            let value = dim
                .parse_value(value.trim())
                .map_err(|e| InputError(format!("--trace-cells: `{item}`: {e}")))?;
            match out.iter_mut().find(|(d, _)| *d == dim) {
                Some((_, values)) => values.push(value),
                None => out.push((dim, vec![value])),
            }
        }
        Ok(CellFilter(out))
    }

    /// Whether the filter chooses `key` (an empty filter chooses every cell).
    pub fn chooses(&self, key: &CellKey) -> bool {
        self.0
            .iter()
            .all(|(dim, values)| key.get(*dim).is_some_and(|v| values.contains(&v)))
    }
}

/// What to trace: the first trial of each chosen cell, its first `frames` measured frames.
#[derive(Clone, Debug, PartialEq)]
pub struct TracePlan {
    /// Where the files go.
    pub target: Target,
    /// The cells traced.
    pub cells: CellFilter,
    /// Frames kept per trace.
    pub frames: usize,
}

impl TracePlan {
    /// Checks the flags before anything runs or is written: `frames` in range, and a file in an
    /// existing, writable folder (or a folder that exists or can be made in one).
    pub fn new(target: Target, cells: CellFilter, frames: i64) -> Result<TracePlan, InputError> {
        if !(1..=MAX_FRAMES as i64).contains(&frames) {
            return Err(InputError(format!(
                "--trace-frames: must be 1 to {MAX_FRAMES}, got {frames}"
            )));
        }
        match &target {
            Target::File(path) => {
                if path.is_dir() {
                    return Err(InputError(format!(
                        "--trace: {} is a folder; give a file path in an existing, writable folder",
                        path.display()
                    )));
                }
                writable_parent("--trace", path, "a file path")?;
            }
            Target::Dir(dir) => {
                if dir.exists() && !dir.is_dir() {
                    return Err(InputError(format!(
                        "--trace: {} is a file; give a folder that exists or can be made in an existing, writable folder",
                        dir.display()
                    )));
                }
                if dir.is_dir() {
                    writable("--trace", dir, "a folder")?;
                } else {
                    writable_parent("--trace", dir, "a folder")?;
                }
            }
        }
        Ok(TracePlan {
            target,
            cells,
            frames: frames as usize,
        })
    }

    /// Whether cell `key` is traced.
    pub fn chooses(&self, key: &CellKey) -> bool {
        self.cells.chooses(key)
    }

    /// The file of cell `key`'s trace.
    pub fn path_for(&self, key: &CellKey) -> PathBuf {
        match &self.target {
            Target::File(path) => path.clone(),
            Target::Dir(dir) => dir.join(format!("{}.trace.json", file_stem(&key.label()))),
        }
    }

    /// Writes cell `key`'s trace (consumed as `consume`) to its file with the run's
    /// `provenance` (a [`crate::findings::provenance::Provenance`], taken as any serializable value so
    /// this module, which the sweep imports, stays below the results), making the folder if
    /// needed.
    pub fn write(
        &self,
        key: &CellKey,
        consume: Consume,
        timeline: &Timeline,
        provenance: &impl serde::Serialize,
    ) -> std::io::Result<()> {
        if let Target::Dir(dir) = &self.target {
            std::fs::create_dir_all(dir)?;
        }
        let mut json = chrome_trace(&key.label(), consume, timeline);
        // `otherData` is the format's own place for free-form metadata; viewers show it as the
        // trace's info and ignore its shape.
        json["otherData"]["provenance"] =
            serde_json::to_value(provenance).map_err(std::io::Error::other)?;
        let bytes = serde_json::to_vec(&json).map_err(std::io::Error::other)?;
        // Written beside and renamed, so an interrupted run leaves no half trace (report's
        // write_atomic would lift this module, which the sweep imports, above the reports).
        let path = self.path_for(key);
        let tmp = path.with_extension("json.tmp");
        std::fs::write(&tmp, bytes)?;
        std::fs::rename(&tmp, path)
    }
}

/// A cell label as a file name: spaces as `-`, anything unusual as `_`.
fn file_stem(label: &str) -> String {
    label
        .chars()
        .map(|c| match c {
            ' ' => '-',
            c if c.is_ascii_alphanumeric() || "._-".contains(c) => c,
            _ => '_',
        })
        .collect()
}

fn writable_parent(flag: &str, path: &Path, what: &str) -> Result<(), InputError> {
    let parent = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    if !parent.is_dir() {
        return Err(InputError(format!(
            "--{}: {}: folder {} does not exist; give {what} in an existing, writable folder",
            flag.trim_start_matches('-'),
            path.display(),
            parent.display()
        )));
    }
    writable(flag, parent, what)
}

fn writable(flag: &str, dir: &Path, what: &str) -> Result<(), InputError> {
    let readonly = std::fs::metadata(dir).map_or(true, |m| m.permissions().readonly());
    if readonly {
        return Err(InputError(format!(
            "{flag}: folder {} is not writable; give {what} in an existing, writable folder",
            dir.display()
        )));
    }
    Ok(())
}

/// Timestamps are written in whole ticks of 1/1024 µs (under 1 ns). A tick count over a power
/// of two is an exact f64, and so are the sums and differences viewers compute from it: a slice
/// whose `ts + dur` is the next slice's `ts` lands exactly on it. In ns ÷ 1000 it lands a rounding
/// error past it, and speedscope then nests every later slice of the thread inside it.
pub const TICKS_PER_US: u64 = 1024;

/// Ticks of [`TICKS_PER_US`] nearest to `ns`; never decreasing, so the order of instants holds.
fn ticks(ns: u64) -> u64 {
    ((u128::from(ns) * u128::from(TICKS_PER_US) + 500) / 1000) as u64
}

/// `ns` as a trace timestamp, in µs.
fn us(ns: u64) -> f64 {
    ticks(ns) as f64 / TICKS_PER_US as f64
}

/// A complete (`X`) slice on thread `tid` from `start` to `end` (ns).
fn slice(name: &str, cat: &str, tid: u64, start: u64, end: u64, args: Json) -> Json {
    let dur = ticks(end).saturating_sub(ticks(start)) as f64 / TICKS_PER_US as f64;
    json!({
        "name": name, "cat": cat, "ph": "X", "pid": PID, "tid": tid,
        "ts": us(start), "dur": dur, "args": args,
    })
}

fn thread_name(tid: u64, name: &str) -> Json {
    json!({"name": "thread_name", "ph": "M", "pid": PID, "tid": tid, "args": {"name": name}})
}

/// The thread a frame's band `h` ran on: helper h's, or in `serial` the main thread.
fn band_tid(timeline: &Timeline, h: usize) -> u64 {
    if timeline.helpers == 0 {
        MAIN_TID
    } else {
        HELPER_TID + h as u64
    }
}

/// The Chrome Trace Event JSON of a traced trial of cell `label`, consumed as `consume`.
///
/// Main thread: a `frame N` slice holding `workload`, `wait` (in `serial`: `step`), the
/// consume slice and `workload on mesh`. Each helper: `helper wait` and `step` (holding its
/// `phase N` slices when split). A flow from the last band's `step` to the `consume` slice links
/// each mesh, once per mesh (under `latest` a mesh taken twice is drawn once); `mesh age` gives
/// each frame's consumed mesh's age in frames and ms.
pub fn chrome_trace(label: &str, consume: Consume, timeline: &Timeline) -> Json {
    let mut events = vec![
        json!({"name": "process_name", "ph": "M", "pid": PID, "args": {"name": format!("oceanbench {label}")}}),
        thread_name(MAIN_TID, "main"),
    ];
    for h in 0..timeline.helpers {
        events.push(thread_name(HELPER_TID + h as u64, &format!("helper {h}")));
    }
    let consume_name = format!("consume ({consume})");
    let mut last_mesh = None;
    for f in &timeline.frames {
        let new_mesh = last_mesh != Some(f.mesh_frame);
        last_mesh = Some(f.mesh_frame);
        frame_events(&mut events, timeline, f, &consume_name, new_mesh);
    }
    json!({
        "traceEvents": events,
        "displayTimeUnit": "ms",
        "otherData": {
            "cell": label,
            "frames_captured": timeline.frames.len(),
            "frames_measured": timeline.measured,
            "frame_cap": timeline.cap,
            "helpers": timeline.helpers,
            "version": env!("CARGO_PKG_VERSION"),
        },
    })
}

/// One frame's slices and mesh age, and when it consumed a mesh not drawn before, that mesh's
/// helper slices and flow.
fn frame_events(
    events: &mut Vec<Json>,
    timeline: &Timeline,
    f: &TracedFrame,
    consume_name: &str,
    new_mesh: bool,
) {
    let serial = timeline.helpers == 0;
    let args = json!({"frame": f.index, "mesh": f.mesh_frame});
    events.push(slice(
        &format!("frame {}", f.index),
        "frame",
        MAIN_TID,
        f.start_ns,
        f.end_ns,
        args.clone(),
    ));
    events.push(slice(
        "workload",
        "main",
        MAIN_TID,
        f.start_ns,
        f.wait_ns,
        json!({}),
    ));
    if !serial {
        events.push(slice(
            "wait",
            "main",
            MAIN_TID,
            f.wait_ns,
            f.consume_ns,
            json!({}),
        ));
    }
    let work_from = f.done_ns.saturating_sub(f.on_mesh_ns).max(f.consume_ns);
    events.push(slice(
        consume_name,
        MESH_CAT,
        MAIN_TID,
        f.consume_ns,
        work_from,
        args.clone(),
    ));
    if f.on_mesh_ns > 0 {
        events.push(slice(
            "workload on mesh",
            "main",
            MAIN_TID,
            work_from,
            f.done_ns,
            json!({}),
        ));
    }
    events.push(json!({
        "name": "mesh age", "ph": "C", "pid": PID, "ts": us(f.consume_ns),
        "args": {"frames": f.age_frames, "ms": f.age_ns as f64 / 1e6},
    }));
    if !new_mesh {
        return;
    }
    let mesh = json!({"mesh": f.mesh_frame});
    for (h, band) in f.helpers.iter().enumerate() {
        let tid = band_tid(timeline, h);
        if band.step_ns > band.wait_ns {
            events.push(slice(
                "helper wait",
                "helper",
                tid,
                band.wait_ns,
                band.step_ns,
                json!({}),
            ));
        }
        events.push(slice(
            "step",
            MESH_CAT,
            tid,
            band.step_ns,
            band.publish_ns,
            mesh.clone(),
        ));
        for (p, &[from, to]) in band.phases.iter().enumerate() {
            events.push(slice(
                &format!("phase {p}"),
                "helper",
                tid,
                from,
                to,
                json!({}),
            ));
        }
    }
    // The mesh is published when its last band is.
    let Some((h, band)) = f
        .helpers
        .iter()
        .enumerate()
        .max_by_key(|(_, b)| b.publish_ns)
    else {
        return;
    };
    let flow = |ph: &str, tid: u64, ts: u64| json!({"name": FLOW_NAME, "cat": MESH_CAT, "ph": ph, "id": f.mesh_frame, "pid": PID, "tid": tid, "ts": us(ts)});
    events.push(flow("s", band_tid(timeline, h), band.step_ns));
    let mut end = flow("f", MAIN_TID, f.consume_ns);
    end["bp"] = json!("e");
    events.push(end);
}
