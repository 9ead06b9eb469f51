//! The tidy CSV: one row per cell, one column per parameter or statistic.

use crate::results::{Cell, Results};
use std::fmt::Write;

/// The CSV header.
pub const HEADER: &str = "size,workload,mode,sync,threading,normals,kernel,workload_iterations,\
fps,fps_min,fps_max,fps_cv_percent,frame_ms_mean,frame_ms_median,frame_ms_p99,frame_ms_max,\
one_percent_low_fps,workload_ms,wait_ms,copy_ms,step_ms,frames,seconds,pinned,error";

/// The results as CSV text.
pub fn to_string(results: &Results) -> String {
    let mut out = String::from(HEADER);
    out.push('\n');
    for cell in &results.cells {
        row(&mut out, cell);
    }
    out
}

fn row(out: &mut String, cell: &Cell) {
    let k = &cell.key;
    let _ = write!(
        out,
        "{},{},{},{},{},{},{},{}",
        k.size,
        k.workload,
        k.mode.name(),
        k.sync.map_or("", |s| s.name()),
        k.threading.map_or("", |t| t.name()),
        k.normals.name(),
        k.kernel.name(),
        cell.workload_iterations
    );
    match &cell.summary {
        Some(s) => {
            let _ = write!(
                out,
                ",{:.3},{:.3},{:.3},{:.2},{:.6},{:.6},{:.6},{:.6},{:.3},{:.6},{:.6},{:.6},{:.6},{},{:.4}",
                s.fps,
                s.fps_spread.min,
                s.fps_spread.max,
                s.fps_spread.cv_percent,
                s.frame_time_ms.mean,
                s.frame_time_ms.median,
                s.frame_time_ms.p99,
                s.frame_time_ms.max,
                s.one_percent_low_fps,
                s.breakdown.workload_ms,
                s.breakdown.wait_ms,
                s.breakdown.copy_ms,
                s.breakdown.step_ms,
                s.frames,
                s.seconds
            );
        }
        None => out.push_str(&",".repeat(15)),
    }
    let error = cell.error.as_deref().unwrap_or("").replace('"', "'");
    let _ = writeln!(out, ",{},\"{}\"", cell.pinned, error);
}
