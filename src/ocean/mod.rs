//! The ocean surface: waves, the grid mesh, normals and the per-frame step that fills them.

pub mod fast;
pub mod mesh;
pub mod normals;
pub mod reference;
pub mod waves;

pub use mesh::{Grid, Mesh, MeshRows};
pub use normals::NormalMethod;
pub use waves::{Wave, WaveSet};

use crate::input::InputError;
use normals::FaceNormals;

crate::named! {
    /// Which implementation fills heights (and analytic normals).
    pub enum Kernel {
        /// The straight port of section 4.2, kept as the oracle.
        Reference,
        /// Separable phase tables, half-angle powers and run-time selected vector code; the same
        /// surface as `Reference`.
        Fast,
    }
}

/// Everything needed to compute one frame's mesh: waves, normal method, kernel and the
/// precomputed topology. Owned by whichever thread runs the step.
#[derive(Clone, Debug)]
pub struct Ocean {
    waves: WaveSet,
    normals: NormalMethod,
    kernel: Kernel,
    faces: Option<FaceNormals>,
    fast: Option<fast::FastKernel>,
    stencil: Option<fast::StencilNormals>,
}

impl Ocean {
    /// Prepares an ocean for `grid`; refuses `lookup` on grids where one frame would take too long.
    pub fn new(
        grid: Grid,
        waves: WaveSet,
        normals: NormalMethod,
        kernel: Kernel,
    ) -> Result<Self, InputError> {
        if normals == NormalMethod::Lookup
            && normals::lookup_work(grid.n) > normals::LOOKUP_MAX_WORK
        {
            return Err(InputError(format!(
                "normals: `lookup` is O(n²) in vertices and would take over a second per frame at \
                 size {}; use size <= {} or normals `neighbors`/`analytic`",
                grid.n,
                normals::lookup_max_size()
            )));
        }
        // The fast kernel replaces the gathered neighbour list with a stencil; `lookup` stays
        // the paper's method whichever kernel runs.
        let stencil_normals = kernel == Kernel::Fast && normals == NormalMethod::Neighbors;
        let faces =
            (normals != NormalMethod::Analytic && !stencil_normals).then(|| FaceNormals::new(grid));
        let stencil = stencil_normals.then(fast::StencilNormals::new);
        let fast = (kernel == Kernel::Fast).then(|| fast::FastKernel::new(&waves));
        Ok(Ocean {
            waves,
            normals,
            kernel,
            faces,
            fast,
            stencil,
        })
    }

    /// Whether `step_rows` can fill a band alone: only analytic normals are a function of the
    /// vertex's own x, y and t; face normals need the heights of the rows next to a band.
    pub fn splits_into_rows(normals: NormalMethod) -> Result<(), InputError> {
        match normals {
            NormalMethod::Analytic => Ok(()),
            other => Err(InputError(format!(
                "helpers: more than one helper needs normals `analytic`; `{}` normals at a \
                 band's edge need the neighbouring band's heights (not supported yet)",
                other.name()
            ))),
        }
    }

    /// Fills `mesh` with the surface and its normals at time `t`.
    pub fn step(&mut self, t: f32, mesh: &mut Mesh) {
        let n = mesh.grid.n;
        self.heights(t, mesh.rows_mut(0..n));
        if let Some(faces) = &mut self.faces {
            faces.compute(mesh, self.normals);
        }
        if let Some(stencil) = &mut self.stencil {
            stencil.compute(mesh);
        }
    }

    /// Fills one band of rows at time `t`, bit-identical to the same rows of `step`. Only for
    /// analytic normals (see [`Ocean::splits_into_rows`]); keep one `Ocean` per band so the fast
    /// kernel's tables are built once.
    pub fn step_rows(&mut self, t: f32, rows: MeshRows<'_>) {
        assert_eq!(
            self.normals,
            NormalMethod::Analytic,
            "step_rows needs analytic normals"
        );
        self.heights(t, rows);
    }

    /// The kernel's part of a step: heights, and the normals too when they are analytic.
    fn heights(&mut self, t: f32, rows: MeshRows<'_>) {
        let analytic = self.normals == NormalMethod::Analytic;
        match self.kernel {
            Kernel::Reference => reference::step_rows(&self.waves, rows, t, analytic),
            Kernel::Fast => {
                let fast = self.fast.as_mut().expect("built for Kernel::Fast");
                fast.step_rows(rows, t, analytic);
            }
        }
    }
}
