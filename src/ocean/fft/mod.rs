//! The FFT ocean (Tessendorf's method, `../shared/reference/gpu-fft-ocean-slides.md`): heights,
//! choppy displacements, slopes and the displacement's Jacobian from inverse 2-D FFTs of a
//! Phillips spectrum sampled once per run; the fold value J and its direction per vertex.

pub mod points;
pub mod size;
pub mod spectrum;
pub mod transform;

#[cfg(test)]
mod tests;

use super::mesh::{Grid, Mesh, MeshRows};
use super::model::{GridKind, Kernel, Model, OceanParams, Stepper};
use super::normals::{FaceNormals, NormalMethod};
use crate::input::InputError;
use glam::Vec3;
use parking_lot::RwLock;
use rustfft::num_complex::Complex;
pub use size::check_size;
use spectrum::Spectrum;
use std::f64::consts::TAU;
use std::ops::Range;
use std::sync::Arc;
use transform::Inverse2d;

/// The FFT ocean model.
#[derive(Clone, Copy, Debug, Default)]
pub struct FftOcean;

impl Model for FftOcean {
    /// One implementation, listed under the default kernel's name; its oracle is the direct
    /// sum of [`Spectrum::fields_f64`] in the tests.
    fn kernels(&self) -> &'static [Kernel] {
        &[Kernel::Reference]
    }

    fn normals(&self) -> &'static [NormalMethod] {
        &[NormalMethod::Analytic, NormalMethod::Neighbors]
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
        (params.fft.patch_metres / grid.n as f64) as f32
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
        if !self.kernels().contains(&kernel) {
            return Err(InputError(format!(
                "kernel: the fft ocean has one kernel, `reference`, not `{}`",
                kernel.name()
            )));
        }
        self.check(grid.n, normals)?;
        params.fft.validate()?;
        let spectrum = Spectrum::new(&params.fft, grid.n);
        Ok(FftState::new(
            &spectrum,
            params.fft.patch_metres,
            params.fft.choppiness,
            normals,
        ))
    }
}

/// The sampled spectrum in the transforms' layout (b·N + a, see [`Inverse2d`]), in f32 but for
/// ω, kept in f64 so that ωt keeps its fraction of a turn at large t.
#[derive(Clone, Debug)]
struct Terms {
    /// Wavenumber of each index (the same for x and y: the patch is square).
    k: Vec<f32>,
    /// h̃₀(k).
    h0: Vec<Complex<f32>>,
    /// conj(h̃₀(−k)).
    h0_minus: Vec<Complex<f32>>,
    omega: Vec<f64>,
    /// 1/|k| (0 at k = 0).
    inv_k: Vec<f32>,
    /// ∂Dx/∂y shares a transform with h, which is larger by about |k|⁻¹ and would drown it in
    /// the transform's rounding: it is packed times this power of two, near h's RMS over its.
    dxy_scale: f32,
}

impl Terms {
    fn new(spectrum: &Spectrum) -> Self {
        let n = spectrum.n();
        let transposed = |f: &dyn Fn(usize, usize) -> Complex<f64>| -> Vec<Complex<f32>> {
            (0..n)
                .flat_map(|b| (0..n).map(move |a| (a, b)))
                .map(|(a, b)| {
                    let c = f(a, b);
                    Complex::new(c.re as f32, c.im as f32)
                })
                .collect()
        };
        let inv_k = transposed(&|a, b| {
            let (kx, ky) = spectrum.wave_vector(a, b);
            let k = kx.hypot(ky);
            Complex::new(if k > 0.0 { 1.0 / k } else { 0.0 }, 0.0)
        });
        let (mut h_power, mut dxy_power) = (0.0, 0.0);
        for a in 0..n {
            for b in 0..n {
                let (kx, ky) = spectrum.wave_vector(a, b);
                let p = spectrum.h0(a, b).norm_sqr();
                h_power += p;
                dxy_power += p * (kx * ky).powi(2) / (kx * kx + ky * ky).max(f64::MIN_POSITIVE);
            }
        }
        let ratio = (h_power / dxy_power).sqrt();
        let dxy_scale = if ratio.is_finite() && ratio > 0.0 {
            2f32.powi(ratio.log2().round().clamp(-60.0, 60.0) as i32)
        } else {
            1.0
        };
        Terms {
            dxy_scale,
            k: (0..n)
                .map(|m| spectrum.wave_vector(0, m).0 as f32)
                .collect(),
            h0: transposed(&|a, b| spectrum.h0(a, b)),
            h0_minus: transposed(&|a, b| spectrum.h0_minus(a, b)),
            omega: (0..n)
                .flat_map(|b| (0..n).map(move |a| (a, b)))
                .map(|(a, b)| spectrum.omega(a, b))
                .collect(),
            inv_k: inv_k.into_iter().map(|c| c.re).collect(),
        }
    }

