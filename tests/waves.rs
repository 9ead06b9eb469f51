//! The wave equations at hand-computed points, and validation of waves files.

use oceanbench::ocean::{Grid, Kernel, Mesh, NormalMethod, OceanKind, OceanParams, Wave, WaveSet};

fn one_wave(steepness: f32) -> WaveSet {
    WaveSet::new(vec![Wave {
        amplitude: 2.0,
        wavelength: 8.0,
        speed: 1.0,
        direction: [3.0, 0.0],
        steepness,
        enabled: true,
    }])
    .unwrap()
}

fn step(waves: &WaveSet, n: usize, t: f32, normals: NormalMethod) -> Mesh {
    let grid = Grid::new(n, 1.0).unwrap();
    let mut ocean = OceanKind::SINES
        .model()
        .prepare(
            grid,
            &OceanParams::default().with(waves.clone()),
            normals,
            Kernel::Reference,
        )
        .unwrap();
    let mut mesh = Mesh::new(grid);
    ocean.step(t, &mut mesh);
    mesh
}

#[test]
fn heights_match_hand_computed_values() {
    // L = 8, direction (1, 0) after normalisation: S = 2π·x/8 + t·2π/8.
    // t = 0: x = 0 → S = 0, sin = 0, base 1/2; x = 2 → S = π/2, base 1; x = 4 → S = π, base 1/2;
    // x = 6 → S = 3π/2, base 0.
    let waves = one_wave(2.0);
    let mesh = step(&waves, 8, 0.0, NormalMethod::Analytic);
    let expected = [0.5, 0.0, 2.0, 0.0, 0.5, 0.0, 0.0, 0.0];
    for (j, &e) in expected.iter().enumerate() {
        if j % 2 == 0 {
            assert!((mesh.z[j] - e).abs() < 1e-5, "x={j}: {} vs {e}", mesh.z[j]);
        }
    }
    // Steepness 2, amplitude 2: 2·(1/2)² = 0.5 at x=0; 2·1² = 2 at x=2; 0 at x=6.
    // t = 2 shifts the phase by 2·2π/8 = π/2, so x = 0 now sits on the crest.
    let later = step(&waves, 8, 2.0, NormalMethod::Analytic);
    assert!((later.z[0] - 2.0).abs() < 1e-5, "{}", later.z[0]);
    // Heights do not depend on the row for a wave travelling along x.
    assert_eq!(mesh.z[0], mesh.z[8]);
}

#[test]
fn steepness_one_is_the_plain_shifted_sine() {
    let waves = one_wave(1.0);
    let mesh = step(&waves, 8, 0.0, NormalMethod::Analytic);
    for j in 0..8 {
        let s = 2.0 * std::f64::consts::PI * j as f64 / 8.0;
        let expected = 2.0 * (s.sin() + 1.0) / 2.0;
        assert!((mesh.z[j] as f64 - expected).abs() < 1e-5);
    }
}

#[test]
fn disabled_waves_do_not_count() {
    let mut set = WaveSet::default();
    let all = step(&set, 16, 3.0, NormalMethod::Analytic);
    set.waves[1].enabled = false;
    let fewer = step(&set, 16, 3.0, NormalMethod::Analytic);
    assert_ne!(all.z, fewer.z);
    for v in 0..all.z.len() {
        let (x, y) = (fewer.x[v] as f64, fewer.y[v] as f64);
        assert!((fewer.z[v] as f64 - set.height_f64(x, y, 3.0)).abs() < 1e-4);
    }
}

#[test]
fn reference_heights_match_the_f64_equation() {
    let set = WaveSet::default();
    let mesh = step(&set, 32, 12.5, NormalMethod::Analytic);
    for v in 0..mesh.z.len() {
        let (x, y) = (mesh.x[v] as f64, mesh.y[v] as f64);
        let h = set.height_f64(x, y, 12.5);
        assert!((mesh.z[v] as f64 - h).abs() < 1e-4, "vertex {v}");
    }
}

#[test]
fn waves_file_parses_with_enabled_optional() {
    let set = WaveSet::from_json(
        r#"{"waves": [{"amplitude": 0.5, "wavelength": 20.0, "speed": 2.0, "direction": [1.0, 0.0], "steepness": 2.0}]}"#,
    )
    .unwrap();
    assert!(set.waves[0].enabled);
}

#[test]
fn invalid_waves_name_the_wave_and_the_field() {
    let wave = |fields: &str| {
        format!(r#"{{"amplitude": 0.5, "speed": 2.0, "direction": [1.0, 0.0], {fields}}}"#)
    };
    let good = wave(r#""wavelength": 20.0, "steepness": 2.0"#);
    let cases = [
        (wave(r#""wavelength": 0.0, "steepness": 2.0"#), "waves[1].wavelength"),
        (wave(r#""wavelength": -3.0, "steepness": 2.0"#), "waves[1].wavelength"),
        (wave(r#""wavelength": 20.0, "steepness": 0.5"#), "waves[1].steepness"),
        (
            r#"{"amplitude": 0.5, "speed": 2.0, "direction": [0.0, 0.0], "wavelength": 20.0, "steepness": 2.0}"#.to_string(),
            "waves[1].direction",
        ),
        (wave(r#""wavelength": 1e39, "steepness": 2.0"#), "waves[1].wavelength: must be a finite"),
        (wave(r#""wavelength": 20.0, "steepness": 2.0, "colour": 1"#), "unknown field `colour`"),
        (wave(r#""wavelength": 20.0"#), "missing field `steepness`"),
    ];
    for (bad, expect) in cases {
        let text = format!(r#"{{"waves": [{good}, {bad}]}}"#);
        let err = WaveSet::from_json(&text).unwrap_err().to_string();
        assert!(err.contains(expect), "{bad}: {err}");
        assert!(err.starts_with("waves"), "{err}");
        assert!(!err.contains('\n'), "one line: {err}");
    }
    assert!(WaveSet::from_json(r#"{"waves": []}"#)
        .unwrap_err()
        .to_string()
        .contains("1 to 16"));
    let seventeen = vec![good.as_str(); 17].join(",");
    assert!(WaveSet::from_json(&format!(r#"{{"waves": [{seventeen}]}}"#)).is_err());
    assert!(WaveSet::from_json(r#"{"wave": []}"#)
        .unwrap_err()
        .to_string()
        .contains("unknown field `wave`"));
}
