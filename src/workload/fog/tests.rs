use super::*;
use crate::camera::Camera;
use crate::ocean::sines::fast::Isa;
use crate::ocean::Grid;
use crate::workload::WorkloadKind;
use ::noise::permutationtable::{NoiseHasher, PermutationTable};
use ::noise::{NoiseFn, Perlin};

const NOISE_TOLERANCE: f32 = noise::ORACLE_TOLERANCE;

fn spec(n: usize, volume: u64) -> WorkSpec {
    WorkSpec {
        kind: WorkloadKind::FOG,
        amount: volume,
        grid: Grid::new(n, 1.5).unwrap(),
        camera: Camera::default(),
        spacing: 1.5,
        time_step: 1.0 / 60.0,
    }
}

/// A mesh with waves, so that heights and distances vary.
fn wavy(grid: Grid) -> Mesh {
    let mut mesh = Mesh::new(grid);
    for (i, z) in mesh.z.iter_mut().enumerate() {
        *z = (i as f32 * 0.37).sin() * 2.0;
    }
    mesh
}

/// A deterministic pseudo-random volume.
fn random_volume(n: usize, seed: u64) -> Vec<f32> {
    let mut z = seed;
    (0..n * n * n)
        .map(|_| {
            z = z
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (z >> 40) as f32 / (1u64 << 24) as f32 - 0.5
        })
        .collect()
}

#[test]
fn the_permutation_is_the_noise_crates_for_the_same_seed() {
    for seed in [0, 1, 42, 0xDEAD_BEEF, u32::MAX] {
        let theirs = PermutationTable::new(seed);
        let ours = noise::permutation(seed);
        for (i, &entry) in ours.iter().enumerate() {
            // A one-coordinate hash is the table entry itself.
            assert_eq!(
                entry as usize,
                theirs.hash(&[i as isize]),
                "seed {seed} entry {i}"
            );
        }
    }
}

#[test]
fn the_fast_noise_is_the_noise_crates_perlin_over_the_same_octaves() {
    let fog = FogParams {
        octaves: 3,
        strides: Some(vec![7.0, 3.3, 0.6]),
        weights: Some(vec![1.0, 0.5, 0.25]),
        seed: 42,
        ..FogParams::default()
    };
    let octaves = fog.octaves();
    let perlins: Vec<Perlin> = (0..3).map(|o| Perlin::new(42 + o)).collect();
    let n = 20;
    for isa in Isa::available() {
        for k in [0, 7] {
            let frame = Fog::frame(k);
            let mut volume = vec![0.0; n * n * n];
            assert!(noise::fill_with(
                isa,
                &mut volume,
                n,
                &octaves,
                &frame,
                None
            ));
            let mut worst = 0.0f32;
            for (v, &got) in volume.iter().enumerate() {
                let (i, j, l) = (v % n, v / n % n, v / (n * n));
                let mut sum = 0.0;
                for (o, p) in octaves.iter().zip(&perlins) {
                    let at = |axis, c| frame.coordinate(axis, c, o.stride);
                    sum += f64::from(o.weight) * p.get([at(0, i), at(1, j), at(2, l)]);
                }
                let want = (sum / 1.75) as f32;
                worst = worst.max((got - want).abs());
            }
            assert!(
                worst <= NOISE_TOLERANCE,
                "{isa:?} frame {k}: off by {worst}"
            );
            assert!(
                volume.iter().any(|&v| v.abs() > 0.1),
                "the noise is not flat"
            );
        }
    }
}

