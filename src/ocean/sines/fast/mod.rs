//! The fast kernel: the reference surface from separable phase tables, half-angle powers and
//! vector loops selected at run time (see `docs/performance.md`).

pub mod fused;
pub mod math;
pub mod phase;
pub mod points;
pub mod simd;
pub mod stencil;
mod vector;

pub use simd::Isa;
pub use stencil::StencilNormals;

use crate::ocean::mesh::{Mesh, MeshRows};
use crate::ocean::waves::WaveSet;
use phase::{Tables, WaveConsts};

/// Which row loop a fast kernel runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Path {
    /// All waves in one pass with the outputs in registers (`fused`): integer exponents only.
    Fused,
    /// One pass over the row per wave (`simd`): any exponent.
    PerWave,
}

impl Path {
    /// Name for reports.
    pub fn name(self) -> &'static str {
        match self {
            Path::Fused => "fused",
            Path::PerWave => "per-wave",
        }
    }
}

/// Per-ocean state of the fast kernel: hoisted wave constants and the phase tables of the grid
/// last stepped (rebuilt when a mesh of another grid comes in).
#[derive(Clone, Debug)]
pub struct FastKernel {
    isa: Isa,
    path: Path,
    waves: Vec<WaveConsts>,
    tables: Option<Tables>,
}

impl FastKernel {
    /// A fast kernel for `waves` using the widest instruction set this CPU has.
    pub fn new(waves: &WaveSet) -> Self {
        Self::with_isa(waves, Isa::detect())
    }

    /// A fast kernel forced to `isa`, which must be one of `Isa::available()`; the fused path
    /// on AVX-512 when it covers the waves. With 16 vector registers (AVX2, portable) the
    /// fused tiles are too narrow to pay for their per-wave dispatch: measured at 256² they ran
    /// at 0.60-0.95× the per-wave loop, so those sets keep it (see docs/performance.md).
    pub fn with_isa(waves: &WaveSet, isa: Isa) -> Self {
        assert!(Isa::available().contains(&isa), "{isa:?} not supported");
        let waves = WaveConsts::from_set(waves);
        let path = if isa == Isa::Avx512 && fused::covers(&waves) {
            Path::Fused
        } else {
            Path::PerWave
        };
        FastKernel {
            isa,
            path,
            waves,
            tables: None,
        }
    }

    /// The same kernel on the per-wave path (for comparisons; the two agree within the
    /// oracle's tolerance, not bit for bit).
    pub fn per_wave(mut self) -> Self {
        self.path = Path::PerWave;
        self
    }

    /// The same kernel on the fused path whatever the instruction set, when the fused loop
    /// covers the waves (for comparisons and tests); otherwise unchanged.
    pub fn fused(mut self) -> Self {
        if fused::covers(&self.waves) {
            self.path = Path::Fused;
        }
        self
    }

    /// The instruction set in use.
    pub fn isa(&self) -> Isa {
        self.isa
    }

    /// The row loop in use.
    pub fn path(&self) -> Path {
        self.path
    }

    /// Fills `mesh.z` for time `t` and, with `analytic_normals`, the normals from the partial
    /// derivatives: the same surface as `reference::step`. The mesh must be a regular grid as
    /// `Mesh::new` builds it (x depends on the column only, y on the row only).
    pub fn step(&mut self, mesh: &mut Mesh, t: f32, analytic_normals: bool) {
        let n = mesh.grid.n;
        self.step_rows(mesh.rows_mut(0..n), t, analytic_normals);
    }

    /// `step` on a band of rows only, bit-identical to the same rows of a whole-mesh step (each
    /// vertex depends on its column's and row's table entries alone). The tables follow the
    /// band, so a kernel kept for one band (one helper) builds them once.
    pub fn step_rows(&mut self, mesh: MeshRows<'_>, t: f32, analytic_normals: bool) {
        let (grid, first_row, rows) = (mesh.grid, mesh.first_row, mesh.rows());
        let tables = match &mut self.tables {
            Some(tb) if (tb.grid, tb.first_row, tb.rows) == (grid, first_row, rows) => tb,
            slot => slot.insert(Tables::for_rows(
                &self.waves,
                grid,
                first_row,
                mesh.x,
                mesh.y,
            )),
        };
        tables.set_time(&self.waves, t as f64, self.path == Path::Fused);
        let step = simd::Step {
            waves: &self.waves,
            tables,
            out: simd::Out {
                z: mesh.z,
                nx: mesh.nx,
                ny: mesh.ny,
                nz: mesh.nz,
            },
            analytic: analytic_normals,
        };
        match self.path {
            Path::Fused => simd::dispatch(self.isa, fused::Fused(step)),
            Path::PerWave => simd::dispatch(self.isa, simd::PerWave(step)),
        }
    }
}
