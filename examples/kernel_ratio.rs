//! Side-by-side throughput and accuracy of the reference kernel and both fast-kernel paths in
//! one run.
//!
//! `cargo run --release --example kernel_ratio [size] [rounds] [isa] [timing] [--out DIR]`: on one
//! pinned core, times the reference, the per-wave fast path and the fused fast path interleaved
//! (one after the other each round, so load from other processes hits all alike; on Linux in the
//! thread's CPU time) and prints million vertices per second (median of the rounds), cycles per
//! vertex at the clock measured at the start and end of the run, and the ratios. `isa` (avx512,
//! avx2 or portable; default the widest) forces the fast kernel's and the stencil's instruction
//! set. Then, unless `timing` is given, the max abs error of height and of each normal component
//! against the f64 oracle for t in {0, 1, 100, 1e4} and sizes up to 1024, and the largest
//! difference between the two fast paths. `--out DIR` also writes the timings as a benchmark run,
//! DIR/bench.json (see docs/performance.md, "Benchmark runs").

use oceanbench::bench_run::{BenchEstimate, BenchRun, SCHEMA_VERSION};
use oceanbench::machine::Machine;
use oceanbench::ocean::normals::FaceNormals;
use oceanbench::ocean::sines::fast::{FastKernel, Isa, Path, StencilNormals};
use oceanbench::ocean::sines::reference;
use oceanbench::ocean::{Grid, Mesh, NormalMethod, WaveSet};

/// The default set with every steepness moved off the half-integers (powf path).
fn non_half_integer() -> WaveSet {
    let mut set = WaveSet::default();
    for (w, k) in set.waves.iter_mut().zip([2.3, 1.7, 2.8, 3.3]) {
        w.steepness = k;
    }
    set
}

/// Eight half-integer waves: the default set and a copy turned by 90° at 0.7 times the
/// wavelength (more waves than any count the fused loop could have been built for).
fn eight_waves() -> WaveSet {
    let mut set = WaveSet::default();
    let turned: Vec<_> = set
        .waves
        .iter()
        .map(|w| {
            let mut w = w.clone();
            w.direction = [-w.direction[1], w.direction[0]];
            w.wavelength *= 0.7;
            w
        })
        .collect();
    set.waves.extend(turned);
    set
}

/// Seconds of this thread's CPU time: on a machine shared with other work the pinned core is
/// time-sliced, and time spent switched out would otherwise count as the kernel's.
#[cfg(target_os = "linux")]
fn now() -> f64 {
    #[repr(C)]
    struct Timespec {
        sec: i64,
        nsec: i64,
    }
    extern "C" {
        fn clock_gettime(clock: i32, tp: *mut Timespec) -> i32;
    }
    const CLOCK_THREAD_CPUTIME_ID: i32 = 3;
    let mut ts = Timespec { sec: 0, nsec: 0 };
    // SAFETY: `ts` is a valid timespec for the call to fill.
    let ok = unsafe { clock_gettime(CLOCK_THREAD_CPUTIME_ID, &mut ts) } == 0;
    assert!(ok, "clock_gettime(CLOCK_THREAD_CPUTIME_ID) failed");
    ts.sec as f64 + ts.nsec as f64 * 1e-9
}

/// Wall-clock seconds where the thread's CPU clock is not at hand.
#[cfg(not(target_os = "linux"))]
fn now() -> f64 {
    use std::sync::OnceLock;
    use std::time::Instant;
    static START: OnceLock<Instant> = OnceLock::new();
    START.get_or_init(Instant::now).elapsed().as_secs_f64()
}

/// Seconds per call of `f`, repeated until at least `min_s` has passed.
fn time(f: &mut dyn FnMut(), min_s: f64) -> f64 {
    let start = now();
    let mut calls = 0u32;
    loop {
        f();
        calls += 1;
        let el = now() - start;
        if el >= min_s {
            return el / calls as f64;
        }
    }
}

