//! Side-by-side throughput and accuracy of the reference and fast kernels in one run.
//!
//! `cargo run --release --example kernel_ratio [size] [rounds]`: times both kernels interleaved
//! on one core (so load from other processes hits both alike), prints million vertices per
//! second and their ratio (median of the rounds), then the max abs error of height and of each
//! normal component against the f64 oracle for t in {0, 1, 100, 1e4} and sizes up to 1024.

use oceanbench::ocean::fast::{FastKernel, StencilNormals};
use oceanbench::ocean::normals::FaceNormals;
use oceanbench::ocean::{reference, Grid, Kernel, Mesh, NormalMethod, Ocean, Wave, WaveSet};
use std::time::Instant;

/// The default set with every steepness moved off the half-integers (powf path).
fn non_half_integer() -> WaveSet {
    let mut set = WaveSet::default();
    for (w, k) in set.waves.iter_mut().zip([2.3, 1.7, 2.8, 3.3]) {
        w.steepness = k;
    }
    set
}

/// Seconds per call of `f`, repeated until at least `min_s` has passed.
fn time(mut f: impl FnMut(), min_s: f64) -> f64 {
    let start = Instant::now();
    let mut calls = 0u32;
    loop {
        f();
        calls += 1;
        let el = start.elapsed().as_secs_f64();
        if el >= min_s {
            return el / calls as f64;
        }
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.partial_cmp(b).unwrap());
    v[v.len() / 2]
}

/// Interleaves `a` (reference) and `b` (fast) for `rounds`; returns their median Mvertices/s.
fn compare(verts: usize, rounds: usize, mut a: impl FnMut(), mut b: impl FnMut()) -> (f64, f64) {
    let (mut ra, mut rb) = (Vec::new(), Vec::new());
    for _ in 0..rounds {
        ra.push(verts as f64 / time(&mut a, 0.05) / 1e6);
        rb.push(verts as f64 / time(&mut b, 0.05) / 1e6);
    }
    (median(ra), median(rb))
}

fn row(name: &str, (r, f): (f64, f64)) {
    println!("| {name:<38} | {r:>10.2} | {f:>10.1} | {:>8.1}x |", f / r);
}

/// Max abs error of z, nx, ny, nz against the f64 oracle.
fn errors(waves: &WaveSet, mesh: &Mesh, t: f32) -> [f64; 4] {
    let mut e = [0.0f64; 4];
    for v in 0..mesh.z.len() {
        let (x, y, t) = (mesh.x[v] as f64, mesh.y[v] as f64, t as f64);
        let h = waves.height_f64(x, y, t);
        let n = waves.normal_f64(x, y, t);
        let got = [mesh.z[v], mesh.nx[v], mesh.ny[v], mesh.nz[v]];
        for (k, want) in [h, n[0], n[1], n[2]].into_iter().enumerate() {
            e[k] = e[k].max((got[k] as f64 - want).abs());
        }
    }
    e
}

fn main() {
    let args: Vec<usize> = std::env::args()
        .skip(1)
        .map(|a| a.parse().unwrap())
        .collect();
    let n = args.first().copied().unwrap_or(256);
    let rounds = args.get(1).copied().unwrap_or(5);
    if let Some(core) = core_affinity::get_core_ids().and_then(|c| c.into_iter().next()) {
        core_affinity::set_for_current(core);
    }
    let grid = Grid::new(n, 1.0).unwrap();
    let verts = grid.vertices();
    let isa = FastKernel::new(&WaveSet::default()).isa();
    println!(
        "# {n}x{n}, one core, fast kernel ISA {}, {rounds} interleaved rounds, median\n",
        isa.name()
    );
    println!("| case (Mvertices/s)                     |  reference |       fast |    ratio |");
    println!("|----------------------------------------|-----------:|-----------:|---------:|");
    for (label, waves) in [
        ("", WaveSet::default()),
        (", non-half-integer k", non_half_integer()),
    ] {
        for (what, analytic) in [("heights only", false), ("heights + analytic", true)] {
            let (mut m1, mut m2) = (Mesh::new(grid), Mesh::new(grid));
            let mut fast = FastKernel::new(&waves);
            let mut t = 0.0f32;
            let mut t2 = 0.0f32;
            let res = compare(
                verts,
                rounds,
                || {
                    t += 0.016;
                    reference::step(&waves, &mut m1, t, analytic)
                },
                || {
                    t2 += 0.016;
                    fast.step(&mut m2, t2, analytic)
                },
            );
            row(&format!("{what}{label}"), res);
        }
    }
    let waves = WaveSet::default();
    let (mut m1, mut m2) = (Mesh::new(grid), Mesh::new(grid));
    reference::step(&waves, &mut m1, 1.0, false);
    m2.z.copy_from_slice(&m1.z);
    let mut faces = FaceNormals::new(grid);
    let mut stencil = StencilNormals::new();
    let res = compare(
        verts,
        rounds,
        || faces.compute(&mut m1, NormalMethod::Neighbors),
        || stencil.compute(&mut m2),
    );
    row("neighbors normals only", res);
    let mut oceans = [Kernel::Reference, Kernel::Fast]
        .map(|k| Ocean::new(grid, waves.clone(), NormalMethod::Neighbors, k).unwrap());
    let [o1, o2] = &mut oceans;
    let res = compare(
        verts,
        rounds,
        || o1.step(1.0, &mut m1),
        || o2.step(1.0, &mut m2),
    );
    row("full step, heights + neighbors", res);

    println!("\n# max abs error vs f64 oracle (analytic normals): reference / fast\n");
    println!("| waves | size | t | z | nx | ny | nz |");
    println!("|---|---:|---:|---|---|---|---|");
    let mut worst = [[0.0f64; 4]; 2];
    for (label, waves) in [
        ("half-int", WaveSet::default()),
        ("non-half", non_half_integer()),
    ] {
        for size in [40usize, 256, 1024] {
            let grid = Grid::new(size, 1.0).unwrap();
            for t in [0.0f32, 1.0, 100.0, 1e4] {
                let mut m = Mesh::new(grid);
                reference::step(&waves, &mut m, t, true);
                let er = errors(&waves, &m, t);
                FastKernel::new(&waves).step(&mut m, t, true);
                let ef = errors(&waves, &m, t);
                let cells: Vec<String> = (0..4)
                    .map(|k| {
                        worst[0][k] = worst[0][k].max(er[k]);
                        worst[1][k] = worst[1][k].max(ef[k]);
                        format!("{:.1e} / {:.1e}", er[k], ef[k])
                    })
                    .collect();
                println!("| {label} | {size} | {t} | {} |", cells.join(" | "));
            }
        }
    }
    let fmt = |w: &[f64; 4]| w.map(|e| format!("{e:.1e}")).join(" ");
    println!(
        "\nworst over all: reference [z nx ny nz] = {}",
        fmt(&worst[0])
    );
    println!(
        "worst over all: fast      [z nx ny nz] = {}",
        fmt(&worst[1])
    );
    let _ = Wave::validate;
}
