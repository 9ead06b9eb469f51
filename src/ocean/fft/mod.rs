//! The FFT ocean (Tessendorf's method, `../shared/reference/gpu-fft-ocean-slides.md`): heights,
//! choppy displacements, slopes and the displacement's Jacobian from inverse 2-D FFTs of a
//! Phillips spectrum sampled once per run; the fold value J and its direction per vertex.

mod fill;
pub mod points;
pub mod size;
pub mod spectrum;
pub mod stream;
pub mod terms;
pub mod transform;

#[cfg(test)]
mod tests;

use super::mesh::{Grid, Mesh, MeshRows};
use super::model::{GridKind, Kernel, Model, OceanParams, Stepper};
use super::normals::{FaceNormals, NormalMethod};
use super::phillips::FftParams;
use crate::input::InputError;
use fill::{Fill, Source};
use parking_lot::RwLock;
use rustfft::num_complex::Complex;
pub use size::check_size;
use spectrum::Spectrum;
use std::ops::Range;
use std::sync::Arc;
use terms::Terms;
use transform::{Inverse2d, Strips, STRIP};

/// The FFT ocean model.
#[derive(Clone, Copy, Debug, Default)]
pub struct FftOcean;

impl Model for FftOcean {
    fn name(&self) -> &'static str {
        "fft"
    }

    fn doc(&self) -> &'static str {
        "Tessendorf's FFT ocean: a Phillips spectrum, choppy displacement and folds."
    }

    /// `reference`: eight fields from four transforms, checked against the direct sum of
    /// [`Spectrum::fields_f64`] in the tests; `fast`: the same heights and displacements from
    /// two of them, slopes and the Jacobian's diagonal from differences (`fill.rs`).
    fn kernels(&self) -> &'static [Kernel] {
        &[Kernel::Reference, Kernel::Fast]
    }

    fn normals(&self) -> &'static [NormalMethod] {
        &[NormalMethod::Analytic, NormalMethod::Neighbors]
    }

    /// The spectral slopes: the surface's own derivatives, at about half the cost of averaging
    /// the faces of the displaced mesh.
    fn default_normals(&self) -> NormalMethod {
        NormalMethod::Analytic
    }

    /// Helpers split the row pass and the column pass by rows, meeting at the frame loop's
    /// barrier between them ([`FftState::split`]); face normals at a band's edge would need
    /// the neighbouring band's vertices.
    fn splits_into_rows(&self, normals: NormalMethod) -> Result<(), InputError> {
        super::model::only_analytic_splits(normals)
    }

    fn check(&self, size: usize, normals: NormalMethod) -> Result<(), InputError> {
        if !self.normals().contains(&normals) {
            return Err(InputError(format!(
                "normals: the fft ocean offers `analytic` and `neighbors`, not `{}`",
                normals.name()
            )));
        }
        check_size(size)
    }

    fn yardstick(&self) -> (Kernel, NormalMethod) {
        (Kernel::Reference, NormalMethod::Analytic)
    }

    fn mesh(&self, grid: Grid) -> Mesh {
        Mesh::new(grid).with_fold()
    }

    fn rest_spacing(&self, grid: Grid, params: &OceanParams) -> f32 {
        (params.get::<FftParams>().patch_metres / grid.n as f64) as f32
    }

    /// The patch repeats without a seam, so it can be sampled at any point of the plane.
    fn grids(&self) -> &'static [GridKind] {
        &[GridKind::Regular, GridKind::Projected]
    }

    /// The patch computed on its own N×N grid, sampled bilinearly at each placed vertex
    /// ([`points::FftAtPoints`]).
    fn prepare_at_points(
        &self,
        grid: Grid,
        params: &OceanParams,
        kernel: Kernel,
    ) -> Result<Box<dyn Stepper>, InputError> {
        let state = self.state(grid, params, NormalMethod::Analytic, kernel)?;
        Ok(Box::new(points::FftAtPoints::new(state)))
    }

    fn prepare(
        &self,
        grid: Grid,
        params: &OceanParams,
        normals: NormalMethod,
        kernel: Kernel,
    ) -> Result<Box<dyn Stepper>, InputError> {
        Ok(Box::new(self.state(grid, params, normals, kernel)?))
    }
}