fn median(v: &[f64]) -> f64 {
    let mut v = v.to_vec();
    v.sort_by(|a, b| a.partial_cmp(b).unwrap());
    v[v.len() / 2]
}

/// Interleaves every function for `rounds`; returns each one's Mvertices/s per round.
fn compare(verts: usize, rounds: usize, fs: &mut [&mut dyn FnMut()]) -> Vec<Vec<f64>> {
    let mut rates = vec![Vec::new(); fs.len()];
    for _ in 0..rounds {
        for (f, r) in fs.iter_mut().zip(&mut rates) {
            r.push(verts as f64 / time(*f, 0.05) / 1e6);
        }
    }
    rates
}

/// One table row: the case, and the rounds of each path in the reference, per-wave and fused
/// columns, named as in the estimates' ids (absent where the case has no such path).
struct Row {
    case: String,
    columns: [Option<(&'static str, Vec<f64>)>; 3],
}

/// Core clock in GHz from a chain of dependent integer adds (one cycle each on every x86-64
/// core), median of five runs of 0.1 s.
#[cfg(target_arch = "x86_64")]
fn clock_ghz() -> f64 {
    const ADDS: u64 = 100_000_000;
    let runs: Vec<f64> = (0..5)
        .map(|_| {
            let start = now();
            // SAFETY: register arithmetic only.
            unsafe {
                std::arch::asm!(
                    "2:",
                    ".rept 16",
                    "add {x}, 1",
                    ".endr",
                    "dec {n}",
                    "jnz 2b",
                    x = inout(reg) 0u64 => _,
                    n = inout(reg) ADDS / 16 => _,
                    options(nomem, nostack),
                );
            }
            ADDS as f64 / (now() - start) / 1e9
        })
        .collect();
    median(&runs)
}

#[cfg(not(target_arch = "x86_64"))]
fn clock_ghz() -> f64 {
    f64::NAN
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

/// Largest |a − b| over every position and normal array of two meshes.
fn mesh_diff(a: &Mesh, b: &Mesh) -> f32 {
    let pairs = [(&a.z, &b.z), (&a.nx, &b.nx), (&a.ny, &b.ny), (&a.nz, &b.nz)];
    pairs
        .iter()
        .flat_map(|(a, b)| a.iter().zip(b.iter()).map(|(a, b)| (a - b).abs()))
        .fold(0.0, f32::max)
}

/// Prints one table row: the median Mvertices/s, cycles per vertex at `ghz` and ratios.
fn print_row(row: &Row, ghz: f64) {
    let [reference, per_wave, fused] = row
        .columns
        .each_ref()
        .map(|c| c.as_ref().map(|(_, rounds)| median(rounds)));
    let name = &row.case;
    let cell = |r: Option<f64>| {
        r.map_or("—".to_string(), |r| {
            format!("{r:.0} ({:.2})", ghz * 1e3 / r)
        })
    };
    let ratio = |a: Option<f64>, b: Option<f64>| match (a, b) {
        (Some(a), Some(b)) => format!("{:.2}x", a / b),
        _ => "—".to_string(),
    };
    let best = fused.or(per_wave);
    println!(
        "| {name:<34} | {:>13} | {:>13} | {:>13} | {:>8} | {:>8} | {:>8} |",
        cell(reference),
        cell(per_wave),
        cell(fused),
        ratio(fused, per_wave),
        ratio(per_wave, reference),
        ratio(best, reference),
    );
}

/// The run's bench.json: per case and path, the median Mvertices/s of the rounds between the
/// slowest and the fastest round.
fn bench_run(
    rows: &[Row],
    n: usize,
    rounds: usize,
    isa: Isa,
    started: String,
    machine: Machine,
) -> BenchRun {
    let estimates = rows
        .iter()
        .flat_map(|row| row.columns.iter().flatten().map(move |c| (row, c)))
        .map(|(row, (path, rates))| BenchEstimate {
            id: format!("{}/{path}/{n}", row.case),
            unit: "Mvertices/s".into(),
            value: median(rates),
            lower: rates.iter().copied().fold(f64::INFINITY, f64::min),
            upper: rates.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            throughput: None,
        })
        .collect();
    BenchRun {
        schema_version: SCHEMA_VERSION,
        name: "kernel_ratio".into(),
        started,
        machine,
        command: std::env::args().collect(),
        source: format!(
            "examples/kernel_ratio.rs on one pinned core, {n}×{n} grid, fast kernel ISA {}: \
             million vertices per second from the thread's CPU time, value the median of \
             {rounds} interleaved rounds, lower and upper the slowest and the fastest round",
            isa.name()
        ),
        estimates,
    }
}

fn main() {
    let started = oceanbench::sweep::utc_now();
    let (args, out) = oceanbench::bench_run::example_args();
    let n: usize = args.first().map_or(256, |a| a.parse().unwrap());
    let rounds: usize = args.get(1).map_or(5, |a| a.parse().unwrap());
    let isa = match args.get(2).map(String::as_str) {
        None => Isa::detect(),
        Some(name) => *Isa::available()
            .iter()
            .find(|i| i.name() == name)
            .unwrap_or_else(|| panic!("isa {name}: not one of {:?}", Isa::available())),
    };
    // Read before pinning: pinned, the process sees one core, and the run would say so.
    let machine = Machine::current();
    if let Some(core) = core_affinity::get_core_ids().and_then(|c| c.into_iter().next()) {
        core_affinity::set_for_current(core);
    }
    let ghz_start = clock_ghz();
    let grid = Grid::new(n, 1.0).unwrap();
    let verts = grid.vertices();
    let kernel = |waves: &WaveSet, path: Path| {
        let k = FastKernel::with_isa(waves, isa);
        match path {
            Path::Fused => k.fused(),
            Path::PerWave => k.per_wave(),
        }
    };
    let mut results = Vec::new();
    for (label, waves) in [
        ("", WaveSet::default()),
        (", 8 waves", eight_waves()),
        (", non-half-integer k", non_half_integer()),
    ] {
        for (what, analytic) in [("heights only", false), ("heights + analytic", true)] {
            let mut meshes = [Mesh::new(grid), Mesh::new(grid), Mesh::new(grid)];
            let [m0, m1, m2] = &mut meshes;
            let mut per_wave = kernel(&waves, Path::PerWave);
            let mut fused = kernel(&waves, Path::Fused);
            let has_fused = fused.path() == Path::Fused;
            let mut ts = [0.0f32; 3];
            let [t0, t1, t2] = &mut ts;
            let mut f0 = || {
                *t0 += 0.016;
                reference::step(&waves, m0, *t0, analytic)
            };
            let mut f1 = || {
                *t1 += 0.016;
                per_wave.step(m1, *t1, analytic)
            };
            let mut f2 = || {
                *t2 += 0.016;
                fused.step(m2, *t2, analytic)
            };
            let mut r = if has_fused {
                compare(verts, rounds, &mut [&mut f0, &mut f1, &mut f2])
            } else {
                compare(verts, rounds, &mut [&mut f0, &mut f1])
            };
            let fused_rates = (r.len() == 3).then(|| ("fused", r.remove(2)));
            let per_wave_rates = r.remove(1);
            results.push(Row {
                case: format!("{what}{label}"),
                columns: [
                    Some(("reference", r.remove(0))),
                    Some(("per-wave", per_wave_rates)),
                    fused_rates,
                ],
            });
        }
    }

    let waves = WaveSet::default();
    let (mut m1, mut m2) = (Mesh::new(grid), Mesh::new(grid));
    reference::step(&waves, &mut m1, 1.0, false);
    m2.z.copy_from_slice(&m1.z);
    let mut faces = FaceNormals::new(grid);
    let mut stencil = StencilNormals::with_isa(isa);
    let [faces_rates, stencil_rates]: [Vec<f64>; 2] = compare(
        verts,
        rounds,
        &mut [
            &mut || faces.compute(&mut m1, NormalMethod::Neighbors),
            &mut || stencil.compute(&mut m2),
        ],
    )
    .try_into()
    .unwrap();
    results.push(Row {
        case: "neighbors normals only".into(),
        columns: [
            Some(("reference", faces_rates)),
            None,
            Some(("stencil", stencil_rates)),
        ],
    });

    // What `Ocean::step` runs for `neighbors`, spelled out so the fast kernel's ISA and path
    // can be chosen.
    let (mut per_wave, mut fused) = (kernel(&waves, Path::PerWave), kernel(&waves, Path::Fused));
    let mut stencil2 = StencilNormals::with_isa(isa);
    let mut m3 = Mesh::new(grid);
    let [ref_rates, per_wave_rates, fused_rates]: [Vec<f64>; 3] = compare(
        verts,
        rounds,
        &mut [
            &mut || {
                reference::step(&waves, &mut m1, 1.0, false);
                faces.compute(&mut m1, NormalMethod::Neighbors)
            },
            &mut || {
                per_wave.step(&mut m2, 1.0, false);
                stencil.compute(&mut m2)
            },
            &mut || {
                fused.step(&mut m3, 1.0, false);
                stencil2.compute(&mut m3)
            },
        ],
    )
    .try_into()
    .unwrap();
    results.push(Row {
        case: "full step, heights + neighbors".into(),
        columns: [
            Some(("reference", ref_rates)),
            Some(("per-wave", per_wave_rates)),
            Some(("fused", fused_rates)),
        ],
    });
    let ghz_end = clock_ghz();
    let ghz = (ghz_start + ghz_end) / 2.0;

    println!(
        "# {n}x{n}, one core, fast kernel ISA {}, {rounds} interleaved rounds, median of thread \
         CPU time; clock {ghz_start:.2} GHz at start, {ghz_end:.2} GHz at end (dependent add \
         chain)\n",
        isa.name()
    );
    println!(
        "| case: Mvertices/s (cycles/vertex)  |     reference |      per-wave |         fused \
         | fused ÷ per-wave | per-wave ÷ ref | fast ÷ ref |"
    );
    println!(
        "|------------------------------------|--------------:|--------------:|--------------:\
         |---------:|---------:|---------:|"
    );
    for row in &results {
        print_row(row, ghz);
    }
    if let Some(dir) = &out {
        bench_run(&results, n, rounds, isa, started, machine)
            .write(dir)
            .unwrap_or_else(|e| panic!("writing {}: {e}", dir.display()));
        println!("\nbench run: {}", dir.join("bench.json").display());
    }

    if args.get(3).is_some_and(|a| a == "timing") {
        return;
    }
    println!("\n# max abs error vs f64 oracle (analytic normals): reference / fast\n");
    println!("| waves | size | t | z | nx | ny | nz |");
    println!("|---|---:|---:|---|---|---|---|");
    let mut worst = [[0.0f64; 4]; 2];
    let mut paths_diff = 0.0f32;
    for (label, waves) in [
        ("half-int", WaveSet::default()),
        ("8 waves", eight_waves()),
        ("non-half", non_half_integer()),
    ] {
        for size in [40usize, 256, 1024] {
            let grid = Grid::new(size, 1.0).unwrap();
            for t in [0.0f32, 1.0, 100.0, 1e4] {
                let mut m = Mesh::new(grid);
                reference::step(&waves, &mut m, t, true);
                let er = errors(&waves, &m, t);
                kernel(&waves, Path::Fused).step(&mut m, t, true);
                let ef = errors(&waves, &m, t);
                let mut p = Mesh::new(grid);
                kernel(&waves, Path::PerWave).step(&mut p, t, true);
                paths_diff = paths_diff.max(mesh_diff(&m, &p));
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
    println!("max |fused − per-wave| over all of the above: {paths_diff:e}");
}
