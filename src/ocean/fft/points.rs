//! The FFT ocean at any point of the sea plane, for the projected grid: the regular N×N surface
//! of the patch is computed as on the regular grid, then each vertex samples it bilinearly at
//! the point the camera placed it, the patch repeating without a seam in both directions. The
//! point is the vertex's rest position: it moves by the sampled choppy displacement and takes
//! the sampled height, normal and fold, as a regular-grid vertex does at its own rest position.
//!
//! Helpers sharing a projected mesh share the patch too ([`FftAtPoints`]'s `split`): each
//! transforms and fills its band of the patch's rows as on the regular grid, and after the
//! phase barrier samples its band of the mesh from the whole patch.

use super::{FftBand, FftState};
use crate::grid::periodic_cell;
use crate::isa;
use crate::ocean::mesh::{Grid, Mesh, MeshRows};
use crate::ocean::model::Stepper;
use crate::ocean::shared_mesh::SharedMesh;
use glam::{Vec2, Vec3};
use parking_lot::RwLock;
use std::ops::Range;
use std::sync::Arc;

/// The patch's surface at the last time asked for, and the state that computes it.
#[derive(Clone, Debug)]
pub struct FftAtPoints {
    state: FftState,
    /// Every row of the patch (made on first use: a state split among helpers never needs it).
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

    /// The patch's grid, and a blank surface of it.
    fn patch(&self) -> (Grid, Mesh) {
        let grid = Grid::new(self.state.n, self.state.spacing()).expect("a checked size");
        (grid, Mesh::new(grid).with_fold())
    }

