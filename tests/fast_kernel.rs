//! The fast kernel against the reference kernel and the f64 oracle, on every instruction set the
//! CPU offers and on both its paths (fused and per-wave, which agree within the kernel's
//! tolerance, not bit for bit: they sum the waves' terms in different orders, up to 7e-7 apart
//! in a height on AVX-512), and its
//! stencil `neighbors` normals against the reference neighbour list.

use oceanbench::ocean::normals::FaceNormals;
use oceanbench::ocean::sines::fast::{FastKernel, Isa, Path, StencilNormals};
use oceanbench::ocean::sines::reference;
use oceanbench::ocean::{Grid, Kernel, Mesh, NormalMethod, OceanKind, Wave, WaveSet};
use proptest::prelude::*;

/// Max abs error of z, nx, ny, nz against the f64 oracle.
fn oracle_errors(waves: &WaveSet, mesh: &Mesh, t: f32) -> [f64; 4] {
    let mut e = [0.0f64; 4];
    for v in 0..mesh.z.len() {
        let (x, y, t) = (mesh.x[v] as f64, mesh.y[v] as f64, t as f64);
        let n = waves.normal_f64(x, y, t);
        let want = [waves.height_f64(x, y, t), n[0], n[1], n[2]];
        let got = [mesh.z[v], mesh.nx[v], mesh.ny[v], mesh.nz[v]];
        for k in 0..4 {
            e[k] = e[k].max((got[k] as f64 - want[k]).abs());
        }
    }
    e
}

/// Error bounds: heights scale with the summed amplitudes, normals are unit vectors.
fn tolerance(waves: &WaveSet) -> [f64; 4] {
    let amp: f64 = waves.enabled().map(|w| w.amplitude as f64).sum();
    [4e-6 * amp + 1e-6, 1e-5, 1e-5, 1e-5]
}

/// Largest |a − b| over two equally long slices.
fn max_diff(a: &[f32], b: &[f32]) -> f32 {
    a.iter()
        .zip(b)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f32::max)
}

/// Whether every enabled steepness is a half-integer with 2k − 2 <= 12, the sets the fused
/// path takes.
fn fused_covers(waves: &WaveSet) -> bool {
    waves
        .enabled()
        .all(|w| (2.0 * w.steepness).fract() == 0.0 && w.steepness <= 7.0)
}

/// The two paths of the fast kernel on `isa`: the one `with_isa` picks (fused where it covers
/// the waves, which this checks) and per-wave.
fn paths(waves: &WaveSet, isa: Isa) -> [FastKernel; 2] {
    let default = FastKernel::with_isa(waves, isa);
    let fused = if fused_covers(waves) {
        Path::Fused
    } else {
        Path::PerWave
    };
    let want = if isa == Isa::Avx512 {
        fused
    } else {
        Path::PerWave
    };
    assert_eq!(default.path(), want, "{isa:?} {waves:?}");
    let fast = default.fused();
    assert_eq!(fast.path(), fused, "{waves:?}");
    [fast.clone(), fast.per_wave()]
}

/// Checks both fast paths on every ISA against the oracle (within the tolerance, or at worst
/// the reference's own error), heights-only against heights with normals, and the paths
/// against each other within the tolerance (not bit for bit: the order of the sums differs).
fn check(waves: &WaveSet, grid: Grid, t: f32) {
    let mut m = Mesh::new(grid);
    reference::step(waves, &mut m, t, true);
    let reference = oracle_errors(waves, &m, t);
    let tol = tolerance(waves);
    for isa in Isa::available() {
        let mut meshes = Vec::new();
        for mut fast in paths(waves, isa) {
            let path = fast.path();
            // Twice, so the cached tables are exercised as well as freshly built ones.
            fast.step(&mut m, t + 1.0, true);
            fast.step(&mut m, t, true);
            let got = oracle_errors(waves, &m, t);
            for k in 0..4 {
                assert!(
                    got[k] <= tol[k].max(reference[k]),
                    "{isa:?} {path:?} component {k}: fast error {:e} > tol {:e} (reference \
                     {:e}), t={t}, {grid:?}, {waves:?}",
                    got[k],
                    tol[k],
                    reference[k]
                );
            }
            let mut heights_only = Mesh::new(grid);
            fast.step(&mut heights_only, t, false);
            assert!(heights_only.nz.iter().all(|&z| z == 1.0), "normals touched");
            let dz = max_diff(&heights_only.z, &m.z);
            assert!(dz <= 1e-6, "{isa:?} {path:?}: heights-only differs by {dz}");
            meshes.push(m.clone());
        }
        let [a, b] = [&meshes[0], &meshes[1]];
        for (k, (x, y)) in [(&a.z, &b.z), (&a.nx, &b.nx), (&a.ny, &b.ny), (&a.nz, &b.nz)]
            .into_iter()
            .enumerate()
        {
            let d = max_diff(x, y) as f64;
            assert!(
                d <= tol[k],
                "{isa:?}: paths differ by {d:e} in component {k}"
            );
        }
    }
}

