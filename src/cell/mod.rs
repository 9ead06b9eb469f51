//! A cell is a point in the study's declared space. Every swept dimension is declared once, in
//! the `dimensions!` invocation below: its config key and defaults, whether serial cells have it,
//! whether it defines a row of interleaved trials, how labels and table headings show it, the
//! value labels leave out, and the check its values must pass.
//!
//! Everything that deals with cells reads this declaration: config parsing and validation
//! ([`Axes`]), the sweep's expansion ([`Axes::cells`]), [`CellKey`] and its label, the CSV
//! columns, the markdown grouping, `compare --by` and the chart variants. A new dimension is one
//! entry here plus the code that implements it; `tests/cell_model.rs` walks every dimension
//! through every output.

pub mod axes;
mod declare;
pub mod rules;

pub use axes::{Consume, Mode, Threading, MAX_DEPTH, MAX_HELPERS};
pub use declare::{DimValue, Value};

use crate::input::InputError;
use crate::ocean::{mesh::MAX_SIZE, GridKind, Kernel, Model, NormalMethod, OceanKind};
use crate::sync::{Policy, SyncMethod};
use crate::workload::WorkloadKind;
use declare::{dim_values, dimensions};
use itertools::Itertools;

dim_values!(
    Mode,
    Policy,
    SyncMethod,
    Threading,
    Consume,
    NormalMethod,
    Kernel,
    GridKind
);

/// Implements [`DimValue`] for a registry's names: a cell names any value a results file holds
/// (a kind or model another program registered), and flags and configs accept the registered
/// ones.
macro_rules! registered_values {
    ($($t:ty => $names:path),+ $(,)?) => {$(
        impl DimValue for $t {
            fn value(self) -> Value {
                Value::Name(self.name())
            }
            fn from_value(value: Value) -> Option<Self> {
                match value {
                    Value::Name(name) => Some(<$t>::named(name)),
                    Value::Count(_) => None,
                }
            }
            fn parse(text: &str) -> Result<Self, InputError> {
                <$t>::parse(text)
            }
            fn names() -> Option<Vec<&'static str>> {
                Some($names())
            }
            fn check_known(self) -> Result<(), InputError> {
                <$t>::parse(self.name()).map(|_| ())
            }
        }
    )+};
}

registered_values!(
    WorkloadKind => crate::workload::names,
    OceanKind => crate::ocean::names,
);

dimensions! {
    /// Mesh size N (N×N vertices).
    Size(size: usize) {
        config: sizes = [40, 128, 256],
        cells: all,
        row: true,
        label: "{}",
        title: "{0}×{0} mesh",
        check: check_size,
    }
    /// Workload level, an index into `workload_levels`.
    Workload(workload: usize) {
        config: workloads = [0, 1, 2, 3],
        cells: all,
        row: true,
        label: "w{}",
        title: "workload {}",
    }
    /// What the main thread does each frame: the synthetic game work, rendering the mesh, or fog.
    WorkloadKind(workload_kind: WorkloadKind) {
        config: workload_kind = [WorkloadKind::SYNTHETIC],
        cells: all,
        row: true,
        label: "{}",
        title: "{} workload",
        quiet: WorkloadKind::SYNTHETIC,
    }
    /// Where the threads run: serial, up (one core) or dp (two cores).
    Mode(mode: Mode) {
        config: modes = [Mode::Serial, Mode::Up, Mode::Dp],
        cells: all,
        row: false,
        label: "{}",
        title: "{}",
    }
    /// Which frames the main thread consumes: every one in order, or the newest.
    Policy(policy: Policy) {
        config: policy = [Policy::Fifo],
        cells: threaded,
        row: false,
        label: "{}",
        title: "{} policy",
        quiet: Policy::Fifo,
    }
    /// The hand-off method.
    Sync(sync: SyncMethod) {
        config: sync = [SyncMethod::Atomic, SyncMethod::Mutex, SyncMethod::Condvar],
        cells: threaded,
        row: false,
        label: "{}",
        title: "{} hand-off",
    }
    /// How helper threads come to exist: a persistent pool or a thread per frame.
    Threading(threading: Threading) {
        config: threading = [Threading::Pool],
        cells: threaded,
        row: false,
        label: "{}",
        title: "{} helper",
    }
    /// Helper threads the mesh's rows are split among (loop-level decomposition).
    Helpers(helpers: usize) {
        config: helpers = [1],
        cells: threaded,
        row: false,
        label: "h{}",
        title: "{} helpers",
        title_one: "{} helper",
        quiet: 1,
        check: check_helpers,
    }
    /// Mesh slots the helper may fill ahead of the main thread (1: the paper's lockstep loop).
    Depth(depth: usize) {
        config: depth = [1],
        cells: threaded,
        row: false,
        label: "d{}",
        title: "depth {}",
        quiet: 1,
        check: check_depth,
    }
    /// How the main thread consumes a mesh: copy it, read it in place, or hand the slot on.
    Consume(consume: Consume) {
        config: consume = [Consume::Copy],
        cells: all,
        row: false,
        label: "{}",
        title: "{} consume",
        quiet: Consume::Copy,
    }
    /// How vertex normals are computed.
    Normals(normals: NormalMethod) {
        config: normals = [NormalMethod::Neighbors],
        cells: all,
        row: true,
        label: "{}",
        title: "{} normals",
    }
    /// Which ocean model the helper computes.
    Ocean(ocean: OceanKind) {
        config: ocean = [OceanKind::SINES],
        cells: all,
        row: true,
        label: "{}",
        title: "{} ocean",
        quiet: OceanKind::SINES,
    }
    /// Which kernel computes the mesh.
    Kernel(kernel: Kernel) {
        config: kernel = [Kernel::Reference],
        cells: all,
        row: true,
        label: "{}",
        title: "{} kernel",
    }
    /// Where the mesh's vertices lie: the regular patch, or projected from the camera.
    Grid(grid: GridKind) {
        config: grid = [GridKind::Regular],
        cells: all,
        row: true,
        label: "{}",
        title: "{} grid",
        quiet: GridKind::Regular,
    }
}

