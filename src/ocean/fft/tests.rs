//! The FFT path against the direct f64 sum of the same spectrum, and the physics the surface
//! must show: real transforms, seamless tiles, Parseval's variance, a mode's phase speed, no
//! fold without choppiness.

use super::*;
use crate::ocean::phillips::FftParams;

/// Steps a mesh of size `n` at time `t`.
fn surface(params: &FftParams, n: usize, t: f32, normals: NormalMethod) -> (FftState, Mesh) {
    let spectrum = Spectrum::new(params, n);
    let mut state = FftState::new(&spectrum, params.patch_metres, params.choppiness, normals);
    let mut mesh = FftOcean.mesh(Grid::new(n, state.spacing()).unwrap());
    state.step(t, &mut mesh);
    // The step fills the mesh chunk by chunk; the whole fields, for the tests to read.
    state.transform(t);
    (state, mesh)
}

/// The eight unpacked fields of vertex e, in the order of [`Spectrum::fields_f64`].
fn fields(state: &FftState, e: usize) -> [f64; 8] {
    let [hd, d, slope, dd] = std::array::from_fn(|f| state.passes.columns[f][e]);
    let dxy = hd.im / state.passes.terms.dxy_scale;
    [hd.re, d.re, d.im, slope.re, slope.im, dd.re, dd.im, dxy].map(f64::from)
}

/// The mean of the heights' squares.
fn mean_square(z: &[f32]) -> f64 {
    z.iter().map(|&z| (z as f64).powi(2)).sum::<f64>() / z.len() as f64
}

/// The largest error of each field against the oracle, over the field's largest value.
fn relative_errors(params: &FftParams, n: usize, t: f32) -> [f64; 8] {
    let (state, _) = surface(params, n, t, NormalMethod::Analytic);
    let spectrum = Spectrum::new(params, n);
    let dx = params.patch_metres / n as f64;
    let mut err = [0.0f64; 8];
    let mut scale = [0.0f64; 8];
    for i in 0..n {
        for j in 0..n {
            let want = spectrum.fields_f64(j as f64 * dx, i as f64 * dx, t as f64);
            let got = fields(&state, i * n + j);
            for f in 0..8 {
                err[f] = err[f].max((got[f] - want[f]).abs());
                scale[f] = scale[f].max(want[f].abs());
            }
        }
    }
    std::array::from_fn(|f| err[f] / scale[f])
}

/// f32 transforms of f32 coefficients: each coefficient is rounded once (ε = 6e-8), the
/// phase's sine and cosine add about ε, and an FFT's error grows as ε·log₂N times the
/// field's norm; 1e-6 of the field's largest value is 17 ε, four times the largest error
/// measured at N = 16, 32 and 40 (2.6e-7). A transform that mixed up two fields, a sign or a
/// factor of k would be off by the field's own size.
const ORACLE_TOLERANCE: f64 = 1e-6;

#[test]
fn the_transforms_agree_with_the_direct_sum() {
    for n in [16, 32, 40] {
        for t in [0.0, 7.3, 1000.0] {
            let errors = relative_errors(&FftParams::default(), n, t);
            for (f, e) in errors.iter().enumerate() {
                assert!(
                    *e < ORACLE_TOLERANCE,
                    "n={n} t={t} field {f}: {e:e} of its largest value ({errors:?})"
                );
            }
        }
    }
}

