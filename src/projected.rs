//! The projected grid (Johanson's "projected grid concept", the grid of Intel's *Ocean Fog*
//! demo): an N×N grid regular in screen space, each vertex its camera ray's intersection with
//! the sea's base plane z = 0, then displaced by the ocean model evaluated there. The mesh
//! covers only what the camera sees and follows it along its path.
//!
//! The clamping rule: a ray that points at or above the horizon, or meets the plane farther
//! than `far` (horizontally) from the eye, ends at the point of the plane at horizontal
//! distance `far` from the eye in the ray's horizontal direction. Rays that meet the plane at
//! exactly `far` give the same point either way, so the far line is continuous.
//!
//! Vertex (i, j) looks through the image point (u, v) = (−1 + 2j/(N−1), −1 + 2i/(N−1)): row 0
//! is the bottom of the image, the nearest sea, and the rows go away from the camera, so the
//! grid's triangles keep facing up as on the regular grid.

use crate::camera::{Camera, View};
use crate::input::InputError;
use crate::isa;
use crate::ocean::{
    Grid, GridKind, Kernel, Mesh, MeshRows, Model, NormalMethod, OceanParams, RowLine, Stepper,
};
use std::ops::Range;

/// Refuses what the projected grid cannot run: normals other than `analytic` (face normals
/// of a moving grid would need its neighbours' positions, and the stencil a regular spacing),
/// and a model that cannot be evaluated at any point of the plane.
pub fn check(
    grid: GridKind,
    ocean: &str,
    model: &dyn Model,
    normals: NormalMethod,
) -> Result<(), InputError> {
    if grid == GridKind::Regular {
        return Ok(());
    }
    if !model.grids().contains(&grid) {
        return Err(InputError(format!(
            "grid: the `{ocean}` ocean runs on the `regular` grid only, not `{grid}`"
        )));
    }
    if normals != NormalMethod::Analytic {
        return Err(InputError(format!(
            "normals: the `{grid}` grid takes `analytic` normals only, not `{normals}`"
        )));
    }
    Ok(())
}

/// The stepper of a run on `kind` of grid: the model's own on the regular grid; on the
/// projected grid, the model evaluated at each vertex after the camera has placed it.
#[allow(clippy::too_many_arguments)]
pub fn stepper(
    kind: GridKind,
    model: &dyn Model,
    grid: Grid,
    params: &OceanParams,
    normals: NormalMethod,
    kernel: Kernel,
    camera: Camera,
) -> Result<Box<dyn Stepper>, InputError> {
    match kind {
        GridKind::Regular => model.prepare(grid, params, normals, kernel),
        GridKind::Projected => Ok(Box::new(Projected {
            camera,
            surface: model.prepare_at_points(grid, params, kernel)?,
            lines: Vec::new(),
        })),
    }
}

/// The projected grid's stepper: places a band's vertices from the camera at time t, then
/// lets the model fill heights and normals there, telling it which rows it laid on a line.
#[derive(Debug)]
pub struct Projected {
    camera: Camera,
    surface: Box<dyn Stepper>,
    /// The last band's rows on a line, as `place` found them.
    lines: Vec<Option<RowLine>>,
}

impl Stepper for Projected {
    fn step(&mut self, t: f32, mesh: &mut Mesh) {
        let n = mesh.grid.n;
        self.step_rows(t, mesh.rows_mut(0..n));
    }

    /// Each vertex depends on its own (i, j), t and the camera alone, so a band is
    /// bit-identical to the same rows of a whole-mesh step.
    fn step_rows(&mut self, t: f32, mut rows: MeshRows<'_>) {
        place(
            &self.camera.view_at(rows.grid, t),
            &mut rows,
            &mut self.lines,
        );
        self.surface.step_rows_on_lines(t, rows, &self.lines);
    }

