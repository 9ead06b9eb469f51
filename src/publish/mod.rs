//! Published numbers: every measured number in README.md and docs/*.md sits in a generated
//! block ([`blocks`]) that names its committed run, and `oceanbench docs --write` rewrites it
//! from that run (`--check` fails when a block and its run disagree). Constants quoted from the
//! code sit in `const` blocks ([`consts`]), so they are checked against the code the same way.
//!
//! The kinds of block:
//! - `table run=R [slice=k=v,...] [findings=yes]`: a Figure 5-1 table of one slice, with its
//!   source line (and the slice's findings after it);
//! - `findings run=R [id=..] [slice=..] [size=N]`: findings sentences (a list, or one inline);
//! - `value run=R cell=LABEL [stat=..] [digits=N]`: one cell's number, with its marks;
//! - `figure run=R finding=ID name=NAME [slice=..] [size=N] [digits=N]`: a finding's number;
//! - `source run=R`: where a run was made (machine, commit and tree, round trip, placement);
//! - `levels run=R`: its workload levels;
//! - `const name=NAME`: a constant of the code;
//! - `ref name=NAME`: a number quoted from outside the project, kept with its source in
//!   `docs/references.json` ([`refs`]);
//! - `grid run=R rows=".." cols=".."`: a table of one stat of many cells (`grid.rs`);
//! - `config file=configs/F.json key=K`: a value of a committed config (`key` a dotted path,
//!   with indexes for lists; a list renders as `a, b, c`);
//! - `bench run=bench-... [id=ID [over=ID]] [ids=PREFIX,...]`: a benchmark run's estimates;
//! - `latency run=latency-... [method=M cores=one|two [stat=..] [over=M2] [unit=..] [digits=N]]`:
//!   a latency run's round-trip table, or one number of it (`latency.rs`);
//! - `compare run=BASE new=NEW [placement=P] [threshold=T]`: `oceanbench compare`'s verdict
//!   counts for the two runs and its exit status.

mod bench;
pub mod blocks;
pub mod consts;
mod grid;
mod latency;
pub mod loose;
pub mod refs;

use crate::cell::Dim;
use crate::findings::{self, Finding, Findings, Slice};
use crate::report::markdown;
use crate::results::{Cell, Results};
use crate::stats;
use blocks::Block;
use std::collections::HashMap;
use std::fmt::Write;
use std::path::{Path, PathBuf};

/// The files whose numbers are published: README.md and every docs/*.md.
pub fn files(root: &Path) -> std::io::Result<Vec<PathBuf>> {
    let mut out = vec![root.join("README.md")];
    let mut docs: Vec<PathBuf> = std::fs::read_dir(root.join("docs"))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "md"))
        .collect();
    docs.sort();
    out.extend(docs);
    Ok(out)
}

/// What a block needs: the checkout's root and the runs read so far.
pub struct Context {
    root: PathBuf,
    runs: HashMap<String, (Results, Findings)>,
}

/// Why a block cannot be generated (a bad block: `docs --check` exits 2).
pub type BlockError = String;

impl Context {
    /// A context reading runs under `root/results/`.
    pub fn new(root: &Path) -> Context {
        Context {
            root: root.to_path_buf(),
            runs: HashMap::new(),
        }
    }

    fn run(&mut self, block: &Block) -> Result<(&str, &Results, &Findings), BlockError> {
        let name = run_name(block)?.to_string();
        self.run_named(name)
    }

    fn run_named(&mut self, name: String) -> Result<(&str, &Results, &Findings), BlockError> {
        if !self.runs.contains_key(&name) {
            let path = self.root.join("results").join(&name);
            if !path.join("results.json").is_file() {
                return Err(format!(
                    "run `{name}` does not exist (no results/{name}/results.json)"
                ));
            }
            let mut results = Results::load(&path).map_err(|e| e.to_string())?;
            crate::findings::placement::label(&mut results);
            if let Some(why) = refused(&results) {
                return Err(format!("run `{name}` {why}"));
            }
            let found = findings::of(&results);
            self.runs.insert(name.clone(), (results, found));
        }
        let (key, (results, found)) = self.runs.get_key_value(&name).expect("inserted above");
        Ok((key.as_str(), results, found))
    }

