//! Charts drawn from results files: Figure 5-1 and the views that explain it (DP ÷ UP, the
//! hand-off methods, frame-time percentiles, the per-frame breakdown), as PNG and SVG.
//!
//! Each chart is first built as plain data (`render::Chart`), then drawn once per format, so the
//! PNG and the SVG always show the same thing.

mod bars;
mod frames;
mod render;

use crate::frame_loop::{Mode, Threading};
use crate::measure::Summary;
use crate::ocean::{Kernel, NormalMethod};
use crate::results::{CellKey, Results};
use crate::sync::SyncMethod;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// An image format charts are written in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum ChartFormat {
    /// A PNG bitmap.
    Png,
    /// An SVG drawing.
    Svg,
}

impl ChartFormat {
    /// The file extension, without the dot.
    pub fn extension(self) -> &'static str {
        match self {
            ChartFormat::Png => "png",
            ChartFormat::Svg => "svg",
        }
    }
}

/// Why charts could not be written.
#[derive(Debug, thiserror::Error)]
pub enum ChartError {
    /// The output directory could not be created.
    #[error("chart directory {}: {source}", path.display())]
    Dir {
        /// The directory.
        path: PathBuf,
        /// What the OS said.
        source: std::io::Error,
    },
    /// The bundled font was rejected by the font loader.
    #[error("the bundled chart font could not be loaded")]
    Font,
    /// Drawing or writing one chart file failed.
    #[error("chart {}: {message}", path.display())]
    Draw {
        /// The file being written.
        path: PathBuf,
        /// What the drawing backend said.
        message: String,
    },
}

/// Every chart, by the file stem it is written under.
pub const CHARTS: [&str; 5] = ["figure-5-1", "relative", "sync", "frame-times", "breakdown"];

/// Chart width and height in pixels (the breakdown grows taller when it has many rows).
pub const CHART_SIZE: (u32, u32) = (1600, 900);

/// What to draw and which cell the single-cell charts (frame-times, breakdown) show.
#[derive(Clone, Debug, PartialEq)]
pub struct ChartOptions {
    /// Formats to write every chart in.
    pub formats: Vec<ChartFormat>,
    /// Mesh size for the single-cell charts; default the largest measured.
    pub size: Option<usize>,
    /// Workload for the single-cell charts; default the highest measured at that size.
    pub workload: Option<usize>,
}

impl Default for ChartOptions {
    fn default() -> Self {
        ChartOptions {
            formats: vec![ChartFormat::Png, ChartFormat::Svg],
            size: None,
            workload: None,
        }
    }
}

/// A chart that was not drawn, and why.
#[derive(Clone, Debug, PartialEq)]
pub struct Skipped {
    /// The chart's file stem, one of [`CHARTS`].
    pub chart: &'static str,
    /// Why it had nothing to show.
    pub reason: String,
}

/// What [`draw_with`] wrote and what it skipped.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Drawn {
    /// Every file written, in chart order then format order.
    pub files: Vec<PathBuf>,
    /// Charts with no data at all.
    pub skipped: Vec<Skipped>,
}

/// Draws every chart of `results` (several runs go side by side) into `out_dir` in each format.
pub fn draw(
    results: &[Results],
    out_dir: &Path,
    formats: &[ChartFormat],
) -> Result<Vec<PathBuf>, ChartError> {
    let options = ChartOptions {
        formats: formats.to_vec(),
        ..ChartOptions::default()
    };
    draw_with(results, out_dir, &options).map(|d| d.files)
}

/// Draws every chart as [`draw`] does, with a choice of cell, and also says what was skipped.
pub fn draw_with(
    results: &[Results],
    out_dir: &Path,
    options: &ChartOptions,
) -> Result<Drawn, ChartError> {
    render::register_font()?;
    std::fs::create_dir_all(out_dir).map_err(|source| ChartError::Dir {
        path: out_dir.to_path_buf(),
        source,
    })?;
    let runs = Runs::new(results);
    let focus = runs.focus(options.size, options.workload);
    let built = [
        bars::figure_5_1(&runs),
        bars::relative(&runs),
        bars::sync(&runs),
        frames::frame_times(&runs, focus),
        frames::breakdown(&runs, focus),
    ];
    let mut drawn = Drawn::default();
    for (name, chart) in CHARTS.into_iter().zip(built) {
        match chart {
            Ok(chart) => {
                for &format in &options.formats {
                    let path = out_dir.join(format!("{name}.{}", format.extension()));
                    render::write(&chart, &path, format)?;
                    drawn.files.push(path);
                }
            }
            Err(reason) => drawn.skipped.push(Skipped {
                chart: name,
                reason,
            }),
        }
    }
    Ok(drawn)
}

