//! The projected grid: every vertex on its camera ray's meeting with the sea plane or on the
//! clamped far line, on the displaced surface (checked in f64 at its own x, y), the footprint
//! of a camera looking straight down, and its bad input. Bit-identity across modes and helper
//! counts is in tests/frame_loop.rs, beside the regular grid's.

mod common;

use common::{assert_one_line_exit_2, assert_success, oceanbench, write_file};
use oceanbench::camera::{Camera, CameraPath, View};
use oceanbench::ocean::sines::Sines;
use oceanbench::ocean::{FftOcean, FftParams};
use oceanbench::ocean::{Grid, GridKind, Kernel, Mesh, Model, NormalMethod, OceanParams, Stepper};
use oceanbench::ocean::{Wave, WaveSet};
use oceanbench::projected;

/// The projected grid's stepper of the sines.
fn stepper(camera: Camera, kernel: Kernel, grid: Grid, waves: &WaveSet) -> Box<dyn Stepper> {
    let params = OceanParams::default().with(waves.clone());
    let analytic = NormalMethod::Analytic;
    projected::stepper(
        GridKind::Projected,
        &Sines,
        grid,
        &params,
        analytic,
        kernel,
        camera,
    )
    .unwrap()
}

/// One projected step of the sines at time `t`.
fn step(camera: Camera, kernel: Kernel, grid: Grid, waves: &WaveSet, t: f32) -> Mesh {
    let mut mesh = Sines.mesh(grid);
    stepper(camera, kernel, grid, waves).step(t, &mut mesh);
    mesh
}

/// Cameras that see the horizon (the default frames the patch with its top edge on it; the
/// low one sees the sky), look straight down, clamp at a short far, and move along a path.
fn cameras() -> Vec<(&'static str, Camera)> {
    let base = Camera::default();
    vec![
        ("default", base),
        (
            "low, sky in view",
            Camera {
                height: Some(6.0),
                pitch_degrees: 8.0,
                fov_degrees: 50.0,
                ..base
            },
        ),
        (
            "straight down",
            Camera {
                height: Some(40.0),
                pitch_degrees: 90.0,
                fov_degrees: 70.0,
                aspect: 1.0,
                ..base
            },
        ),
        (
            "short far, narrow image",
            Camera {
                height: Some(20.0),
                pitch_degrees: 35.0,
                aspect: 0.5,
                far: Some(45.0),
                ..base
            },
        ),
        (
            "on a path",
            Camera {
                height: Some(12.0),
                pitch_degrees: 25.0,
                path: Some(CameraPath {
                    radius: 30.0,
                    period_seconds: 7.0,
                }),
                ..base
            },
        ),
    ]
}

/// f32 rounding of a phase grows with the point's distance from the origin and with t, in
/// both kernels alike (the reference sums x·2π/L in f32): the bound on height and slope
/// errors is that many units in the last place of every wave's phase, times its height's
/// and slope's rate of change, plus the fast kernel's tolerance on the regular grid.
fn tolerance(waves: &WaveSet, x: f64, y: f64, t: f64) -> (f64, f64) {
    let mut z = 1e-5;
    let mut slope = 2e-5;
    for w in waves.enabled() {
        let k = w.frequency() as f64;
        let phase = k * (x.abs() + y.abs() + (w.speed as f64 * t).abs()) + 1.0;
        let err = 8.0 * phase * f32::EPSILON as f64;
        let a = w.amplitude as f64 * w.steepness as f64;
        z += a * k * err;
        slope += a * k * k * w.steepness as f64 * err;
    }
    (z, slope)
}

/// The ray of vertex (i, j) in f64, straight from the image point as the module describes.
fn ray(view: &View, n: usize, i: usize, j: usize) -> [f64; 3] {
    let u = -1.0 + 2.0 * j as f64 / (n - 1) as f64;
    let v = -1.0 + 2.0 * i as f64 / (n - 1) as f64;
    let tan_y = view.tan_half_fov as f64;
    let tan_x = tan_y * view.aspect as f64;
    let c = |k: usize| {
        view.forward[k] as f64 + u * tan_x * view.right[k] as f64 + v * tan_y * view.up[k] as f64
    };
    [c(0), c(1), c(2)]
}