fn steepness() -> impl Strategy<Value = f32> {
    prop_oneof![Just(1.0f32), half_integer_steepness(), 1.0f32..8.0,]
}

/// k = 1, 1.5, …, 8: exponents 2k − 2 of 0 to 14, the fused path's 0..=12 and two above it.
fn half_integer_steepness() -> impl Strategy<Value = f32> {
    (2u32..=16).prop_map(|m| m as f32 / 2.0)
}

fn wave() -> impl Strategy<Value = Wave> {
    wave_with(steepness())
}

fn wave_with(steepness: impl Strategy<Value = f32>) -> impl Strategy<Value = Wave> {
    (
        0.01f32..2.0,
        2.0f32..100.0,
        0.0f32..20.0,
        0.0f32..std::f32::consts::TAU,
        0.5f32..2.0,
        steepness,
        prop::bool::weighted(0.8),
    )
        .prop_map(
            |(amplitude, wavelength, speed, angle, len, steepness, enabled)| Wave {
                amplitude,
                wavelength,
                speed,
                direction: [len * angle.cos(), len * angle.sin()],
                steepness,
                enabled,
            },
        )
}

fn time() -> impl Strategy<Value = f32> {
    prop_oneof![Just(0.0f32), 0.0f32..100.0, Just(1e4f32)]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn fast_matches_oracle(
        waves in prop::collection::vec(wave(), 1..=6),
        n in 2usize..50,
        spacing in 0.25f32..3.0,
        t in time(),
    ) {
        let waves = WaveSet::new(waves).unwrap();
        check(&waves, Grid::new(n, spacing).unwrap(), t);
    }

    /// Half-integer sets of up to 16 waves (the most a set holds), which the fused path takes
    /// unless an exponent is above 12.
    #[test]
    fn fused_and_per_wave_agree_within_tolerance(
        waves in prop::collection::vec(wave_with(half_integer_steepness()), 1..=16),
        n in 2usize..90,
        spacing in 0.25f32..3.0,
        t in time(),
    ) {
        let waves = WaveSet::new(waves).unwrap();
        check(&waves, Grid::new(n, spacing).unwrap(), t);
    }

    /// Any band of rows is bit-identical to the same rows of a whole step, on both paths.
    #[test]
    fn bands_match_whole_steps(
        waves in prop::collection::vec(wave(), 1..=6),
        n in 2usize..70,
        cut in 0.0f64..1.0,
        t in time(),
    ) {
        let waves = WaveSet::new(waves).unwrap();
        let grid = Grid::new(n, 1.0).unwrap();
        // Bands are never empty: the frame loop gives each helper at least one row.
        let cut = 1 + (cut * (n - 1) as f64) as usize;
        for isa in Isa::available() {
            for kernel in [FastKernel::with_isa(&waves, isa), FastKernel::with_isa(&waves, isa).per_wave()] {
                for analytic in [false, true] {
                    let mut whole = Mesh::new(grid);
                    kernel.clone().step(&mut whole, t, analytic);
                    let mut banded = Mesh::new(grid);
                    for rows in [0..cut, cut..n] {
                        kernel.clone().step_rows(banded.rows_mut(rows), t, analytic);
                    }
                    prop_assert!(banded == whole, "{:?} {:?} analytic={}", isa, kernel.path(), analytic);
                }
            }
        }
    }

    #[test]
    fn stencil_neighbors_match_reference(
        waves in prop::collection::vec(wave(), 1..=4),
        n in 2usize..50,
        spacing in 0.25f32..3.0,
        t in time(),
    ) {
        let waves = WaveSet::new(waves).unwrap();
        let grid = Grid::new(n, spacing).unwrap();
        let mut want = Mesh::new(grid);
        reference::step(&waves, &mut want, t, false);
        let mut got = want.clone();
        FaceNormals::new(grid).compute(&mut want, NormalMethod::Neighbors);
        for isa in Isa::available() {
            StencilNormals::with_isa(isa).compute(&mut got);
            for (a, b) in [(&got.nx, &want.nx), (&got.ny, &want.ny), (&got.nz, &want.nz)] {
                let d = max_diff(a, b);
                prop_assert!(d <= 3e-7, "{:?}: neighbors differ by {}", isa, d);
            }
        }
    }
}