#[test]
fn the_blur_is_a_wrapped_binomial_convolution_and_keeps_the_mean() {
    assert_eq!(blur::weights(3), [0.25, 0.5, 0.25]);
    assert_eq!(
        blur::weights(5),
        [1.0, 4.0, 6.0, 4.0, 1.0].map(|w| w / 16.0)
    );
    // Width 9 on a 7³ volume wraps more than once around a row.
    for (n, width) in [(8, 3), (7, 5), (7, 9), (1, 3)] {
        let w = blur::weights(width);
        let r = width / 2;
        let input = random_volume(n, 3);
        for isa in Isa::available() {
            let mut volume = input.clone();
            let mut scratch = vec![0.0; volume.len()];
            assert!(blur::blur_with(isa, &mut volume, &mut scratch, n, &w, None));
            let at = |x: isize, y: isize, z: isize| {
                let m = |c: isize| c.rem_euclid(n as isize) as usize;
                input[(m(z) * n + m(y)) * n + m(x)]
            };
            for (v, &got) in volume.iter().enumerate() {
                let (x, y, z) = (
                    (v % n) as isize,
                    (v / n % n) as isize,
                    (v / (n * n)) as isize,
                );
                let mut want = 0.0f64;
                for (a, &wa) in w.iter().enumerate() {
                    for (b, &wb) in w.iter().enumerate() {
                        for (c, &wc) in w.iter().enumerate() {
                            let o = |t: usize| t as isize - r as isize;
                            want += f64::from(wa * wb * wc)
                                * f64::from(at(x + o(a), y + o(b), z + o(c)));
                        }
                    }
                }
                assert!(
                    (f64::from(got) - want).abs() < 1e-5,
                    "{isa:?} n {n} width {width} voxel {v}"
                );
            }
            let mean = |v: &[f32]| v.iter().map(|&x| f64::from(x)).sum::<f64>() / v.len() as f64;
            assert!(
                (mean(&volume) - mean(&input)).abs() < 1e-6,
                "{isa:?} n {n} width {width}"
            );
        }
    }
}

#[test]
fn a_periodic_volume_stays_periodic_across_the_wrap() {
    let (n, period) = (12, 4);
    let tile = random_volume(period, 9);
    let mut volume: Vec<f32> = (0..n * n * n)
        .map(|v| {
            let (x, y, z) = (v % n % period, v / n % n % period, v / (n * n) % period);
            tile[(z * period + y) * period + x]
        })
        .collect();
    let mut scratch = vec![0.0; volume.len()];
    assert!(blur::blur(
        &mut volume,
        &mut scratch,
        n,
        &blur::weights(7),
        None
    ));
    let at = |x: usize, y: usize, z: usize| volume[((z % n) * n + y % n) * n + x % n];
    for v in 0..n * n * n {
        let (x, y, z) = (v % n, v / n % n, v / (n * n));
        for shifted in [
            at(x + period, y, z),
            at(x, y + period, z),
            at(x, y, z + period),
        ] {
            assert!(
                (shifted - at(x, y, z)).abs() < 1e-6,
                "voxel ({x}, {y}, {z})"
            );
        }
    }
    assert!(
        volume.iter().any(|&v| (v - volume[0]).abs() > 1e-3),
        "not flattened"
    );
}

#[test]
fn the_coefficient_is_one_at_the_camera_and_falls_with_density() {
    for (dy, n) in [(0.0, 0.0), (0.7, 0.5), (2.0, 1.0)] {
        assert_eq!(coefficient::coefficient(4.0, 0.0, dy, n), 1.0);
        for d in [0.1, 1.0, 3.0] {
            let f: Vec<f32> = [0.0, 0.5, 1.0, 4.0, 40.0]
                .iter()
                .map(|&rho| coefficient::coefficient(rho, d, dy, n))
                .collect();
            assert_eq!(f[0], 1.0, "no fog without density");
            assert!(
                f.windows(2).all(|w| w[1] < w[0]),
                "d {d} dy {dy} n {n}: {f:?}"
            );
        }
    }
}

