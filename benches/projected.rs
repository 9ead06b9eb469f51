//! Criterion bench: the projected grid's step beside the regular grid's at the same N, for
//! each kernel, measured in one run (issue 28's target: projected ≤ 1.5 × regular). The regular
//! grid runs with `analytic` normals, the projected grid's only method, so the ratio is the
//! cost of placing the vertices and of evaluating the waves at scattered points; the regular
//! grid with the paper's `neighbors` normals is listed too. `place` is the ray–plane work alone,
//! `evaluate-placed` the fast kernel at the points it placed: the projected step's two parts.
//! At 256² each part is also timed on the rows that lie on a line and on those that do not.
//! The camera is the default one (pitch 30°, fov 60°, height framing the patch), whose image's
//! top edge lies on the horizon, so the far clamp is exercised too.
//!
//! `fft-projected` is the FFT ocean's step on each grid at the same N (reference kernel): the
//! projected step computes the same patch and then samples it at every placed vertex, so the
//! difference is the sampling.
//!
//! `flock /work/bench.lock cargo bench --bench projected -- --warm-up-time 1 --measurement-time 2`

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use oceanbench::camera::Camera;
use oceanbench::ocean::sines::Sines;
use oceanbench::ocean::{FftOcean, Grid, GridKind, Kernel, Model, NormalMethod, OceanParams};
use oceanbench::projected;

const SIZES: [usize; 4] = [40, 128, 256, 512];

/// The N at which each part of the projected step is also timed on its two bands of rows.
const SPLIT_N: usize = 256;

fn steps(c: &mut Criterion) {
    let params = OceanParams::default();
    let camera = Camera::default();
    for kernel in [Kernel::Reference, Kernel::Fast] {
        let mut group = c.benchmark_group(format!("grid-step-{}", kernel.name()));
        for n in SIZES {
            let grid = Grid::new(n, 1.0).unwrap();
            group.throughput(Throughput::Elements(grid.vertices() as u64));
            for (name, kind, normals) in [
                (
                    "regular-analytic",
                    GridKind::Regular,
                    NormalMethod::Analytic,
                ),
                (
                    "regular-neighbors",
                    GridKind::Regular,
                    NormalMethod::Neighbors,
                ),
                ("projected", GridKind::Projected, NormalMethod::Analytic),
            ] {
                let mut ocean =
                    projected::stepper(kind, &Sines, grid, &params, normals, kernel, camera)
                        .unwrap();
                let mut mesh = Sines.mesh(grid);
                group.bench_function(BenchmarkId::new(name, n), |b| {
                    b.iter(|| ocean.step(black_box(1.5), &mut mesh))
                });
            }
        }
        group.finish();
    }
    let mut group = c.benchmark_group("grid-place");
    for n in SIZES {
        let grid = Grid::new(n, 1.0).unwrap();
        group.throughput(Throughput::Elements(grid.vertices() as u64));
        let mut mesh = Sines.mesh(grid);
        let view = camera.view_at(grid, 1.5);
        let mut lines = Vec::with_capacity(n);
        group.bench_function(BenchmarkId::new("place", n), |b| {
            b.iter(|| projected::place(black_box(&view), &mut mesh.rows_mut(0..n), &mut lines))
        });
        // The other part of the projected step: the fast kernel at the points placed, told
        // which rows lie on a line. Placed here too, so a filter that skips `place` still has
        // the points.
        projected::place(&view, &mut mesh.rows_mut(0..n), &mut lines);
        let mut surface = Sines
            .prepare_at_points(grid, &params, Kernel::Fast)
            .unwrap();
        group.bench_function(BenchmarkId::new("evaluate-placed", n), |b| {
            b.iter(|| surface.step_rows_on_lines(black_box(1.5), mesh.rows_mut(0..n), &lines))
        });
        if n != SPLIT_N {
            continue;
        }
        // Each part again on the band of rows that lie on a line and on the band of those
        // that do not (the far clamp's, at the image's top), so a vertex of each kind has a
        // cost of its own to set beside the regular grid's.
        let on = lines.iter().take_while(|line| line.is_some()).count();
        assert!(
            0 < on && lines[on..].iter().all(Option::is_none),
            "the default camera's rows on a line come first"
        );
        for (band, rows) in [("on-lines", 0..on), ("off-lines", on..n)] {
            // The band's vertices, so a time per element is one per vertex of the band.
            group.throughput(Throughput::Elements((rows.len() * n) as u64));
            let mut band_lines = Vec::with_capacity(n);
            let id = format!("place-{band}-{}-rows", rows.len());
            group.bench_function(BenchmarkId::new(id, n), |b| {
                b.iter(|| {
                    let mut rows = mesh.rows_mut(rows.clone());
                    projected::place(black_box(&view), &mut rows, &mut band_lines)
                })
            });
            let id = format!("evaluate-placed-{band}-{}-rows", rows.len());
            let band_lines = &lines[rows.clone()];
            group.bench_function(BenchmarkId::new(id, n), |b| {
                b.iter(|| {
                    let rows = mesh.rows_mut(rows.clone());
                    surface.step_rows_on_lines(black_box(1.5), rows, band_lines)
                })
            });
        }
    }
    group.finish();
}

fn fft(c: &mut Criterion) {
    let params = OceanParams::default();
    let mut group = c.benchmark_group("fft-projected");
    group.sample_size(20);
    for n in [256, 512] {
        let spacing = FftOcean.rest_spacing(Grid::new(n, 1.0).unwrap(), &params);
        let grid = Grid::new(n, spacing).unwrap();
        group.throughput(Throughput::Elements(grid.vertices() as u64));
        for (name, kind) in [
            ("regular", GridKind::Regular),
            ("projected", GridKind::Projected),
        ] {
            let mut ocean = projected::stepper(
                kind,
                &FftOcean,
                grid,
                &params,
                NormalMethod::Analytic,
                Kernel::Reference,
                Camera::default(),
            )
            .unwrap();
            let mut mesh = FftOcean.mesh(grid);
            // A new time each iteration: the patch is computed once per time asked for.
            let mut t = 0.0f32;
            group.bench_function(BenchmarkId::new(name, n), |b| {
                b.iter(|| {
                    t += 1.0 / 64.0;
                    ocean.step(black_box(t), &mut mesh)
                })
            });
        }
    }
    group.finish();
}

criterion_group!(benches, steps, fft);
criterion_main!(benches);
