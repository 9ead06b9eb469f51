//! Criterion benches of the FFT ocean at 512² beside rustfft alone: the model's transforms
//! (the four packed spectra at t, then per field a row pass, a transpose and a row pass), the
//! same four fields' row passes alone (2N transforms of length N per field, no transposes, no
//! packing: the floor), whole steps with `analytic` and `neighbors` normals, and a step split
//! in two bands with its phases run in turn on one thread (what splitting costs, without the
//! threads); and whole steps at 64², 256² and 512².
//!
//! `cargo bench --bench fft -- --quick`. Each 2-D complex transform of M = N² points counts
//! 5·M·log₂M flops, four per step; criterion's throughput is in those flops, so its
//! "elem/s" reads as flops per second.

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use oceanbench::ocean::fft::spectrum::Spectrum;
use oceanbench::ocean::fft::FftState;
use oceanbench::ocean::{FftOcean, FftParams, Grid, Model, NormalMethod, OceanParams, Stepper};
use rustfft::num_complex::Complex;
use rustfft::FftPlanner;

const N: usize = 512;
/// Complex transforms per step: eight real fields, two per transform.
const FIELDS: usize = 4;

fn flops(n: usize) -> u64 {
    let m = (n * n) as f64;
    (FIELDS as f64 * 5.0 * m * m.log2()) as u64
}

fn fft_512(c: &mut Criterion) {
    let mut group = c.benchmark_group("fft-512");
    group.throughput(Throughput::Elements(flops(N)));
    let params = FftParams::default();

    let spectrum = Spectrum::new(&params, N);
    let mut state = FftState::new(
        &spectrum,
        params.patch_metres,
        params.choppiness,
        NormalMethod::Analytic,
    );
    group.bench_function("model transforms", |b| {
        b.iter(|| state.transform(black_box(1.5)))
    });

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

    for normals in [NormalMethod::Analytic, NormalMethod::Neighbors] {
        let grid = Grid::new(N, 1.0).unwrap();
        let mut stepper = FftOcean
            .prepare(
                grid,
                &OceanParams::default(),
                normals,
                oceanbench::ocean::Kernel::Reference,
            )
            .unwrap();
        let mut mesh = FftOcean.mesh(grid);
        group.bench_function(format!("model step, {normals} normals"), |b| {
            b.iter(|| stepper.step(black_box(1.5), &mut mesh))
        });
    }
    let grid = Grid::new(N, 1.0).unwrap();
    let mut mesh = FftOcean.mesh(grid);
    let bands = [0..N / 2, N / 2..N];
    let mut split = state.split(&bands);
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
        let grid = Grid::new(n, 1.0).unwrap();
        let mut stepper = FftOcean
            .prepare(
                grid,
                &OceanParams::default(),
                NormalMethod::Analytic,
                oceanbench::ocean::Kernel::Reference,
            )
            .unwrap();
        let mut mesh = FftOcean.mesh(grid);
        group.bench_function(BenchmarkId::from_parameter(n), |b| {
            b.iter(|| stepper.step(black_box(1.5), &mut mesh))
        });
    }
    group.finish();
}

criterion_group!(benches, fft_512, steps);
criterion_main!(benches);
