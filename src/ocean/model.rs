//! The seam between the frame loops and what the helper computes: an ocean [`Model`] says what
//! it offers, validates its own parameters and builds, once per run, the [`Stepper`] that fills
//! a mesh (or one band of its rows) for a time t.

use super::mesh::{Grid, Mesh, MeshRows};
use super::normals::NormalMethod;
use super::row_line::RowLine;
use crate::input::InputError;
use serde::de::DeserializeOwned;
use serde::Serialize;
use std::any::{Any, TypeId};
use std::ops::Range;
use std::sync::Arc;

/// The run's parameters of every model, one value per type: each model reads its own (the
/// sines their [`WaveSet`](super::WaveSet), the FFT ocean its
/// [`FftParams`](super::FftParams), a registered model whatever type it parses), and a model
/// whose value is missing runs on its type's default.
#[derive(Clone, Default)]
pub struct OceanParams {
    values: Vec<(TypeId, Arc<dyn Any + Send + Sync>, serde_json::Value)>,
}

impl OceanParams {
    /// These parameters with `value` as its type's (replacing any before).
    pub fn with<T: Serialize + Send + Sync + 'static>(mut self, value: T) -> OceanParams {
        self.insert(value);
        self
    }

    /// Sets `value` as its type's parameters.
    pub fn insert<T: Serialize + Send + Sync + 'static>(&mut self, value: T) {
        let json = serde_json::to_value(&value).unwrap_or_default();
        self.values.retain(|(id, _, _)| *id != TypeId::of::<T>());
        self.values.push((TypeId::of::<T>(), Arc::new(value), json));
    }

    /// The parameters of type `T`, or its default when none were given.
    pub fn get<T: Default + Clone + 'static>(&self) -> T {
        self.values
            .iter()
            .find_map(|(_, v, _)| v.downcast_ref::<T>())
            .cloned()
            .unwrap_or_default()
    }

    /// Parses `raw`, the config object of model `name`, into its type `T` and keeps it; an
    /// error names `name.key`.
    pub fn parse<T>(&mut self, name: &str, raw: &serde_json::Value) -> Result<T, InputError>
    where
        T: DeserializeOwned + Serialize + Clone + Send + Sync + 'static,
    {
        let value: T = serde_path_to_error::deserialize(raw.clone()).map_err(|e| {
            let path = e.path().to_string();
            let msg = crate::suggest::with_suggestion(&e.into_inner().to_string());
            match path.as_str() {
                "." | "" => InputError(format!("{name}: {msg}")),
                _ => InputError(format!("{name}.{path}: {msg}")),
            }
        })?;
        self.insert(value.clone());
        Ok(value)
    }
}

impl std::fmt::Debug for OceanParams {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_list()
            .entries(self.values.iter().map(|(_, _, json)| json))
            .finish()
    }
}

impl PartialEq for OceanParams {
    fn eq(&self, other: &Self) -> bool {
        self.values.len() == other.values.len()
            && self
                .values
                .iter()
                .all(|(id, _, json)| other.values.iter().any(|(o, _, j)| o == id && j == json))
    }
}

crate::named! {
    /// Which implementation of a model fills heights (and analytic normals).
    pub enum Kernel {
        /// The straight port of section 4.2, kept as the oracle.
        Reference,
        /// Separable phase tables, half-angle powers and run-time selected vector code; the same
        /// surface as `Reference`.
        Fast,
    }
}

crate::named! {
    /// Where a mesh's vertices lie on the sea plane.
    pub enum GridKind {
        /// The paper's N×N grid over a fixed patch.
        Regular,
        /// An N×N grid regular in screen space, projected from the camera onto the sea plane
        /// (the projected grid of Johanson's thesis): the mesh follows the camera.
        Projected,
    }
}

/// Refuses a split among helpers for normals other than `analytic`: face normals at a band's
/// edge need the neighbouring band's heights, which another helper is still computing.
pub fn only_analytic_splits(normals: NormalMethod) -> Result<(), InputError> {
    match normals {
        NormalMethod::Analytic => Ok(()),
        other => Err(InputError(format!(
            "helpers: more than one helper needs normals `analytic`; `{}` normals at a \
             band's edge need the neighbouring band's heights (not supported yet)",
            other.name()
        ))),
    }
}

/// What the helper computes each frame. Implementations are stateless descriptions; the
/// per-run state lives in the [`Stepper`] that [`Model::prepare`] builds.
pub trait Model: Send + Sync {
    /// Its name in configs, flags, cells and results.
    fn name(&self) -> &'static str;