#[test]
fn the_mesh_is_built_from_the_fields() {
    let params = FftParams {
        choppiness: 1.5,
        ..FftParams::default()
    };
    let (state, mesh) = surface(&params, 32, 4.0, NormalMethod::Analytic);
    let lambda = 1.5;
    let spectrum = Spectrum::new(&params, 32);
    let dx = params.patch_metres / 32.0;
    let mut max_fold_err = 0.0f64;
    for (e, (&x, &z)) in mesh.x.iter().zip(mesh.z.iter()).enumerate() {
        let (i, j) = (e / 32, e % 32);
        let f = fields(&state, e);
        assert_eq!(z as f64, f[0]);
        assert!((x as f64 - (j as f64 * dx + lambda * f[1])).abs() < 1e-3);
        assert!((mesh.y[e] as f64 - (i as f64 * dx + lambda * f[2])).abs() < 1e-3);
        let w = spectrum.fields_f64(j as f64 * dx, i as f64 * dx, 4.0);
        let (a, d, b) = (1.0 + lambda * w[5], 1.0 + lambda * w[6], lambda * w[7]);
        let fold = a * d - b * b;
        max_fold_err = max_fold_err.max((mesh.fold[e] as f64 - fold).abs());
        // The fold direction is the unit eigenvector of the smaller eigenvalue.
        let small = (a + d) / 2.0 - (((a - d) / 2.0).powi(2) + b * b).sqrt();
        let (vx, vy) = (mesh.fold_dx[e] as f64, mesh.fold_dy[e] as f64);
        assert!((vx.hypot(vy) - 1.0).abs() < 1e-6, "unit direction");
        let (mx, my) = (a * vx + b * vy, b * vx + d * vy);
        assert!(
            (mx - small * vx).hypot(my - small * vy) < 1e-4,
            "vertex {e}: not the smaller eigenvector"
        );
        // The analytic normal is the cross product of the displaced surface's tangents.
        let n = [b * w[4] - w[3] * d, w[3] * b - a * w[4], fold];
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        let got = [mesh.nx[e], mesh.ny[e], mesh.nz[e]].map(f64::from);
        for c in 0..3 {
            assert!((got[c] - n[c] / len).abs() < 1e-4, "vertex {e} normal");
        }
    }
    assert!(max_fold_err < 1e-4, "fold error {max_fold_err}");
    assert!(
        mesh.fold.iter().any(|&j| (j - 1.0).abs() > 0.01),
        "λ = 1.5 moves the surface"
    );
}

#[test]
fn one_field_alone_transforms_to_a_real_field() {
    let n = 64;
    let spectrum = Spectrum::new(&FftParams::default(), n);
    let terms = Terms::new(&spectrum);
    let mut height: Vec<Complex<f32>> = (0..n * n).map(|e| terms.coefficient(e, 5.0)).collect();
    Inverse2d::new(n).process(&mut height);
    let re = height.iter().map(|c| c.re.abs()).fold(0.0, f32::max);
    let im = height.iter().map(|c| c.im.abs()).fold(0.0, f32::max);
    assert!(re > 0.1, "a sea, not a flat field ({re})");
    assert!(
        im < 1e-6 * re,
        "imaginary parts {im} against heights up to {re}"
    );
}

#[test]
fn the_surface_tiles_without_a_seam() {
    let n = 64;
    let (_, mesh) = surface(&FftParams::default(), n, 3.0, NormalMethod::Analytic);
    let z = |i: usize, j: usize| mesh.z[i * n + j];
    let mut inner = 0.0f32;
    let mut seam = 0.0f32;
    for i in 0..n {
        for j in 0..n - 1 {
            inner = inner.max((z(i, j + 1) - z(i, j)).abs());
            inner = inner.max((z(j + 1, i) - z(j, i)).abs());
        }
        seam = seam.max((z(i, 0) - z(i, n - 1)).abs());
        seam = seam.max((z(0, i) - z(n - 1, i)).abs());
    }
    assert!(
        seam <= inner,
        "seam step {seam} > largest step inside {inner}"
    );
    // The direct sum is periodic by construction: the vertex one patch away is vertex 0.
    let spectrum = Spectrum::new(&FftParams::default(), n);
    let l = FftParams::default().patch_metres;
    let beyond = spectrum.fields_f64(l, l, 3.0)[0];
    assert!(
        (beyond - z(0, 0) as f64).abs() < 1e-4,
        "{beyond} vs {}",
        z(0, 0)
    );
}

