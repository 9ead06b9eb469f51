//! `latency` blocks: a committed `oceanbench latency` run (`results/latency-<UTC>/latency.json`)
//! as a table, or one of its numbers, each row the median over the run's repeats. Every number
//! says beside it what the run records of its machine and commit: a bare list of rows from
//! before runs kept them records neither (its folder's README.md says how it was made).
//!
//! - `<!-- ob:latency run=R -->` on its own line: a row per method with its one-core and two-core
//!   batched / p99 round trip and CPU time, and × floor (batched ÷ the ping-pong's batched on the
//!   same cores);
//! - `<!-- ob:latency run=R method=M cores=one|two [stat=S] [over=M2] [unit=U] [digits=N] -->`:
//!   one number. `method="A;B"` gives the range `lo-hi`; `stat` is `batched` (the default),
//!   `median`, `p99`, `cpu`, `samples` or `x_floor`; `over` divides by the same stat of another
//!   method on the same cores (one method for all, or one per method); `unit` is `ns` (the
//!   default), `us` or `ms`.

use super::blocks::Block;
use super::{qualified, BlockError};
use crate::latency::LatencyRow;
use crate::results::latency::LatencyRun;
use std::fmt::Write;
use std::path::Path;

use crate::results::latency::FILE_NAME;

/// What every number of a latency run carries beside it.
pub const UNRECORDED: &str = "no machine or commit recorded";

/// The row that every other is measured against.
const FLOOR: &str = "ping-pong";

/// A latency run: its folder's name and its rows.
struct Run {
    name: String,
    rows: Vec<LatencyRow>,
    /// What the run records of its machine and commit, said beside every number.
    recorded: String,
}

/// Where a row's two threads ran.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Cores {
    One,
    Two,
}

impl Cores {
    fn of(row: &LatencyRow) -> Cores {
        if row.main_core == row.helper_core {
            Cores::One
        } else {
            Cores::Two
        }
    }

    fn parse(text: &str) -> Result<Cores, BlockError> {
        match text {
            "one" => Ok(Cores::One),
            "two" => Ok(Cores::Two),
            other => Err(format!("cores: `{other}` is not one or two")),
        }
    }

    fn name(self) -> &'static str {
        match self {
            Cores::One => "one core",
            Cores::Two => "two cores",
        }
    }
}

fn load(root: &Path, block: &Block) -> Result<Run, BlockError> {
    let name = super::run_name(block)?.to_string();
    let path = root.join("results").join(&name).join(FILE_NAME);
    if !path.is_file() {
        return Err(format!(
            "run `{name}` does not exist (no results/{name}/{FILE_NAME})"
        ));
    }
    let run = LatencyRun::load(&path).map_err(|e| e.to_string())?;
    let recorded = match &run.machine {
        None => UNRECORDED.to_string(),
        Some(m) => format!(
            "{}, {}, median of {} repeats",
            m.cpu_model,
            m.provenance_line(),
            run.repeats
        ),
    };
    Ok(Run {
        name,
        rows: run.summary_rows(),
        recorded,
    })
}

impl Run {
    /// The methods of the run: the floor first, then the others in the order of the file.
    fn methods(&self) -> Vec<&str> {
        let mut out: Vec<&str> = Vec::new();
        for r in &self.rows {
            if !out.contains(&r.method.as_str()) {
                out.push(&r.method);
            }
        }
        out.sort_by_key(|m| *m != FLOOR);
        out
    }

    fn row(&self, method: &str, cores: Cores) -> Option<&LatencyRow> {
        self.rows
            .iter()
            .find(|r| r.method == method && Cores::of(r) == cores)
    }

    fn find(&self, method: &str, cores: Cores) -> Result<&LatencyRow, BlockError> {
        self.row(method, cores).ok_or_else(|| {
            format!(
                "latency run `{}` has no method `{method}` on {} (its methods: {})",
                self.name,
                cores.name(),
                self.methods().join(", ")
            )
        })
    }