impl FftOcean {
    /// The checked per-run state of a regular-grid step.
    fn state(
        &self,
        grid: Grid,
        params: &OceanParams,
        normals: NormalMethod,
        kernel: Kernel,
    ) -> Result<FftState, InputError> {
        self.check(grid.n, normals)?;
        let fft = params.get::<FftParams>();
        fft.validate()?;
        let spectrum = Spectrum::new(&fft, grid.n);
        Ok(FftState::with_kernel(
            &spectrum,
            fft.patch_metres,
            fft.choppiness,
            normals,
            kernel,
        ))
    }
}

/// How the fill reads the column pass's output rows of each transform.
type Reader = for<'a> fn(&'a [Vec<Complex<f32>>]) -> Source<'a>;

/// The per-step machinery of a step or of one band of it: the spectrum's terms, the plan, and
/// the row and column passes' scratch.
#[derive(Clone, Debug)]
struct Passes {
    n: usize,
    /// Complex transforms per step: 4 for `reference`, 2 for `fast`.
    transforms: usize,
    terms: Arc<Terms>,
    inverse: Inverse2d,
    /// A few rows of each spectrum at t, transformed while they are in L1 (made on first use).
    spectra: Vec<Vec<Complex<f32>>>,
    /// The column pass's output rows of each transform.
    columns: Vec<Vec<Complex<f32>>>,
}

impl Passes {
    /// Rows `rows` of the spectra at t, transformed and scattered into `out`'s strips.
    fn row_pass(&mut self, t: f32, rows: Range<usize>, out: &mut [&mut Strips]) {
        let n = self.n;
        // About 8 KiB a transform, so that the batch of every transform stays in L1.
        let batch = (1024 / n).max(1);
        for spectrum in &mut self.spectra {
            spectrum.resize(batch * n, Complex::default());
        }
        self.spectra
            .resize(self.transforms, vec![Complex::default(); batch * n]);
        for first in rows.clone().step_by(batch) {
            let chunk = first..(first + batch).min(rows.end);
            let mut bufs: Vec<&mut [Complex<f32>]> = self
                .spectra
                .iter_mut()
                .map(|s| &mut s[..chunk.len() * n])
                .collect();
            self.terms.spectra(t, chunk.clone(), &mut bufs);
            for (buf, strips) in bufs.into_iter().zip(out.iter_mut()) {
                self.inverse.row_pass(buf, first, strips);
            }
        }
    }

    /// The column pass of the mesh rows `band` and their fill, a chunk of rows at a time
    /// (at most a strip's worth), each chunk filled while it is in cache; `ranges` are the
    /// column pass's output rows ([`FftState::ranges`]): the band, and for differences the
    /// row above it and the row below it, which the `halo` (0 or 1) rows either side of each
    /// filled row need.
    #[allow(clippy::too_many_arguments)]
    fn columns_and_fill(
        &mut self,
        parts: &[Vec<&Strips>],
        ranges: &[Range<usize>],
        halo: usize,
        fill: &Fill,
        source: Reader,
        rows: &mut MeshRows<'_>,
    ) {
        let n = self.n;
        self.columns.resize(self.transforms, Vec::new());
        for window in &mut self.columns {
            window.resize((STRIP + 2 * halo) * n, Complex::default());
        }
        // Rows in the window, and mesh rows of the band filled so far.
        let (mut have, mut filled) = (0, 0);
        for range in ranges {
            let mut i = range.start;
            while i < range.end {
                let end = range.end.min((i / STRIP + 1) * STRIP);
                let chunk = i..end;
                for (window, parts) in self.columns.iter_mut().zip(parts) {
                    let out = &mut window[have * n..(have + chunk.len()) * n];
                    self.inverse
                        .column_pass(parts, std::slice::from_ref(&chunk), out);
                }
                have += chunk.len();
                i = end;
                if have > 2 * halo {
                    let centres = have - 2 * halo;
                    fill.fill(source(&self.columns), rows, filled..filled + centres);
                    filled += centres;
                    // The last rows are the next rows' neighbours.
                    for window in &mut self.columns {
                        window.copy_within(centres * n..have * n, 0);
                    }
                    have = 2 * halo;
                }
            }
        }
        debug_assert_eq!(filled, rows.rows(), "every row of the band filled");
    }