    /// The generated text of `block` in the file at `file`.
    pub fn render(&mut self, file: &Path, block: &Block) -> Result<String, BlockError> {
        let known: &[&str] = match block.kind.as_str() {
            "table" => &["run", "slice", "findings"],
            "findings" => &["run", "id", "slice", "size"],
            "value" => &["run", "cell", "stat", "digits", "over"],
            "grid" => &["run", "head", "rows", "cols", "gaps"],
            "figure" => &["run", "finding", "name", "slice", "size", "digits"],
            "source" | "levels" => &["run"],
            "const" => &["name"],
            "config" => &["file", "key"],
            "ref" => &["name"],
            "bench" => &["run", "id", "over", "per", "ids"],
            "latency" => &["run", "method", "cores", "stat", "over", "unit", "digits"],
            "compare" => &["run", "new", "placement", "threshold"],
            other => {
                return Err(format!(
                    "unknown block kind `{other}` (allowed: table, findings, value, grid, figure, source, levels, const, config, ref, bench, latency, compare)"
                ))
            }
        };
        if let Some((k, _)) = block
            .attrs
            .iter()
            .find(|(k, _)| !known.contains(&k.as_str()))
        {
            return Err(format!(
                "`{}` takes no attribute `{k}` (allowed: {})",
                block.kind,
                known.join(", ")
            ));
        }
        if block.kind == "const" {
            let name = block.attr("name").ok_or("`const` needs name=NAME")?;
            return consts::value(name);
        }
        if block.kind == "ref" {
            return refs::render(&self.root, block);
        }
        if block.kind == "config" {
            return consts::config_value(&self.root, block);
        }
        let link = self.link(file, block)?;
        if block.kind == "bench" {
            return bench::render(&self.root, block, &link);
        }
        if block.kind == "latency" {
            return latency::render(&self.root, block, &link);
        }
        if block.kind == "compare" {
            return self.compare(block);
        }
        let multiline = block.multiline;
        let (_, results, found) = self.run(block)?;
        let unknown = tree_unknown(results);
        match block.kind.as_str() {
            "table" => {
                let mut out = table(results, block, &link)?;
                match block.attr("findings") {
                    None | Some("no") => {}
                    Some("yes") => {
                        out.push_str("\nWhat the run shows (`oceanbench findings`):\n\n");
                        for f in choose(found, block)? {
                            let _ = writeln!(out, "- {}", f.sentence);
                        }
                    }
                    Some(other) => return Err(format!("findings: `{other}` is not yes or no")),
                }
                Ok(out)
            }
            "findings" => {
                let chosen = choose(found, block)?;
                if multiline {
                    let mut out = source(results, &link);
                    out.push('\n');
                    for f in chosen {
                        let _ = writeln!(out, "- {}", f.sentence);
                    }
                    Ok(out)
                } else if chosen.len() == 1 {
                    let sentence = chosen[0].sentence.trim_end_matches('.');
                    // A sentence that ends with its caveats takes the run's qualifier into
                    // the same parenthesis: `(no per-trial records; tree unknown)`.
                    let ends_with_caveats = sentence.strip_suffix(')').is_some_and(|s| {
                        s.rsplit_once('(').is_some_and(|(_, last)| {
                            last.split("; ").any(|part| {
                                chosen[0]
                                    .figures
                                    .iter()
                                    .any(|f| f.caveats.iter().any(|c| c == part))
                            })
                        })
                    });
                    match unknown {
                        Some(note) if ends_with_caveats => Ok(format!(
                            "{}; {note})",
                            sentence.strip_suffix(')').unwrap_or(sentence)
                        )),
                        _ => Ok(qualified(sentence.to_string(), &[unknown])),
                    }
                } else {
                    Err(format!(
                        "an inline `findings` span must choose one finding; {} match (add id=, slice= or size=)",
                        chosen.len()
                    ))
                }
            }
            "value" => value(results, block),
            "grid" => grid::render(results, block, &link),
            "figure" => {
                let chosen = choose(found, block)?;
                let name = block.attr("name").ok_or("`figure` needs name=NAME")?;
                let [f] = chosen.as_slice() else {
                    return Err(format!(
                        "`figure` must choose one finding; {} match (add slice= or size=)",
                        chosen.len()
                    ));
                };
                let fig = f.figures.iter().find(|g| g.name == name).ok_or_else(|| {
                    format!(
                        "finding `{}` has no figure `{name}` (it has: {})",
                        f.id,
                        f.figures
                            .iter()
                            .map(|g| g.name.as_str())
                            .collect::<Vec<_>>()
                            .join(", ")
                    )
                })?;
                let digits = digits(block, if fig.value >= 100.0 { 0 } else { 2 })?;
                let marks = if fig.caveats.is_empty() { "" } else { "*" };
                Ok(qualified(
                    format!("{:.digits$}{marks}", fig.value),
                    &[unknown],
                ))
            }
            "source" => Ok(source(results, &link)),
            "levels" => Ok(markdown::levels(results)),
            _ => unreachable!("kinds are checked above"),
        }
    }