#[test]
fn no_choppiness_no_fold_and_no_displacement() {
    let params = FftParams {
        choppiness: 0.0,
        ..FftParams::default()
    };
    let (state, mesh) = surface(&params, 32, 2.0, NormalMethod::Analytic);
    assert!(mesh.fold.iter().all(|&j| j == 1.0));
    let rest = Mesh::new(Grid::new(32, state.spacing()).unwrap());
    assert_eq!((&mesh.x, &mesh.y), (&rest.x, &rest.y));
}

#[test]
fn the_heights_variance_is_the_spectrum_sum() {
    for (n, t) in [(64, 0.0), (256, 11.0)] {
        let params = FftParams::default();
        let (_, mesh) = surface(&params, n, t, NormalMethod::Analytic);
        let mean_square = mean_square(&mesh.z);
        let power = Spectrum::new(&params, n).power(t as f64);
        assert!(
            (mean_square / power - 1.0).abs() < 1e-4,
            "n={n}: mean of h² {mean_square}, Σ|h̃|² {power}"
        );
    }
}

#[test]
fn a_single_mode_moves_at_its_phase_speed() {
    let params = FftParams {
        choppiness: 0.0,
        ..FftParams::default()
    };
    let n = 32;
    let mut h0 = vec![Complex::default(); n * n];
    let (a, b) = (0, 2);
    h0[a * n + b] = Complex::new(1.0, 0.0);
    let spectrum = Spectrum::with_amplitudes(&params, n, h0);
    let (kx, _) = spectrum.wave_vector(a, b);
    let speed = spectrum.omega(a, b) / kx;
    let dx = params.patch_metres / n as f64;
    let cells = 3;
    // h = 2 cos(kx·x + ωt): the crest moves towards −x by `cells` in t.
    let t = (cells as f64 * dx / speed) as f32;
    let mut state = FftState::new(&spectrum, params.patch_metres, 0.0, NormalMethod::Analytic);
    let grid = Grid::new(n, state.spacing()).unwrap();
    let (mut before, mut after) = (FftOcean.mesh(grid), FftOcean.mesh(grid));
    state.step(0.0, &mut before);
    state.step(t, &mut after);
    let mut moved = 0.0f32;
    for i in 0..n {
        for j in 0..n {
            let shifted = before.z[i * n + (j + cells) % n];
            let now = after.z[i * n + j];
            assert!(
                (now - shifted).abs() < 1e-4,
                "({i}, {j}): {now} vs {shifted}"
            );
            moved = moved.max((now - before.z[i * n + j]).abs());
        }
    }
    assert!(moved > 0.5, "the wave moved ({moved})");
    assert!((before.z[0] - 2.0).abs() < 1e-5, "a crest of 2 at x = 0");
}

#[test]
fn neighbors_on_the_displaced_mesh_approach_the_analytic_normals() {
    // Face normals see a wave well only over several vertices: the cutoff damps waves under
    // about 2π·10 m, 16 spacings of 3.9 m.
    let n = 256;
    let params = FftParams {
        cutoff_metres: 10.0,
        ..FftParams::default()
    };
    let (_, analytic) = surface(&params, n, 1.0, NormalMethod::Analytic);
    let (_, faces) = surface(&params, n, 1.0, NormalMethod::Neighbors);
    assert_eq!((&analytic.x, &analytic.z), (&faces.x, &faces.z));
    let mut angles: Vec<f64> = (1..n - 1)
        .flat_map(|i| (1..n - 1).map(move |j| i * n + j))
        .map(|v| {
            let dot = analytic.nx[v] * faces.nx[v]
                + analytic.ny[v] * faces.ny[v]
                + analytic.nz[v] * faces.nz[v];
            (dot as f64).clamp(-1.0, 1.0).acos().to_degrees()
        })
        .collect();
    angles.sort_by(f64::total_cmp);
    let median = angles[angles.len() / 2];
    assert!(median < 0.5, "median angle {median}°");
}