    /// The output rows `ranges` of every transform, from the row pass's `parts` (per
    /// transform, together every row).
    fn column_pass(&mut self, parts: &[Vec<&Strips>], ranges: &[Range<usize>]) {
        let rows: usize = ranges.iter().map(|r| r.len()).sum();
        self.columns.resize(self.transforms, Vec::new());
        for (column, parts) in self.columns.iter_mut().zip(parts) {
            column.resize(rows * self.n, Complex::default());
            self.inverse.column_pass(parts, ranges, column);
        }
    }
}

/// The per-run state: the spectrum in the transforms' layout, the plan, the field buffers.
///
/// Eight real fields come out of four complex transforms, two per transform (a + ib, both
/// Hermitian, transforms to A + iB): (h, ∂Dx/∂y · [`Terms::dxy_scale`]), (Dx, Dy),
/// (∂h/∂x, ∂h/∂y), (∂Dx/∂x, ∂Dy/∂y); the `fast` kernel makes the first two and takes the rest
/// from differences (`fill.rs`).
#[derive(Clone, Debug)]
pub struct FftState {
    n: usize,
    kernel: Kernel,
    normals: NormalMethod,
    fill: Fill,
    faces: Option<FaceNormals>,
    passes: Passes,
    /// The whole row pass of each transform (made on first use: a state split among helpers
    /// never needs it).
    strips: Vec<Strips>,
}

impl FftState {
    /// The state for `spectrum` on a patch of `patch_metres`, with the `reference` kernel.
    pub fn new(
        spectrum: &Spectrum,
        patch_metres: f64,
        choppiness: f64,
        normals: NormalMethod,
    ) -> Self {
        Self::with_kernel(
            spectrum,
            patch_metres,
            choppiness,
            normals,
            Kernel::Reference,
        )
    }

    /// The state for `spectrum` on a patch of `patch_metres` with `kernel` (`reference`: four
    /// transforms; `fast`: two and differences).
    pub fn with_kernel(
        spectrum: &Spectrum,
        patch_metres: f64,
        choppiness: f64,
        normals: NormalMethod,
        kernel: Kernel,
    ) -> Self {
        let n = spectrum.n();
        let grid = Grid::new(n, (patch_metres / n as f64) as f32).expect("a checked size");
        let terms = Terms::new(spectrum);
        FftState {
            n,
            kernel,
            normals,
            fill: Fill {
                n,
                spacing: grid.spacing,
                lambda: choppiness as f32,
                // Exact: the scale is a power of two.
                unscale: 1.0 / terms.dxy_scale,
                analytic: normals == NormalMethod::Analytic,
                chunk: fill::CHUNK,
            },
            faces: (normals == NormalMethod::Neighbors).then(|| FaceNormals::new(grid)),
            passes: Passes {
                n,
                transforms: match kernel {
                    Kernel::Reference => 4,
                    Kernel::Fast => 2,
                },
                terms: Arc::new(terms),
                inverse: Inverse2d::new(n),
                spectra: Vec::new(),
                columns: Vec::new(),
            },
            strips: Vec::new(),
        }
    }

    /// Vertex spacing L ÷ N in metres.
    pub fn spacing(&self) -> f32 {
        self.fill.spacing
    }