    /// One line for `--help` and the docs.
    fn doc(&self) -> &'static str {
        ""
    }

    /// Its config object's defaults, under the config key of its name; `None` for a model with
    /// no object of its own (the sines read `waves`, the FFT ocean `fft_params`).
    fn default_params(&self) -> Option<serde_json::Value> {
        None
    }

    /// Parses and checks its config object into `params` (see [`OceanParams::parse`]).
    fn parse_params(
        &self,
        raw: &serde_json::Value,
        params: &mut OceanParams,
    ) -> Result<(), InputError> {
        let _ = (raw, params);
        Err(InputError(format!(
            "{}: this ocean takes no object of its own",
            self.name()
        )))
    }

    /// The kernels it runs, in the order it lists them.
    fn kernels(&self) -> &'static [Kernel];

    /// The normal methods it offers.
    fn normals(&self) -> &'static [NormalMethod];

    /// The normals a sweep that names none runs it with: `neighbors`, the paper's, unless the
    /// model has a better one of its own.
    fn default_normals(&self) -> NormalMethod {
        NormalMethod::Neighbors
    }

    /// Whether several helpers can each fill a band of rows alone with `normals`; the error, one
    /// line under the `helpers` field, says why not.
    fn splits_into_rows(&self, normals: NormalMethod) -> Result<(), InputError>;

    /// Refuses parameters it cannot run at mesh size `size` (one line naming the field).
    fn check(&self, size: usize, normals: NormalMethod) -> Result<(), InputError>;

    /// The kernel and normals whose step is the yardstick `step_fraction` levels are given in.
    fn yardstick(&self) -> (Kernel, NormalMethod);

    /// The grids it runs on: every model runs on the regular grid; one that can be evaluated at
    /// any point of the sea plane also runs on the projected grid.
    fn grids(&self) -> &'static [GridKind] {
        &[GridKind::Regular]
    }

    /// Builds the per-run state of a stepper that fills each vertex of a band at the x, y the
    /// band already holds (placed there by the projected grid), with `analytic` normals; only
    /// for models whose [`Model::grids`] list [`GridKind::Projected`].
    fn prepare_at_points(
        &self,
        grid: Grid,
        params: &OceanParams,
        kernel: Kernel,
    ) -> Result<Box<dyn Stepper>, InputError> {
        let _ = (grid, params, kernel);
        Err(InputError(
            "grid: this ocean runs on the `regular` grid only".into(),
        ))
    }

    /// A blank mesh with the optional fields this model fills (none unless it says so).
    fn mesh(&self, grid: Grid) -> Mesh {
        Mesh::new(grid)
    }

    /// Distance between the rest positions of neighbouring vertices of the meshes it fills on
    /// `grid` (the grid's own spacing unless the model sets its own scale).
    fn rest_spacing(&self, grid: Grid, _params: &OceanParams) -> f32 {
        grid.spacing
    }

    /// Builds the per-run state for `grid`, after [`Model::check`].
    fn prepare(
        &self,
        grid: Grid,
        params: &OceanParams,
        normals: NormalMethod,
        kernel: Kernel,
    ) -> Result<Box<dyn Stepper>, InputError>;
}

/// A model's per-run state, owned by the thread that steps it. Each helper gets its own clone:
/// a kernel may keep tables for the band it fills.
pub trait Stepper: Send + std::fmt::Debug {
    /// Fills the whole mesh at time `t`.
    fn step(&mut self, t: f32, mesh: &mut Mesh);

    /// Fills one band of rows at time `t`, bit-identical to the same rows of [`Stepper::step`];
    /// only for the normal methods [`Model::splits_into_rows`] accepts.
    fn step_rows(&mut self, t: f32, rows: MeshRows<'_>);

    /// [`Stepper::step_rows`] for a band the projected grid placed: `lines[r]`, when Some, is
    /// the line row r's vertices lie evenly spaced on, which a kernel may use without checking
    /// the row. By default the lines go unused.
    fn step_rows_on_lines(&mut self, t: f32, rows: MeshRows<'_>, _lines: &[Option<RowLine>]) {
        self.step_rows(t, rows);
    }

    /// A copy of this state for another helper.
    fn boxed_clone(&self) -> Box<dyn Stepper>;

    /// Phases of a banded step: helpers filling bands of one mesh all finish a phase (and the
    /// frame before) before any starts the next. 1: every band is computed alone.
    fn phases(&self) -> usize {
        1
    }

    /// Phase `phase` of this helper's band, bit-identical in the end to the band's rows of
    /// [`Stepper::step`]; with one phase, [`Stepper::step_rows`].
    fn step_phase(&mut self, phase: usize, t: f32, rows: MeshRows<'_>) {
        debug_assert_eq!(phase, 0, "one phase");
        self.step_rows(t, rows);
    }

    /// The steppers of helpers that fill `bands` of each mesh, helper h `bands[h]`: clones by
    /// default; a model whose phases read each other's bands shares that state among them.
    fn split(&self, bands: &[Range<usize>]) -> Vec<Box<dyn Stepper>> {
        bands.iter().map(|_| self.boxed_clone()).collect()
    }
}

impl Clone for Box<dyn Stepper> {
    fn clone(&self) -> Self {
        self.boxed_clone()
    }
}