#[test]
fn every_vertex_is_on_its_ray_or_the_far_line_and_on_the_surface() {
    let waves = WaveSet::default();
    let grid = Grid::new(33, 1.5).unwrap();
    let n = grid.n;
    for (name, camera) in cameras() {
        camera.validate().unwrap();
        let (mut on_ray, mut on_far) = (0, 0);
        for kernel in [Kernel::Reference, Kernel::Fast] {
            for t in [0.0f32, 2.3, 611.25] {
                let mesh = step(camera, kernel, grid, &waves, t);
                let view = camera.view_at(grid, t);
                let eye = [view.eye.x as f64, view.eye.y as f64, view.eye.z as f64];
                let far = view.far as f64;
                for i in 0..n {
                    for j in 0..n {
                        let v = grid.index(i, j);
                        let what = format!("{name} {kernel} t {t} vertex ({i}, {j})");
                        let (x, y) = (mesh.x[v] as f64, mesh.y[v] as f64);
                        let (qx, qy) = (x - eye[0], y - eye[1]);
                        let reach = qx.hypot(qy);
                        let d = ray(&view, n, i, j);
                        let d_flat = d[0].hypot(d[1]);
                        // Where the ray meets the plane, as a horizontal distance.
                        let meets = (d[2] < 0.0).then(|| eye[2] / -d[2] * d_flat);
                        let cross = (qx * d[1] - qy * d[0]) / d_flat;
                        assert!(
                            cross.abs() <= 1e-5 * reach.max(1.0) && qx * d[0] + qy * d[1] >= 0.0,
                            "{what}: ({x}, {y}) is off its ray's vertical plane by {cross}"
                        );
                        match meets {
                            Some(m) if m <= far => {
                                assert!(
                                    (reach - m).abs() <= 1e-5 * m.max(1.0),
                                    "{what}: at {reach} from the eye, its ray meets the sea at {m}"
                                );
                                on_ray += 1;
                            }
                            _ => {
                                assert!(
                                    (reach - far).abs() <= 1e-5 * far,
                                    "{what}: a clamped vertex at {reach}, not far = {far}"
                                );
                                on_far += 1;
                            }
                        }
                        let (tz, ts) = tolerance(&waves, x, y, t as f64);
                        let z = waves.height_f64(x, y, t as f64);
                        assert!(
                            (mesh.z[v] as f64 - z).abs() <= tz,
                            "{what}: z {} vs {z} (tolerance {tz})",
                            mesh.z[v]
                        );
                        let normal = waves.normal_f64(x, y, t as f64);
                        let got = [mesh.nx[v], mesh.ny[v], mesh.nz[v]];
                        for (g, e) in got.iter().zip(normal) {
                            assert!(
                                (*g as f64 - e).abs() <= ts,
                                "{what}: normal {got:?} vs {normal:?} (tolerance {ts})"
                            );
                        }
                    }
                }
            }
        }
        assert!(on_ray > 0, "{name}: no vertex on the sea");
        if name != "straight down" {
            assert!(on_far > 0, "{name}: the far line is never reached");
        }
    }
}