fn check_size(&n: &usize) -> Result<(), InputError> {
    if (2..=MAX_SIZE).contains(&n) {
        Ok(())
    } else {
        Err(InputError(format!(
            "{n} is not allowed; sizes are 2 to {MAX_SIZE}"
        )))
    }
}

fn check_depth(&n: &usize) -> Result<(), InputError> {
    if (1..=MAX_DEPTH).contains(&n) {
        Ok(())
    } else {
        Err(InputError(format!("must be 1 to {MAX_DEPTH}, got {n}")))
    }
}

fn check_helpers(&n: &usize) -> Result<(), InputError> {
    if (1..=MAX_HELPERS).contains(&n) {
        Ok(())
    } else {
        Err(InputError(format!("must be 1 to {MAX_HELPERS}, got {n}")))
    }
}

/// Refuses a kernel or normal method the `ocean`'s model does not offer.
fn check_offers(
    ocean: OceanKind,
    model: &dyn Model,
    kernel: Kernel,
    normals: NormalMethod,
) -> Result<(), InputError> {
    let refuse = |key: &str, value: &str, offered: Vec<&str>| {
        InputError(format!(
            "{key}: the `{ocean}` ocean offers {}, not `{value}`",
            offered.join(", ")
        ))
    };
    if !model.kernels().contains(&kernel) {
        let offered = model.kernels().iter().map(|k| k.name()).collect();
        return Err(refuse("kernel", kernel.name(), offered));
    }
    if !model.normals().contains(&normals) {
        let offered = model.normals().iter().map(|n| n.name()).collect();
        return Err(refuse("normals", normals.name(), offered));
    }
    Ok(())
}

/// Whether a cell with this mode is serial: the one rule that decides which dimensions apply.
fn is_serial(mode: Option<Value>) -> bool {
    mode == Some(Mode::Serial.value())
}

/// A config list must be non-empty, list no value twice, and pass its dimension's check.
fn check_list<T: PartialEq + std::fmt::Debug + DimValue>(
    key: &str,
    list: &[T],
    check: impl Fn(&T) -> Result<(), InputError>,
) -> Result<(), InputError> {
    if list.is_empty() {
        return Err(InputError(format!("{key}: must list at least one value")));
    }
    for (i, v) in list.iter().enumerate() {
        if list[..i].contains(v) {
            return Err(InputError(format!("{key}: {} is listed twice", v.value())));
        }
        v.check_known()
            .and_then(|()| check(v))
            .map_err(|e| InputError(format!("{key}: {e}")))?;
    }
    Ok(())
}

impl CellKey {
    /// Whether this cell runs everything on one thread.
    pub fn is_serial(&self) -> bool {
        self.mode == Mode::Serial
    }