    fn boxed_clone(&self) -> Box<dyn Stepper> {
        Box::new(Projected {
            camera: self.camera,
            surface: self.surface.boxed_clone(),
            lines: Vec::new(),
        })
    }

    fn phases(&self) -> usize {
        self.surface.phases()
    }

    /// The model's phases, the band placed just before the last, which evaluates the model at
    /// the placed points. A model of one phase is told the rows on a line, as in `step_rows`.
    fn step_phase(&mut self, phase: usize, t: f32, rows: MeshRows<'_>) {
        match self.surface.phases() {
            1 => self.step_rows(t, rows),
            phases => {
                let mut rows = rows;
                if phase + 1 == phases {
                    place(
                        &self.camera.view_at(rows.grid, t),
                        &mut rows,
                        &mut self.lines,
                    );
                }
                self.surface.step_phase(phase, t, rows);
            }
        }
    }

    /// The model's own split (the FFT ocean's helpers share the patch), each placing its band.
    fn split(&self, bands: &[Range<usize>]) -> Vec<Box<dyn Stepper>> {
        self.surface
            .split(bands)
            .into_iter()
            .map(|surface| {
                Box::new(Projected {
                    camera: self.camera,
                    surface,
                    lines: Vec::new(),
                }) as Box<dyn Stepper>
            })
            .collect()
    }
}

/// Writes x, y of a band's vertices: each the intersection of its ray with z = 0, clamped as
/// the module says. The same IEEE operations on every instruction set (no fused multiply-add),
/// so helpers agree bit for bit whichever set they run. `lines` becomes, row by row, the line
/// a level row short of far was laid on (None for every other row).
pub fn place(view: &View, rows: &mut MeshRows<'_>, lines: &mut Vec<Option<RowLine>>) {
    lines.clear();
    isa::run_widest(Place { view, rows, lines })
}

/// `place_rows` as a loop for [`isa::run_widest`]: its division and square root run as wide as
/// the CPU allows.
struct Place<'a, 'm> {
    view: &'a View,
    rows: &'a mut MeshRows<'m>,
    lines: &'a mut Vec<Option<RowLine>>,
}

impl isa::Loop for Place<'_, '_> {
    type Output = ();

    #[inline(always)]
    fn run(self) {
        place_rows(self.view, self.rows, self.lines)
    }
}

#[inline(always)]
fn place_rows(view: &View, rows: &mut MeshRows<'_>, lines: &mut Vec<Option<RowLine>>) {
    let n = rows.grid.n;
    let xs = rows.x.chunks_exact_mut(n).zip(rows.y.chunks_exact_mut(n));
    for (r, (xs, ys)) in xs.enumerate() {
        let row = ImageRow::new(view, n, rows.first_row + r);
        let level = row.place_level(xs, ys);
        if !level {
            row.place(xs, ys);
        }
        lines.push(if level {
            RowLine::through(xs, ys)
        } else {
            None
        });
    }
}

/// One image row's rays: ray j's direction is `base + u_j·right`, u_j = −1 + j·step. The row
/// loops turn j into an f32 through i32: the same value below 2^24, and a conversion LLVM
/// vectorises, where usize's is a scalar instruction per vertex on x86-64.
#[derive(Clone, Copy, Debug)]
struct ImageRow {
    eye: glam::Vec3,
    far: f32,
    step: f32,
    n: usize,
    /// The image's right, scaled to the half width, component by component so the row
    /// loops are plain f32 arithmetic for LLVM to vectorise.
    right: [f32; 3],
    base: [f32; 3],
}

impl ImageRow {
    /// Row `i` of an n×n image seen from `view`.
    #[inline(always)]
    fn new(view: &View, n: usize, i: usize) -> ImageRow {
        let step = 2.0 / (n - 1) as f32;
        let tan_y = view.tan_half_fov;
        let tan_x = tan_y * view.aspect;
        let v = -1.0 + i as f32 * step;
        ImageRow {
            eye: view.eye,
            far: view.far,
            step,
            n,
            right: (view.right * tan_x).to_array(),
            base: (view.forward + view.up * (v * tan_y)).to_array(),
        }
    }