    /// The column pass's output rows for the mesh rows `band`: the band, and for differences
    /// the row above it and the row below it (wrapped).
    fn ranges(&self, band: Range<usize>) -> Vec<Range<usize>> {
        let n = self.n;
        match self.kernel {
            Kernel::Reference => vec![band],
            Kernel::Fast => {
                let (above, below) = ((band.start + n - 1) % n, band.end % n);
                vec![above..above + 1, band, below..below + 1]
            }
        }
    }

    /// The spectra at t and their whole row pass.
    fn whole_row_pass(&mut self, t: f32) {
        let n = self.n;
        self.strips
            .resize_with(self.passes.transforms, || Strips::new(n, 0..n));
        let mut out: Vec<&mut Strips> = self.strips.iter_mut().collect();
        self.passes.row_pass(t, 0..n, &mut out);
    }

    /// The packed spectra at time t (see [`FftState`]) and their transforms, the mesh's rows
    /// `band` of them (and the rows beside it that differences read) in the column pass's
    /// output.
    fn transform_band(&mut self, t: f32, band: Range<usize>) {
        self.whole_row_pass(t);
        let parts: Vec<Vec<&Strips>> = self.strips.iter().map(|s| vec![s]).collect();
        let ranges = self.ranges(band);
        self.passes.column_pass(&parts, &ranges);
    }

    /// The spectra at t and their transforms, every row: what a whole step computes before it
    /// fills the mesh.
    pub fn transform(&mut self, t: f32) {
        self.transform_band(t, 0..self.n);
    }

    /// The rows either side of a filled row that its fill reads, and how it reads the column
    /// pass's output.
    fn reading(&self) -> (usize, Reader) {
        match self.kernel {
            Kernel::Reference => (0, |c| Source::Spectral([&c[0], &c[1], &c[2], &c[3]])),
            Kernel::Fast => (1, |c| Source::Differences([&c[0], &c[1]])),
        }
    }

    /// The column pass of `band` from `parts` (per transform) and the fill of its rows.
    fn columns_and_fill(&mut self, parts: &[Vec<&Strips>], rows: &mut MeshRows<'_>) {
        let band = rows.first_row..rows.first_row + rows.rows();
        let ranges = self.ranges(band);
        let (halo, source) = self.reading();
        self.passes
            .columns_and_fill(parts, &ranges, halo, &self.fill, source, rows);
    }

    /// Every step's work for the mesh rows `rows`: the whole row pass, then the rows' column
    /// pass and fill.
    fn step_band(&mut self, t: f32, mut rows: MeshRows<'_>) {
        self.whole_row_pass(t);
        let strips = std::mem::take(&mut self.strips);
        let parts: Vec<Vec<&Strips>> = strips.iter().map(|s| vec![s]).collect();
        self.columns_and_fill(&parts, &mut rows);
        drop(parts);
        self.strips = strips;
    }
}

impl Stepper for FftState {
    fn step(&mut self, t: f32, mesh: &mut Mesh) {
        self.step_band(t, mesh.rows_mut(0..self.n));
        if let Some(faces) = &mut self.faces {
            faces.compute(mesh, self.normals);
        }
    }

    /// Correct but whole: the band needs every row's row pass, so this computes it all;
    /// helpers sharing a mesh step the phases of [`FftState::split`]'s band steppers instead.
    fn step_rows(&mut self, t: f32, rows: MeshRows<'_>) {
        assert_eq!(
            self.normals,
            NormalMethod::Analytic,
            "step_rows needs analytic normals"
        );
        self.step_band(t, rows);
    }

    fn boxed_clone(&self) -> Box<dyn Stepper> {
        Box::new(self.clone())
    }

    fn split(&self, bands: &[Range<usize>]) -> Vec<Box<dyn Stepper>> {
        self.bands(bands)
            .into_iter()
            .map(|band| Box::new(band) as Box<dyn Stepper>)
            .collect()
    }
}