    /// The ping-pong row on the same two cores as `row`.
    fn floor(&self, row: &LatencyRow) -> Option<&LatencyRow> {
        self.rows.iter().find(|f| {
            f.method == FLOOR && (f.main_core, f.helper_core) == (row.main_core, row.helper_core)
        })
    }

    /// `row`'s batched round trip ÷ its floor's.
    fn x_floor(&self, row: &LatencyRow) -> Option<f64> {
        row.batched_ns
            .zip(self.floor(row).and_then(|f| f.batched_ns))
            .map(|(b, f)| b / f)
    }

    /// A row's `stat` in ns (a count or a ratio for `samples` and `x_floor`).
    fn stat(&self, row: &LatencyRow, stat: &str) -> Result<f64, BlockError> {
        let missing = |what: &str| {
            format!(
                "latency run `{}`: `{}` on {} has no {what}",
                self.name,
                row.method,
                Cores::of(row).name()
            )
        };
        match stat {
            "batched" => row.batched_ns.ok_or_else(|| missing("batched round trip")),
            "median" => Ok(row.median_ns),
            "p99" => Ok(row.p99_ns),
            "cpu" => row.cpu_ns.ok_or_else(|| missing("CPU time")),
            "samples" => Ok(row.samples as f64),
            "x_floor" => self
                .x_floor(row)
                .ok_or_else(|| missing("ping-pong floor on its cores")),
            other => Err(format!(
                "stat: unknown `{other}` (allowed: batched, median, p99, cpu, samples, x_floor)"
            )),
        }
    }
}

/// `v` with `digits` decimals and its whole part grouped by threes with spaces: `7 937 461`.
fn grouped(v: f64, digits: usize) -> String {
    let text = format!("{:.digits$}", v.abs());
    let (whole, frac) = text
        .split_once('.')
        .map_or((text.as_str(), None), |(w, f)| (w, Some(f)));
    let mut out = String::new();
    for (i, c) in whole.chars().enumerate() {
        if i > 0 && (whole.len() - i) % 3 == 0 {
            out.push(' ');
        }
        out.push(c);
    }
    if let Some(f) = frac {
        let _ = write!(out, ".{f}");
    }
    if v < 0.0 {
        out.insert(0, '-');
    }
    out
}

/// Renders a `latency` block: the run's table, or one number (with `method=`).
pub fn render(root: &Path, block: &Block, link: &str) -> Result<String, BlockError> {
    let run = load(root, block)?;
    if block.attr("method").is_some() {
        return value(&run, block);
    }
    if let Some(k) = ["cores", "stat", "over", "unit", "digits"]
        .into_iter()
        .find(|k| block.attr(k).is_some())
    {
        return Err(format!("{k}= needs method=M (a table takes only run=)"));
    }
    if !block.multiline {
        return Err(
            "an inline `latency` span needs method=M; a table needs its own lines".to_string(),
        );
    }
    Ok(table(&run, link))
}

/// One number, or a range over methods, of the run.
fn value(run: &Run, block: &Block) -> Result<String, BlockError> {
    let methods: Vec<&str> = block
        .attr("method")
        .unwrap_or_default()
        .split(';')
        .map(str::trim)
        .collect();
    let cores = Cores::parse(
        block
            .attr("cores")
            .ok_or("`latency` with method= needs cores=one or cores=two")?,
    )?;
    let stat = block.attr("stat").unwrap_or("batched");
    let over: Vec<&str> = block
        .attr("over")
        .map_or(Vec::new(), |o| o.split(';').map(str::trim).collect());
    if over.len() > 1 && over.len() != methods.len() {
        return Err(format!(
            "over= names {} methods and method= {}: one, or one each",
            over.len(),
            methods.len()
        ));
    }
    let ratio = !over.is_empty() || stat == "x_floor";
    let (scale, unit_digits) = match (block.attr("unit"), ratio || stat == "samples") {
        (Some(_), true) => {
            return Err(format!(
                "unit= applies to times, and this {stat} is a {}",
                if ratio { "ratio" } else { "count" }
            ))
        }
        (None, true) => (1.0, if ratio { 2 } else { 0 }),
        (None | Some("ns"), false) => (1.0, 0),
        (Some("us"), false) => (1e3, 1),
        (Some("ms"), false) => (1e6, 2),
        (Some(other), false) => return Err(format!("unit: `{other}` is not ns, us or ms")),
    };
    let digits = match block.attr("digits") {
        None => unit_digits,
        Some(d) => d
            .parse::<usize>()
            .ok()
            .filter(|&d| d <= 6)
            .ok_or_else(|| format!("digits: `{d}` is not 0 to 6"))?,
    };
    let mut numbers = Vec::new();
    let mut unpinned = false;
    for (i, method) in methods.iter().enumerate() {
        let row = run.find(method, cores)?;
        unpinned |= !row.pinned;
        let mut n = run.stat(row, stat)?;
        if let Some(base) = over.get(i).or(over.first()) {
            let base = run.find(base, cores)?;
            unpinned |= !base.pinned;
            n /= run.stat(base, stat)?;
        }
        numbers.push(n / scale);
    }
    let (lo, hi) = crate::stats::min_max(&numbers);
    let (lo, hi) = (grouped(lo, digits), grouped(hi, digits));
    let text = if lo == hi { lo } else { format!("{lo}-{hi}") };
    Ok(qualified(
        text,
        &[Some(&run.recorded), unpinned.then_some("pin did not hold")],
    ))
}

