//! Criterion benches of the spray's particle loop beside its memory-streaming floor, at 32k,
//! 131k and 524k particles: the glam `Vec4` integration (the fast path), the plain loop it is
//! checked against, the floor (every byte the integration reads and writes, the seven `f32`
//! arrays, read and written once by the simplest loop there is), the kill pass against a 512²
//! FFT surface, and a whole spray frame on that surface (integrate, kill, emit) in steady state.
//!
//! `cargo bench --bench spray -- --quick`. Throughput is the seven arrays' bytes, so the
//! integration's and the floor's "B/s" compare directly.

use criterion::{
    black_box, criterion_group, criterion_main, BatchSize, BenchmarkId, Criterion, Throughput,
};
use oceanbench::camera::Camera;
use oceanbench::ocean::Kernel;
use oceanbench::ocean::{FftOcean, FftParams, Grid, Mesh, Model, NormalMethod, OceanParams};
use oceanbench::workload::spray::{Pool, Step, Surface};
use oceanbench::workload::{MeshWork, Spray, SprayParams, WorkSpec, WorkloadKind};

const SIZES: [usize; 3] = [32_768, 131_072, 524_288];
const DT: f32 = 1.0 / 60.0;
/// The arrays the integration reads and writes: position, velocity, age.
const ARRAYS: usize = 7;

fn step() -> Step {
    Step {
        dt: DT,
        gravity_dt: 9.81 * DT,
        keep: (-0.2f32 * DT).exp(),
    }
}

/// Every slot alive, spread over the patch above the surface, flying up.
fn full_pool(n: usize, patch: f32) -> Pool {
    let mut pool = Pool::new(n);
    for i in 0..n {
        let f = i as f32 / n as f32;
        let p = [
            patch * f,
            patch * (f * 7.0).fract(),
            20.0 + 5.0 * (f * 13.0).fract(),
        ];
        pool.spawn(p, [1.0, -1.0, 3.0]);
    }
    pool
}

/// The 512² FFT sea at t = 10 s, the meshes of two frames, and their rest spacing.
fn surface() -> (Vec<Mesh>, f32) {
    let grid = Grid::new(512, 1.0).unwrap();
    let params = OceanParams::default().with(FftParams::default());
    let mut ocean = FftOcean
        .prepare(grid, &params, NormalMethod::Analytic, Kernel::Reference)
        .unwrap();
    let meshes = (0..2)
        .map(|k| {
            let mut m = FftOcean.mesh(grid);
            ocean.step(10.0 + k as f32 * DT, &mut m);
            m
        })
        .collect();
    (meshes, FftOcean.rest_spacing(grid, &params))
}

fn particles(c: &mut Criterion) {
    let (meshes, spacing) = surface();
    let patch = spacing * 511.0;
    let mut group = c.benchmark_group("spray");
    for n in SIZES {
        group.throughput(Throughput::Bytes((ARRAYS * 4 * n) as u64));
        let mut pool = full_pool(n, patch);
        group.bench_with_input(BenchmarkId::new("integrate simd", n), &n, |b, &n| {
            b.iter(|| pool.integrate(black_box(step()), 0..n))
        });
        group.bench_with_input(BenchmarkId::new("integrate plain", n), &n, |b, &n| {
            b.iter(|| pool.integrate_plain(black_box(step()), 0..n))
        });
        group.bench_with_input(BenchmarkId::new("streaming floor", n), &n, |b, _| {
            b.iter(|| {
                for a in pool.floats_mut() {
                    a.iter_mut().for_each(|v| *v += 1.0);
                    black_box(&a);
                }
            })
        });
        let full = full_pool(n, patch);
        let surface = Surface::of(&meshes[0], spacing);
        group.bench_with_input(BenchmarkId::new("kill pass", n), &n, |b, &n| {
            b.iter_batched_ref(
                || full.clone(),
                |pool| pool.kill(black_box(&surface), 2.0, 0..n),
                BatchSize::LargeInput,
            )
        });
        // The same pass on one pool kept warm, as the integration's benches run: every
        // particle flies above the surface and younger than its lifetime, so none dies and
        // the pool is the same at every iteration.
        let mut warm = full_pool(n, patch);
        group.bench_with_input(
            BenchmarkId::new("kill pass, none dies, warm pool", n),
            &n,
            |b, &n| {
                b.iter(|| {
                    let killed = warm.kill(black_box(&surface), 2.0, 0..n);
                    assert_eq!(killed, 0, "every particle flies above the sea");
                    killed
                })
            },
        );
        let mut spray = Spray::new(
            &WorkSpec {
                kind: WorkloadKind::SPRAY,
                amount: n as u64,
                grid: meshes[0].grid,
                camera: Camera::default(),
                spacing,
                time_step: DT,
            },
            SprayParams::default(),
        );
        let mut k = 0u64;
        for _ in 0..120 {
            k += 1;
            spray.run(k, &meshes[(k % 2) as usize], None).unwrap();
        }
        group.bench_with_input(BenchmarkId::new("whole frame", n), &n, |b, _| {
            b.iter(|| {
                k += 1;
                spray.run(k, &meshes[(k % 2) as usize], None).unwrap()
            })
        });
    }
    group.finish();
}

criterion_group!(benches, particles);
criterion_main!(benches);
