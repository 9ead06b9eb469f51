//! CSV files through the `csv` crate, from flat row structs: the results table (one row per
//! cell, one column per dimension or statistic) and `mesh --out`.

use super::export::{Export, ExportError, Exporter};
use crate::findings::placement::CellPlacement;
use crate::level::Calibrate;
use crate::placement::Class;
use crate::results::balance::Ratio;
use crate::results::{Cell, CellKey, CellNoise, Results};
use crate::stats;
use itertools::Itertools;
use serde::Serialize;
use std::io::Write;

/// One results row: the cell's dimensions, its statistics, what disturbed it and how its level
/// was calibrated; blank where a cell has no value.
#[derive(Serialize)]
struct CellRow<'a> {
    #[serde(flatten)]
    key: &'a CellKey,
    workload_iterations: u64,
    workload_unit: &'a str,
    workload_amount: u64,
    fps: Option<f64>,
    fps_min: Option<f64>,
    fps_max: Option<f64>,
    fps_cv_percent: Option<f64>,
    frame_ms_mean: Option<f64>,
    frame_ms_median: Option<f64>,
    frame_ms_p99: Option<f64>,
    frame_ms_max: Option<f64>,
    one_percent_low_fps: Option<f64>,
    p1_fps: Option<f64>,
    one_percent_low_average_fps: Option<f64>,
    one_percent_low_integral_fps: Option<f64>,
    p0_1_fps: Option<f64>,
    point_one_percent_low_average_fps: Option<f64>,
    point_one_percent_low_integral_fps: Option<f64>,
    stutter_time_percent: Option<f64>,
    workload_ms: Option<f64>,
    wait_ms: Option<f64>,
    wait_cpu_ms: Option<f64>,
    helper_wait_ms: Option<f64>,
    helper_wait_cpu_ms: Option<f64>,
    copy_ms: Option<f64>,
    step_ms: Option<f64>,
    other_ms: Option<f64>,
    age_frames_mean: Option<f64>,
    age_ms_median: Option<f64>,
    age_ms_p99: Option<f64>,
    input_to_consume_ms_median: Option<f64>,
    input_to_consume_ms_p99: Option<f64>,
    dropped: Option<u64>,
    repeated: Option<u64>,
    read_checksum: Option<u64>,
    frames: Option<usize>,
    seconds: Option<f64>,
    pinned: bool,
    preempted_percent: Option<f64>,
    steal_percent: Option<f64>,
    involuntary_switches: Option<u64>,
    noisy_trials: Option<usize>,
    retries: Option<usize>,
    calibrate: Option<Calibrate>,
    level_micros: Option<f64>,
    step_ms_at_start: Option<f64>,
    step_ms_in_row: Option<f64>,
    ns_per_iteration_at_start: Option<f64>,
    ns_per_iteration_in_row: Option<f64>,
    placement: Option<String>,
    trials_near: usize,
    trials_far: usize,
    trials_moved: usize,
    fps_near: Option<f64>,
    fps_far: Option<f64>,
    set_aside: usize,
    /// The workload kind's own counts and record, one column per key any cell has
    /// (`work_<key>_per_frame`, `work_<key>`), blank where this cell has none.
    #[serde(flatten)]
    work: serde_json::Map<String, serde_json::Value>,
    error: Option<&'a str>,
}

/// The work columns of a results table: each count's mean per frame, then each recorded value,
/// under every key any cell has.
struct WorkColumns {
    counts: Vec<String>,
    record: Vec<String>,
}

impl WorkColumns {
    fn of(results: &Results) -> WorkColumns {
        let summaries = || results.cells.iter().filter_map(|c| c.summary.as_ref());
        WorkColumns {
            counts: summaries()
                .flat_map(|s| s.work_trials.iter().flat_map(|t| &t.counts))
                .map(|c| c.key.clone())
                .unique()
                .collect(),
            record: results
                .cells
                .iter()
                .filter_map(|c| c.work.as_ref())
                .flat_map(|r| r.iter().map(|(k, _)| k.to_string()))
                .unique()
                .collect(),
        }
    }

