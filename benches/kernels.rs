//! Criterion benches: the kernels (reference, fast per-wave, fast fused) with heights only and
//! with analytic normals, `neighbors` normals alone (`FaceNormals` vs the stencil), and whole
//! steps through the sines model's stepper for each normal method, over grid sizes.
//!
//! `cargo bench --bench kernels -- --warm-up-time 1 --measurement-time 2`; throughput is in
//! vertices, so criterion reports vertices per second. `lookup` is skipped above 64 (O(n²)).

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use oceanbench::ocean::normals::FaceNormals;
use oceanbench::ocean::sines::fast::{FastKernel, StencilNormals};
use oceanbench::ocean::sines::reference;
use oceanbench::ocean::{Grid, Kernel, Mesh, NormalMethod, OceanKind, OceanParams, WaveSet};

const SIZES: [usize; 5] = [40, 128, 256, 512, 1024];

/// The kernel alone: heights only, or heights and analytic normals.
fn kernels(c: &mut Criterion) {
    let waves = WaveSet::default();
    for (name, analytic) in [("heights", false), ("analytic", true)] {
        let mut group = c.benchmark_group(name);
        for n in SIZES {
            let grid = Grid::new(n, 1.0).unwrap();
            group.throughput(Throughput::Elements(grid.vertices() as u64));
            let mut mesh = Mesh::new(grid);
            group.bench_function(BenchmarkId::new("reference", n), |b| {
                b.iter(|| reference::step(&waves, &mut mesh, black_box(1.5), analytic))
            });
            for (path, mut fast) in [
                ("per-wave", FastKernel::new(&waves).per_wave()),
                ("fused", FastKernel::new(&waves)),
            ] {
                group.bench_function(BenchmarkId::new(path, n), |b| {
                    b.iter(|| fast.step(&mut mesh, black_box(1.5), analytic))
                });
            }
        }
        group.finish();
    }
}

/// `neighbors` normals from given heights: the reference neighbour list against the stencil.
fn neighbors_only(c: &mut Criterion) {
    let mut group = c.benchmark_group("neighbors-normals");
    for n in SIZES {
        let grid = Grid::new(n, 1.0).unwrap();
        group.throughput(Throughput::Elements(grid.vertices() as u64));
        let mut mesh = Mesh::new(grid);
        reference::step(&WaveSet::default(), &mut mesh, 1.5, false);
        let mut faces = FaceNormals::new(grid);
        group.bench_function(BenchmarkId::new("reference", n), |b| {
            b.iter(|| faces.compute(black_box(&mut mesh), NormalMethod::Neighbors))
        });
        let mut stencil = StencilNormals::new();
        group.bench_function(BenchmarkId::new("stencil", n), |b| {
            b.iter(|| stencil.compute(black_box(&mut mesh)))
        });
    }
    group.finish();
}

fn full_step(c: &mut Criterion) {
    let params = OceanParams::default();
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
                let mut ocean = OceanKind::SINES
                    .model()
                    .prepare(grid, &params, normals, kernel)
                    .unwrap();
                let mut mesh = Mesh::new(grid);
                group.bench_function(BenchmarkId::new(kernel.name(), n), |b| {
                    b.iter(|| ocean.step(black_box(1.5), &mut mesh))
                });
            }
        }
        group.finish();
    }
}

criterion_group!(benches, kernels, neighbors_only, full_step);
criterion_main!(benches);