/// One results file and the name its series carry.
struct Run<'a> {
    label: String,
    results: &'a Results,
}

/// The results being charted, with what they have in common.
struct Runs<'a> {
    runs: Vec<Run<'a>>,
}

/// The hand-off, threading, normals and kernel a chart holds fixed.
#[derive(Clone, Copy, Debug)]
struct Variant {
    sync: SyncMethod,
    threading: Threading,
    normals: NormalMethod,
    kernel: Kernel,
}

impl Variant {
    fn key(&self, size: usize, workload: usize, mode: Mode, sync: SyncMethod) -> CellKey {
        let threaded = mode != Mode::Serial;
        CellKey {
            size,
            workload,
            mode,
            sync: threaded.then_some(sync),
            threading: threaded.then_some(self.threading),
            normals: self.normals,
            kernel: self.kernel,
            // Charts draw the single-helper cells; split-mesh cells are in the tables.
            helpers: 1,
        }
    }

    fn describe(&self, with_sync: bool) -> String {
        let sync = if with_sync {
            format!("{} hand-off, ", self.sync.name())
        } else {
            String::new()
        };
        format!(
            "{sync}{} helper, {} normals, {} kernel",
            self.threading.name(),
            self.normals.name(),
            self.kernel.name()
        )
    }
}

/// Cells a chart wanted and did not find, to say so under the chart.
#[derive(Default)]
struct Missing {
    items: Vec<String>,
}

impl Missing {
    fn add(&mut self, item: String) {
        if !self.items.contains(&item) {
            self.items.push(item);
        }
    }

    /// One note line, shortened so that a mostly empty run does not bury the chart.
    fn notes(&self) -> Vec<String> {
        const SHOWN: usize = 12;
        if self.items.is_empty() {
            return vec![];
        }
        let mut line = format!(
            "missing ({}): {}",
            self.items.len(),
            self.items
                .iter()
                .take(SHOWN)
                .cloned()
                .collect::<Vec<_>>()
                .join("; ")
        );
        if self.items.len() > SHOWN {
            line.push_str(&format!("; and {} more", self.items.len() - SHOWN));
        }
        vec![line]
    }
}

/// The display name of a mode, saying how many cores it uses.
fn mode_name(mode: Mode) -> &'static str {
    match mode {
        Mode::Serial => "serial",
        Mode::Up => "UP (1 core)",
        Mode::Dp => "DP (2 cores)",
    }
}

fn short_mode(mode: Mode) -> &'static str {
    match mode {
        Mode::Serial => "serial",
        Mode::Up => "UP",
        Mode::Dp => "DP",
    }
}

/// `2026-11-22T02:17:33Z` as `2026-11-22 02:17 UTC`; other text is shown as it is.
fn run_date(started: &str) -> String {
    match started.get(..16) {
        Some(day_time) if started.ends_with('Z') => format!("{} UTC", day_time.replace('T', " ")),
        _ => started.to_string(),
    }
}

/// First item of `order` that `present` accepts.
fn first_present<T: Copy>(
    order: impl IntoIterator<Item = T>,
    present: impl Fn(T) -> bool,
) -> Option<T> {
    order.into_iter().find(|&t| present(t))
}

