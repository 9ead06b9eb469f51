//! Criterion benches: each kernel × normal method (plus heights only) × grid size.
//!
//! `cargo bench --bench kernels -- --warm-up-time 1 --measurement-time 2`; throughput is in
//! vertices, so criterion reports vertices per second. `lookup` is skipped above 64 (O(n²)).

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use oceanbench::ocean::fast::FastKernel;
use oceanbench::ocean::{reference, Grid, Kernel, Mesh, NormalMethod, Ocean, WaveSet};

const SIZES: [usize; 5] = [40, 128, 256, 512, 1024];

fn heights_only(c: &mut Criterion) {
    let waves = WaveSet::default();
    let mut group = c.benchmark_group("heights");
    for n in SIZES {
        let grid = Grid::new(n, 1.0).unwrap();
        group.throughput(Throughput::Elements(grid.vertices() as u64));
        let mut mesh = Mesh::new(grid);
        group.bench_function(BenchmarkId::new("reference", n), |b| {
            b.iter(|| reference::step(&waves, &mut mesh, black_box(1.5), false))
        });
        let mut fast = FastKernel::new(&waves);
        group.bench_function(BenchmarkId::new("fast", n), |b| {
            b.iter(|| fast.step(&mut mesh, black_box(1.5), false))
        });
    }
    group.finish();
}

fn full_step(c: &mut Criterion) {
    let waves = WaveSet::default();
    for normals in [
        NormalMethod::Analytic,
        NormalMethod::Neighbors,
        NormalMethod::Lookup,
    ] {
        let mut group = c.benchmark_group(format!("step-{}", normals.name()));
        for n in SIZES {
            if normals == NormalMethod::Lookup && n > 64 {
                continue;
            }
            let grid = Grid::new(n, 1.0).unwrap();
            group.throughput(Throughput::Elements(grid.vertices() as u64));
            for kernel in [Kernel::Reference, Kernel::Fast] {
                let mut ocean = Ocean::new(grid, waves.clone(), normals, kernel).unwrap();
                let mut mesh = Mesh::new(grid);
                group.bench_function(BenchmarkId::new(kernel.name(), n), |b| {
                    b.iter(|| ocean.step(black_box(1.5), &mut mesh))
                });
            }
        }
        group.finish();
    }
}

criterion_group!(benches, heights_only, full_step);
criterion_main!(benches);
