//! The reference kernel: a straight port of the paper's `TakeStepSumOfWavesWithExp` (section 4.2),
//! per vertex and per wave, `sin` and `powf` in f32. It is kept as the oracle for faster kernels.

use crate::ocean::mesh::{Mesh, MeshRows};
use crate::ocean::waves::WaveSet;
use std::f32::consts::PI;

/// Fills `mesh.z` for time `t`, and the normals from the partial derivatives of section 3.5 when
/// `analytic_normals` is set.
pub fn step(waves: &WaveSet, mesh: &mut Mesh, t: f32, analytic_normals: bool) {
    let n = mesh.grid.n;
    step_rows(waves, mesh.rows_mut(0..n), t, analytic_normals);
}

/// `step` on a band of rows only: every vertex depends on its own x, y alone, so a band's values
/// are bit-identical to the same rows of a whole-mesh step.
pub fn step_rows(waves: &WaveSet, mesh: MeshRows<'_>, t: f32, analytic_normals: bool) {
    let dirs: Vec<[f32; 2]> = waves.waves.iter().map(|w| w.unit_direction()).collect();
    for v in 0..mesh.z.len() {
        let (px, py) = (mesh.x[v], mesh.y[v]);
        let mut height = 0.0f32;
        let (mut dfdx, mut dfdy) = (0.0f32, 0.0f32);
        for (w, dir) in waves.waves.iter().zip(&dirs) {
            if !w.enabled {
                continue;
            }
            let mut dotresult = dir[0] * px + dir[1] * py;
            dotresult *= (2.0 * PI) / w.wavelength;
            let phase_constant = t * (w.speed * 2.0 * PI / w.wavelength);
            let s = dotresult + phase_constant;
            let base = (s.sin() + 1.0) / 2.0;
            height += w.amplitude * base.powf(w.steepness);
            if analytic_normals {
                let common = 0.5
                    * w.steepness
                    * (2.0 * PI / w.wavelength)
                    * w.amplitude
                    * base.powf(w.steepness - 1.0)
                    * s.cos();
                dfdx += common * dir[0];
                dfdy += common * dir[1];
            }
        }
        mesh.z[v] = height;
        if analytic_normals {
            let inv = 1.0 / (dfdx * dfdx + dfdy * dfdy + 1.0).sqrt();
            mesh.nx[v] = -dfdx * inv;
            mesh.ny[v] = -dfdy * inv;
            mesh.nz[v] = inv;
        }
    }
}
