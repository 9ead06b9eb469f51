use super::*;
use crate::camera::Camera;
use crate::ocean::{FftParams, GridKind, Kernel, NormalMethod, OceanKind, OceanParams};
use crate::workload::WorkloadKind;

fn spec(n: usize, particles: u64) -> WorkSpec {
    WorkSpec {
        kind: WorkloadKind::SPRAY,
        amount: particles,
        grid: Grid::new(n, 1.0).unwrap(),
        camera: Camera::default(),
        spacing: 2.0,
        time_step: 0.1,
    }
}

/// A flat mesh (rest spacing 2) folding at vertex (1, 1) only, towards +x.
fn folding_mesh(n: usize) -> Mesh {
    let mut mesh = Mesh::new(Grid::new(n, 1.0).unwrap()).with_fold();
    for (x, y) in mesh.x.iter_mut().zip(mesh.y.iter_mut()) {
        (*x, *y) = (*x * 2.0, *y * 2.0);
    }
    let v = n + 1;
    (mesh.fold[v], mesh.fold_dx[v], mesh.fold_dy[v]) = (0.2, 1.0, 0.0);
    mesh
}

/// FFT meshes of a steep sea (choppiness 3, so the surface folds at N = 32), frames 0 to
/// `frames` − 1 at 1/60 s apart, and their rest spacing.
fn fft_meshes(n: usize, frames: u64) -> (Vec<Mesh>, f32) {
    let grid = Grid::new(n, 1.0).unwrap();
    let params = OceanParams::default().with(FftParams {
        choppiness: 3.0,
        ..FftParams::default()
    });
    let model = OceanKind::FFT.model();
    let mut ocean = model
        .prepare(grid, &params, NormalMethod::Analytic, Kernel::Reference)
        .unwrap();
    let meshes = (0..frames)
        .map(|k| {
            let mut m = model.mesh(grid);
            ocean.step(k as f32 / 60.0, &mut m);
            m
        })
        .collect();
    (meshes, model.rest_spacing(grid, &params))
}

#[test]
fn particles_are_born_only_where_the_surface_folds_along_its_direction() {
    let params = SprayParams {
        emission_cap: 3,
        speed: 10.0,
        ..SprayParams::default()
    };
    let mut spray = Spray::new(&spec(4, 8), params);
    let mesh = folding_mesh(4);
    spray.run(0, &mesh, None).unwrap();
    assert_eq!(
        spray.counts(),
        Some(WorkCounts::new(&super::COUNTS, &[3, 3, 0]))
    );
    let pool = spray.pool();
    for i in (0..8).filter(|&i| pool.alive[i]) {
        assert!((pool.px[i] - 2.0).abs() <= 1.0 && (pool.py[i] - 2.0).abs() <= 1.0);
        assert_eq!(pool.pz[i], 0.0, "born on the surface");
        // 10·(1/√2) along +x and up, ±1 of jitter; no surface velocity on the first frame.
        for (v, want) in [(pool.vx[i], 7.07), (pool.vy[i], 0.0), (pool.vz[i], 7.07)] {
            assert!((v - want).abs() <= 1.01, "{v} vs {want}");
        }
        assert_eq!(pool.age[i], 0.0);
    }
    let mut flat = mesh.clone();
    flat.fold[5] = 1.0;
    let mut none = Spray::new(&spec(4, 8), params);
    none.run(0, &flat, None).unwrap();
    assert_eq!(
        none.counts().unwrap().get("emitted").unwrap(),
        0,
        "no fold, no spray"
    );
}

#[test]
fn a_vertex_that_moved_since_the_last_mesh_adds_its_velocity() {
    let params = SprayParams {
        emission_cap: 1,
        speed: 0.0,
        lifetime: 100.0,
        ..SprayParams::default()
    };
    let mut spray = Spray::new(&spec(4, 4), params);
    let mut mesh = folding_mesh(4);
    spray.run(3, &mesh, None).unwrap();
    // Two frames later (0.2 s at 0.1 s per frame) the folding vertex is 1 m higher: 5 m/s up.
    mesh.z[5] = 1.0;
    spray.run(5, &mesh, None).unwrap();
    let pool = spray.pool();
    let newest = (0..4)
        .filter(|&i| pool.alive[i])
        .min_by(|&a, &b| pool.age[a].total_cmp(&pool.age[b]))
        .unwrap();
    assert_eq!(pool.age[newest], 0.0);
    assert!((pool.vz[newest] - 5.0).abs() < 1e-5, "{}", pool.vz[newest]);
    assert_eq!(pool.vx[newest], 0.0);
    assert_eq!(spray.surface_frame(), Some(5));
}

