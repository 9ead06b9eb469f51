//! The FFT ocean at any point of the sea plane, for the projected grid: the regular N×N surface
//! of the patch is computed as on the regular grid, then each vertex samples it bilinearly at
//! the point the camera placed it, the patch repeating without a seam in both directions. The
//! point is the vertex's rest position: it moves by the sampled choppy displacement and takes
//! the sampled height, normal and fold, as a regular-grid vertex does at its own rest position.

use super::FftState;
use crate::ocean::mesh::{Grid, Mesh, MeshRows};
use crate::ocean::model::Stepper;
use glam::{Vec2, Vec3};
use parking_lot::RwLock;
use std::ops::Range;
use std::sync::Arc;

/// The patch's surface at the last time asked for, and the state that computes it.
#[derive(Clone, Debug)]
pub struct FftAtPoints {
    state: FftState,
    /// Made on first use: the band steppers of a split keep one only for a whole step.
    surface: Option<Mesh>,
    /// The time `surface` was computed for (bits of the f32), so that the bands one helper
    /// fills for one frame share one transform.
    at: Option<u32>,
}

impl FftAtPoints {
    /// Samples the surface `state` computes; `state` fills analytic normals.
    pub fn new(state: FftState) -> Self {
        FftAtPoints {
            state,
            surface: None,
            at: None,
        }
    }

    /// The patch's mesh, before any step.
    fn blank(&self) -> Mesh {
        let grid = Grid::new(self.state.n, self.state.spacing()).expect("a checked size");
        Mesh::new(grid).with_fold()
    }

    fn surface_at(&mut self, t: f32) -> &Mesh {
        if self.surface.is_none() {
            self.surface = Some(self.blank());
        }
        let surface = self.surface.as_mut().expect("made above");
        if self.at != Some(t.to_bits()) {
            self.state.step(t, surface);
            self.at = Some(t.to_bits());
        }
        surface
    }
}

impl Stepper for FftAtPoints {
    fn step(&mut self, t: f32, mesh: &mut Mesh) {
        let n = mesh.grid.n;
        self.step_rows(t, mesh.rows_mut(0..n));
    }

    /// The whole patch: a projected vertex may sample any part of it. Helpers splitting a
    /// projected mesh share the patch's transform instead ([`FftAtPoints::split`]).
    fn step_rows(&mut self, t: f32, rows: MeshRows<'_>) {
        let surface = self.surface_at(t);
        let n = surface.grid.n;
        sample(&Surface::of(&vec![surface; n], surface.grid), rows);
    }

    fn boxed_clone(&self) -> Box<dyn Stepper> {
        Box::new(self.clone())
    }

    /// Helper h computes its band's rows of the patch with [`FftState::split`]'s two phases,
    /// into a patch of its own, then after the barrier samples its mesh rows from every
    /// helper's rows: the same transform and the same sampling as one helper, so the same bits.
    /// The mesh's bands are the patch's: both are N×N.
    fn split(&self, bands: &[Range<usize>]) -> Vec<Box<dyn Stepper>> {
        let shared = Arc::new(Patches {
            bands: bands.to_vec(),
            patches: bands.iter().map(|_| RwLock::new(self.blank())).collect(),
        });
        let alone = FftAtPoints {
            surface: None,
            at: None,
            ..self.clone()
        };
        self.state
            .split(bands)
            .into_iter()
            .enumerate()
            .map(|(band, patch)| {
                Box::new(FftAtPointsBand {
                    whole: alone.clone(),
                    patch,
                    band,
                    shared: Arc::clone(&shared),
                }) as Box<dyn Stepper>
            })
            .collect()
    }
}

/// The patch of a split projected step: helper h's patch holds, once phase 1 is over, the
/// rows of band h (its other rows are never read). The locks are never contended when the
/// frame loop's barrier orders the phases; they make a misordered use wrong rather than unsound.
#[derive(Debug)]
struct Patches {
    bands: Vec<Range<usize>>,
    patches: Vec<RwLock<Mesh>>,
}

/// One helper's part of a projected FFT step split among helpers: phases 0 and 1 are its band
/// of the patch's transform ([`super::FftBand`]), phase 2 samples its band of the mesh.
#[derive(Debug)]
struct FftAtPointsBand {
    /// For a whole step alone.
    whole: FftAtPoints,
    /// This band's stepper of the patch's transform.
    patch: Box<dyn Stepper>,
    band: usize,
    shared: Arc<Patches>,
}

impl Stepper for FftAtPointsBand {
    fn step(&mut self, t: f32, mesh: &mut Mesh) {
        self.whole.step(t, mesh);
    }

    fn step_rows(&mut self, t: f32, rows: MeshRows<'_>) {
        self.whole.step_rows(t, rows);
    }

    fn boxed_clone(&self) -> Box<dyn Stepper> {
        Box::new(FftAtPointsBand {
            whole: self.whole.clone(),
            patch: self.patch.boxed_clone(),
            band: self.band,
            shared: Arc::clone(&self.shared),
        })
    }

