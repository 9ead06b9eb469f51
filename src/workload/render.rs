//! `render`: what the paper's main thread still did at workload 0, and ours did not. Every
//! frame it transforms every vertex of the consumed mesh by the camera's view-projection into
//! clip space and every normal into view space, writing a vertex buffer it owns (the work of a
//! vertex shader, or of a CPU-side skinning pass before an upload), then spends the level's
//! iterations of the synthetic chain as the fixed cost of submitting the frame.

use super::synthetic::run_unless;
use super::{MeshWork, Stopped, Work, WorkOutput, WorkSpec};
use crate::ocean::Mesh;
use glam::{Mat3, Mat4, Vec3, Vec4};
use std::sync::atomic::{AtomicBool, Ordering};

/// Vertices transformed between two looks at the stop flag: tens of microseconds.
const CHUNK: usize = 1 << 14;

/// The kind's name.
pub(super) const NAME: &str = "render";

/// The descriptor of the render workload.
pub struct RenderKind;

impl super::Kind for RenderKind {
    type Params = ();

    fn name(&self) -> &'static str {
        NAME
    }

    fn doc(&self) -> &'static str {
        "Transforms every vertex and normal of the consumed mesh into a vertex buffer with the \
         camera's view-projection, then spends the level's work as the cost of submitting the frame."
    }

    fn unit(&self) -> &'static str {
        Render::UNIT
    }

    fn build(&self, spec: &WorkSpec, _: &()) -> Work {
        Work::on_mesh(Render::new(spec))
    }
}

/// The render workload's state for one loop: the matrices and the vertex buffer.
pub struct Render {
    view_projection: Mat4,
    view_rotation: Mat3,
    submit_iterations: u64,
    /// Clip-space positions, one per vertex.
    positions: Vec<Vec4>,
    /// View-space normals, one per vertex.
    normals: Vec<Vec3>,
    frame: u64,
}

impl Render {
    /// A render level counts the iterations of the submit cost's chain.
    pub const UNIT: &'static str = "iterations";

    /// The buffers for `spec.grid` and the camera's matrices for it.
    pub fn new(spec: &WorkSpec) -> Render {
        let vertices = spec.grid.n * spec.grid.n;
        let view = spec.camera.view(spec.grid);
        Render {
            view_projection: spec.camera.view_projection(spec.grid),
            view_rotation: Mat3::from_mat4(view),
            submit_iterations: spec.amount,
            positions: vec![Vec4::ZERO; vertices],
            normals: vec![Vec3::ZERO; vertices],
            frame: 0,
        }
    }

    /// The vertex buffer the last frame wrote: clip-space positions and view-space normals.
    pub fn buffer(&self) -> (&[Vec4], &[Vec3]) {
        (&self.positions, &self.normals)
    }

    fn transform(&mut self, mesh: &Mesh, range: std::ops::Range<usize>) {
        let (vp, rot) = (self.view_projection, self.view_rotation);
        let (x, y, z) = (
            &mesh.x[range.clone()],
            &mesh.y[range.clone()],
            &mesh.z[range.clone()],
        );
        let (nx, ny, nz) = (
            &mesh.nx[range.clone()],
            &mesh.ny[range.clone()],
            &mesh.nz[range.clone()],
        );
        let out = self.positions[range.clone()].iter_mut();
        for (i, p) in out.enumerate() {
            *p = vp * Vec4::new(x[i], y[i], z[i], 1.0);
        }
        for (i, n) in self.normals[range].iter_mut().enumerate() {
            *n = rot * Vec3::new(nx[i], ny[i], nz[i]);
        }
    }
}

impl WorkOutput for Render {
    fn digest(&self) -> u64 {
        let bits = self
            .positions
            .iter()
            .flat_map(|p| p.to_array())
            .chain(self.normals.iter().flat_map(|n| n.to_array()));
        super::fold_digest(self.frame, bits.map(|v| u64::from(v.to_bits())))
    }
}

impl MeshWork for Render {
    fn run(&mut self, k: u64, mesh: &Mesh, stop: Option<&AtomicBool>) -> Result<(), Stopped> {
        assert_eq!(
            mesh.x.len(),
            self.positions.len(),
            "the mesh render was built for"
        );
        let vertices = self.positions.len();
        for start in (0..vertices).step_by(CHUNK) {
            if stop.is_some_and(|s| s.load(Ordering::Relaxed)) {
                return Err(Stopped);
            }
            self.transform(mesh, start..(start + CHUNK).min(vertices));
        }
        run_unless(self.submit_iterations, k, stop).ok_or(Stopped)?;
        self.frame = k;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Camera;
    use crate::ocean::Grid;
    use crate::workload::WorkloadKind;

    fn spec(n: usize) -> WorkSpec {
        WorkSpec {
            kind: WorkloadKind::RENDER,
            amount: 0,
            grid: Grid::new(n, 1.0).unwrap(),
            camera: Camera::default(),
            spacing: 1.0,
            time_step: 1.0 / 60.0,
        }
    }

    #[test]
    fn every_vertex_and_normal_is_transformed_as_glam_would_one_by_one() {
        let s = spec(150);
        let mut mesh = Mesh::new(s.grid);
        for (i, z) in mesh.z.iter_mut().enumerate() {
            *z = (i as f32 * 0.01).sin();
        }
        mesh.nz.fill(1.0);
        mesh.nx[7] = 0.5;
        let mut r = Render::new(&s);
        r.run(3, &mesh, None).unwrap();
        let vp = s.camera.view_projection(s.grid);
        let view = s.camera.view(s.grid);
        let (pos, nrm) = r.buffer();
        assert_eq!(pos.len(), 150 * 150);
        for i in [0, 7, 12_345, 150 * 150 - 1] {
            let p = vp * Vec4::new(mesh.x[i], mesh.y[i], mesh.z[i], 1.0);
            assert_eq!(pos[i], p, "vertex {i}");
            let n = view * Vec4::new(mesh.nx[i], mesh.ny[i], mesh.nz[i], 0.0);
            assert!((nrm[i] - n.truncate()).length() < 1e-6, "normal {i}");
        }
        let before = r.digest();
        mesh.z[12_345] += 1.0;
        r.run(3, &mesh, None).unwrap();
        assert_ne!(r.digest(), before, "the digest sees one vertex move");
    }

    #[test]
    fn a_raised_stop_flag_stops_the_frame() {
        let s = spec(8);
        let mesh = Mesh::new(s.grid);
        let stop = AtomicBool::new(true);
        assert_eq!(Render::new(&s).run(0, &mesh, Some(&stop)), Err(Stopped));
    }
}