    fn row(&self, cell: &Cell) -> serde_json::Map<String, serde_json::Value> {
        let trials = cell
            .summary
            .as_ref()
            .map_or(&[][..], |s| &s.work_trials[..]);
        let mut out = serde_json::Map::new();
        for key in &self.counts {
            let means: Vec<f64> = trials
                .iter()
                .filter_map(|t| t.count(key).map(|c| c.mean))
                .collect();
            let mean = (!means.is_empty()).then(|| stats::mean(&means));
            out.insert(format!("work_{key}_per_frame"), mean.into());
        }
        for key in &self.record {
            let value = cell.work.as_ref().and_then(|r| r.get(key));
            out.insert(format!("work_{key}"), value.into());
        }
        out
    }
}

impl<'a> CellRow<'a> {
    fn of(cell: &'a Cell, work: &WorkColumns) -> CellRow<'a> {
        let s = cell.summary.as_ref();
        let (noise, cal) = (cell.noise.as_ref(), cell.calibration.as_ref());
        let latency = s.and_then(|s| s.latency.as_ref());
        let mailbox = s.and_then(|s| s.mailbox.as_ref());
        let metrics = s.and_then(|s| s.frame_metrics.as_ref());
        let stat = |f: fn(&crate::summary::Summary) -> f64| s.map(f);
        let placed = CellPlacement::of(cell);
        let trials = |c: Class| placed.get(c).map_or(0, |t| t.trials);
        let fps = |c: Class| placed.get(c).map(|t| t.fps);
        CellRow {
            key: &cell.key,
            workload_iterations: cell.workload_iterations,
            workload_unit: cell.workload_unit(),
            workload_amount: cell.workload_amount(),
            fps: stat(|s| s.fps),
            fps_min: stat(|s| s.fps_spread.min),
            fps_max: stat(|s| s.fps_spread.max),
            fps_cv_percent: stat(|s| s.fps_spread.cv_percent),
            frame_ms_mean: stat(|s| s.frame_time_ms.mean),
            frame_ms_median: stat(|s| s.frame_time_ms.median),
            frame_ms_p99: stat(|s| s.frame_time_ms.p99),
            frame_ms_max: stat(|s| s.frame_time_ms.max),
            one_percent_low_fps: stat(|s| s.one_percent_low_fps),
            p1_fps: metrics.map(|m| m.p1_fps),
            one_percent_low_average_fps: metrics.map(|m| m.one_percent_low_average_fps),
            one_percent_low_integral_fps: metrics.map(|m| m.one_percent_low_integral_fps),
            p0_1_fps: metrics.map(|m| m.p0_1_fps),
            point_one_percent_low_average_fps: metrics.map(|m| m.point_one_percent_low_average_fps),
            point_one_percent_low_integral_fps: metrics
                .map(|m| m.point_one_percent_low_integral_fps),
            stutter_time_percent: metrics.map(|m| m.stutter_time_percent),
            workload_ms: stat(|s| s.breakdown.workload_ms),
            wait_ms: stat(|s| s.breakdown.wait_ms),
            wait_cpu_ms: stat(|s| s.breakdown.wait_cpu_ms),
            helper_wait_ms: stat(|s| s.breakdown.helper_wait_ms),
            helper_wait_cpu_ms: stat(|s| s.breakdown.helper_wait_cpu_ms),
            copy_ms: stat(|s| s.breakdown.copy_ms),
            step_ms: stat(|s| s.breakdown.step_ms),
            other_ms: stat(|s| s.breakdown.other_ms),
            age_frames_mean: latency.map(|l| l.age_frames_mean),
            age_ms_median: latency.map(|l| l.age_ms_median),
            age_ms_p99: latency.map(|l| l.age_ms_p99),
            input_to_consume_ms_median: latency.map(|l| l.input_to_consume_ms_median),
            input_to_consume_ms_p99: latency.map(|l| l.input_to_consume_ms_p99),
            dropped: mailbox.map(|m| m.dropped),
            repeated: mailbox.map(|m| m.repeated),
            read_checksum: s.and_then(|s| s.read_checksum),
            frames: s.map(|s| s.frames),
            seconds: stat(|s| s.seconds),
            pinned: cell.pinned,
            preempted_percent: noise.map(CellNoise::preempted_percent),
            steal_percent: noise.map(CellNoise::steal_percent),
            involuntary_switches: noise.map(CellNoise::involuntary_switches),
            noisy_trials: noise.map(CellNoise::noisy_trials),
            retries: noise.map(|n| n.retries),
            calibrate: cal.map(|c| c.calibrate),
            level_micros: cal.map(|c| c.level_micros),
            step_ms_at_start: cal.map(|c| c.step_ms_at_start),
            step_ms_in_row: cal.map(|c| c.step_ms_in_row),
            ns_per_iteration_at_start: cal.map(|c| c.ns_per_iteration_at_start),
            ns_per_iteration_in_row: cal.map(|c| c.ns_per_iteration_in_row),
            placement: match placed.only() {
                Some(c) => Some(c.to_string()),
                None if placed.mixed() => Some("mixed".into()),
                None => None,
            },
            trials_near: trials(Class::Near),
            trials_far: trials(Class::Far),
            trials_moved: trials(Class::Moved),
            fps_near: fps(Class::Near),
            fps_far: fps(Class::Far),
            set_aside: cell.set_aside.len(),
            work: work.row(cell),
            error: cell.error.as_deref(),
        }
    }
}

/// Why a CSV file could not be written.
#[derive(Debug, thiserror::Error)]
pub enum CsvError {
    /// The writer failed (I/O, or a record of another length than the header).
    #[error(transparent)]
    Csv(#[from] csv::Error),
    /// A row did not serialise to a flat object of scalars.
    #[error("a CSV row must be a flat object of scalars: {0}")]
    Shape(String),
}

/// Writes `rows` as CSV with a header of their field names. A row is serialised to a JSON
/// object first, because the csv crate cannot write `#[serde(flatten)]` fields; the object keeps
/// the fields in declaration order, and `null` is written as an empty field.
pub fn write<T: Serialize>(
    out: impl Write,
    rows: impl IntoIterator<Item = T>,
) -> Result<(), CsvError> {
    let mut w = csv::Writer::from_writer(out);
    let mut header_written = false;
    for row in rows {
        let serde_json::Value::Object(fields) =
            serde_json::to_value(&row).map_err(|e| CsvError::Shape(e.to_string()))?
        else {
            return Err(CsvError::Shape("not an object".into()));
        };
        if !header_written {
            w.write_record(fields.keys())?;
            header_written = true;
        }
        let mut record = Vec::with_capacity(fields.len());
        for (name, value) in fields {
            record.push(match value {
                serde_json::Value::Null => String::new(),
                serde_json::Value::String(s) => s,
                serde_json::Value::Bool(b) => b.to_string(),
                serde_json::Value::Number(n) => n.to_string(),
                _ => return Err(CsvError::Shape(format!("field `{name}` is not a scalar"))),
            });
        }
        w.write_record(&record)?;
    }
    w.flush().map_err(csv::Error::from)?;
    Ok(())
}

/// The results as CSV text: one row per cell.
pub fn to_string(results: &Results) -> Result<String, CsvError> {
    let work = WorkColumns::of(results);
    to_text(results.cells.iter().map(|c| CellRow::of(c, &work)))
}

/// One trial of a cell: the cell, the trial's FPS and breakdown, its canaries and round trips,
/// and for a slow trial what made it slow.
#[derive(Serialize)]
struct TrialRow<'a> {
    #[serde(flatten)]
    key: &'a CellKey,
    trial: usize,
    fps: f64,
    #[serde(flatten)]
    breakdown: &'a crate::summary::Breakdown,
    step_ratio: Option<f64>,
    workload_ratio: Option<f64>,
    round_trip_before_ns: Option<f64>,
    round_trip_after_ns: Option<f64>,
    taken_away: bool,
    slow_below_median_percent: Option<f64>,
    slow_causes: Option<String>,
    placement: Option<Class>,
}

/// Every trial of every cell as CSV (`trials.csv`), trials numbered from 1 in the order run.
pub fn trials(results: &Results) -> Result<String, CsvError> {
    let rows = results.cells.iter().flat_map(|c| {
        c.trials.iter().enumerate().map(move |(i, t)| TrialRow {
            key: &c.key,
            trial: i + 1,
            fps: t.fps,
            breakdown: &t.breakdown,
            step_ratio: t.step_ratio,
            workload_ratio: t.workload_ratio,
            round_trip_before_ns: t.round_trip_ns.map(|r| r[0]),
            round_trip_after_ns: t.round_trip_ns.map(|r| r[1]),
            taken_away: t.taken_away,
            slow_below_median_percent: t.slow.as_ref().map(|s| s.below_median_percent),
            slow_causes: t.slow.as_ref().map(|s| {
                let names: Vec<&str> = s.causes.iter().map(|c| c.name()).collect();
                names.join(" ")
            }),
            placement: t.placement,
        })
    });
    to_text(rows)
}

/// A balance point's bracket and ratios, as a search's headline or one placement's gives them.
#[derive(Serialize)]
struct Figures {
    balance_us: Option<f64>,
    balance_us_low: Option<f64>,
    balance_us_high: Option<f64>,
    balance_fraction: Option<f64>,
    dp_over_serial: Option<f64>,
    dp_over_serial_low: Option<f64>,
    dp_over_serial_high: Option<f64>,
    dp_over_up: Option<f64>,
    dp_over_up_low: Option<f64>,
    dp_over_up_high: Option<f64>,
}

impl Figures {
    fn of(
        bracket: [Option<f64>; 3],
        fraction: Option<f64>,
        serial: Option<Ratio>,
        up: Option<Ratio>,
    ) -> Figures {
        Figures {
            balance_us: bracket[0],
            balance_us_low: bracket[1],
            balance_us_high: bracket[2],
            balance_fraction: fraction,
            dp_over_serial: serial.map(|r| r.value),
            dp_over_serial_low: serial.map(|r| r.low),
            dp_over_serial_high: serial.map(|r| r.high),
            dp_over_up: up.map(|r| r.value),
            dp_over_up_low: up.map(|r| r.low),
            dp_over_up_high: up.map(|r| r.high),
        }
    }
}

/// One balance point: the searched cell, then what the search found.
#[derive(Serialize)]
struct BalanceRow<'a> {
    #[serde(flatten)]
    key: &'a CellKey,
    step_us: f64,
    #[serde(flatten)]
    figures: Figures,
    overhead_percent: Option<f64>,
    probes: usize,
    placement: Option<Class>,
    set_aside: usize,
    note: Option<&'a str>,
}