    /// The four packed spectra at time t of the transposed rows `rows` (x-wavenumber indices),
    /// row `rows.start` at the start of each of `out`.
    fn spectra(&self, t: f32, rows: Range<usize>, out: [&mut [Complex<f32>]; 4]) {
        let n = self.k.len();
        let t = t as f64;
        let [f0, f1, f2, f3] = out;
        for b in rows.clone() {
            let kx = self.k[b];
            for a in 0..n {
                let (e, o) = (b * n + a, (b - rows.start) * n + a);
                let ky = self.k[a];
                let ik = self.inv_k[e];
                let h = self.coefficient(e, t);
                f0[o] = h * Complex::new(1.0, kx * ky * ik * self.dxy_scale);
                f1[o] = h * Complex::new(ky * ik, -kx * ik);
                f2[o] = h * Complex::new(-ky, kx);
                f3[o] = h * Complex::new(kx * kx * ik, ky * ky * ik);
            }
        }
    }

    /// h̃(k, t) = h̃₀(k)·e^{iωt} + conj(h̃₀(−k))·e^{−iωt} at element e.
    fn coefficient(&self, e: usize, t: f64) -> Complex<f32> {
        let phase = self.omega[e] * t;
        // Whole turns dropped by truncation (a cast, where `floor` is a libm call on the
        // baseline x86-64 target): the rest lies within one turn of 0 either side.
        let (s, c) = ((phase - TAU * (phase / TAU) as i64 as f64) as f32).sin_cos();
        let turn = Complex::new(c, s);
        self.h0[e] * turn + self.h0_minus[e] * turn.conj()
    }
}

/// The per-run state: the spectrum in the transforms' layout, the plan, the field buffers.
///
/// Eight real fields come out of four complex transforms, two per transform (a + ib, both
/// Hermitian, transforms to A + iB): (h, ∂Dx/∂y · [`Terms::dxy_scale`]), (Dx, Dy),
/// (∂h/∂x, ∂h/∂y), (∂Dx/∂x, ∂Dy/∂y).
#[derive(Clone, Debug)]
pub struct FftState {
    n: usize,
    /// L ÷ N in metres.
    spacing: f32,
    choppiness: f32,
    normals: NormalMethod,
    faces: Option<FaceNormals>,
    terms: Terms,
    fields: [Vec<Complex<f32>>; 4],
    inverse: Inverse2d,
}

impl FftState {
    /// The state for `spectrum` on a patch of `patch_metres`.
    pub fn new(
        spectrum: &Spectrum,
        patch_metres: f64,
        choppiness: f64,
        normals: NormalMethod,
    ) -> Self {
        let n = spectrum.n();
        let grid = Grid::new(n, (patch_metres / n as f64) as f32).expect("a checked size");
        FftState {
            n,
            spacing: grid.spacing,
            choppiness: choppiness as f32,
            normals,
            faces: (normals == NormalMethod::Neighbors).then(|| FaceNormals::new(grid)),
            terms: Terms::new(spectrum),
            fields: Default::default(),
            inverse: Inverse2d::new(n),
        }
    }

    /// Vertex spacing L ÷ N in metres.
    pub fn spacing(&self) -> f32 {
        self.spacing
    }