    /// A `compare` block: `oceanbench compare RUN NEW [--placement P] [--threshold T]`'s
    /// summary line, then what its exit status would be.
    fn compare(&mut self, block: &Block) -> Result<String, BlockError> {
        let new_name = block
            .attr("new")
            .ok_or("`compare` needs new=NAME (the run compared against run=)")?
            .trim_end_matches('/')
            .trim_start_matches("results/")
            .to_string();
        let placement = block
            .attr("placement")
            .map(|p| {
                <crate::placement::Class as clap::ValueEnum>::from_str(p, false)
                    .map_err(|_| format!("placement: `{p}` is not one, near, far or moved"))
            })
            .transpose()?;
        let threshold = match block.attr("threshold") {
            None => crate::report::compare::DEFAULT_THRESHOLD_PCT,
            Some(t) => t
                .parse::<f64>()
                .ok()
                .filter(|t| t.is_finite() && *t >= 0.0)
                .ok_or_else(|| format!("threshold: `{t}` is not a percentage >= 0"))?,
        };
        let placed = |r: &Results| match placement {
            Some(class) => r.in_placement(class),
            None => r.clone(),
        };
        let (base, base_unknown) = {
            let (_, r, _) = self.run(block)?;
            (placed(r), tree_unknown(r))
        };
        let (new, new_unknown) = {
            let (_, r, _) = self.run_named(new_name)?;
            (placed(r), tree_unknown(r))
        };
        let c = crate::report::compare::between(
            &base,
            &new,
            threshold,
            crate::report::compare::Metric::Fps,
        );
        if let Some(why) = c.nothing_compared() {
            return Err(format!("compare: {why}"));
        }
        let exit = if c.regressed() { 1 } else { 0 };
        Ok(qualified(
            format!("{}, exit {exit}", c.summary_line()),
            &[base_unknown.or(new_unknown)],
        ))
    }

    /// The relative link from `file` to the block's run folder.
    fn link(&self, file: &Path, block: &Block) -> Result<String, BlockError> {
        let name = run_name(block).unwrap_or_default();
        let depth = file
            .parent()
            .and_then(|p| p.strip_prefix(&self.root).ok())
            .map_or(0, |p| p.components().count());
        Ok(format!("{}results/{name}/", "../".repeat(depth)))
    }
}

/// The folder under results/ a block's `run=` names (`results/` and a trailing `/` allowed).
fn run_name(block: &Block) -> Result<&str, BlockError> {
    Ok(block
        .attr("run")
        .ok_or_else(|| format!("`{}` needs run=NAME (a folder of results/)", block.kind))?
        .trim_end_matches('/')
        .trim_start_matches("results/"))
}

/// Why a run cannot be cited at all: it was made from a tree with uncommitted changes.
fn refused(results: &Results) -> Option<String> {
    match results.machine.tree() {
        crate::machine::Tree::Dirty { diff_hash } => Some(format!(
            "was made from a dirty tree (uncommitted changes, diff {diff_hash}): re-run it from a commit"
        )),
        _ => None,
    }
}

/// What a number from a run recorded before the dirty flag carries beside it.
fn tree_unknown(results: &Results) -> Option<&'static str> {
    matches!(results.machine.tree(), crate::machine::Tree::Unknown).then_some("tree unknown")
}

/// One line naming where a run was made: its folder, machine, commit and tree, round trip and
/// placement, and what the marks mean.
pub fn source(results: &Results, link: &str) -> String {
    let m = &results.machine;
    let mut out = format!(
        "Run [`{}`]({link}) (`{}`): {}, {} logical cores, {}; {}",
        link.trim_end_matches('/')
            .rsplit('/')
            .next()
            .unwrap_or(link),
        results.config.name,
        m.cpu_model,
        m.logical_cores,
        m.os,
        m.provenance_line()
    );
    // The placement line names the round trips; a run without one names them alone.
    if let Some(line) = markdown::placement_line(results) {
        let _ = write!(out, "; placement: {line}");
    } else {
        let rts: Vec<f64> = crate::findings::placement::round_trips(results);
        if !rts.is_empty() {
            let (lo, hi) = stats::min_max(&rts);
            let _ = write!(out, "; cross-core round trip {lo:.0}-{hi:.0} ns");
        }
    }
    out.push_str(". ");
    out.push_str(MARKS);
    out.push('\n');
    out
}