#[test]
fn a_camera_looking_straight_down_covers_a_square_of_side_2h_tan_half_fov() {
    let calm = WaveSet::new(vec![Wave {
        amplitude: 0.0,
        ..WaveSet::default().waves[0].clone()
    }])
    .unwrap();
    for (h, fov) in [
        (10.0f32, 90.0f32),
        (40.0, 60.0),
        (3.0, 20.0),
        (100.0, 120.0),
    ] {
        for n in [2, 17, 64] {
            let camera = Camera {
                height: Some(h),
                pitch_degrees: 90.0,
                fov_degrees: fov,
                aspect: 1.0,
                // Beyond the corners, which a small patch's default far would clamp.
                far: Some(10.0 * h * (fov / 2.0).to_radians().tan()),
                ..Camera::default()
            };
            let grid = Grid::new(n, 1.0).unwrap();
            let side = 2.0 * h as f64 * (fov as f64 / 2.0).to_radians().tan();
            for kernel in [Kernel::Reference, Kernel::Fast] {
                let mesh = step(camera, kernel, grid, &calm, 1.0);
                let span = |c: &[f32]| {
                    let lo = c.iter().copied().fold(f32::INFINITY, f32::min) as f64;
                    let hi = c.iter().copied().fold(f32::NEG_INFINITY, f32::max) as f64;
                    hi - lo
                };
                let what = format!("h {h} fov {fov} n {n} {kernel}");
                for (axis, c) in [("x", &mesh.x), ("y", &mesh.y)] {
                    let got = span(c);
                    assert!(
                        (got - side).abs() <= 1e-5 * side,
                        "{what}: {axis} spans {got}, not {side}"
                    );
                }
                // Straight down, the rows and columns stay evenly spaced on a flat sea.
                let step = side / (n - 1) as f64;
                for j in 1..n {
                    let dx = (mesh.x[j] - mesh.x[j - 1]) as f64;
                    assert!((dx - step).abs() <= 1e-4 * side, "{what}: column {j}");
                }
                assert!(mesh.z.iter().all(|&z| z == 0.0), "{what}: a flat sea");
                assert!(mesh.nz.iter().all(|&z| z == 1.0), "{what}: upward normals");
            }
        }
    }
}

#[test]
fn the_mesh_follows_the_camera_along_its_path() {
    let camera = cameras().remove(4).1;
    let grid = Grid::new(9, 1.0).unwrap();
    let waves = WaveSet::default();
    let at = |t: f32| step(camera, Kernel::Reference, grid, &waves, t);
    let (a, b, c) = (at(0.0), at(1.75), at(7.0));
    let moved = camera.view_at(grid, 1.75).eye - camera.view_at(grid, 0.0).eye;
    for v in 0..grid.vertices() {
        let near = |p: f32, q: f32| (p - q).abs() <= 1e-3;
        // A path keeps the heading, so the ground footprint translates with the eye.
        assert!(near(b.x[v] - a.x[v], moved.x) && near(b.y[v] - a.y[v], moved.y));
        // One period later it is back where it started.
        assert!(near(c.x[v], a.x[v]) && near(c.y[v], a.y[v]), "vertex {v}");
    }
    assert!(moved.length() > 1.0);
}

#[test]
fn bands_are_bit_identical_to_whole_steps() {
    let waves = WaveSet::default();
    let grid = Grid::new(20, 1.0).unwrap();
    for (name, camera) in cameras() {
        for kernel in [Kernel::Reference, Kernel::Fast] {
            let whole = step(camera, kernel, grid, &waves, 3.5);
            let mut banded = Sines.mesh(grid);
            let mut s = stepper(camera, kernel, grid, &waves);
            for rows in [0..7, 7..8, 8..20] {
                s.step_rows(3.5, banded.rows_mut(rows));
            }
            assert!(banded == whole, "{name} {kernel}");
        }
    }
}

/// Exit status 2, one stderr line naming `needles`, and the file at `kept` untouched.
fn refused(args: &[&str], needles: &[&str], kept: &std::path::Path) {
    assert_one_line_exit_2(&oceanbench(args), needles);
    assert_eq!(std::fs::read_to_string(kept).unwrap(), "kept", "{args:?}");
}