/// The run's table: a row per method, one core and two cores side by side.
fn table(run: &Run, link: &str) -> String {
    let mut placed = Vec::new();
    for cores in [Cores::One, Cores::Two] {
        if let Some(r) = run.rows.iter().find(|r| Cores::of(r) == cores) {
            placed.push(if cores == Cores::One {
                format!("one core: both threads on core {}", r.main_core)
            } else {
                format!(
                    "two cores: main thread on core {}, helper on core {}",
                    r.main_core, r.helper_core
                )
            });
        }
    }
    let most = run.rows.iter().map(|r| r.samples).max().unwrap_or(0);
    let mut out = format!(
        "Latency run [`{}`]({link}) (`oceanbench latency`): {} (the folder's README.md \
         says how it was made); {}; up to {} round trips timed per row. Batched: the median of \
         batches of round trips timed with one clock read each; p99: over trips timed one by one \
         (clock reads included); CPU: both threads' CPU time per round trip; × floor: batched ÷ \
         the {FLOOR}'s batched on the same cores.\n\n",
        run.name,
        run.recorded,
        placed.join("; "),
        grouped(most as f64, 0)
    );
    out.push_str(
        "| method | one core: batched / p99 (ns) | CPU (ns) | two cores: batched / p99 (ns) | × floor | CPU (ns) |\n\
         |---|---:|---:|---:|---:|---:|\n",
    );
    let dash = |v: Option<f64>, digits: usize| v.map_or("–".to_string(), |v| grouped(v, digits));
    for method in run.methods() {
        let label = match method.strip_suffix(" latest") {
            Some(m) => format!("{m} (`latest`)"),
            None if method == FLOOR => format!("{FLOOR} (the floor)"),
            None => method.to_string(),
        };
        let mut unpinned = false;
        let mut cells = Vec::new();
        for cores in [Cores::One, Cores::Two] {
            match run.row(method, cores) {
                Some(r) => {
                    unpinned |= !r.pinned;
                    cells.push(format!(
                        "{} / {}",
                        dash(r.batched_ns, 0),
                        grouped(r.p99_ns, 0)
                    ));
                    if cores == Cores::Two {
                        cells.push(dash(run.x_floor(r), 2));
                    }
                    cells.push(dash(r.cpu_ns, 0));
                }
                None => {
                    cells.push("–".into());
                    if cores == Cores::Two {
                        cells.push("–".into());
                    }
                    cells.push("–".into());
                }
            }
        }
        let pin = if unpinned { " (pin did not hold)" } else { "" };
        let _ = writeln!(out, "| {label}{pin} | {} |", cells.join(" | "));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const RUN: &str = "latency-20261125T065137Z";

    fn root() -> &'static Path {
        Path::new(env!("CARGO_MANIFEST_DIR"))
    }

    /// The one block of `text`, rendered from the checkout through the docs' own dispatch.
    fn rendered(text: &str) -> Result<String, BlockError> {
        let blocks = super::super::blocks::parse(text).expect("the block parses");
        let mut ctx = super::super::Context::new(root());
        ctx.render(&root().join("docs/handoffs.md"), &blocks[0])
    }

    #[test]
    fn a_committed_run_renders_as_a_table_saying_what_it_does_not_record() {
        let out = rendered(&format!("<!-- ob:latency run={RUN} -->\n<!-- /ob -->\n")).unwrap();
        assert!(
            out.starts_with(&format!(
                "Latency run [`{RUN}`](../results/{RUN}/) (`oceanbench latency`): {UNRECORDED}"
            )),
            "{out}"
        );
        assert!(
            out.contains("| ping-pong (the floor) | – | – | 107 / 254 | 1.00 | – |"),
            "{out}"
        );
        assert!(
            out.contains("| atomic | 928 / 1 017 | 985 | 252 / 548 | 2.36 | 687 |"),
            "{out}"
        );
        assert!(out.contains("| spin | 7 937 461 / 8 017 441 |"), "{out}");
        assert!(out.contains("| atomic (`latest`) | 988 / 1 210 |"), "{out}");
    }

    #[test]
    fn single_values_ranges_and_ratios_carry_the_qualifier() {
        let one = |attrs: &str| {
            rendered(&format!(
                "<!-- ob:latency run={RUN} {attrs} -->x<!-- /ob -->"
            ))
        };
        let q = format!(" ({UNRECORDED})");
        assert_eq!(one("method=atomic cores=two").unwrap(), format!("252{q}"));
        assert_eq!(
            one("method=spin cores=one stat=p99").unwrap(),
            format!("8 017 441{q}")
        );
        assert_eq!(
            one("method=condvar cores=two stat=x_floor").unwrap(),
            format!("522.66{q}")
        );
        assert_eq!(
            one("method=\"condvar;futex\" cores=two unit=us digits=0").unwrap(),
            format!("56-57{q}")
        );
        assert_eq!(
            one("method=std-channel cores=two over=crossbeam digits=0").unwrap(),
            format!("90{q}")
        );
        assert_eq!(
            one("method=\"atomic latest\" cores=one stat=cpu").unwrap(),
            format!("1 054{q}")
        );
    }

    #[test]
    fn a_missing_method_or_run_is_a_one_line_error() {
        let one = |attrs: &str| rendered(&format!("<!-- ob:latency {attrs} -->x<!-- /ob -->"));
        for (attrs, needle) in [
            (
                format!("run={RUN} method=nothing cores=two"),
                "has no method `nothing` on two cores",
            ),
            (
                format!("run={RUN} method=ping-pong cores=one"),
                "has no method `ping-pong` on one core",
            ),
            (
                "run=latency-nowhere method=atomic cores=two".to_string(),
                "run `latency-nowhere` does not exist",
            ),
            (
                format!("run={RUN} method=ping-pong cores=two stat=cpu"),
                "has no CPU time",
            ),
            (
                format!("run={RUN} method=atomic cores=three"),
                "cores: `three`",
            ),
            (format!("run={RUN} method=atomic"), "needs cores="),
            (format!("run={RUN}"), "needs method=M"),
            (
                format!("run={RUN} method=atomic cores=two stat=fps"),
                "stat: unknown `fps`",
            ),
            (
                format!("run={RUN} method=atomic cores=two colour=red"),
                "takes no attribute `colour`",
            ),
        ] {
            let e = one(&attrs).expect_err(&attrs);
            assert!(e.contains(needle), "{attrs}: {e}");
            assert!(!e.contains('\n'), "one line: {e}");
        }
    }

    #[test]
    fn numbers_are_grouped_by_threes() {
        assert_eq!(grouped(928.4, 0), "928");
        assert_eq!(grouped(1017.0, 0), "1 017");
        assert_eq!(grouped(7_937_461.06, 0), "7 937 461");
        assert_eq!(grouped(59_445.2, 1), "59 445.2");
        assert_eq!(grouped(0.71, 2), "0.71");
    }
}
