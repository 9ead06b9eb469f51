//! The FFT ocean (Tessendorf's method, `../shared/reference/gpu-fft-ocean-slides.md`): heights,
//! choppy displacements, slopes and the displacement's Jacobian from inverse 2-D FFTs of a
//! Phillips spectrum sampled once per run; the fold value J and its direction per vertex.

pub mod size;
pub mod spectrum;
pub mod transform;

#[cfg(test)]
mod tests;

use super::mesh::{Grid, Mesh, MeshRows};
use super::model::{Kernel, Model, OceanParams, Stepper};
use super::normals::{FaceNormals, NormalMethod};
use crate::input::InputError;
use glam::Vec3;
use rustfft::num_complex::Complex;
pub use size::check_size;
use spectrum::Spectrum;
use std::f64::consts::TAU;
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

    /// Every row of the output needs every row of the spectrum: rows among helpers need a
    /// barrier between the row and the column passes, which is not built yet.
    fn splits_into_rows(&self, _normals: NormalMethod) -> Result<(), InputError> {
        Err(InputError(
            "helpers: the fft ocean runs on 1 helper (its column transforms need every row; \
             splitting them among helpers is not supported yet)"
                .into(),
        ))
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

    fn prepare(
        &self,
        grid: Grid,
        params: &OceanParams,
        normals: NormalMethod,
        kernel: Kernel,
    ) -> Result<Box<dyn Stepper>, InputError> {
        if !self.kernels().contains(&kernel) {
            return Err(InputError(format!(
                "kernel: the fft ocean has one kernel, `reference`, not `{}`",
                kernel.name()
            )));
        }
        self.check(grid.n, normals)?;
        params.fft.validate()?;
        let spectrum = Spectrum::new(&params.fft, grid.n);
        Ok(Box::new(FftState::new(
            &spectrum,
            params.fft.patch_metres,
            params.fft.choppiness,
            normals,
        )))
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
            fields: std::array::from_fn(|_| vec![Complex::default(); n * n]),
            inverse: Inverse2d::new(n),
        }
    }

    /// Vertex spacing L ÷ N in metres.
    pub fn spacing(&self) -> f32 {
        self.spacing
    }

    /// The four packed spectra at time t (see [`FftState`]), then their transforms.
    pub fn transform(&mut self, t: f32) {
        self.spectra(t);
        for field in &mut self.fields {
            self.inverse.process(field);
        }
    }

    /// The four packed spectra at time t, in the transforms' layout.
    fn spectra(&mut self, t: f32) {
        let n = self.n;
        let t = t as f64;
        let terms = &self.terms;
        let [f0, f1, f2, f3] = &mut self.fields;
        for b in 0..n {
            let kx = terms.k[b];
            for a in 0..n {
                let e = b * n + a;
                let ky = terms.k[a];
                let ik = terms.inv_k[e];
                let h = terms.coefficient(e, t);
                f0[e] = h * Complex::new(1.0, kx * ky * ik * terms.dxy_scale);
                f1[e] = h * Complex::new(ky * ik, -kx * ik);
                f2[e] = h * Complex::new(-ky, kx);
                f3[e] = h * Complex::new(kx * kx * ik, ky * ky * ik);
            }
        }
    }

    /// The unpacked fields into one band of rows: displaced positions, heights, fold value and
    /// direction, and the analytic normal when asked for.
    fn fill(&self, rows: MeshRows<'_>) {
        let n = self.n;
        let lambda = self.choppiness;
        let analytic = self.normals == NormalMethod::Analytic;
        let [hd, dxy, slope, dd] = &self.fields;
        // Exact: the scale is a power of two.
        let unscale = 1.0 / self.terms.dxy_scale;
        for r in 0..rows.rows() {
            let i = rows.first_row + r;
            for j in 0..n {
                let (v, e) = (r * n + j, i * n + j);
                let (hd, dxy, slope, dd) = (hd[e], dxy[e], slope[e], dd[e]);
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

impl Stepper for FftState {
    fn step(&mut self, t: f32, mesh: &mut Mesh) {
        self.transform(t);
        self.fill(mesh.rows_mut(0..self.n));
        if let Some(faces) = &mut self.faces {
            faces.compute(mesh, self.normals);
        }
    }

    /// Correct but whole: the band needs every row's transforms, so this computes them all
    /// (one helper only: [`FftOcean::splits_into_rows`]).
    fn step_rows(&mut self, t: f32, rows: MeshRows<'_>) {
        assert_eq!(
            self.normals,
            NormalMethod::Analytic,
            "step_rows needs analytic normals"
        );
        self.transform(t);
        self.fill(rows);
    }

    fn boxed_clone(&self) -> Box<dyn Stepper> {
        Box::new(self.clone())
    }
}