/// The legend every generated table and list carries.
const MARKS: &str = "† a kept trial was disturbed beyond the noise threshold, ‡ a slow trial nothing recorded explains, § trials in more than one placement.";

/// `slice=k=v,k=v` as pairs.
fn slice_filter(block: &Block) -> Result<Vec<(String, String)>, BlockError> {
    let Some(text) = block.attr("slice") else {
        return Ok(Vec::new());
    };
    text.split(',')
        .map(|kv| {
            let (k, v) = kv
                .split_once('=')
                .ok_or_else(|| format!("slice: `{kv}` is not key=value"))?;
            let k = k.trim();
            if !Dim::ALL.iter().any(|d| d.config_key() == k) {
                return Err(format!(
                    "slice: `{k}` is no dimension (allowed: {})",
                    Dim::ALL
                        .iter()
                        .map(|d| d.config_key())
                        .collect::<Vec<_>>()
                        .join(", ")
                ));
            }
            Ok((k.to_string(), v.trim().to_string()))
        })
        .collect()
}

fn size_filter(block: &Block) -> Result<Option<usize>, BlockError> {
    block
        .attr("size")
        .map(|s| {
            s.parse()
                .map_err(|_| format!("size: `{s}` is not a whole number"))
        })
        .transpose()
}

fn digits(block: &Block, default: usize) -> Result<usize, BlockError> {
    match block.attr("digits") {
        None => Ok(default),
        Some(d) => d
            .parse::<usize>()
            .ok()
            .filter(|&d| d <= 6)
            .ok_or_else(|| format!("digits: `{d}` is not 0 to 6")),
    }
}

/// The findings a block chooses by id, slice and size.
fn choose<'a>(found: &'a Findings, block: &Block) -> Result<Vec<&'a Finding>, BlockError> {
    let filter = slice_filter(block)?;
    let size = size_filter(block)?;
    let id = block.attr("id").or(block.attr("finding"));
    let chosen: Vec<&Finding> = found
        .findings
        .iter()
        .filter(|f| id.is_none_or(|id| f.id == id))
        .filter(|f| f.slice.matches(&filter))
        .filter(|f| size.is_none_or(|n| f.size == Some(n)))
        .collect();
    if chosen.is_empty() {
        let ids: Vec<&str> = found.findings.iter().map(|f| f.id.as_str()).collect();
        return Err(format!(
            "no finding of the run matches (its findings: {})",
            dedup(ids).join(", ")
        ));
    }
    Ok(chosen)
}

fn dedup(mut v: Vec<&str>) -> Vec<&str> {
    let mut seen = Vec::new();
    v.retain(|x| {
        let new = !seen.contains(x);
        seen.push(*x);
        new
    });
    v
}

/// The Figure 5-1 table of the slice the block names.
fn table(results: &Results, block: &Block, link: &str) -> Result<String, BlockError> {
    let filter = slice_filter(block)?;
    let tables = markdown::fps_tables_of(results);
    let chosen: Vec<_> = tables
        .iter()
        .filter(|(slice, _)| slice.matches(&filter))
        .collect();
    let [(_, t)] = chosen.as_slice() else {
        let slices: Vec<String> = tables.iter().map(|(s, _)| slice_text(s)).collect();
        return Err(format!(
            "slice={} matches {} tables of the run (its slices: {})",
            block.attr("slice").unwrap_or(""),
            chosen.len(),
            slices.join("; ")
        ));
    };
    let mut out = source(results, link);
    out.push('\n');
    let md = t.to_markdown();
    // The heading becomes a caption: a generated block sits inside the page's own sections.
    let body = md.strip_prefix("### ").unwrap_or(&md);
    let (title, rest) = body.split_once('\n').unwrap_or((body, ""));
    let _ = writeln!(out, "{title}:");
    out.push_str(rest.trim_end());
    out.push('\n');
    Ok(out)
}

fn slice_text(s: &Slice) -> String {
    if s.values.is_empty() {
        return "(one slice: no slice= needed)".into();
    }
    s.values
        .iter()
        .map(|(k, v)| format!("{k}={v}"))
        .collect::<Vec<_>>()
        .join(",")
}

