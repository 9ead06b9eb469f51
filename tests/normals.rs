//! The three normal methods against each other and against the equations.

use oceanbench::ocean::{Grid, Kernel, Mesh, NormalMethod, OceanKind, OceanParams, WaveSet};

fn step(n: usize, spacing: f32, t: f32, normals: NormalMethod) -> Mesh {
    let grid = Grid::new(n, spacing).unwrap();
    let mut ocean = OceanKind::SINES
        .model()
        .prepare(grid, &OceanParams::default(), normals, Kernel::Reference)
        .unwrap();
    let mut mesh = Mesh::new(grid);
    ocean.step(t, &mut mesh);
    mesh
}

#[test]
fn analytic_normals_match_finite_differences_of_the_height() {
    let set = WaveSet::default();
    let mesh = step(24, 1.5, 7.25, NormalMethod::Analytic);
    let h = 1e-4;
    for v in 0..mesh.z.len() {
        let (x, y) = (mesh.x[v] as f64, mesh.y[v] as f64);
        let dx = (set.height_f64(x + h, y, 7.25) - set.height_f64(x - h, y, 7.25)) / (2.0 * h);
        let dy = (set.height_f64(x, y + h, 7.25) - set.height_f64(x, y - h, 7.25)) / (2.0 * h);
        let len = (dx * dx + dy * dy + 1.0).sqrt();
        let expected = [-dx / len, -dy / len, 1.0 / len];
        let got = [mesh.nx[v], mesh.ny[v], mesh.nz[v]];
        for c in 0..3 {
            assert!(
                (got[c] as f64 - expected[c]).abs() < 2e-4,
                "vertex {v} component {c}: {} vs {}",
                got[c],
                expected[c]
            );
        }
    }
}

#[test]
fn lookup_and_neighbors_give_identical_normals() {
    for (n, t) in [(2, 0.0), (7, 1.0), (33, 4.5)] {
        let a = step(n, 1.0, t, NormalMethod::Lookup);
        let b = step(n, 1.0, t, NormalMethod::Neighbors);
        assert_eq!(a, b, "size {n}");
    }
}

#[test]
fn normals_are_unit_length_and_face_up() {
    for method in [NormalMethod::Neighbors, NormalMethod::Analytic] {
        let m = step(20, 1.0, 2.0, method);
        for v in 0..m.z.len() {
            let len = (m.nx[v].powi(2) + m.ny[v].powi(2) + m.nz[v].powi(2)).sqrt();
            assert!((len - 1.0).abs() < 1e-5 && m.nz[v] > 0.0, "{method:?} {v}");
        }
    }
}

/// Largest angle (radians) between the `neighbors` and `analytic` normals over interior vertices
/// of a patch of fixed world size, sampled at `n` vertices per side.
fn max_angle(n: usize, world: f32) -> f64 {
    let spacing = world / (n - 1) as f32;
    let a = step(n, spacing, 3.0, NormalMethod::Neighbors);
    let b = step(n, spacing, 3.0, NormalMethod::Analytic);
    let mut worst = 0.0f64;
    for i in 1..n - 1 {
        for j in 1..n - 1 {
            let v = i * n + j;
            let dot = a.nx[v] as f64 * b.nx[v] as f64
                + a.ny[v] as f64 * b.ny[v] as f64
                + a.nz[v] as f64 * b.nz[v] as f64;
            worst = worst.max(dot.clamp(-1.0, 1.0).acos());
        }
    }
    worst
}

#[test]
fn neighbors_approaches_analytic_as_spacing_shrinks() {
    let errors: Vec<f64> = [17, 33, 65, 129]
        .iter()
        .map(|&n| max_angle(n, 32.0))
        .collect();
    for pair in errors.windows(2) {
        assert!(pair[1] < pair[0] * 0.75, "error must shrink: {errors:?}");
    }
    assert!(errors[3] < 0.01, "{errors:?}");
}

#[test]
fn lookup_refuses_grids_that_would_take_too_long() {
    let grid = Grid::new(512, 1.0).unwrap();
    let err = OceanKind::SINES
        .model()
        .prepare(
            grid,
            &OceanParams::default(),
            NormalMethod::Lookup,
            Kernel::Reference,
        )
        .unwrap_err()
        .to_string();
    assert!(err.contains("lookup") && err.contains("size <="), "{err}");
}