impl FftState {
    /// The steppers of helpers that fill `bands` of the patch, sharing their row passes.
    fn bands(&self, bands: &[Range<usize>]) -> Vec<FftBand> {
        let n = self.n;
        let shared = Arc::new(RowPasses {
            bands: bands.to_vec(),
            parts: bands
                .iter()
                .map(|r| {
                    (0..self.passes.transforms)
                        .map(|_| RwLock::new(Strips::new(n, r.clone())))
                        .collect()
                })
                .collect(),
        });
        let alone = FftState {
            strips: Vec::new(),
            ..self.clone()
        };
        (0..bands.len())
            .map(|band| FftBand {
                whole: alone.clone(),
                band,
                shared: Arc::clone(&shared),
            })
            .collect()
    }
}

/// The row passes of every band of a split step, shared by its helpers: band h's rows
/// (x-wavenumber indices in its rows) of each transform, written in phase 0 by helper h alone
/// and read by every helper in phase 1. The locks are never contended when the frame loop's
/// barrier orders the phases; they make a misordered use wrong rather than unsound.
#[derive(Debug)]
struct RowPasses {
    bands: Vec<Range<usize>>,
    /// Per band, per transform.
    parts: Vec<Vec<RwLock<Strips>>>,
}

/// One helper's part of an FFT step split among helpers by rows: phase 0 builds its band's
/// rows of the spectra and their row pass; phase 1 gathers its band's columns from every
/// band, transforms them and fills its rows of the mesh. The result is bit-identical to
/// [`FftState::step`]: every row and column is the same transform of the same values.
#[derive(Clone, Debug)]
pub struct FftBand {
    /// The per-run state: terms, plan, and scratch for [`Stepper::step`] alone.
    whole: FftState,
    band: usize,
    shared: Arc<RowPasses>,
}

impl FftBand {
    /// Phase 0: this band's rows of the spectra at t, and their row pass.
    fn row_pass(&mut self, t: f32) {
        let rows = self.shared.bands[self.band].clone();
        let mut guards: Vec<_> = self.shared.parts[self.band]
            .iter()
            .map(|p| p.write())
            .collect();
        let mut out: Vec<&mut Strips> = guards.iter_mut().map(|g| &mut **g).collect();
        self.whole.passes.row_pass(t, rows, &mut out);
    }

    /// Phase 1: this band's rows of the column pass (and the rows beside it that differences
    /// read), from every band's row pass, and the mesh rows they make.
    fn column_pass(&mut self, mut rows: MeshRows<'_>) {
        let guards: Vec<Vec<_>> = self
            .shared
            .parts
            .iter()
            .map(|band| band.iter().map(|p| p.read()).collect())
            .collect();
        let parts: Vec<Vec<&Strips>> = (0..self.whole.passes.transforms)
            .map(|f| guards.iter().map(|band| &*band[f]).collect())
            .collect();
        self.whole.columns_and_fill(&parts, &mut rows);
    }
}

impl Stepper for FftBand {
    fn step(&mut self, t: f32, mesh: &mut Mesh) {
        self.whole.step(t, mesh);
    }

    fn step_rows(&mut self, t: f32, rows: MeshRows<'_>) {
        self.whole.step_rows(t, rows);
    }

    fn boxed_clone(&self) -> Box<dyn Stepper> {
        Box::new(self.clone())
    }

    fn phases(&self) -> usize {
        2
    }

    fn step_phase(&mut self, phase: usize, t: f32, rows: MeshRows<'_>) {
        let band = &self.shared.bands[self.band];
        assert_eq!(
            (rows.first_row, rows.rows()),
            (band.start, band.len()),
            "a band stepper fills its own band"
        );
        match phase {
            0 => self.row_pass(t),
            1 => self.column_pass(rows),
            _ => unreachable!("two phases"),
        }
    }

    fn split(&self, bands: &[Range<usize>]) -> Vec<Box<dyn Stepper>> {
        self.whole.split(bands)
    }
}
