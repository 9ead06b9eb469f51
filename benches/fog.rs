//! Criterion benches of the fog's two volume passes, each beside its yardstick:
//!
//! - `fog-noise/N`: the fast gradient noise filling an N³ volume with the default four octaves,
//!   beside the `noise` crate's `Perlin` computing the same samples (same seeds, strides,
//!   weights and positions) one `get` at a time. Throughput is in samples (voxels × octaves), so
//!   criterion's "elem/s" reads as noise samples per second. Target: fast ≥ 5 × the crate.
//! - `fog-blur/N`: the three-pass binomial blur of an N³ volume (default width 5) beside three
//!   read-and-write passes over the same bytes (a copy from one buffer to the other and back).
//!   Throughput is the volume's bytes. Target: blur ≤ 2 × the copies.
//! - `fog-coefficients/N`: the coefficient of every vertex of an N×N sines mesh from a 64³
//!   volume (a trilinear wrapped lookup, a distance and an exponential each). Throughput is in
//!   vertices. Target: ≤ 3 ns a vertex.
//!
//! `cargo bench --bench fog -- --quick`; docs/fog.md has the numbers.

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use noise::{NoiseFn, Perlin};
use oceanbench::ocean::sines::Sines;
use oceanbench::ocean::{Grid, Kernel, Model, NormalMethod, OceanParams};
use oceanbench::workload::fog::coefficient::{self, View};
use oceanbench::workload::fog::{blur, noise as fast, Fog, FogParams};

fn noise(c: &mut Criterion) {
    let mut group = c.benchmark_group("fog-noise");
    group.sample_size(10);
    let params = FogParams::default();
    let octaves = params.octaves();
    let perlins: Vec<Perlin> = (0..octaves.len() as u32)
        .map(|o| Perlin::new(params.seed + o))
        .collect();
    let total: f32 = octaves.iter().map(|o| o.weight).sum();
    let frame = Fog::frame(3);
    for n in [64usize, 128] {
        group.throughput(Throughput::Elements((n.pow(3) * octaves.len()) as u64));
        let mut volume = vec![0.0f32; n.pow(3)];
        group.bench_with_input(BenchmarkId::new("fast", n), &n, |b, &n| {
            b.iter(|| fast::fill(black_box(&mut volume), n, &octaves, &frame, None))
        });
        group.bench_with_input(BenchmarkId::new("noise crate", n), &n, |b, &n| {
            b.iter(|| {
                for (v, out) in volume.iter_mut().enumerate() {
                    let (i, j, k) = (v % n, v / n % n, v / (n * n));
                    let mut sum = 0.0;
                    for (o, p) in octaves.iter().zip(&perlins) {
                        let at = |axis, c| frame.coordinate(axis, c, o.stride);
                        sum += f64::from(o.weight) * p.get([at(0, i), at(1, j), at(2, k)]);
                    }
                    *out = sum as f32 / total;
                }
                black_box(&volume);
            })
        });
    }
    group.finish();
}

fn blur_vs_copy(c: &mut Criterion) {
    let mut group = c.benchmark_group("fog-blur");
    group.sample_size(10);
    let weights = blur::weights(FogParams::default().blur_width as usize);
    for n in [128usize, 256] {
        group.throughput(Throughput::Bytes((n.pow(3) * 4) as u64));
        let mut a: Vec<f32> = (0..n.pow(3)).map(|i| (i % 97) as f32).collect();
        let mut b = vec![0.0f32; n.pow(3)];
        group.bench_with_input(BenchmarkId::new("blur", n), &n, |bench, &n| {
            bench.iter(|| blur::blur(black_box(&mut a), &mut b, n, &weights, None))
        });
        group.bench_with_input(BenchmarkId::new("three copies", n), &n, |bench, _| {
            bench.iter(|| {
                b.copy_from_slice(black_box(&a));
                a.copy_from_slice(black_box(&b));
                b.copy_from_slice(black_box(&a));
            })
        });
    }
    group.finish();
}

fn coefficients(c: &mut Criterion) {
    let mut group = c.benchmark_group("fog-coefficients");
    let n = 64;
    let volume: Vec<f32> = (0..n * n * n).map(|i| ((i as f32) * 0.37).sin()).collect();
    for size in [256usize, 512] {
        let grid = Grid::new(size, 1.0).unwrap();
        let mut mesh = Sines.mesh(grid);
        Sines
            .prepare(
                grid,
                &OceanParams::default(),
                NormalMethod::Analytic,
                Kernel::Fast,
            )
            .unwrap()
            .step(1.5, &mut mesh);
        let width = size as f32;
        let view = View {
            eye: glam::Vec3::new(width / 2.0, -width / 2.0, width / 4.0),
            width,
            density: FogParams::default().density,
        };
        let mut out = vec![0.0f32; grid.vertices()];
        group.throughput(Throughput::Elements(grid.vertices() as u64));
        group.bench_with_input(BenchmarkId::new("fill", size), &size, |bench, _| {
            bench.iter(|| {
                coefficient::fill(
                    &mesh,
                    0..grid.vertices(),
                    black_box(&volume),
                    n,
                    &view,
                    &mut out,
                )
            })
        });
    }
    group.finish();
}

criterion_group!(benches, noise, blur_vs_copy, coefficients);
criterion_main!(benches);