#[test]
fn sizes_40_and_1536_run() {
    for n in [40, 1536] {
        let params = FftParams::default();
        let (_, mesh) = surface(&params, n, 2.0, NormalMethod::Analytic);
        assert!(mesh
            .z
            .iter()
            .chain(mesh.x.iter())
            .chain(mesh.fold.iter())
            .all(|v| v.is_finite()));
        let mean_square = mean_square(&mesh.z);
        let power = Spectrum::new(&params, n).power(2.0);
        assert!((mean_square / power - 1.0).abs() < 1e-3, "n={n}");
    }
}

#[test]
fn the_model_refuses_what_it_cannot_run() {
    let grid = Grid::new(97, 1.0).unwrap();
    let params = OceanParams::default();
    let err = |r: Result<Box<dyn Stepper>, InputError>| r.unwrap_err().0;
    assert!(
        err(FftOcean.prepare(grid, &params, NormalMethod::Analytic, Kernel::Reference))
            .starts_with("size: ")
    );
    let grid = Grid::new(64, 1.0).unwrap();
    assert!(
        err(FftOcean.prepare(grid, &params, NormalMethod::Lookup, Kernel::Reference))
            .starts_with("normals: ")
    );
}

#[test]
fn rows_filled_a_few_columns_at_a_time_give_whole_rows_bits() {
    let params = FftParams::default();
    let n = 40;
    let spectrum = Spectrum::new(&params, n);
    for kernel in [Kernel::Reference, Kernel::Fast] {
        for normals in [NormalMethod::Analytic, NormalMethod::Neighbors] {
            let step = |chunk: usize| {
                let mut state =
                    FftState::with_kernel(&spectrum, params.patch_metres, 1.0, normals, kernel);
                assert!(state.fill.chunk >= n, "a 40² row is one chunk by default");
                state.fill.chunk = chunk;
                let mut mesh = FftOcean.mesh(Grid::new(n, state.spacing()).unwrap());
                state.step(1.5, &mut mesh);
                mesh
            };
            let whole = step(n);
            // 7 leaves a short last chunk; 1 puts each wrapped end of a row alone in its own.
            for chunk in [1, 7, 16] {
                assert!(
                    step(chunk) == whole,
                    "{kernel} {normals}: chunks of {chunk} differ from whole rows"
                );
            }
        }
    }
}

#[test]
fn bands_stepped_phase_by_phase_give_the_whole_step_bit_for_bit() {
    let params = FftParams::default();
    let spectrum = Spectrum::new(&params, 16);
    for kernel in [Kernel::Reference, Kernel::Fast] {
        for (n, bands) in [
            (16, vec![0..5, 5..11, 11..16]),
            (16, vec![0..1, 1..15, 15..16]),
            (40, vec![0..13, 13..27, 27..40]),
        ] {
            let spectrum = if n == 16 {
                spectrum.clone()
            } else {
                Spectrum::new(&params, n)
            };
            let mut whole = FftState::with_kernel(
                &spectrum,
                params.patch_metres,
                1.0,
                NormalMethod::Analytic,
                kernel,
            );
            let grid = Grid::new(n, whole.spacing()).unwrap();
            let mut want = FftOcean.mesh(grid);
            let mut split = whole.split(&bands);
            assert!(split.iter().all(|s| s.phases() == 2));
            for t in [0.5f32, 3.0] {
                whole.step(t, &mut want);
                let mut got = FftOcean.mesh(grid);
                for phase in 0..2 {
                    for (stepper, band) in split.iter_mut().zip(&bands) {
                        stepper.step_phase(phase, t, got.rows_mut(band.clone()));
                    }
                }
                assert!(
                    got == want,
                    "{kernel} {bands:?} t = {t}: the banded mesh differs"
                );
            }
        }
    }
}