    /// The four packed spectra at time t (see [`FftState`]), then their transforms. The
    /// buffers are made on first use: a state split among helpers never needs them.
    pub fn transform(&mut self, t: f32) {
        let n = self.n;
        for field in &mut self.fields {
            field.resize(n * n, Complex::default());
        }
        let [f0, f1, f2, f3] = &mut self.fields;
        self.terms.spectra(t, 0..n, [f0, f1, f2, f3]);
        for field in &mut self.fields {
            self.inverse.process(field);
        }
    }

    /// The unpacked fields into one band of rows: displaced positions, heights, fold value and
    /// direction, and the analytic normal when asked for. `fields` start at the band's first
    /// row.
    fn fill(&self, fields: [&[Complex<f32>]; 4], rows: MeshRows<'_>) {
        let n = self.n;
        let lambda = self.choppiness;
        let analytic = self.normals == NormalMethod::Analytic;
        let [hd, dxy, slope, dd] = fields;
        // Exact: the scale is a power of two.
        let unscale = 1.0 / self.terms.dxy_scale;
        for r in 0..rows.rows() {
            let i = rows.first_row + r;
            for j in 0..n {
                let v = r * n + j;
                let (hd, dxy, slope, dd) = (hd[v], dxy[v], slope[v], dd[v]);
                rows.x[v] = j as f32 * self.spacing + lambda * dxy.re;
                rows.y[v] = i as f32 * self.spacing + lambda * dxy.im;
                rows.z[v] = hd.re;
                // The Jacobian of (x, y) ↦ (x + λDx, y + λDy): [[a, b], [b, d]].
                let a = 1.0 + lambda * dd.re;
                let d = 1.0 + lambda * dd.im;
                let b = lambda * hd.im * unscale;
                rows.fold[v] = a * d - b * b;
                let (dx, dy) = compressing_direction(a, b, d);
                rows.fold_dx[v] = dx;
                rows.fold_dy[v] = dy;
                if analytic {
                    // The cross product of the displaced surface's tangents ∂/∂x and ∂/∂y.
                    let tx = Vec3::new(a, b, slope.re);
                    let ty = Vec3::new(b, d, slope.im);
                    let normal = tx.cross(ty).normalize_or(Vec3::Z);
                    rows.nx[v] = normal.x;
                    rows.ny[v] = normal.y;
                    rows.nz[v] = normal.z;
                }
            }
        }
    }
}

/// The unit eigenvector of the smaller eigenvalue of the symmetric [[a, b], [b, d]], the
/// direction in which the surface compresses; (0, 1) where every direction is one.
fn compressing_direction(a: f32, b: f32, d: f32) -> (f32, f32) {
    let half = 0.5 * (a - d);
    let r = (half * half + b * b).sqrt();
    // Of the two rows of M − μI, μ = (a + d)/2 − r, the one with the larger diagonal entry
    // (h + r or r − h) gives the eigenvector without cancellation.
    let (x, y) = if half >= 0.0 {
        (-b, half + r)
    } else {
        (r - half, -b)
    };
    let len = (x * x + y * y).sqrt();
    if len > 0.0 {
        (x / len, y / len)
    } else {
        (0.0, 1.0)
    }
}

impl FftState {
    /// The whole transforms' rows from `first_row` on, for [`FftState::fill`].
    fn whole_fields(&self, first_row: usize) -> [&[Complex<f32>]; 4] {
        let start = first_row * self.n;
        std::array::from_fn(|f| &self.fields[f][start..])
    }
}

impl Stepper for FftState {
    fn step(&mut self, t: f32, mesh: &mut Mesh) {
        self.transform(t);
        self.fill(self.whole_fields(0), mesh.rows_mut(0..self.n));
        if let Some(faces) = &mut self.faces {
            faces.compute(mesh, self.normals);
        }
    }

    /// Correct but whole: the band needs every row's transforms, so this computes them all;
    /// helpers sharing a mesh step the phases of [`FftState::split`]'s band steppers instead.
    fn step_rows(&mut self, t: f32, rows: MeshRows<'_>) {
        assert_eq!(
            self.normals,
            NormalMethod::Analytic,
            "step_rows needs analytic normals"
        );
        self.transform(t);
        self.fill(self.whole_fields(rows.first_row), rows);
    }