impl<'a> Runs<'a> {
    fn new(results: &'a [Results]) -> Runs<'a> {
        let names: Vec<String> = results.iter().map(|r| r.config.name.clone()).collect();
        let unique = |labels: &[String]| {
            labels
                .iter()
                .enumerate()
                .all(|(i, l)| !labels[..i].contains(l))
        };
        // Runs are told apart by name; the machine is added only when names collide, and a
        // number only when that is not enough either.
        let labels = if unique(&names) {
            names
        } else {
            let with_machine: Vec<String> = results
                .iter()
                .map(|r| format!("{} on {}", r.config.name, r.machine.cpu_model))
                .collect();
            if unique(&with_machine) {
                with_machine
            } else {
                names
                    .iter()
                    .enumerate()
                    .map(|(i, n)| format!("{n} #{}", i + 1))
                    .collect()
            }
        };
        Runs {
            runs: labels
                .into_iter()
                .zip(results)
                .map(|(label, results)| Run { label, results })
                .collect(),
        }
    }

    fn multi(&self) -> bool {
        self.runs.len() > 1
    }

    /// A series name, prefixed with the run when several runs share the chart.
    fn series(&self, run: &Run, name: &str) -> String {
        if self.multi() {
            format!("{}: {name}", run.label)
        } else {
            name.to_string()
        }
    }

    /// The subtitle lines naming each machine and the date of each run.
    fn machine_lines(&self) -> Vec<String> {
        self.runs
            .iter()
            .map(|run| {
                let r = run.results;
                let line = format!(
                    "{} · run \"{}\" started {}",
                    r.machine.line(),
                    r.config.name,
                    run_date(&r.started)
                );
                if self.multi() {
                    format!("{}: {line}", run.label)
                } else {
                    line
                }
            })
            .collect()
    }

    fn keys(&self) -> impl Iterator<Item = &CellKey> {
        self.runs
            .iter()
            .flat_map(|r| r.results.cells.iter().map(|c| &c.key))
    }

    fn sizes(&self) -> Vec<usize> {
        let mut v: Vec<usize> = self
            .runs
            .iter()
            .flat_map(|r| r.results.config.sizes.iter().copied())
            .chain(self.keys().map(|k| k.size))
            .collect();
        v.sort_unstable();
        v.dedup();
        v
    }

    fn workloads(&self) -> Vec<usize> {
        let mut v: Vec<usize> = self
            .runs
            .iter()
            .flat_map(|r| r.results.config.workloads.iter().copied())
            .chain(self.keys().map(|k| k.workload))
            .collect();
        v.sort_unstable();
        v.dedup();
        v
    }

    fn modes(&self) -> Vec<Mode> {
        [Mode::Serial, Mode::Up, Mode::Dp]
            .into_iter()
            .filter(|&m| {
                self.keys().any(|k| k.mode == m)
                    || self
                        .runs
                        .iter()
                        .any(|r| r.results.config.modes.contains(&m))
            })
            .collect()
    }

    fn syncs(&self) -> Vec<SyncMethod> {
        SyncMethod::ALL
            .into_iter()
            .filter(|&s| {
                self.keys().any(|k| k.sync == Some(s))
                    || self.runs.iter().any(|r| r.results.config.sync.contains(&s))
            })
            .collect()
    }

    /// The first hand-off, normals and kernel present (in config order), and pool threading
    /// when it was measured, as Figure 5-1 uses the paper's thread pool.
    fn variant(&self) -> Option<Variant> {
        let configs = || self.runs.iter().map(|r| &r.results.config);
        let sync = first_present(
            configs()
                .flat_map(|c| c.sync.iter().copied())
                .chain(SyncMethod::ALL),
            |s| self.keys().any(|k| k.sync == Some(s)),
        )
        .unwrap_or(SyncMethod::ALL[0]);
        let threading = first_present([Threading::Pool, Threading::Spawn], |t| {
            self.keys().any(|k| k.threading == Some(t))
        })
        .unwrap_or(Threading::Pool);
        let normals = first_present(
            configs()
                .flat_map(|c| c.normals.iter().copied())
                .chain(self.keys().map(|k| k.normals)),
            |n| self.keys().any(|k| k.normals == n),
        )?;
        let kernel = first_present(
            configs()
                .flat_map(|c| c.kernel.iter().copied())
                .chain(self.keys().map(|k| k.kernel)),
            |n| self.keys().any(|k| k.kernel == n),
        )?;
        Some(Variant {
            sync,
            threading,
            normals,
            kernel,
        })
    }

    /// The cell of the single-cell charts: the largest size with a measured cell, at its highest
    /// measured workload, unless asked otherwise.
    fn focus(&self, size: Option<usize>, workload: Option<usize>) -> Option<(usize, usize)> {
        let measured = || {
            self.runs
                .iter()
                .flat_map(|r| &r.results.cells)
                .filter(|c| c.summary.is_some())
                .map(|c| &c.key)
        };
        let size = size.or_else(|| measured().map(|k| k.size).max())?;
        let workload = workload.or_else(|| {
            measured()
                .filter(|k| k.size == size)
                .map(|k| k.workload)
                .max()
        })?;
        Some((size, workload))
    }

    /// The summary of `key` in `run`, noting it as missing (or failed) when there is none.
    fn summary(&self, run: &Run<'a>, key: &CellKey, missing: &mut Missing) -> Option<&'a Summary> {
        let cell = run.results.cell(key);
        let what = match cell {
            Some(c) if c.summary.is_some() => return c.summary.as_ref(),
            Some(_) => "failed",
            None => "not measured",
        };
        let mut label = format!(
            "{0}×{0} w{1} {2}",
            key.size,
            key.workload,
            short_mode(key.mode)
        );
        if let Some(s) = key.sync {
            label.push(' ');
            label.push_str(s.name());
        }
        let label = self.series(run, &label);
        missing.add(if what == "failed" {
            format!("{label} (failed)")
        } else {
            label
        });
        None
    }
}