    /// The same cell with `dim` set to `value`. Dimensions that stop applying follow the mode;
    /// `None` when the new key would lack a value (a serial cell turned threaded has no method).
    pub fn with(&self, dim: Dim, value: Value) -> Option<CellKey> {
        CellKey::from_fn(|d| if d == dim { Some(value) } else { self.get(d) }).ok()
    }

    /// A short label such as `256 w2 dp atomic pool neighbors reference`: every value in
    /// dimension order, leaving out quiet ones.
    pub fn label(&self) -> String {
        self.label_without(&[])
    }

    /// The label without the dimensions in `skip`.
    pub fn label_without(&self, skip: &[Dim]) -> String {
        Dim::ALL
            .iter()
            .filter(|d| !skip.contains(d))
            .filter_map(|&d| {
                let v = self.get(d)?;
                (Some(v) != d.quiet()).then(|| d.label(v))
            })
            .join(" ")
    }

    /// The label of the cell's row: its row dimensions' values only.
    pub fn row_label(&self) -> String {
        let others: Vec<Dim> = Dim::ALL.iter().copied().filter(|d| !d.row()).collect();
        self.label_without(&others)
    }

    /// The values the rules read ([`rules::Runnable`]).
    pub fn runnable(&self) -> rules::Runnable {
        rules::Runnable {
            size: self.size,
            ocean: self.ocean,
            grid: self.grid,
            normals: self.normals,
            kernel: self.kernel,
            workload_kind: self.workload_kind,
            mode: self.mode,
            policy: self.policy,
            sync: self.sync,
            threading: self.threading,
            helpers: self.helpers,
            depth: self.depth,
        }
    }

    /// Whether the loops can run this combination of values ([`rules::Runnable::combination`]).
    /// The sweep leaves such combinations out of its product; see [`Axes::check_coverage`].
    pub fn coherent(&self) -> Result<(), InputError> {
        self.runnable().combination()
    }

    /// The values of the row dimensions: cells with equal rows run interleaved.
    pub fn row(&self) -> Vec<Option<Value>> {
        Dim::ALL
            .iter()
            .filter(|d| d.row())
            .map(|&d| self.get(d))
            .collect()
    }
}

impl Axes {
    /// Every cell of the sweep, row by row: the cartesian product of the row dimensions, and
    /// within each row the product of the others, each in declaration order. Serial cells drop
    /// the hand-off dimensions, so a row has one serial cell however many methods it crosses;
    /// combinations the loops cannot run (see [`CellKey::coherent`]) are left out.
    pub fn cells(&self) -> Vec<CellKey> {
        self.product()
            .into_iter()
            .filter(|k| k.coherent().is_ok())
            .collect()
    }

    /// Gives normals nobody named: each listed model's own (neighbors for the sines, as the
    /// paper; analytic for the FFT ocean), unless a crossed cell cannot run with them (the
    /// projected grid, or helpers splitting the rows); then the first method every cell can
    /// run, analytic first, and the sentence that says so, for the caller to print once.
    pub fn fit_default_normals(&mut self) -> Option<String> {
        if self.ocean.is_empty() {
            return None;
        }
        self.normals = self
            .ocean
            .iter()
            .map(|o| o.model().default_normals())
            .unique()
            .collect();
        let why = self.refusal()?;
        let default = self.normals.clone();
        for normals in [
            NormalMethod::Analytic,
            NormalMethod::Neighbors,
            NormalMethod::Lookup,
        ] {
            self.normals = vec![normals];
            if self.refusal().is_none() {
                let default: Vec<&str> = default.iter().map(|n| n.name()).collect();
                return Some(format!(
                    "normals {normals}: the default ({}) cannot run these cells ({why})",
                    default.join(", ")
                ));
            }
        }
        self.normals = default;
        None
    }

    /// Why the first of the crossed cells that cannot run is refused (a combination or a
    /// value), if one cannot.
    pub fn refusal(&self) -> Option<InputError> {
        self.product()
            .iter()
            .find_map(|k| k.runnable().check().err())
            .map(rules::Refusal::error)
    }