/// One cell's number, or the range of several cells' (`cell="A;B;C"` gives `lo-hi`): `fps` (all
/// frames ÷ all seconds, as the tables), `median` (median trial), `cv` (% spread), `spread`
/// ((max − min) ÷ median, %), `one_percent_low`, `step_ms`, `workload_ms`, `copy_ms`,
/// `wait_ms` (the frame's breakdown, ms), `frame_ms`, `frame_us`,
/// `wait_cpu_ms`, `wait_cpu_us` (every thread), `main_wait_cpu_us`, `helper_wait_cpu_us`,
/// `repeated_percent` (frames that re-showed a mesh, `latest`), or
/// a ratio of median trials against its twin: `dp_over_up`, `dp_over_serial`, `up_over_serial`.
/// With `over="C;D"`, each number is divided by the same stat of the matching cell. The
/// cells' marks (†, ‡, §) follow it.
fn value(results: &Results, block: &Block) -> Result<String, BlockError> {
    let (text, bare) = value_text(results, block)?;
    Ok(qualified(
        text,
        &[tree_unknown(results), bare.then_some("no trial records")],
    ))
}

/// A `value` block's number with its marks, and whether a cell it read has no trial records.
fn value_text(results: &Results, block: &Block) -> Result<(String, bool), BlockError> {
    let labels = block.attr("cell").ok_or("`value` needs cell=LABEL")?;
    let stat = block.attr("stat").unwrap_or("fps");
    let mut numbers = Vec::new();
    let mut involved: Vec<&Cell> = Vec::new();
    let mut default_digits = 0;
    // `over="C;D"`: each cell's number divided by the same stat of the matching cell, for
    // comparisons across a dimension no twin covers (a grid, a kind).
    let over: Vec<&str> = block
        .attr("over")
        .map_or(Vec::new(), |o| o.split(';').map(str::trim).collect());
    let count = labels.split(';').count();
    if !over.is_empty() && over.len() != count {
        return Err(format!(
            "over= names {} cell(s) and cell= {count}: one each",
            over.len()
        ));
    }
    let find = |label: &str| -> Result<&Cell, BlockError> {
        results
            .cells
            .iter()
            .find(|c| c.key.label() == label)
            .ok_or_else(|| {
                format!(
                    "the run has no cell `{label}` (its cells look like `{}`)",
                    results
                        .cells
                        .first()
                        .map(|c| c.key.label())
                        .unwrap_or_default()
                )
            })
    };
    for (i, label) in labels.split(';').map(str::trim).enumerate() {
        let cell = find(label)?;
        let (mut number, mut digits, others) = stat_of(results, cell, stat)?;
        if let Some(base_label) = over.get(i) {
            let base = find(base_label)?;
            let (base_number, _, base_others) = stat_of(results, base, stat)?;
            number /= base_number;
            digits = 2;
            involved.push(base);
            involved.extend(base_others);
        }
        numbers.push(number);
        default_digits = digits;
        involved.push(cell);
        involved.extend(others);
    }
    let digits = digits(block, default_digits)?;
    let (lo, hi) = stats::min_max(&numbers);
    let (lo, hi) = (format!("{lo:.digits$}"), format!("{hi:.digits$}"));
    let text = if lo == hi { lo } else { format!("{lo}-{hi}") };
    let mut marks = String::new();
    for c in &involved {
        for (on, mark) in [
            (c.noisy(), markdown::NOISY),
            (c.unexplained_slow_trials() > 0, markdown::UNEXPLAINED),
            (c.mixed_placements(), markdown::MIXED),
        ] {
            if on && !marks.contains(mark) {
                marks.push_str(mark);
            }
        }
    }
    let bare = involved.iter().any(|c| c.trials.is_empty());
    Ok((format!("{text}{marks}"), bare))
}

/// A number with what qualifies it in one parenthesis: `831† (tree unknown; no trial records)`.
fn qualified(number: String, notes: &[Option<&str>]) -> String {
    let notes: Vec<&str> = notes.iter().flatten().copied().collect();
    if notes.is_empty() {
        number
    } else {
        format!("{number} ({})", notes.join("; "))
    }
}