    /// Every vertex of the row, clamped or not. Branch-free: a ray meets the plane at s_hit
    /// along it (never at or above the horizon) and reaches the far line at s_far; it stops at
    /// the nearer, and s_hit > s_far is exactly "meets the plane beyond far".
    #[inline(always)]
    fn place(&self, xs: &mut [f32], ys: &mut [f32]) {
        let ([bx, by, bz], [rx, ry, rz], eye, far) = (self.base, self.right, self.eye, self.far);
        for (j, (x, y)) in xs.iter_mut().zip(ys.iter_mut()).enumerate() {
            let u = -1.0 + j as i32 as f32 * self.step;
            let (dx, dy, dz) = (bx + u * rx, by + u * ry, bz + u * rz);
            let s_hit = if dz < 0.0 { eye.z / -dz } else { f32::INFINITY };
            let s_far = far / (dx * dx + dy * dy).sqrt();
            // A ray straight down has no horizontal direction (s_far infinite) but always
            // meets the plane; the bound only keeps 0 × ∞ out of reach.
            let s = if s_hit < s_far { s_hit } else { s_far };
            let s = if s < f32::MAX { s } else { f32::MAX };
            *x = eye.x + dx * s;
            *y = eye.y + dy * s;
        }
    }

    /// `place`'s result for a level row (the image's right horizontal) none of whose rays is
    /// clamped, without its division and square root per vertex; false, writing nothing, for
    /// any other row. Such a row meets the plane at one s along every ray, and even its widest
    /// ray (|d_h|² is convex in u, so at one of the row's ends) reaches the plane well short of
    /// far, so `place` would pick that s at every vertex and do the same operations with it.
    #[inline(always)]
    fn place_level(&self, xs: &mut [f32], ys: &mut [f32]) -> bool {
        let ([bx, by, bz], [rx, ry, rz], eye) = (self.base, self.right, self.eye);
        if rz != 0.0 || bz >= 0.0 {
            return false;
        }
        let s = eye.z / -bz;
        // In f64, where an f32's square cannot overflow, so no libm `hypotf` (2.5 % of a 256²
        // fast step for two calls a row).
        let reach = |u: f32| {
            let (x, y) = ((bx + u * rx) as f64, (by + u * ry) as f64);
            (x * x + y * y).sqrt()
        };
        let widest = reach(-1.0).max(reach(-1.0 + (self.n - 1) as f32 * self.step));
        if s as f64 * widest * (1.0 + 1.0 / 1024.0) >= self.far as f64 {
            return false;
        }
        for (j, (x, y)) in xs.iter_mut().zip(ys.iter_mut()).enumerate() {
            let u = -1.0 + j as i32 as f32 * self.step;
            *x = eye.x + (bx + u * rx) * s;
            *y = eye.y + (by + u * ry) * s;
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Both ways of placing row `i` of `view`'s n×n image: `place_level`'s (None when it
    /// declines the row) and `place`'s.
    fn both(view: &View, n: usize, i: usize) -> (Option<Vec<u32>>, Vec<u32>) {
        let row = ImageRow::new(view, n, i);
        let bits = |x: Vec<f32>, y: Vec<f32>| x.iter().chain(&y).map(|v| v.to_bits()).collect();
        let (mut x, mut y) = (vec![0.0; n], vec![0.0; n]);
        let level = row.place_level(&mut x, &mut y).then(|| bits(x, y));
        let (mut x, mut y) = (vec![0.0; n], vec![0.0; n]);
        row.place(&mut x, &mut y);
        (level, bits(x, y))
    }

    /// The default camera, a low one looking almost level, and one looking straight down.
    fn cameras() -> [Camera; 3] {
        [
            Camera::default(),
            Camera {
                height: Some(6.0),
                pitch_degrees: 8.0,
                ..Camera::default()
            },
            Camera {
                height: Some(40.0),
                pitch_degrees: 90.0,
                ..Camera::default()
            },
        ]
    }

    #[test]
    fn a_level_row_short_of_far_is_placed_bit_for_bit_as_every_row_is() {
        for camera in cameras() {
            for n in [33, 256] {
                let view = camera.view_at(crate::ocean::Grid::new(n, 1.0).unwrap(), 0.7);
                let (mut level, mut declined) = (0, 0);
                for i in 0..n {
                    match both(&view, n, i) {
                        (Some(fast), all) => {
                            assert_eq!(fast, all, "{camera:?} n {n} row {i}");
                            level += 1;
                        }
                        (None, _) => declined += 1,
                    }
                }
                // Every camera here frames some sea short of far; all but the one looking
                // straight down reach it at the image's top.
                assert!(level > 0, "{camera:?} n {n}: no row taken as level");
                if camera.pitch_degrees < 90.0 {
                    assert!(declined > 0, "{camera:?} n {n}: no clamped row declined");
                }
            }
        }
    }

    #[test]
    fn a_rolled_or_clamped_row_is_declined() {
        let grid = crate::ocean::Grid::new(17, 1.0).unwrap();
        let mut view = Camera::default().view_at(grid, 0.0);
        let (mut x, mut y) = (vec![0.0; 17], vec![0.0; 17]);
        // The bottom row is short of far; the top row's rays end on the far line.
        assert!(ImageRow::new(&view, 17, 0).place_level(&mut x, &mut y));
        assert!(!ImageRow::new(&view, 17, 16).place_level(&mut x, &mut y));
        view.right = glam::Vec3::new(1.0, 0.0, 0.01).normalize();
        let (before_x, before_y) = (x.clone(), y.clone());
        assert!(!ImageRow::new(&view, 17, 0).place_level(&mut x, &mut y));
        assert_eq!(
            (x, y),
            (before_x, before_y),
            "a declined row is left as it was"
        );
    }

    #[test]
    fn every_row_placed_as_a_line_is_one_and_the_model_told_so_steps_as_if_it_checked() {
        use crate::ocean::sines::Sines;
        let params = OceanParams::default();
        for camera in cameras() {
            for n in [33, 256] {
                let grid = Grid::new(n, 1.0).unwrap();
                let mut placed = Mesh::new(grid);
                let mut lines = Vec::new();
                place(
                    &camera.view_at(grid, 0.7),
                    &mut placed.rows_mut(0..n),
                    &mut lines,
                );
                assert_eq!(lines.len(), n);
                assert!(lines.iter().any(Option::is_some), "{camera:?} n {n}");
                for (i, line) in lines.iter().enumerate() {
                    let (x, y) = (&placed.x[i * n..][..n], &placed.y[i * n..][..n]);
                    if line.is_some() {
                        assert_eq!(*line, RowLine::of(x, y), "{camera:?} n {n} row {i}");
                    }
                }
                let analytic = NormalMethod::Analytic;
                let mut told = Sines.mesh(grid);
                stepper(
                    GridKind::Projected,
                    &Sines,
                    grid,
                    &params,
                    analytic,
                    Kernel::Fast,
                    camera,
                )
                .unwrap()
                .step(0.7, &mut told);
                let mut surface = Sines
                    .prepare_at_points(grid, &params, Kernel::Fast)
                    .unwrap();
                surface.step_rows(0.7, placed.rows_mut(0..n));
                for (a, b) in [
                    (&told.x, &placed.x),
                    (&told.y, &placed.y),
                    (&told.z, &placed.z),
                    (&told.nx, &placed.nx),
                    (&told.ny, &placed.ny),
                    (&told.nz, &placed.nz),
                ] {
                    assert_eq!(a, b, "{camera:?} n {n}");
                }
            }
        }
    }
}
