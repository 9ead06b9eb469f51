//! The fog coefficient of every vertex, the article's f = e^(−ρ·d·n) with its height falloff
//! n' = n·ΔY²/2 + 0.001.
//!
//! Reading of the article (its shader is not published): n is the blurred noise texture
//! sampled where the vertex is, as a texture holds it, in [0, 1] (here (s + 1)/2 of the volume's
//! octave sum s ∈ [−1, 1]); d is the vertex's distance to the camera; ΔY is the camera's height
//! minus the vertex's (the article's y is up; ours is z). Distances are in units of the patch
//! width, so one density looks the same at every mesh size; the volume tiles the world with
//! one edge per patch width, its middle at the still sea, and is sampled trilinearly with
//! wrap-around, as a GPU samples a 3-D texture in wrap mode.

use super::isa::{self, Isa};
use crate::grid::periodic_cell;
use crate::ocean::Mesh;
use glam::Vec3;

/// What the coefficients are computed from besides the mesh.
#[derive(Clone, Copy, Debug)]
pub struct View {
    /// The camera's position.
    pub eye: Vec3,
    /// The patch width: world units per volume edge and per unit of distance.
    pub width: f32,
    /// Fog density ρ.
    pub density: f32,
}

/// Added to the height falloff so that fog never vanishes at the camera's height.
pub const FLOOR: f32 = 0.001;

/// The coefficient for a vertex at normalised distance `d` and height difference `dy` (both in
/// patch widths) through noise `n` ∈ [0, 1].
#[inline(always)]
pub fn coefficient(density: f32, d: f32, dy: f32, n: f32) -> f32 {
    let falloff = n * dy * dy / 2.0 + FLOOR;
    (-density * d * falloff).exp()
}

/// Writes the coefficient of every vertex of `mesh` into `out` for vertices `range`, sampling
/// the `n`³ blurred `volume` (x fastest), compiled for the widest instruction set the CPU has
/// ([`isa`]): the same IEEE operations and the same `exp` on each.
pub fn fill(
    mesh: &Mesh,
    range: std::ops::Range<usize>,
    volume: &[f32],
    n: usize,
    view: &View,
    out: &mut [f32],
) {
    isa::run(
        Isa::detect(),
        Coefficients {
            mesh,
            range,
            volume,
            n,
            view,
            out,
        },
    )
}

/// The coefficient loop, compiled per instruction set.
struct Coefficients<'a> {
    mesh: &'a Mesh,
    range: std::ops::Range<usize>,
    volume: &'a [f32],
    n: usize,
    view: &'a View,
    out: &'a mut [f32],
}

impl isa::Loop for Coefficients<'_> {
    type Output = ();

    #[inline(always)]
    fn run(self) {
        let Coefficients {
            mesh,
            range,
            volume,
            n,
            view,
            out,
        } = self;
        let inv = 1.0 / view.width;
        let scale = n as f32 * inv;
        let (x, y, z) = (
            &mesh.x[range.clone()],
            &mesh.y[range.clone()],
            &mesh.z[range],
        );
        for (i, f) in out.iter_mut().enumerate() {
            let p = Vec3::new(x[i], y[i], z[i]);
            let s = sample(
                volume,
                n,
                p.x * scale,
                p.y * scale,
                (p.z * inv + 0.5) * scale,
            );
            let d = (view.eye - p).length() * inv;
            let dy = (view.eye.z - p.z) * inv;
            *f = coefficient(view.density, d, dy, (s + 1.0) / 2.0);
        }
    }
}

/// The volume at voxel coordinates (u, v, w), trilinear, wrapping on every axis.
#[inline(always)]
fn sample(volume: &[f32], n: usize, u: f32, v: f32, w: f32) -> f32 {
    let split = |c: f32| periodic_cell(c, n);
    let ((x0, x1, fx), (y0, y1, fy), (z0, z1, fz)) = (split(u), split(v), split(w));
    let at = |x: usize, y: usize, z: usize| volume[(z * n + y) * n + x];
    let lerp = |a: f32, b: f32, t: f32| a + t * (b - a);
    let plane = |z: usize| {
        lerp(
            lerp(at(x0, y0, z), at(x1, y0, z), fx),
            lerp(at(x0, y1, z), at(x1, y1, z), fx),
            fy,
        )
    };
    lerp(plane(z0), plane(z1), fz)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn trilinear_sampling_wraps_and_hits_voxels() {
        let n = 4;
        let volume: Vec<f32> = (0..n * n * n).map(|i| i as f32).collect();
        assert_eq!(
            sample(&volume, n, 1.0, 2.0, 3.0),
            (3 * 16 + 2 * 4 + 1) as f32
        );
        assert_eq!(
            sample(&volume, n, 5.0, 2.0, 3.0),
            sample(&volume, n, 1.0, 2.0, 3.0)
        );
        assert_eq!(
            sample(&volume, n, -3.0, 2.0, 3.0),
            sample(&volume, n, 1.0, 2.0, 3.0)
        );
        // Halfway between x = 3 and x = 0 (wrapped).
        let mid = sample(&volume, n, 3.5, 0.0, 0.0);
        assert_eq!(mid, (3.0 + 0.0) / 2.0);
    }
}