fn wave_k(steepness: f32, enabled: bool) -> Wave {
    Wave {
        amplitude: 0.8,
        wavelength: 23.0,
        speed: 6.0,
        direction: [0.6, -0.8],
        steepness,
        enabled,
    }
}

#[test]
fn steepness_exactly_one_and_non_half_integer() {
    let grid = Grid::new(37, 0.7).unwrap();
    for k in [1.0, 1.3, 2.7, 6.25, 7.5, 9.0] {
        let waves = WaveSet::new(vec![wave_k(k, true)]).unwrap();
        for t in [0.0, 1.0, 100.0, 1e4] {
            check(&waves, grid, t);
        }
    }
}

#[test]
fn default_waves_at_large_t_and_size() {
    let grid = Grid::new(300, 1.0).unwrap();
    for t in [0.0, 1e4] {
        check(&WaveSet::default(), grid, t);
    }
}

#[test]
fn disabled_waves_contribute_nothing() {
    let grid = Grid::new(20, 1.0).unwrap();
    let with = WaveSet::new(vec![wave_k(2.0, true), wave_k(3.3, false)]).unwrap();
    let without = WaveSet::new(vec![wave_k(2.0, true)]).unwrap();
    let (mut a, mut b) = (Mesh::new(grid), Mesh::new(grid));
    FastKernel::new(&with).step(&mut a, 5.0, true);
    FastKernel::new(&without).step(&mut b, 5.0, true);
    assert_eq!(a, b);
    let none = WaveSet::new(vec![wave_k(2.0, false)]).unwrap();
    FastKernel::new(&none).step(&mut a, 5.0, true);
    assert!(a.z.iter().all(|&z| z == 0.0) && a.nz.iter().all(|&z| z == 1.0));
}

#[test]
fn ocean_fast_kernel_matches_reference_for_every_normal_method() {
    let grid = Grid::new(24, 1.0).unwrap();
    for normals in [
        NormalMethod::Lookup,
        NormalMethod::Neighbors,
        NormalMethod::Analytic,
    ] {
        let mut meshes = [Mesh::new(grid), Mesh::new(grid)];
        for (kernel, mesh) in [Kernel::Reference, Kernel::Fast]
            .into_iter()
            .zip(&mut meshes)
        {
            let mut ocean = OceanKind::SINES
                .model()
                .prepare(
                    grid,
                    &oceanbench::ocean::OceanParams::default(),
                    normals,
                    kernel,
                )
                .unwrap();
            ocean.step(3.5, mesh);
        }
        let [r, f] = &meshes;
        for (a, b) in [(&r.z, &f.z), (&r.nx, &f.nx), (&r.ny, &f.ny), (&r.nz, &f.nz)] {
            let d = max_diff(a, b);
            assert!(d < 1e-5, "{normals:?}: kernels differ by {d}");
        }
    }
}

#[test]
fn kernel_name_and_serde() {
    assert_eq!(Kernel::Fast.name(), "fast");
    assert_eq!(serde_json::to_string(&Kernel::Fast).unwrap(), "\"fast\"");
}
