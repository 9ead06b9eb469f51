//! The paper's ocean: a sum of sine waves with exponent (section 4.2), its heights from the
//! reference or the fast kernel, its normals by any of the three methods.

pub mod fast;
pub mod reference;

use super::mesh::{Grid, Mesh, MeshRows};
use super::model::{GridKind, Kernel, Model, OceanParams, Stepper};
use super::normals::{self, FaceNormals, NormalMethod};
use super::row_line::{RowLine, RowLines};
use super::waves::WaveSet;
use crate::input::InputError;

/// The sum-of-sines model.
#[derive(Clone, Copy, Debug, Default)]
pub struct Sines;

impl Model for Sines {
    fn name(&self) -> &'static str {
        "sines"
    }

    fn doc(&self) -> &'static str {
        "The paper's sum of four sine waves with exponent."
    }

    fn kernels(&self) -> &'static [Kernel] {
        &[Kernel::Reference, Kernel::Fast]
    }

    fn normals(&self) -> &'static [NormalMethod] {
        &[
            NormalMethod::Lookup,
            NormalMethod::Neighbors,
            NormalMethod::Analytic,
        ]
    }

    /// Only analytic normals are a function of the vertex's own x, y and t; face normals need
    /// the heights of the rows next to a band.
    fn splits_into_rows(&self, normals: NormalMethod) -> Result<(), InputError> {
        super::model::only_analytic_splits(normals)
    }

    /// Refuses `lookup` on grids where one frame would take over a second.
    fn check(&self, size: usize, normals: NormalMethod) -> Result<(), InputError> {
        if normals == NormalMethod::Lookup && normals::lookup_work(size) > normals::LOOKUP_MAX_WORK
        {
            return Err(InputError(format!(
                "normals: `lookup` is O(n²) in vertices and would take over a second per frame at \
                 size {size}; use size <= {} or normals `neighbors`/`analytic`",
                normals::lookup_max_size()
            )));
        }
        Ok(())
    }

    /// Heights and slopes are functions of any point's x, y and t.
    fn grids(&self) -> &'static [GridKind] {
        &[GridKind::Regular, GridKind::Projected]
    }

    /// The reference kernel reads each vertex's x, y already; the fast kernel's phase tables
    /// assume a regular grid, so it runs its per-vertex path (`fast::points`).
    fn prepare_at_points(
        &self,
        grid: Grid,
        params: &OceanParams,
        kernel: Kernel,
    ) -> Result<Box<dyn Stepper>, InputError> {
        let mut state = SinesState::new(
            grid,
            params.get::<WaveSet>(),
            NormalMethod::Analytic,
            Kernel::Reference,
        );
        state.kernel = kernel;
        state.points = (kernel == Kernel::Fast)
            .then(|| fast::points::PointsKernel::new(&params.get::<WaveSet>()));
        Ok(Box::new(state))
    }

    /// The paper's build: the reference kernel with the neighbour list.
    fn yardstick(&self) -> (Kernel, NormalMethod) {
        (Kernel::Reference, NormalMethod::Neighbors)
    }

    fn prepare(
        &self,
        grid: Grid,
        params: &OceanParams,
        normals: NormalMethod,
        kernel: Kernel,
    ) -> Result<Box<dyn Stepper>, InputError> {
        self.check(grid.n, normals)?;
        Ok(Box::new(SinesState::new(
            grid,
            params.get::<WaveSet>(),
            normals,
            kernel,
        )))
    }
}

/// Everything needed to compute one frame's mesh: waves, normal method, kernel and the
/// precomputed topology.
#[derive(Clone, Debug)]
pub struct SinesState {
    waves: WaveSet,
    normals: NormalMethod,
    kernel: Kernel,
    faces: Option<FaceNormals>,
    fast: Option<fast::FastKernel>,
    stencil: Option<fast::StencilNormals>,
    /// The fast kernel at scattered points, which replaces `fast` on the projected grid.
    points: Option<fast::points::PointsKernel>,
}

impl SinesState {
    fn new(grid: Grid, waves: WaveSet, normals: NormalMethod, kernel: Kernel) -> Self {
        // The fast kernel replaces the gathered neighbour list with a stencil; `lookup` stays
        // the paper's method whichever kernel runs.
        let stencil_normals = kernel == Kernel::Fast && normals == NormalMethod::Neighbors;
        let faces =
            (normals != NormalMethod::Analytic && !stencil_normals).then(|| FaceNormals::new(grid));
        let stencil = stencil_normals.then(fast::StencilNormals::new);
        let fast = (kernel == Kernel::Fast).then(|| fast::FastKernel::new(&waves));
        SinesState {
            waves,
            normals,
            kernel,
            faces,
            fast,
            stencil,
            points: None,
        }
    }

    /// The kernel's part of a step: heights, and the normals too when they are analytic.
    /// A band's step: heights and analytic normals only.
    fn band(&mut self, t: f32, rows: MeshRows<'_>, lines: RowLines<'_>) {
        assert_eq!(
            self.normals,
            NormalMethod::Analytic,
            "step_rows needs analytic normals"
        );
        self.heights(t, rows, lines);
    }

    /// `lines`, the rows known to lie on a line, is for the fast kernel at points.
    fn heights(&mut self, t: f32, rows: MeshRows<'_>, lines: RowLines<'_>) {
        let analytic = self.normals == NormalMethod::Analytic;
        match (self.kernel, &mut self.points) {
            (Kernel::Reference, _) => reference::step_rows(&self.waves, rows, t, analytic),
            (Kernel::Fast, Some(points)) => points.step_rows(rows, t, lines),
            (Kernel::Fast, None) => {
                let fast = self.fast.as_mut().expect("built for Kernel::Fast");
                fast.step_rows(rows, t, analytic);
            }
        }
    }
}

impl Stepper for SinesState {
    fn step(&mut self, t: f32, mesh: &mut Mesh) {
        let n = mesh.grid.n;
        self.heights(t, mesh.rows_mut(0..n), None);
        if let Some(faces) = &mut self.faces {
            faces.compute(mesh, self.normals);
        }
        if let Some(stencil) = &mut self.stencil {
            stencil.compute(mesh);
        }
    }

    fn step_rows(&mut self, t: f32, rows: MeshRows<'_>) {
        self.band(t, rows, None);
    }

    fn step_rows_on_lines(&mut self, t: f32, rows: MeshRows<'_>, lines: &[Option<RowLine>]) {
        self.band(t, rows, Some(lines));
    }

    fn boxed_clone(&self) -> Box<dyn Stepper> {
        Box::new(self.clone())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sines_moves_no_vertex_and_leaves_the_fold_fields_empty() {
        let grid = Grid::new(8, 0.5).unwrap();
        for kernel in [Kernel::Reference, Kernel::Fast] {
            let mut mesh = Sines.mesh(grid);
            let mut state = Sines
                .prepare(
                    grid,
                    &OceanParams::default(),
                    NormalMethod::Analytic,
                    kernel,
                )
                .unwrap();
            state.step(2.0, &mut mesh);
            let rest = Mesh::new(grid);
            assert_ne!(mesh.z, rest.z, "{kernel}: the step ran");
            assert_eq!((&mesh.x, &mesh.y), (&rest.x, &rest.y), "{kernel}");
            assert!(!mesh.has_fold(), "{kernel}");
        }
    }
}