    fn boxed_clone(&self) -> Box<dyn Stepper> {
        Box::new(self.clone())
    }

    fn split(&self, bands: &[Range<usize>]) -> Vec<Box<dyn Stepper>> {
        let n = self.n;
        let shared = Arc::new(RowPasses {
            bands: bands.to_vec(),
            fields: bands
                .iter()
                .map(|r| {
                    std::array::from_fn(|_| RwLock::new(vec![Complex::default(); r.len() * n]))
                })
                .collect(),
        });
        let alone = FftState {
            fields: Default::default(),
            ..self.clone()
        };
        bands
            .iter()
            .enumerate()
            .map(|(band, r)| {
                Box::new(FftBand {
                    whole: alone.clone(),
                    band,
                    shared: Arc::clone(&shared),
                    columns: std::array::from_fn(|_| vec![Complex::default(); r.len() * n]),
                }) as Box<dyn Stepper>
            })
            .collect()
    }
}

/// Output rows a column pass gathers at once.
const GATHER: usize = 8;

/// The first pass of every band of a split step, shared by its helpers: band h's transposed
/// rows (x-wavenumber indices in its rows) of each field, written in phase 0 by helper h alone
/// and read by every helper in phase 1. The locks are never contended when the frame loop's
/// barrier orders the phases; they make a misordered use wrong rather than unsound.
#[derive(Debug)]
struct RowPasses {
    bands: Vec<Range<usize>>,
    fields: Vec<[RwLock<Vec<Complex<f32>>>; 4]>,
}

/// One helper's part of an FFT step split among helpers by rows: phase 0 builds its band's
/// rows of the four spectra and transforms them; phase 1 gathers its band's columns from every
/// band (the transpose), transforms them and fills its rows of the mesh. The result is
/// bit-identical to [`FftState::step`]: every row is the same transform of the same values.
#[derive(Clone, Debug)]
pub struct FftBand {
    /// The per-run state: terms, plan, and whole buffers for [`Stepper::step`] alone.
    whole: FftState,
    band: usize,
    shared: Arc<RowPasses>,
    /// This band's rows after the transpose and the second pass, one buffer per field.
    columns: [Vec<Complex<f32>>; 4],
}

impl FftBand {
    /// Phase 0: this band's rows of the four spectra at t, and their row pass.
    fn row_pass(&mut self, t: f32) {
        let rows = self.shared.bands[self.band].clone();
        let mut out = self.shared.fields[self.band].each_ref().map(|f| f.write());
        let [f0, f1, f2, f3] = &mut out;
        self.whole.terms.spectra(t, rows, [f0, f1, f2, f3]);
        for field in &mut out {
            self.whole.inverse.rows(field);
        }
    }

    /// Phase 1: this band's columns of every band's rows (its rows of the transposed fields),
    /// their pass, and the mesh rows they make.
    fn column_pass(&mut self, rows: MeshRows<'_>) {
        let n = self.whole.n;
        let mine = self.shared.bands[self.band].clone();
        for (f, column) in self.columns.iter_mut().enumerate() {
            for (band, from) in self.shared.bands.iter().zip(&self.shared.fields) {
                let from = from[f].read();
                // Eight output rows at a time: rows N apart share a cache set, and eight fit
                // its ways, so each output line stays in L1 while it fills.
                for i0 in (0..mine.len()).step_by(GATHER) {
                    let i1 = (i0 + GATHER).min(mine.len());
                    for (r, b) in band.clone().enumerate() {
                        let at = r * n + mine.start;
                        for (i, value) in (i0..i1).zip(&from[at + i0..at + i1]) {
                            column[i * n + b] = *value;
                        }
                    }
                }
            }
            self.whole.inverse.rows(column);
        }
        let fields = self.columns.each_ref().map(|c| c.as_slice());
        self.whole.fill(fields, rows);
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