/// A cell's `stat` (see [`value`]), its default digits, and the other cells it read.
fn stat_of<'a>(
    results: &'a Results,
    cell: &'a Cell,
    stat: &str,
) -> Result<(f64, usize, Vec<&'a Cell>), BlockError> {
    use crate::cell::DimValue;
    use crate::frame_loop::Mode;
    let label = cell.key.label();
    let s = cell
        .summary
        .as_ref()
        .ok_or_else(|| format!("cell `{label}` failed: no number"))?;
    let frame_ms = s.seconds / s.frames as f64 * 1e3;
    Ok(match stat {
        "fps" => (s.fps, 0, vec![]),
        "median" => (s.median_trial_fps(), 0, vec![]),
        "cv" => (s.fps_spread.cv_percent, 1, vec![]),
        "spread" => (
            (s.fps_spread.max - s.fps_spread.min) / s.median_trial_fps() * 100.0,
            0,
            vec![],
        ),
        "one_percent_low" => (s.one_percent_low_fps, 0, vec![]),
        "step_ms" => (s.breakdown.step_ms, 2, vec![]),
        "workload_ms" => (s.breakdown.workload_ms, 2, vec![]),
        "copy_ms" => (s.breakdown.copy_ms, 3, vec![]),
        "wait_ms" => (s.breakdown.wait_ms, 3, vec![]),
        "frame_ms" => (frame_ms, 2, vec![]),
        "frame_us" => (frame_ms * 1e3, 1, vec![]),
        "wait_cpu_ms" => (s.breakdown.wait_cpu_ms(), 3, vec![]),
        "wait_cpu_us" => (s.breakdown.wait_cpu_ms() * 1e3, 0, vec![]),
        "main_wait_cpu_us" => (s.breakdown.wait_cpu_ms * 1e3, 0, vec![]),
        "helper_wait_cpu_us" => (s.breakdown.helper_wait_cpu_ms * 1e3, 0, vec![]),
        "repeated_percent" => {
            let m = s
                .mailbox
                .as_ref()
                .ok_or_else(|| format!("cell `{label}` is no `latest` cell: nothing re-shown"))?;
            (m.repeated as f64 / s.frames as f64 * 100.0, 0, vec![])
        }
        "dp_over_up" | "dp_over_serial" | "up_over_serial" => {
            let (mode, over) = match stat {
                "dp_over_up" => (Mode::Dp, Mode::Up),
                "dp_over_serial" => (Mode::Dp, Mode::Serial),
                _ => (Mode::Up, Mode::Serial),
            };
            if cell.key.mode != mode {
                return Err(format!(
                    "stat={stat} needs a {mode} cell; `{label}` is {}",
                    cell.key.mode
                ));
            }
            let base = cell
                .key
                .with(Dim::Mode, over.value())
                .and_then(|k| results.cell(&k))
                .filter(|c| c.summary.is_some())
                .ok_or_else(|| format!("cell `{label}` has no {over} twin in the run"))?;
            let base_fps = base.summary.as_ref().map_or(f64::NAN, |b| b.median_trial_fps());
            (s.median_trial_fps() / base_fps, 2, vec![base])
        }
        other => {
            return Err(format!(
                "stat: unknown `{other}` (allowed: fps, median, cv, spread, one_percent_low, step_ms, workload_ms, copy_ms, wait_ms, frame_ms, frame_us, wait_cpu_ms, wait_cpu_us, main_wait_cpu_us, helper_wait_cpu_us, repeated_percent, dp_over_up, dp_over_serial, up_over_serial)"
            ))
        }
    })
}

/// What `check` and `write` found in one file.
#[derive(Debug, Default)]
pub struct FileOutcome {
    /// The file's text with every block regenerated.
    pub text: String,
    /// Blocks whose text differs from what their run gives (1-based lines).
    pub stale: Vec<usize>,
}

/// Regenerates every block of `file`; a bad block is an error naming the file and line.
pub fn regenerate(ctx: &mut Context, file: &Path) -> Result<FileOutcome, String> {
    let text = std::fs::read_to_string(file).map_err(|e| format!("{}: {e}", file.display()))?;
    let blocks = blocks::parse(&text)
        .map_err(|e| format!("{}:{}: {}", file.display(), e.line, e.message))?;
    let mut stale = Vec::new();
    let new = blocks::rewrite(&text, &blocks, |b| {
        let body = ctx
            .render(file, b)
            .map_err(|e| format!("{}:{}: {e}", file.display(), b.line))?;
        let old = &text[b.body.clone()];
        let same = if b.multiline {
            old.trim_matches('\n') == body.trim_end_matches('\n')
        } else {
            old.trim() == body.trim()
        };
        if !same {
            stale.push(b.line);
        }
        Ok::<_, String>(body)
    })?;
    Ok(FileOutcome { text: new, stale })
}