    fn surface_at(&mut self, t: f32) -> &Mesh {
        if self.surface.is_none() {
            self.surface = Some(self.patch().1);
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

    /// Computes the whole patch (a projected vertex may sample any part of it): helpers
    /// sharing a mesh step the phases of `split`'s band steppers instead.
    fn step_rows(&mut self, t: f32, rows: MeshRows<'_>) {
        sample(self.surface_at(t), rows);
    }

    fn boxed_clone(&self) -> Box<dyn Stepper> {
        Box::new(self.clone())
    }

    /// Helper h of H transforms and fills rows h·N/H..(h + 1)·N/H of the patch, whatever band
    /// of the projected mesh it samples.
    fn split(&self, bands: &[Range<usize>]) -> Vec<Box<dyn Stepper>> {
        let ((grid, surface), h) = (self.patch(), bands.len());
        let rows: Vec<Range<usize>> = (0..h)
            .map(|k| k * grid.n / h..(k + 1) * grid.n / h)
            .collect();
        let shared = Arc::new(SharedPatch {
            surface: SharedMesh::new(surface),
            locks: rows.iter().map(|_| RwLock::new(())).collect(),
            rows: rows.clone(),
        });
        let alone = FftAtPoints::new(self.state.clone());
        self.state
            .bands(&rows)
            .into_iter()
            .enumerate()
            .map(|(band, patch)| {
                Box::new(PointsBand {
                    alone: alone.clone(),
                    patch,
                    band,
                    shared: Arc::clone(&shared),
                }) as Box<dyn Stepper>
            })
            .collect()
    }
}

/// The patch that helpers sharing a projected mesh fill together: rows `rows[h]` by helper h
/// in phase 1, the whole patch read by every helper in phase 2. Every access holds the locks of
/// the rows it touches (a band's for writing it, every band's for reading the patch), so a
/// misordered use waits rather than races; the frame loop's barrier orders the phases, so the
/// locks are never contended.
#[derive(Debug)]
struct SharedPatch {
    surface: SharedMesh,
    rows: Vec<Range<usize>>,
    locks: Vec<RwLock<()>>,
}

impl SharedPatch {
    /// Band `band`'s rows of the patch, to fill.
    fn fill(&self, band: usize, f: impl FnOnce(MeshRows<'_>)) {
        let _mine = self.locks[band].write();
        // SAFETY: a band's rows are touched only under its lock, held here for writing.
        f(unsafe { self.surface.rows(self.rows[band].clone()) })
    }

    /// The whole patch, to read.
    fn read(&self, f: impl FnOnce(&Mesh)) {
        let _all: Vec<_> = self.locks.iter().map(|lock| lock.read()).collect();
        // SAFETY: every band's lock is held for reading, so no band is being written.
        f(unsafe { &*self.surface.get() })
    }
}

/// One helper's part of a projected FFT step split among helpers: phase 0 is its band of the
/// patch's row pass, phase 1 that band's column pass and fill, phase 2 its band of the mesh
/// sampled from the whole patch. Bit-identical to [`FftAtPoints::step`]: the patch's rows are
/// [`FftBand`]'s, and each vertex samples the same values with the same operations.
#[derive(Clone, Debug)]
struct PointsBand {
    /// The state for [`Stepper::step`] alone.
    alone: FftAtPoints,
    patch: FftBand,
    band: usize,
    shared: Arc<SharedPatch>,
}

impl Stepper for PointsBand {
    fn step(&mut self, t: f32, mesh: &mut Mesh) {
        self.alone.step(t, mesh);
    }

    fn step_rows(&mut self, t: f32, rows: MeshRows<'_>) {
        self.alone.step_rows(t, rows);
    }

    fn boxed_clone(&self) -> Box<dyn Stepper> {
        Box::new(self.clone())
    }

    fn phases(&self) -> usize {
        3
    }

    fn step_phase(&mut self, phase: usize, t: f32, rows: MeshRows<'_>) {
        // More helpers than the patch has rows: this one has none to fill.
        let empty = self.shared.rows[self.band].is_empty();
        match phase {
            0 if !empty => self.patch.row_pass(t),
            1 if !empty => {
                let patch = &mut self.patch;
                self.shared.fill(self.band, |mine| patch.column_pass(mine));
            }
            0 | 1 => {}
            2 => self.shared.read(|surface| sample(surface, rows)),
            _ => unreachable!("three phases"),
        }
    }

    fn split(&self, bands: &[Range<usize>]) -> Vec<Box<dyn Stepper>> {
        self.alone.split(bands)
    }
}

/// The four surface vertices around a point and their bilinear weights.
#[derive(Clone, Copy, Default)]
struct Corners {
    index: [usize; 4],
    /// Each corner's rest position on the patch.
    rest: [Vec2; 4],
    weight: [f32; 4],
}

impl Corners {
    /// Around (px, py) on a patch of n × n vertices `spacing` apart, repeating every n.
    #[inline(always)]
    fn around(px: f32, py: f32, n: usize, spacing: f32) -> Corners {
        let wrap = |u: f32| periodic_cell(u, n);
        let (j0, j1, a) = wrap(px / spacing);
        let (i0, i1, b) = wrap(py / spacing);
        let rest = |i: usize, j: usize| Vec2::new(j as f32, i as f32) * spacing;
        Corners {
            index: [i0 * n + j0, i0 * n + j1, i1 * n + j0, i1 * n + j1],
            rest: [rest(i0, j0), rest(i0, j1), rest(i1, j0), rest(i1, j1)],
            weight: [(1.0 - a) * (1.0 - b), a * (1.0 - b), (1.0 - a) * b, a * b],
        }
    }

    #[inline(always)]
    fn of(&self, field: &[f32]) -> f32 {
        let [w0, w1, w2, w3] = self.weight;
        let [v0, v1, v2, v3] = self.index.map(|v| field[v]);
        w0 * v0 + w1 * v1 + w2 * v2 + w3 * v3
    }

    /// The displacement of the surface's vertices from their rest positions, interpolated.
    #[inline(always)]
    fn displacement(&self, surface: &Mesh) -> Vec2 {
        let mut d = Vec2::ZERO;
        for ((&v, &rest), &w) in self.index.iter().zip(&self.rest).zip(&self.weight) {
            d += w * (Vec2::new(surface.x[v], surface.y[v]) - rest);
        }
        d
    }
}

/// Fills a band whose x, y hold the placed points from the patch's `surface`, compiled for the
/// widest instruction set the CPU has: the same IEEE operations on each (no fused multiply-add),
/// so helpers agree bit for bit whichever runs; the sets give `floor` an instruction of its own
/// where baseline x86-64 calls libm.
fn sample(surface: &Mesh, rows: MeshRows<'_>) {
    isa::run_widest(Sample { surface, rows })
}

/// `sample_points` as a loop for [`isa::run_widest`].
struct Sample<'a, 'm> {
    surface: &'a Mesh,
    rows: MeshRows<'m>,
}

impl isa::Loop for Sample<'_, '_> {
    type Output = ();

    #[inline(always)]
    fn run(self) {
        sample_points(self.surface, self.rows)
    }
}

/// Vertices sampled together: each pass over them is short enough that the CPU keeps many
/// vertices' loads in flight, where one vertex at a time waits on its own chain of a division,
/// a floor, four scattered loads per field and a square root.
const CHUNK: usize = 64;

#[inline(always)]
fn sample_points(surface: &Mesh, rows: MeshRows<'_>) {
    let (n, spacing) = (surface.grid.n, surface.grid.spacing);
    let fold = !rows.fold.is_empty();
    let mut corners: [Corners; CHUNK] = std::array::from_fn(|_| Corners::default());
    // Per vertex: displacement x and y, height, the normal's three parts, fold and its
    // direction's two parts, as the corners give them.
    let mut sampled = [[0.0f32; 9]; CHUNK];
    let mut first = 0;
    while first < rows.z.len() {
        let chunk = first..(first + CHUNK).min(rows.z.len());
        for (c, v) in corners.iter_mut().zip(chunk.clone()) {
            *c = Corners::around(rows.x[v], rows.y[v], n, spacing);
        }
        for (c, out) in corners.iter().zip(&mut sampled).take(chunk.len()) {
            let d = c.displacement(surface);
            *out = [
                d.x,
                d.y,
                c.of(&surface.z),
                c.of(&surface.nx),
                c.of(&surface.ny),
                c.of(&surface.nz),
                0.0,
                0.0,
                0.0,
            ];
            if fold {
                out[6] = c.of(&surface.fold);
                out[7] = c.of(&surface.fold_dx);
                out[8] = c.of(&surface.fold_dy);
            }
        }
        for (out, v) in sampled.iter().zip(chunk.clone()) {
            let [dx, dy, z, nx, ny, nz, j, fx, fy] = *out;
            rows.x[v] += dx;
            rows.y[v] += dy;
            rows.z[v] = z;
            let normal = Vec3::new(nx, ny, nz).normalize_or(Vec3::Z);
            rows.nx[v] = normal.x;
            rows.ny[v] = normal.y;
            rows.nz[v] = normal.z;
            if fold {
                rows.fold[v] = j;
                let dir = Vec2::new(fx, fy).try_normalize().unwrap_or(Vec2::Y);
                rows.fold_dx[v] = dir.x;
                rows.fold_dy[v] = dir.y;
            }
        }
        first = chunk.end;
    }
}