    /// Refuses lists with a value no runnable cell has, giving the reason the cells with it
    /// cannot run (`policy: [latest]` with only `fifo` methods, say): a listed value that
    /// silently vanished from the sweep would be a figure missing without a word.
    pub fn check_coverage(&self) -> Result<(), InputError> {
        let (kept, dropped): (Vec<CellKey>, Vec<CellKey>) = self
            .product()
            .into_iter()
            .partition(|k| k.coherent().is_ok());
        for &dim in Dim::ALL {
            for value in self.values(dim) {
                let has = |k: &&CellKey| k.get(dim) == Some(value);
                if kept.iter().any(|k| has(&k)) {
                    continue;
                }
                if let Some(Err(reason)) = dropped.iter().find(has).map(CellKey::coherent) {
                    // A kind that cannot work on a listed surface (spray on sines) loses those
                    // cells alone, which the sweep says once (`sweep::kind_skips`), unless
                    // nothing is left to run.
                    let kind_skips = dropped
                        .iter()
                        .filter(has)
                        .all(|k| k.workload_kind.check_surface(k.ocean, k.grid).is_err());
                    if kind_skips && !kept.is_empty() {
                        continue;
                    }
                    return Err(reason);
                }
            }
        }
        Ok(())
    }

    /// The whole product of the lists, runnable or not, without repeats.
    fn product(&self) -> Vec<CellKey> {
        let product = |row: bool| {
            let dims: Vec<Dim> = Dim::ALL
                .iter()
                .copied()
                .filter(|d| d.row() == row)
                .collect();
            let lists: Vec<Vec<Value>> = dims.iter().map(|&d| self.values(d)).collect();
            (
                dims,
                lists.into_iter().multi_cartesian_product().collect_vec(),
            )
        };
        let (row_dims, rows) = product(true);
        let (col_dims, cols) = product(false);
        let mut out = Vec::new();
        let mut seen = std::collections::HashSet::new();
        for row in &rows {
            for col in &cols {
                let value = |d: Dim| {
                    let at = |dims: &[Dim], vals: &[Value]| {
                        dims.iter().position(|&x| x == d).map(|i| vals[i])
                    };
                    at(&row_dims, row).or_else(|| at(&col_dims, col))
                };
                let key = CellKey::from_fn(value).expect("every dimension has a listed value");
                if seen.insert(key.clone()) {
                    out.push(key);
                }
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ocean::{sines::Sines, Grid, OceanParams, Stepper};

    /// A model offering the reference kernel with analytic normals only.
    struct Narrow;

    impl Model for Narrow {
        fn name(&self) -> &'static str {
            "narrow"
        }
        fn kernels(&self) -> &'static [Kernel] {
            &[Kernel::Reference]
        }
        fn normals(&self) -> &'static [NormalMethod] {
            &[NormalMethod::Analytic]
        }
        fn splits_into_rows(&self, normals: NormalMethod) -> Result<(), InputError> {
            Sines.splits_into_rows(normals)
        }
        fn check(&self, size: usize, normals: NormalMethod) -> Result<(), InputError> {
            Sines.check(size, normals)
        }
        fn yardstick(&self) -> (Kernel, NormalMethod) {
            (Kernel::Reference, NormalMethod::Analytic)
        }
        fn prepare(
            &self,
            grid: Grid,
            params: &OceanParams,
            normals: NormalMethod,
            kernel: Kernel,
        ) -> Result<Box<dyn Stepper>, InputError> {
            Sines.prepare(grid, params, normals, kernel)
        }
    }

    #[test]
    fn a_count_of_one_is_titled_in_the_singular() {
        assert_eq!(Dim::Helpers.title(Value::Count(1)), "1 helper");
        assert_eq!(Dim::Helpers.title(Value::Count(2)), "2 helpers");
        assert_eq!(Dim::Depth.title(Value::Count(1)), "depth 1");
    }

    #[test]
    fn a_kernel_or_normals_the_model_lacks_is_refused_by_name() {
        let (r, a) = (Kernel::Reference, NormalMethod::Analytic);
        let ocean = OceanKind::SINES;
        assert!(check_offers(ocean, &Narrow, r, a).is_ok());
        let err = check_offers(ocean, &Narrow, Kernel::Fast, a).unwrap_err().0;
        assert_eq!(
            err,
            "kernel: the `sines` ocean offers reference, not `fast`"
        );
        let err = check_offers(ocean, &Narrow, r, NormalMethod::Lookup)
            .unwrap_err()
            .0;
        assert_eq!(
            err,
            "normals: the `sines` ocean offers analytic, not `lookup`"
        );
        for kernel in [Kernel::Reference, Kernel::Fast] {
            for normals in [NormalMethod::Lookup, NormalMethod::Neighbors, a] {
                assert!(check_offers(ocean, ocean.model(), kernel, normals).is_ok());
            }
        }
    }