/// One probe of a balance search.
#[derive(Serialize)]
struct ProbeRow<'a> {
    #[serde(flatten)]
    key: &'a CellKey,
    step_us: f64,
    workload_us: f64,
    workload_over_step: f64,
    fps: f64,
    serial_fps: f64,
    up_fps: Option<f64>,
    over_serial: f64,
    main_wait_us: f64,
    helper_wait_us: f64,
    frame_ms: f64,
    probe_step_us: Option<f64>,
    round_trip_ns: Option<f64>,
    placement: Option<Class>,
}

/// The balance points as CSV: one row per searched cell.
pub fn balance(results: &Results) -> Result<String, CsvError> {
    let rows = results.balance.iter().map(|e| {
        let serial = e.dp_over_serial.map(|value| Ratio {
            value,
            low: e.dp_over_serial_low.unwrap_or(value),
            high: e.dp_over_serial_high.unwrap_or(value),
        });
        BalanceRow {
            key: &e.key,
            step_us: e.step_us,
            figures: Figures::of(
                [e.balance_us, e.balance_us_low, e.balance_us_high],
                e.fraction(),
                serial,
                e.dp_over_up,
            ),
            overhead_percent: e.overhead_percent,
            probes: e.probes.len(),
            placement: e.placement,
            set_aside: e.set_aside,
            note: e.note.as_deref(),
        }
    });
    to_text(rows)
}

