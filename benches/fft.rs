//! Criterion benches of the FFT ocean at 512² beside rustfft alone: the model's transforms
//! (the packed spectra at t, a row pass and a column pass per transform) with the `reference`
//! kernel's four transforms and the `fast` kernel's two; the same four fields' row passes
//! alone (2N transforms of length N per field, no gathers, no packing: the floor) and the
//! whole-field 2-D transforms the model used before its strips (row pass, the `transpose`
//! crate's transpose, row pass); whole steps with each kernel and with `analytic` and
//! `neighbors` normals, and a step split in two bands with its phases run in turn on one
//! thread (what splitting costs, without the threads); whole steps at 64², 256² and 512²; and
//! the reference step at 512², 1024² and 2048² side by side (the cost's growth with N).
//!
//! `cargo bench --bench fft -- --quick`. Each 2-D complex transform of M = N² points counts
//! 5·M·log₂M flops, four per step; criterion's throughput is in those flops, so its
//! "elem/s" reads as flops per second.

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use oceanbench::ocean::fft::spectrum::Spectrum;
use oceanbench::ocean::fft::FftState;
use oceanbench::ocean::{
    FftOcean, FftParams, Grid, Kernel, Model, NormalMethod, OceanParams, Stepper,
};
use rustfft::num_complex::Complex;
use rustfft::FftPlanner;

const N: usize = 512;
/// Complex transforms per step: eight real fields, two per transform.
const FIELDS: usize = 4;

fn flops(n: usize) -> u64 {
    let m = (n * n) as f64;
    (FIELDS as f64 * 5.0 * m * m.log2()) as u64
}

/// A whole-mesh stepper of size `n`.
fn stepper(n: usize, normals: NormalMethod, kernel: Kernel) -> (Box<dyn Stepper>, Grid) {
    let grid = Grid::new(n, 1.0).unwrap();
    let stepper = FftOcean
        .prepare(grid, &OceanParams::default(), normals, kernel)
        .unwrap();
    (stepper, grid)
}

fn fft_512(c: &mut Criterion) {
    let mut group = c.benchmark_group("fft-512");
    group.throughput(Throughput::Elements(flops(N)));
    let params = FftParams::default();

    let spectrum = Spectrum::new(&params, N);
    for kernel in [Kernel::Reference, Kernel::Fast] {
        let mut state = FftState::with_kernel(
            &spectrum,
            params.patch_metres,
            params.choppiness,
            NormalMethod::Analytic,
            kernel,
        );
        let name = match kernel {
            Kernel::Reference => "model transforms".to_string(),
            other => format!("model transforms, {other} kernel"),
        };
        group.bench_function(name, |b| b.iter(|| state.transform(black_box(1.5))));
    }

    let fft = FftPlanner::<f32>::new().plan_fft_inverse(N);
    let mut scratch = vec![Complex::default(); fft.get_inplace_scratch_len()];
    let mut fields = vec![vec![Complex::new(0.5f32, -0.25); N * N]; FIELDS];
    group.bench_function("rustfft row passes alone", |b| {
        b.iter(|| {
            for field in &mut fields {
                fft.process_with_scratch(field, &mut scratch);
                fft.process_with_scratch(field, &mut scratch);
            }
            black_box(&fields);
        })
    });
    let mut spare = vec![Complex::default(); N * N];
    group.bench_function("rustfft with whole transposes", |b| {
        b.iter(|| {
            for field in &mut fields {
                fft.process_with_scratch(field, &mut scratch);
                transpose::transpose(field, &mut spare, N, N);
                std::mem::swap(field, &mut spare);
                fft.process_with_scratch(field, &mut scratch);
            }
            black_box(&fields);
        })
    });

    for kernel in [Kernel::Reference, Kernel::Fast] {
        for normals in [NormalMethod::Analytic, NormalMethod::Neighbors] {
            let (mut stepper, grid) = stepper(N, normals, kernel);
            let mut mesh = FftOcean.mesh(grid);
            let name = match kernel {
                Kernel::Reference => format!("model step, {normals} normals"),
                other => format!("model step, {other} kernel, {normals} normals"),
            };
            group.bench_function(name, |b| b.iter(|| stepper.step(black_box(1.5), &mut mesh)));
        }
    }
    let (whole, grid) = stepper(N, NormalMethod::Analytic, Kernel::Reference);
    let mut mesh = FftOcean.mesh(grid);
    let bands = [0..N / 2, N / 2..N];
    let mut split = whole.split(&bands);
    group.bench_function("model step split in 2 bands, phases in turn", |b| {
        b.iter(|| {
            for phase in 0..2 {
                for (stepper, band) in split.iter_mut().zip(&bands) {
                    stepper.step_phase(phase, black_box(1.5), mesh.rows_mut(band.clone()));
                }
            }
        })
    });
    group.finish();
}

/// Whole steps with `analytic` normals at the sizes of `configs/figure-5-1-fft.json`, whose
/// workload levels are placed around them.
fn steps(c: &mut Criterion) {
    let mut group = c.benchmark_group("fft-step-analytic");
    for n in [64, 256, 512] {
        group.throughput(Throughput::Elements(flops(n)));
        let (mut stepper, grid) = stepper(n, NormalMethod::Analytic, Kernel::Reference);
        let mut mesh = FftOcean.mesh(grid);
        group.bench_function(BenchmarkId::from_parameter(n), |b| {
            b.iter(|| stepper.step(black_box(1.5), &mut mesh))
        });
    }
    group.finish();
}

/// The reference step at 512², 1024² and 2048² in one group: the ratio of the largest to the
/// smallest against N² log N's 19.6.
fn scaling(c: &mut Criterion) {
    let mut group = c.benchmark_group("fft-scaling");
    group.sample_size(10);
    for n in [512, 1024, 2048] {
        group.throughput(Throughput::Elements(flops(n)));
        let (mut stepper, grid) = stepper(n, NormalMethod::Analytic, Kernel::Reference);
        let mut mesh = FftOcean.mesh(grid);
        group.bench_function(BenchmarkId::from_parameter(n), |b| {
            b.iter(|| stepper.step(black_box(1.5), &mut mesh))
        });
    }
    group.finish();
}

criterion_group!(benches, fft_512, steps, scaling);
criterion_main!(benches);