#[test]
fn fog_gives_every_vertex_a_coefficient_and_moves_with_the_frame() {
    let s = spec(24, 16);
    let mesh = wavy(s.grid);
    let mut fog = Fog::new(&s, &FogParams::default());
    fog.run(0, &mesh, None).unwrap();
    let first = fog.digest();
    let f = fog.coefficients();
    assert_eq!(f.len(), 24 * 24);
    assert!(
        f.iter().all(|&f| f > 0.0 && f < 1.0),
        "fog everywhere, never opaque"
    );
    let spread = f.iter().cloned().fold(f32::MIN, f32::max) - f.iter().cloned().fold(1.0, f32::min);
    assert!(spread > 0.01, "the fog varies over the patch: {spread}");
    fog.run(1, &mesh, None).unwrap();
    assert_ne!(fog.digest(), first, "the fog drifts");
    let Some(r) = fog.pass_record() else {
        panic!("fog records its pass")
    };
    assert_eq!((r.volume, r.octaves), (16, 4));
    assert!(r.noise_ms > 0.0 && r.blur_ms > 0.0 && r.coefficient_ms > 0.0);

    // Denser fog, less light through it, vertex by vertex.
    let mut dense = Fog::new(
        &spec(24, 16),
        &FogParams {
            density: 8.0,
            ..FogParams::default()
        },
    );
    dense.run(0, &mesh, None).unwrap();
    let mut again = Fog::new(&s, &FogParams::default());
    again.run(0, &mesh, None).unwrap();
    assert_eq!(
        again.digest(),
        first,
        "the same frame twice is the same fog"
    );
    assert!(dense
        .coefficients()
        .iter()
        .zip(again.coefficients())
        .all(|(d, f)| d < f));
}

#[test]
fn volume_zero_runs_no_pass_and_a_raised_stop_flag_stops_the_frame() {
    let s = spec(8, 0);
    let mut none = Fog::new(&s, &FogParams::default());
    none.run(5, &Mesh::new(s.grid), None).unwrap();
    assert!(none.coefficients().is_empty() && none.volume().is_empty());
    assert!(none.record().is_none());
    let s = spec(8, 8);
    let stop = AtomicBool::new(true);
    assert_eq!(
        Fog::new(&s, &FogParams::default()).run(0, &Mesh::new(s.grid), Some(&stop)),
        Err(Stopped)
    );
}

#[test]
fn every_bad_parameter_is_named_with_what_is_allowed() {
    let bad = [
        (
            FogParams {
                octaves: 0,
                ..FogParams::default()
            },
            "fog.octaves: must be 1 to 8",
        ),
        (
            FogParams {
                octaves: 9,
                ..FogParams::default()
            },
            "fog.octaves: must be 1 to 8",
        ),
        (
            FogParams {
                density: -0.5,
                ..FogParams::default()
            },
            "fog.density: must be a finite number >= 0",
        ),
        (
            FogParams {
                density: f32::NAN,
                ..FogParams::default()
            },
            "fog.density",
        ),
        (
            FogParams {
                blur_width: 4,
                ..FogParams::default()
            },
            "fog.blur_width: must be odd, 3 to 31",
        ),
        (
            FogParams {
                blur_width: 1,
                ..FogParams::default()
            },
            "fog.blur_width: must be odd, 3 to 31",
        ),
        (
            FogParams {
                strides: Some(vec![8.0]),
                ..FogParams::default()
            },
            "fog.strides: give one per octave",
        ),
        (
            FogParams {
                strides: Some(vec![8.0, 4.0, 0.0, 1.0]),
                ..FogParams::default()
            },
            "fog.strides[2]: must be 0.25 to 4096",
        ),
        (
            FogParams {
                weights: Some(vec![0.0; 4]),
                ..FogParams::default()
            },
            "fog.weights: at least one",
        ),
        (
            FogParams {
                weights: Some(vec![1.0, -1.0, 0.0, 0.0]),
                ..FogParams::default()
            },
            "fog.weights[1]",
        ),
    ];
    for (params, message) in bad {
        let e = params.validate().unwrap_err().0;
        assert!(e.starts_with(message), "{e}");
    }
    FogParams::default().validate().unwrap();
}

#[test]
fn a_volume_too_large_or_beyond_memory_says_what_it_would_need() {
    let e = check_volume("v", 513, None).unwrap_err().0;
    assert!(e.contains("0 to 512") && e.contains("1030 MiB"), "{e}");
    let e = check_volume("v", 128, Some(8 << 20)).unwrap_err().0;
    assert!(
        e.contains("needs 16 MiB") && e.contains("only 8 MiB"),
        "{e}"
    );
    check_volume("v", 512, None).unwrap();
    check_volume("v", 128, Some(16 << 20)).unwrap();
}