#[test]
fn helpers_sharing_the_patch_sample_the_whole_step_s_bits() {
    let params = FftParams::default();
    let n = 16;
    let spectrum = Spectrum::new(&params, n);
    // Points anywhere on the plane: off the patch on every side, on its vertices, between them.
    let m = 24;
    let points = |mesh: &mut Mesh| {
        for v in 0..m * m {
            let (i, j) = ((v / m) as f32, (v % m) as f32);
            mesh.x[v] = (j - 7.3) * 13.7 + i * 0.61;
            mesh.y[v] = (i - 11.0) * 9.25 - j * 1.3;
        }
    };
    let grid = Grid::new(m, 1.0).unwrap();
    for kernel in [Kernel::Reference, Kernel::Fast] {
        let state = FftState::with_kernel(
            &spectrum,
            params.patch_metres,
            params.choppiness,
            NormalMethod::Analytic,
            kernel,
        );
        let mut whole = points::FftAtPoints::new(state);
        // Three helpers; twenty, more than the patch has rows, so that some fill none of it.
        for bands in [vec![0..5, 5..6, 6..24], (0..20).map(|k| k..k + 1).collect()] {
            let bands: Vec<Range<usize>> = bands;
            let mut split = whole.split(&bands);
            assert!(split.iter().all(|s| s.phases() == 3));
            for t in [0.5f32, 3.0] {
                let mut want = FftOcean.mesh(grid);
                points(&mut want);
                whole.step(t, &mut want);
                let mut got = FftOcean.mesh(grid);
                points(&mut got);
                for phase in 0..3 {
                    for (stepper, band) in split.iter_mut().zip(&bands) {
                        stepper.step_phase(phase, t, got.rows_mut(band.clone()));
                    }
                }
                // Twenty bands leave the mesh's last rows to nobody.
                let covered = bands.last().unwrap().end * m;
                let same = |a: &[f32], b: &[f32]| a[..covered] == b[..covered];
                assert!(
                    same(&got.x, &want.x)
                        && same(&got.y, &want.y)
                        && same(&got.z, &want.z)
                        && same(&got.nx, &want.nx)
                        && same(&got.ny, &want.ny)
                        && same(&got.nz, &want.nz)
                        && same(&got.fold, &want.fold)
                        && same(&got.fold_dx, &want.fold_dx)
                        && same(&got.fold_dy, &want.fold_dy),
                    "{kernel} {} bands t = {t}: the sampled mesh differs",
                    bands.len()
                );
                assert!(want.z.iter().any(|&z| z != 0.0), "a surface with waves");
            }
        }
    }
}

/// The `fast` kernel's mesh beside the `reference` kernel's at the same (n, t, λ): the largest
/// and the 99th-percentile angle between their normals in degrees, the largest |ΔJ|.
fn fast_against_reference(n: usize, t: f32, params: &FftParams) -> (f64, f64, f64) {
    let spectrum = Spectrum::new(params, n);
    let meshes = [Kernel::Reference, Kernel::Fast].map(|kernel| {
        let mut state = FftState::with_kernel(
            &spectrum,
            params.patch_metres,
            params.choppiness,
            NormalMethod::Analytic,
            kernel,
        );
        let mut mesh = FftOcean.mesh(Grid::new(n, state.spacing()).unwrap());
        state.step(t, &mut mesh);
        mesh
    });
    let [reference, fast] = &meshes;
    assert_eq!(fast.z, reference.z, "n={n}: heights bit for bit");
    assert_eq!(
        (&fast.x, &fast.y),
        (&reference.x, &reference.y),
        "n={n}: positions"
    );
    let mut angles: Vec<f64> = (0..n * n)
        .map(|v| {
            let dot = reference.nx[v] as f64 * fast.nx[v] as f64
                + reference.ny[v] as f64 * fast.ny[v] as f64
                + reference.nz[v] as f64 * fast.nz[v] as f64;
            dot.clamp(-1.0, 1.0).acos().to_degrees()
        })
        .collect();
    angles.sort_by(f64::total_cmp);
    let fold = (0..n * n)
        .map(|v| (fast.fold[v] as f64 - reference.fold[v] as f64).abs())
        .fold(0.0, f64::max);
    (
        angles[angles.len() - 1],
        angles[angles.len() * 99 / 100],
        fold,
    )
}

