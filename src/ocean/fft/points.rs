//! The FFT ocean at any point of the sea plane, for the projected grid: the regular N×N surface
//! of the patch is computed as on the regular grid, then each vertex samples it bilinearly at
//! the point the camera placed it, the patch repeating without a seam in both directions. The
//! point is the vertex's rest position: it moves by the sampled choppy displacement and takes
//! the sampled height, normal and fold, as a regular-grid vertex does at its own rest position.

use super::FftState;
use crate::ocean::mesh::{Grid, Mesh, MeshRows};
use crate::ocean::model::Stepper;
use glam::{Vec2, Vec3};

/// The patch's surface at the last time asked for, and the state that computes it.
#[derive(Clone, Debug)]
pub struct FftAtPoints {
    state: FftState,
    surface: Mesh,
    /// The time `surface` was computed for (bits of the f32), so that the bands one helper
    /// fills for one frame share one transform.
    at: Option<u32>,
}

impl FftAtPoints {
    /// Samples the surface `state` computes; `state` fills analytic normals.
    pub fn new(state: FftState) -> Self {
        let grid = Grid::new(state.n, state.spacing()).expect("a checked size");
        FftAtPoints {
            state,
            surface: Mesh::new(grid).with_fold(),
            at: None,
        }
    }

    fn surface_at(&mut self, t: f32) -> &Mesh {
        if self.at != Some(t.to_bits()) {
            self.state.step(t, &mut self.surface);
            self.at = Some(t.to_bits());
        }
        &self.surface
    }
}

impl Stepper for FftAtPoints {
    fn step(&mut self, t: f32, mesh: &mut Mesh) {
        let n = mesh.grid.n;
        self.step_rows(t, mesh.rows_mut(0..n));
    }

    /// Every band computes the whole patch (a projected vertex may sample any part of it), so
    /// helpers splitting a projected mesh each transform the patch: the same bits as one
    /// helper, no faster.
    fn step_rows(&mut self, t: f32, rows: MeshRows<'_>) {
        sample(self.surface_at(t), rows);
    }

    fn boxed_clone(&self) -> Box<dyn Stepper> {
        Box::new(self.clone())
    }
}

/// The four surface vertices around a point and their bilinear weights.
struct Corners {
    index: [usize; 4],
    weight: [f32; 4],
}

impl Corners {
    /// Around (px, py) on a patch of n × n vertices `spacing` apart, repeating every n.
    fn around(px: f32, py: f32, n: usize, spacing: f32) -> Corners {
        let wrap = |u: f32| {
            let cell = u.floor();
            let i0 = (cell as i64).rem_euclid(n as i64) as usize;
            (i0, (i0 + 1) % n, u - cell)
        };
        let (j0, j1, a) = wrap(px / spacing);
        let (i0, i1, b) = wrap(py / spacing);
        Corners {
            index: [i0 * n + j0, i0 * n + j1, i1 * n + j0, i1 * n + j1],
            weight: [(1.0 - a) * (1.0 - b), a * (1.0 - b), (1.0 - a) * b, a * b],
        }
    }

    fn of(&self, field: &[f32]) -> f32 {
        let [w0, w1, w2, w3] = self.weight;
        let [v0, v1, v2, v3] = self.index.map(|v| field[v]);
        w0 * v0 + w1 * v1 + w2 * v2 + w3 * v3
    }

    /// The displacement of the surface's vertices from their rest positions, interpolated.
    fn displacement(&self, surface: &Mesh) -> Vec2 {
        let n = surface.grid.n;
        let spacing = surface.grid.spacing;
        let mut d = Vec2::ZERO;
        for (&v, &w) in self.index.iter().zip(&self.weight) {
            let rest = Vec2::new((v % n) as f32, (v / n) as f32) * spacing;
            d += w * (Vec2::new(surface.x[v], surface.y[v]) - rest);
        }
        d
    }
}

/// Fills a band whose x, y hold the placed points from the patch's `surface`.
fn sample(surface: &Mesh, rows: MeshRows<'_>) {
    let (n, spacing) = (surface.grid.n, surface.grid.spacing);
    for v in 0..rows.z.len() {
        let (px, py) = (rows.x[v], rows.y[v]);
        let c = Corners::around(px, py, n, spacing);
        let d = c.displacement(surface);
        rows.x[v] = px + d.x;
        rows.y[v] = py + d.y;
        rows.z[v] = c.of(&surface.z);
        let normal = Vec3::new(c.of(&surface.nx), c.of(&surface.ny), c.of(&surface.nz))
            .normalize_or(Vec3::Z);
        rows.nx[v] = normal.x;
        rows.ny[v] = normal.y;
        rows.nz[v] = normal.z;
        if !rows.fold.is_empty() {
            rows.fold[v] = c.of(&surface.fold);
            let dir = Vec2::new(c.of(&surface.fold_dx), c.of(&surface.fold_dy))
                .try_normalize()
                .unwrap_or(Vec2::Y);
            rows.fold_dx[v] = dir.x;
            rows.fold_dy[v] = dir.y;
        }
    }
}
