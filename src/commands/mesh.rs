//! `oceanbench mesh`: one frame of the surface as CSV.

use super::CliError;
use crate::cli::MeshArgs;
use crate::config::InputError;
use crate::ocean::{FftParams, Grid, OceanParams, WaveSet};
use crate::report::csv;
use serde::Serialize;

/// One vertex of the CSV: its grid position, coordinates, normal and, for a model that fills
/// it, the fold value J.
#[derive(Serialize)]
struct VertexRow {
    i: usize,
    j: usize,
    #[serde(serialize_with = "shortest")]
    x: f32,
    #[serde(serialize_with = "shortest")]
    y: f32,
    #[serde(serialize_with = "shortest")]
    z: f32,
    #[serde(serialize_with = "shortest")]
    nx: f32,
    #[serde(serialize_with = "shortest")]
    ny: f32,
    #[serde(serialize_with = "shortest")]
    nz: f32,
    #[serde(skip_serializing_if = "Option::is_none")]
    fold: Option<Shortest>,
}

/// An f32 written in its own shortest digits.
struct Shortest(f32);

impl Serialize for Shortest {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        shortest(&self.0, s)
    }
}

/// An f32 in its own shortest digits (`0.3`): the CSV writer goes through f64, which would
/// print the same value as `0.30000001192092896`.
fn shortest<S: serde::Serializer>(v: &f32, s: S) -> Result<S::Ok, S::Error> {
    s.collect_str(v)
}

pub(super) fn mesh(args: MeshArgs) -> Result<(), CliError> {
    let model = args.ocean.model();
    // The model's own size rule first: its message names the sizes it takes.
    model.check(args.size, args.normals)?;
    crate::projected::check(args.grid, args.ocean.name(), model, args.normals)?;
    let mut camera = crate::camera::Camera::default();
    args.camera.apply(&mut camera);
    camera.validate()?;
    let grid = Grid::new(args.size, args.spacing)?;
    if !args.time.is_finite() {
        return Err(InputError(format!(
            "--time: must be a finite number, got {}",
            args.time
        ))
        .into());
    }
    let waves = match &args.waves {
        Some(path) => WaveSet::load(path).map_err(|e| InputError(e.to_string()))?,
        None => WaveSet::default(),
    };
    let fft = match &args.fft_params {
        Some(path) => FftParams::load(path)?,
        None => FftParams::default(),
    };
    let params = OceanParams::default().with(waves).with(fft);
    let mut ocean = crate::projected::stepper(
        args.grid,
        model,
        grid,
        &params,
        args.normals,
        args.kernel,
        camera,
    )?;
    let mut mesh = model.mesh(grid);
    ocean.step(args.time, &mut mesh);
    let file = std::fs::File::create(&args.out)
        .map_err(|e| InputError(format!("--out: cannot create {}: {e}", args.out.display())))?;
    let rows = (0..grid.n).flat_map(|i| (0..grid.n).map(move |j| (i, j)));
    let rows = rows.map(|(i, j)| {
        let v = grid.index(i, j);
        VertexRow {
            i,
            j,
            x: mesh.x[v],
            y: mesh.y[v],
            z: mesh.z[v],
            nx: mesh.nx[v],
            ny: mesh.ny[v],
            nz: mesh.nz[v],
            fold: mesh.fold.get(v).copied().map(Shortest),
        }
    });
    csv::write(std::io::BufWriter::new(file), rows)
        .map_err(|e| anyhow::anyhow!("{}: {e}", args.out.display()))?;
    Ok(())
}