/// What central differences over two spacings give up against the spectral derivatives on the
/// default sea, whose spectrum (cutoff 0.1 m) reaches the grid's Nyquist wavenumber at every
/// N: a wave of k·L/N = θ has its slope scaled by sin θ / θ, so the shortest waves, which carry
/// a good part of the slopes, lose most. Measured at N = 64 to 512 and t = 0, 7.3 and 1000:
/// normals within 8.1-13.0° at worst and 5.7-5.9° at the 99th percentile, |ΔJ| up to 0.22.
/// The bounds leave about a quarter more; a wrong sign, axis or factor of two is far outside.
const FAST_MAX_DEGREES: f64 = 16.0;
const FAST_P99_DEGREES: f64 = 7.5;
const FAST_MAX_FOLD: f64 = 0.3;

#[test]
fn the_fast_kernel_keeps_heights_and_positions_and_stays_near_the_spectral_slopes() {
    for n in [64, 128, 512] {
        for t in [0.0, 7.3, 1000.0] {
            let (max, p99, fold) = fast_against_reference(n, t, &FftParams::default());
            assert!(max < FAST_MAX_DEGREES, "n={n} t={t}: normals {max}° apart");
            assert!(
                p99 < FAST_P99_DEGREES,
                "n={n} t={t}: 99th percentile {p99}°"
            );
            assert!(fold < FAST_MAX_FOLD, "n={n} t={t}: J {fold} apart");
        }
    }
}

#[test]
fn the_fast_kernel_takes_central_differences_of_the_displaced_surface() {
    let params = FftParams {
        choppiness: 1.5,
        ..FftParams::default()
    };
    let n = 32;
    let spectrum = Spectrum::new(&params, n);
    let mut state = FftState::with_kernel(
        &spectrum,
        params.patch_metres,
        params.choppiness,
        NormalMethod::Analytic,
        Kernel::Fast,
    );
    let s = state.spacing() as f64;
    let mut mesh = FftOcean.mesh(Grid::new(n, state.spacing()).unwrap());
    state.step(2.0, &mut mesh);
    let w = |i: usize, j: usize| ((i + n) % n) * n + (j + n) % n;
    // λ·(Dx, Dy) of vertex v: its position less its rest position.
    let moved_x = |v: usize| mesh.x[v] as f64 - (v % n) as f64 * s;
    let moved_y = |v: usize| mesh.y[v] as f64 - (v / n) as f64 * s;
    for i in 0..n {
        for j in 0..n {
            let v = w(i, j);
            let (e, west) = (w(i, j + 1), w(i, j + n - 1));
            let (north, south) = (w(i + 1, j), w(i + n - 1, j));
            let dx = |f: &[f32], a: usize, b: usize| (f[a] as f64 - f[b] as f64) / (2.0 * s);
            let a = 1.0 + (moved_x(e) - moved_x(west)) / (2.0 * s);
            let d = 1.0 + (moved_y(north) - moved_y(south)) / (2.0 * s);
            let (hx, hy) = (dx(&mesh.z, e, west), dx(&mesh.z, north, south));
            // The off-diagonal is the spectral one, free from the height transform.
            let b = params.choppiness * spectrum.fields_f64(j as f64 * s, i as f64 * s, 2.0)[7];
            let fold = a * d - b * b;
            assert!((mesh.fold[v] as f64 - fold).abs() < 2e-3, "({i}, {j}) J");
            let c = [b * hy - d * hx, hx * b - hy * a, fold];
            let len = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
            let got = [mesh.nx[v], mesh.ny[v], mesh.nz[v]].map(f64::from);
            for k in 0..3 {
                assert!((got[k] - c[k] / len).abs() < 2e-3, "({i}, {j}) normal");
            }
        }
    }
}