    /// The default axes with `dim` listing `values` (parsed as a config names them).
    fn axes_with(changes: &[(Dim, &[&str])]) -> Axes {
        let mut axes = Axes::default();
        for &(dim, values) in changes {
            let values: Vec<Value> = values.iter().map(|v| dim.parse_value(v).unwrap()).collect();
            axes.set(dim, &values).unwrap();
        }
        axes
    }

    #[test]
    fn depth_and_helpers_out_of_range_are_refused_by_key() {
        let refused = |dim: Dim, v: &str| axes_with(&[(dim, &[v])]).check().unwrap_err().0;
        assert_eq!(
            refused(Dim::Depth, "0"),
            format!("depth: must be 1 to {MAX_DEPTH}, got 0")
        );
        let over = (MAX_DEPTH + 1).to_string();
        assert_eq!(
            refused(Dim::Depth, &over),
            format!("depth: must be 1 to {MAX_DEPTH}, got {over}")
        );
        assert_eq!(
            refused(Dim::Helpers, "0"),
            format!("helpers: must be 1 to {MAX_HELPERS}, got 0")
        );
        let over = (MAX_HELPERS + 1).to_string();
        assert_eq!(
            refused(Dim::Helpers, &over),
            format!("helpers: must be 1 to {MAX_HELPERS}, got {over}")
        );
        for (dim, top) in [(Dim::Depth, MAX_DEPTH), (Dim::Helpers, MAX_HELPERS)] {
            let edges = ["1".to_string(), top.to_string()];
            let edges: Vec<&str> = edges.iter().map(String::as_str).collect();
            assert_eq!(axes_with(&[(dim, &edges)]).check(), Ok(()), "{dim:?}");
        }
    }

    #[test]
    fn a_row_label_names_the_row_dimensions_alone() {
        let axes = axes_with(&[
            (Dim::Size, &["128"]),
            (Dim::Workload, &["2"]),
            (Dim::Mode, &["dp"]),
            (Dim::Kernel, &["fast"]),
            (Dim::Ocean, &["fft"]),
            (Dim::Normals, &["analytic"]),
        ]);
        let cells = axes.cells();
        assert!(!cells.is_empty());
        for cell in cells {
            assert_eq!(cell.row_label(), "128 w2 analytic fft fast", "{cell:?}");
        }
    }

    #[test]
    fn normals_nobody_named_fit_the_cells_and_say_so() {
        let mut axes = axes_with(&[(Dim::Grid, &["projected"])]);
        let note = axes
            .fit_default_normals()
            .expect("neighbors cannot run projected");
        assert!(
            note.starts_with("normals analytic: the default (neighbors) cannot run these cells ("),
            "{note}"
        );
        assert_eq!(axes.normals, vec![NormalMethod::Analytic]);
        assert_eq!(axes.refusal(), None);
        let mut axes = Axes::default();
        assert_eq!(axes.fit_default_normals(), None);
        assert_eq!(axes.normals, vec![NormalMethod::Neighbors]);
        let mut none = Axes {
            ocean: vec![],
            ..Axes::default()
        };
        assert_eq!(none.fit_default_normals(), None);
    }

    #[test]
    fn a_listed_value_no_runnable_cell_has_is_refused_with_the_reason() {
        assert_eq!(Axes::default().check_coverage(), Ok(()));
        assert_eq!(Axes::default().refusal(), None);
        // Projected needs analytic normals: with neighbors only, no projected cell is left,
        // while the regular grid's still run.
        for grids in [&["projected"][..], &["regular", "projected"]] {
            let axes = axes_with(&[(Dim::Grid, grids)]);
            let err = axes.check_coverage().unwrap_err().0;
            assert!(err.starts_with("normals: "), "{grids:?}: {err}");
            assert_eq!(axes.refusal().map(|e| e.0), Some(err));
        }
        // Spray cannot run on the sines: beside a kind that can, only its cells go (the
        // sweep says so once); alone, nothing would run.
        let kinds = [(Dim::WorkloadKind, &["synthetic", "spray"][..])];
        assert_eq!(axes_with(&kinds).check_coverage(), Ok(()));
        let alone = axes_with(&[(Dim::WorkloadKind, &["spray"])]);
        assert!(alone.check_coverage().is_err());
        // One method of three the FFT ocean does not offer, while the other two run: that
        // method alone is refused, by its own reason.
        let three = axes_with(&[
            (Dim::Ocean, &["fft"]),
            (Dim::Normals, &["neighbors", "analytic", "lookup"]),
        ]);
        let err = three.check_coverage().unwrap_err().0;
        assert!(err.contains("lookup"), "{err}");
    }
}