/// Every probe of every balance search as CSV, means over the paired trials.
pub fn balance_probes(results: &Results) -> Result<String, CsvError> {
    let rows = results.balance.iter().flat_map(|e| {
        e.probes.iter().map(move |p| ProbeRow {
            key: &e.key,
            step_us: e.step_us,
            workload_us: p.workload_us,
            workload_over_step: p.workload_us / e.step_us,
            fps: stats::mean(&p.fps),
            serial_fps: stats::mean(&p.serial_fps),
            up_fps: (!p.up_fps.is_empty()).then(|| stats::mean(&p.up_fps)),
            over_serial: stats::mean(&p.fps) / stats::mean(&p.serial_fps),
            main_wait_us: stats::mean(&p.main_wait_us),
            helper_wait_us: stats::mean(&p.helper_wait_us),
            frame_ms: p.frame_ms,
            probe_step_us: p.step(),
            round_trip_ns: (!p.round_trip_ns.is_empty()).then(|| stats::median(&p.round_trip_ns)),
            placement: p.placement,
        })
    });
    to_text(rows)
}

/// One placement of one balance search: the figures of its probes alone.
#[derive(Serialize)]
struct PlacementRow<'a> {
    #[serde(flatten)]
    key: &'a CellKey,
    placement: Class,
    headline: bool,
    probes: usize,
    round_trip_ns_min: f64,
    round_trip_ns_max: f64,
    step_us: Option<f64>,
    #[serde(flatten)]
    figures: Figures,
}