#[test]
fn bad_cameras_and_combinations_exit_2_with_one_line_and_keep_the_output() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("kept.csv");
    std::fs::write(&out, "kept").unwrap();
    let out = out.to_str().unwrap();
    let mesh = ["mesh", "--grid", "projected", "--time", "1"];
    for (flags, needles) in [
        (
            vec!["--pitch", "0"],
            vec!["camera.pitch_degrees", "above 0", "90"],
        ),
        (vec!["--pitch", "-10"], vec!["camera.pitch_degrees"]),
        (
            vec!["--pitch", "90.5"],
            vec!["camera.pitch_degrees", "at most 90"],
        ),
        (vec!["--fov", "0"], vec!["camera.fov_degrees", "below 180"]),
        (
            vec!["--fov", "180"],
            vec!["camera.fov_degrees", "below 180"],
        ),
        (
            vec!["--camera-height", "0"],
            vec!["camera.height", "above 0"],
        ),
        (vec!["--camera-height", "-3"], vec!["camera.height"]),
        (vec!["--aspect", "0"], vec!["camera.aspect", "above 0"]),
        (vec!["--far", "0"], vec!["camera.far", "above 0"]),
        (vec!["--far", "-1"], vec!["camera.far"]),
        (
            vec!["--path-radius", "5", "--path-period", "0"],
            vec!["camera.path.period_seconds"],
        ),
        (
            vec!["--normals", "neighbors"],
            vec!["normals", "analytic", "neighbors"],
        ),
        (vec!["--normals", "lookup"], vec!["normals", "analytic"]),
    ] {
        let args = [&mesh[..], &flags, &["--size", "8", "--out", out]].concat();
        refused(&args, &needles, std::path::Path::new(out));
    }

    let results = dir.path().join("results");
    std::fs::create_dir(&results).unwrap();
    let kept = results.join("kept.txt");
    std::fs::write(&kept, "kept").unwrap();
    let base = r#""sizes": [8], "workloads": [0], "modes": ["serial"], "grid": ["projected"], "normals": ["analytic"]"#;
    for (camera, needles) in [
        (r#"{"pitch_degrees": 0}"#, vec!["camera.pitch_degrees"]),
        (r#"{"pitch_degrees": 91}"#, vec!["camera.pitch_degrees"]),
        (r#"{"fov_degrees": 180}"#, vec!["camera.fov_degrees"]),
        (r#"{"height": 0}"#, vec!["camera.height"]),
        (r#"{"aspect": -1}"#, vec!["camera.aspect"]),
        (r#"{"far": 0}"#, vec!["camera.far"]),
        (r#"{"pitch": 10}"#, vec!["camera.pitch", "pitch_degrees"]),
        (
            r#"{"path": {"radius": 1, "period": 2}}"#,
            vec!["camera.path.period", "period_seconds"],
        ),
    ] {
        let config = write_file(
            dir.path(),
            "c.json",
            &format!(r#"{{{base}, "camera": {camera}}}"#),
        );
        let args = ["sweep", &config, "--out", results.to_str().unwrap()];
        refused(&args, &needles, &kept);
    }
    let config = write_file(
        dir.path(),
        "c.json",
        &format!(r#"{{{}}}"#, base.replace("analytic", "neighbors")),
    );
    let args = ["sweep", &config, "--out", results.to_str().unwrap()];
    refused(&args, &["normals", "analytic"], &kept);
    refused(
        &[
            "run",
            "--grid",
            "projected",
            "--normals",
            "neighbors",
            "--frames",
            "1",
        ],
        &["normals", "analytic"],
        &kept,
    );
}

#[test]
fn mesh_csv_of_the_projected_grid_has_the_regular_grid_s_columns() {
    let dir = tempfile::tempdir().unwrap();
    let csv = |grid: &str| {
        let path = dir.path().join(format!("{grid}.csv"));
        let out = oceanbench(&[
            "mesh",
            "--grid",
            grid,
            "--size",
            "6",
            "--time",
            "2.5",
            "--camera-height",
            "15",
            "--pitch",
            "40",
            "--out",
            path.to_str().unwrap(),
        ]);
        assert_success(&out);
        std::fs::read_to_string(path).unwrap()
    };
    let (regular, projected) = (csv("regular"), csv("projected"));
    assert_eq!(regular.lines().next(), projected.lines().next());
    assert_eq!(projected.lines().count(), 37);
    let camera = Camera {
        height: Some(15.0),
        pitch_degrees: 40.0,
        ..Camera::default()
    };
    let grid = Grid::new(6, 1.0).unwrap();
    let mesh = step(camera, Kernel::Reference, grid, &WaveSet::default(), 2.5);
    for (row, line) in projected.lines().skip(1).enumerate() {
        let v: Vec<f32> = line.split(',').map(|s| s.parse().unwrap()).collect();
        assert_eq!((v[0] as usize, v[1] as usize), (row / 6, row % 6));
        let want = [
            mesh.x[row],
            mesh.y[row],
            mesh.z[row],
            mesh.nx[row],
            mesh.ny[row],
            mesh.nz[row],
        ];
        assert_eq!(v[2..], want, "row {row}");
    }
}

/// The FFT patch on the projected grid: a vertex placed on one of the patch's own vertices, or
/// on one a whole number of patches away, takes that vertex's surface; one placed half way
/// between two takes their mean height and displacement.
#[test]
fn the_fft_ocean_is_sampled_from_its_patch_repeating_without_a_seam() {
    let n = 32;
    let params = OceanParams::default().with(FftParams {
        choppiness: 1.5,
        ..FftParams::default()
    });
    let spacing = FftOcean.rest_spacing(Grid::new(n, 1.0).unwrap(), &params);
    let patch = Grid::new(n, spacing).unwrap();
    let t = 3.25;
    let mut regular = FftOcean.mesh(patch);
    FftOcean
        .prepare(patch, &params, NormalMethod::Analytic, Kernel::Reference)
        .unwrap()
        .step(t, &mut regular);
    let mut sampler = FftOcean
        .prepare_at_points(Grid::new(n, 1.0).unwrap(), &params, Kernel::Reference)
        .unwrap();
    assert!(FftOcean.grids().contains(&GridKind::Projected));
    let l = n as f32 * spacing;
    let (i, j) = (5, 9);
    let v = i * n + j;
    let (rest_x, rest_y) = (j as f32 * spacing, i as f32 * spacing);
    let points = [
        (rest_x, rest_y),
        (rest_x + 2.0 * l, rest_y - l),
        (rest_x + 0.5 * spacing, rest_y),
    ];
    let mut mesh = FftOcean.mesh(Grid::new(n, 1.0).unwrap());
    for (k, &(px, py)) in points.iter().enumerate() {
        mesh.x[k] = px;
        mesh.y[k] = py;
    }
    let last = mesh.x.len() - 1;
    mesh.x[last] = -l * 0.25;
    mesh.y[last] = l * 7.5;
    sampler.step(t, &mut mesh);
    let close = |a: f32, b: f32, what: &str| {
        assert!(
            (a - b).abs() <= 1e-3 * (1.0 + b.abs()),
            "{what}: {a} against {b}"
        );
    };
    for (k, &(px, py)) in points.iter().enumerate().take(2) {
        close(mesh.z[k], regular.z[v], "height");
        close(mesh.x[k] - px, regular.x[v] - rest_x, "displacement x");
        close(mesh.y[k] - py, regular.y[v] - rest_y, "displacement y");
        close(mesh.nz[k], regular.nz[v], "normal z");
        close(mesh.fold[k], regular.fold[v], "fold");
    }
    let mean = 0.5 * (regular.z[v] + regular.z[v + 1]);
    close(mesh.z[2], mean, "height half way");
    let dx = 0.5 * (regular.x[v] + regular.x[v + 1] - 2.0 * rest_x - spacing);
    close(mesh.x[2] - points[2].0, dx, "displacement half way");
    for k in 0..mesh.z.len() {
        let normal = (mesh.nx[k].powi(2) + mesh.ny[k].powi(2) + mesh.nz[k].powi(2)).sqrt();
        close(normal, 1.0, "unit normal");
        assert!(mesh.z[k].is_finite() && mesh.fold[k].is_finite());
    }
}

#[test]
fn mesh_writes_the_fft_ocean_on_the_projected_grid_with_its_fold() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("fft.csv");
    let out = oceanbench(&[
        "mesh",
        "--grid",
        "projected",
        "--ocean",
        "fft",
        "--size",
        "64",
        "--time",
        "1",
        "--out",
        path.to_str().unwrap(),
    ]);
    assert_success(&out);
    let csv = std::fs::read_to_string(path).unwrap();
    assert!(csv.lines().next().unwrap().ends_with(",fold"), "{csv:.80}");
    assert_eq!(csv.lines().count(), 64 * 64 + 1);
}