#[test]
fn the_fast_loop_and_the_plain_loop_fly_the_same_particles_bit_for_bit() {
    let (meshes, spacing) = fft_meshes(32, 40);
    let params = SprayParams {
        emission_cap: 300,
        ..SprayParams::default()
    };
    let make = || {
        Spray::new(
            &WorkSpec {
                spacing,
                time_step: 1.0 / 60.0,
                ..spec(32, 2_003)
            },
            params,
        )
    };
    let (mut fast, mut plain) = (make(), make());
    let mut live = 0i64;
    for (k, mesh) in meshes.iter().enumerate() {
        fast.run(k as u64, mesh, None).unwrap();
        plain.run_plain(k as u64, mesh);
        let c = fast.counts().unwrap();
        live += c.get("emitted").unwrap() as i64 - c.get("recycled").unwrap() as i64;
        assert_eq!(
            c.get("live").unwrap() as i64,
            live,
            "frame {k}: live = born - dead"
        );
    }
    assert_eq!(fast.pool(), plain.pool());
    assert_eq!(fast.digest(), plain.digest());
    let c = fast.counts().unwrap();
    assert!(
        c.get("live") > Some(0) && c.get("recycled") > Some(0),
        "{c:?}: a steep sea sprays"
    );
}

#[test]
fn frames_allocate_nothing_and_a_full_pool_emits_nothing() {
    let (meshes, spacing) = fft_meshes(32, 12);
    let params = SprayParams {
        emission_cap: 50,
        lifetime: 1000.0,
        ..SprayParams::default()
    };
    let mut spray = Spray::new(
        &WorkSpec {
            spacing,
            ..spec(32, 64)
        },
        params,
    );
    spray.run(0, &meshes[0], None).unwrap();
    let buffers = |s: &Spray| {
        (
            s.pool.px.as_ptr(),
            s.pool.free.as_ptr(),
            s.pool.free.capacity(),
            s.candidates.capacity() + s.previous.capacity(),
            s.previous_at.capacity(),
        )
    };
    let before = buffers(&spray);
    for (k, mesh) in meshes.iter().enumerate().skip(1) {
        spray.run(k as u64, mesh, None).unwrap();
    }
    // The candidate and previous lists swap every frame, so only their sum is fixed.
    assert_eq!(buffers(&spray), before);
    assert!(spray.pool().live() <= 64);
}

#[test]
fn a_raised_stop_flag_stops_the_frame() {
    let mesh = folding_mesh(4);
    let stop = AtomicBool::new(true);
    let mut spray = Spray::new(&spec(4, 8), SprayParams::default());
    assert_eq!(spray.run(0, &mesh, Some(&stop)), Err(Stopped));
}

#[test]
fn bad_parameters_name_their_field_and_range() {
    assert!(SprayParams::default().validate().is_ok());
    let cases = [
        (
            SprayParams {
                threshold: 1.5,
                ..Default::default()
            },
            "spray.threshold: must be -100 to 1",
        ),
        (
            SprayParams {
                lifetime: -1.0,
                ..Default::default()
            },
            "spray.lifetime: must be above 0",
        ),
        (
            SprayParams {
                speed: -2.0,
                ..Default::default()
            },
            "spray.speed: must be 0 to 1000",
        ),
        (
            SprayParams {
                drag: f64::NAN,
                ..Default::default()
            },
            "spray.drag: must be 0 to 1000",
        ),
        (
            SprayParams {
                emission_cap: 0,
                ..Default::default()
            },
            "spray.emission_cap: must be 1 to",
        ),
    ];
    for (params, start) in cases {
        let e = params.validate().unwrap_err().0;
        assert!(e.starts_with(start), "{e}");
    }
}

#[test]
fn particle_counts_must_be_whole_positive_and_fit_in_memory() {
    assert!(check_particles("p", 131_072.0, Some(1 << 30)).is_ok());
    for bad in [0.0, -5.0, 2.5, f64::NAN] {
        let e = check_particles("p", bad, None).unwrap_err().0;
        assert!(
            e.starts_with("p: must be a whole number of particles, 1 to"),
            "{e}"
        );
    }
    let e = check_particles("p", 1e9, Some(1 << 30)).unwrap_err().0;
    assert_eq!(
        e,
        "p: 1000000000 particles need 31471 MiB for the pool (33 bytes each) but only 1024 MiB is available"
    );
    let e = check_particles("p", 1e10, None).unwrap_err().0;
    assert!(e.starts_with("p: must be 1 to 4294967295"), "{e}");
}

#[test]
fn only_a_folding_ocean_takes_spray() {
    assert!(check_ocean("fft", OceanKind::FFT.model()).is_ok());
    let e = check_ocean("sines", OceanKind::SINES.model())
        .unwrap_err()
        .0;
    assert!(
        e.starts_with("workload_kind: spray needs the fft ocean's folds"),
        "{e}"
    );
}

#[test]
fn only_the_regular_grid_takes_spray() {
    assert!(check_grid(GridKind::Regular).is_ok());
    let e = check_grid(GridKind::Projected).unwrap_err().0;
    assert!(e.starts_with("grid: spray"), "{e}");
    assert!(e.contains("`regular`") && e.contains("`projected`"), "{e}");
    let fft = WorkloadKind::SPRAY.check_surface(OceanKind::FFT, GridKind::Projected);
    assert_eq!(fft.unwrap_err().0, e);
}