/// Each balance search's figures per placement as CSV (`balance-placements.csv`).
pub fn balance_placements(results: &Results) -> Result<String, CsvError> {
    let rows = results.balance.iter().flat_map(|e| {
        e.placements.iter().map(move |p| PlacementRow {
            key: &e.key,
            placement: p.placement,
            headline: Some(p.placement) == e.placement,
            probes: p.probes,
            round_trip_ns_min: p.round_trip_ns[0],
            round_trip_ns_max: p.round_trip_ns[1],
            step_us: p.step_us,
            figures: Figures::of(
                [p.balance_us, p.balance_us_low, p.balance_us_high],
                p.fraction(),
                p.dp_over_serial,
                p.dp_over_up,
            ),
        })
    });
    to_text(rows)
}

fn to_text<T: Serialize>(rows: impl IntoIterator<Item = T>) -> Result<String, CsvError> {
    let mut out = Vec::new();
    write(&mut out, rows)?;
    Ok(String::from_utf8(out).expect("every field written is UTF-8"))
}

/// The CSV format: one row per cell (`results.csv`), per trial (`trials.csv`) and, with balance
/// points, per point, per probe and per placement.
pub struct Csv;

impl Exporter for Csv {
    fn export(&self, results: &Results) -> Result<Vec<Export>, ExportError> {
        let file = |name: &'static str, text: Result<String, CsvError>| {
            text.map(|text| Export { name, text })
                .map_err(|e| ExportError::of(name)(e.to_string()))
        };
        let mut files = Vec::new();
        if !results.cells.is_empty() {
            files.push(file("results.csv", to_string(results))?);
        }
        if results.cells.iter().any(|c| !c.trials.is_empty()) {
            files.push(file("trials.csv", trials(results))?);
        }
        if !results.balance.is_empty() {
            files.push(file("balance.csv", balance(results))?);
            files.push(file("balance-probes.csv", balance_probes(results))?);
            if results.balance.iter().any(|e| !e.placements.is_empty()) {
                files.push(file("balance-placements.csv", balance_placements(results))?);
            }
        }
        Ok(files)
    }
}