    fn phases(&self) -> usize {
        3
    }

    fn step_phase(&mut self, phase: usize, t: f32, rows: MeshRows<'_>) {
        let band = self.shared.bands[self.band].clone();
        assert_eq!(
            (rows.first_row, rows.rows()),
            (band.start, band.len()),
            "a band stepper fills its own band"
        );
        match phase {
            0 | 1 => {
                let mut patch = self.shared.patches[self.band].write();
                self.patch.step_phase(phase, t, patch.rows_mut(band));
            }
            2 => {
                let patches: Vec<_> = self.shared.patches.iter().map(|p| p.read()).collect();
                let grid = patches[0].grid;
                let mut by_row = Vec::with_capacity(grid.n);
                for (band, patch) in self.shared.bands.iter().zip(&patches) {
                    by_row.extend(band.clone().map(|_| &**patch));
                }
                sample(&Surface::of(&by_row, grid), rows);
            }
            _ => unreachable!("three phases"),
        }
    }

    fn split(&self, bands: &[Range<usize>]) -> Vec<Box<dyn Stepper>> {
        self.whole.split(bands)
    }
}

/// The patch's surface by rows: `rows[i]` is a mesh whose row i holds the patch's row i.
struct Surface<'a, 'm> {
    grid: Grid,
    rows: &'a [&'m Mesh],
}

impl<'a, 'm> Surface<'a, 'm> {
    fn of(rows: &'a [&'m Mesh], grid: Grid) -> Self {
        debug_assert_eq!(rows.len(), grid.n, "one mesh per row");
        Surface { grid, rows }
    }
}

/// The four surface vertices around a point, the meshes holding their two rows, and their
/// bilinear weights.
struct Corners<'m> {
    rows: [&'m Mesh; 2],
    index: [usize; 4],
    weight: [f32; 4],
}

impl<'m> Corners<'m> {
    /// Around (px, py) on the surface, which repeats every n vertices.
    fn around(px: f32, py: f32, surface: &Surface<'_, 'm>) -> Corners<'m> {
        let (n, spacing) = (surface.grid.n, surface.grid.spacing);
        let wrap = |u: f32| {
            let cell = u.floor();
            let i0 = (cell as i64).rem_euclid(n as i64) as usize;
            (i0, (i0 + 1) % n, u - cell)
        };
        let (j0, j1, a) = wrap(px / spacing);
        let (i0, i1, b) = wrap(py / spacing);
        Corners {
            rows: [surface.rows[i0], surface.rows[i1]],
            index: [i0 * n + j0, i0 * n + j1, i1 * n + j0, i1 * n + j1],
            weight: [(1.0 - a) * (1.0 - b), a * (1.0 - b), (1.0 - a) * b, a * b],
        }
    }

    /// Corner k's mesh.
    fn mesh(&self, k: usize) -> &'m Mesh {
        self.rows[k / 2]
    }

    fn of(&self, field: impl Fn(&'m Mesh) -> &'m [f32]) -> f32 {
        let [w0, w1, w2, w3] = self.weight;
        let [v0, v1, v2, v3] = [0, 1, 2, 3].map(|k| field(self.mesh(k))[self.index[k]]);
        w0 * v0 + w1 * v1 + w2 * v2 + w3 * v3
    }

    /// The displacement of the surface's vertices from their rest positions, interpolated.
    fn displacement(&self, grid: Grid) -> Vec2 {
        let (n, spacing) = (grid.n, grid.spacing);
        let mut d = Vec2::ZERO;
        for (k, (&v, &w)) in self.index.iter().zip(&self.weight).enumerate() {
            let rest = Vec2::new((v % n) as f32, (v / n) as f32) * spacing;
            let mesh = self.mesh(k);
            d += w * (Vec2::new(mesh.x[v], mesh.y[v]) - rest);
        }
        d
    }
}

/// Fills a band whose x, y hold the placed points from the patch's `surface`.
fn sample(surface: &Surface<'_, '_>, rows: MeshRows<'_>) {
    for v in 0..rows.z.len() {
        let (px, py) = (rows.x[v], rows.y[v]);
        let c = Corners::around(px, py, surface);
        let d = c.displacement(surface.grid);
        rows.x[v] = px + d.x;
        rows.y[v] = py + d.y;
        rows.z[v] = c.of(|m| &m.z);
        let normal =
            Vec3::new(c.of(|m| &m.nx), c.of(|m| &m.ny), c.of(|m| &m.nz)).normalize_or(Vec3::Z);
        rows.nx[v] = normal.x;
        rows.ny[v] = normal.y;
        rows.nz[v] = normal.z;
        if !rows.fold.is_empty() {
            rows.fold[v] = c.of(|m| &m.fold);
            let dir = Vec2::new(c.of(|m| &m.fold_dx), c.of(|m| &m.fold_dy))
                .try_normalize()
                .unwrap_or(Vec2::Y);
            rows.fold_dx[v] = dir.x;
            rows.fold_dy[v] = dir.y;
        }
    }
}
