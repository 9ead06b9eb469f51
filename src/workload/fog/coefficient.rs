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

#[cfg(target_arch = "x86_64")]
use super::gather;
use crate::grid::periodic_cell;
use crate::isa::{self, Isa};
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
    exp(-density * d * falloff)
}

/// e^x without a call or a branch, so that the coefficient loop vectorises (libm's `expf` was a
/// third of its time): Cephes' `expf`, a reduction by ln 2 in two parts, a degree-5 polynomial,
/// and the power of two written into the exponent bits. Within 2 ulp of libm's over
/// [−87, 88] (tested); below −87, where e^x is subnormal, it stays at e^−87.
#[inline(always)]
pub fn exp(x: f32) -> f32 {
    // ln 2 split so that k·LN2_HI is exact for the k this range gives.
    const LN2_HI: f32 = 0.693_359_4;
    const LN2_LO: f32 = -2.121_944_4e-4;
    let x = x.clamp(-87.0, 88.0);
    let k = (x * std::f32::consts::LOG2_E + 0.5).floor();
    let r = x - k * LN2_HI - k * LN2_LO;
    let p = ((((1.987_569_1e-4 * r + 1.398_199_9e-3) * r + 8.333_452e-3) * r + 4.166_579_6e-2) * r
        + 1.666_666_5e-1)
        * r
        + 0.5;
    let y = p * (r * r) + r + 1.0;
    // 2^k, built in the exponent bits. k is an integer in [−126, 127] here, so k + 127 + 2²³ is
    // exact and its low mantissa bits are k + 127, shifted into the exponent (the 2²³ shifts
    // out). Not `k as i32`: a saturating conversion, which LLVM does one lane at a time.
    const BIAS: f32 = 8_388_608.0 + 127.0;
    y * f32::from_bits((k + BIAS).to_bits() << 23)
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
    let isa = Isa::detect();
    isa::run(
        isa,
        Coefficients {
            isa,
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
    isa: Isa,
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
            isa,
            mesh,
            range,
            volume,
            n,
            view,
            out,
        } = self;
        assert_eq!(volume.len(), n * n * n, "an n³ volume");
        assert!(n * n * n <= i32::MAX as usize, "voxel indices fit an i32");
        let inv = 1.0 / view.width;
        let scale = n as f32 * inv;
        let (x, y, z) = (
            &mesh.x[range.clone()],
            &mesh.y[range.clone()],
            &mesh.z[range],
        );
        // In chunks, two passes each: the noise's scattered lookups (gathered sixteen at a time
        // on AVX-512, one vertex at a time otherwise), then the distance and the exponential,
        // which have none and so run lane-wise.
        let mut noise = [0.0f32; CHUNK];
        let chunks = x.chunks(CHUNK).zip(y.chunks(CHUNK)).zip(z.chunks(CHUNK));
        for (out, ((x, y), z)) in out.chunks_mut(CHUNK).zip(chunks) {
            // Zipped rather than indexed: a bounds check per vertex would keep a loop scalar.
            let points = || x.iter().zip(y).zip(z);
            let noise = &mut noise[..x.len()];
            let gathered = match isa {
                // SAFETY: the CPU has AVX-512F (`isa` is detected); the volume holds n³ values
                // and n³ fits an i32 (both asserted above); the chunks have one length.
                #[cfg(target_arch = "x86_64")]
                Isa::Avx512 => unsafe { gather::noise(volume, n, (scale, inv), (x, y, z), noise) },
                _ => 0,
            };
            for (s, ((&x, &y), &z)) in noise.iter_mut().zip(points()).skip(gathered) {
                // SAFETY: the volume holds n³ values (asserted above).
                *s = unsafe { sample(volume, n, x * scale, y * scale, (z * inv + 0.5) * scale) };
            }
            for (f, (&s, ((&x, &y), &z))) in out.iter_mut().zip(noise.iter().zip(points())) {
                let p = Vec3::new(x, y, z);
                let d = (view.eye - p).length() * inv;
                let dy = (view.eye.z - z) * inv;
                *f = coefficient(view.density, d, dy, (s + 1.0) / 2.0);
            }
        }
    }
}

/// Vertices per chunk: their coordinates, noise and coefficients (20 KiB) stay in L1 between the
/// two passes, and the gathered pass's set-up is paid once per 1024 vertices rather than per 64.
const CHUNK: usize = 1024;

/// The volume at voxel coordinates (u, v, w), trilinear, wrapping on every axis.
///
/// # Safety
/// `volume` holds at least n³ values.
#[inline(always)]
unsafe fn sample(volume: &[f32], n: usize, u: f32, v: f32, w: f32) -> f32 {
    let split = |c: f32| periodic_cell(c, n);
    let ((x0, x1, fx), (y0, y1, fy), (z0, z1, fz)) = (split(u), split(v), split(w));
    // SAFETY: `periodic_cell` gives cells below n, and the caller guarantees n³ values;
    // unchecked, the lookups gather instead of branching to a panic.
    let at = |x: usize, y: usize, z: usize| unsafe { *volume.get_unchecked((z * n + y) * n + x) };
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
        // SAFETY: the volume holds n³ values.
        let at = |u, v, w| unsafe { sample(&volume, n, u, v, w) };
        assert_eq!(at(1.0, 2.0, 3.0), (3 * 16 + 2 * 4 + 1) as f32);
        assert_eq!(at(5.0, 2.0, 3.0), at(1.0, 2.0, 3.0));
        assert_eq!(at(-3.0, 2.0, 3.0), at(1.0, 2.0, 3.0));
        // Halfway between x = 3 and x = 0 (wrapped).
        assert_eq!(at(3.5, 0.0, 0.0), (3.0 + 0.0) / 2.0);
    }

    #[test]
    fn the_chunked_fill_is_each_vertex_alone_bit_for_bit() {
        use crate::ocean::sines::Sines;
        use crate::ocean::{Grid, Kernel, Model, NormalMethod, OceanParams};
        // 37² vertices: chunks of CHUNK and a short one at the end, each gathered sixteen at a
        // time where the CPU has AVX-512 and the rest one by one.
        let grid = Grid::new(37, 1.0).unwrap();
        let mut mesh = Sines.mesh(grid);
        Sines
            .prepare(
                grid,
                &OceanParams::default(),
                NormalMethod::Analytic,
                Kernel::Fast,
            )
            .unwrap()
            .step(0.7, &mut mesh);
        // Points below the volume's origin and far past it wrap too.
        for v in (0..grid.vertices()).step_by(7) {
            mesh.x[v] -= 40.0 * (v % 3) as f32;
            mesh.y[v] += 1.0e5 * (v % 5) as f32;
        }
        // Beyond 2^24 cells, where the wrap rounds and is clamped into the volume.
        for (v, far) in [(40, -3.0e9), (41, 3.0e9), (42, -1.0e30), (43, 7.7e8)] {
            mesh.x[v] = far;
        }
        // 7 is not a power of two, so that dividing a far cell by n rounds; 8 is, and there a
        // gathered vector with no lane at x = n − 1 reads its x corners in pairs.
        for n in [7, 8] {
            check_each_vertex(&mesh, grid.vertices(), n);
        }
    }

    fn check_each_vertex(mesh: &Mesh, vertices: usize, n: usize) {
        let volume: Vec<f32> = (0..n * n * n).map(|i| ((i as f32) * 0.37).sin()).collect();
        let view = View {
            eye: Vec3::new(18.0, -20.0, 9.0),
            width: 37.0,
            density: 3.0,
        };
        let range = 5..vertices - 3;
        let mut out = vec![0.0f32; range.len()];
        fill(mesh, range.clone(), &volume, n, &view, &mut out);
        let (inv, scale) = (1.0 / view.width, n as f32 / view.width);
        for (f, v) in out.iter().zip(range) {
            let p = Vec3::new(mesh.x[v], mesh.y[v], mesh.z[v]);
            // SAFETY: the volume holds n³ values.
            let s = unsafe {
                sample(
                    &volume,
                    n,
                    p.x * scale,
                    p.y * scale,
                    (p.z * inv + 0.5) * scale,
                )
            };
            let d = (view.eye - p).length() * inv;
            let dy = (view.eye.z - p.z) * inv;
            let want = coefficient(view.density, d, dy, (s + 1.0) / 2.0);
            assert_eq!(f.to_bits(), want.to_bits(), "n {n}, vertex {v}");
            assert!(*f > 0.0 && *f < 1.0, "n {n}, vertex {v}: {f}");
        }
    }

    /// Distance in units in the last place between two finite floats of one sign.
    fn ulps(a: f32, b: f32) -> u32 {
        a.to_bits().abs_diff(b.to_bits())
    }

    #[test]
    fn the_exponential_is_within_two_ulp_of_libms() {
        let mut worst = (0, 0.0f32);
        // Every 997th float between −87 and 88, and the ends.
        let (lo, hi) = (-87.0f32, 88.0f32);
        let mut x = lo;
        while x <= hi {
            let e = ulps(exp(x), x.exp());
            if e > worst.0 {
                worst = (e, x);
            }
            x = if x < 0.0 {
                f32::from_bits(x.to_bits() - 997)
            } else {
                f32::from_bits(x.to_bits() + 997)
            };
            if x.to_bits() == (-0.0f32).to_bits() || (x < 0.0 && x > -1e-30) {
                x = 0.0;
            }
        }
        assert!(worst.0 <= 2, "{} ulp at {}", worst.0, worst.1);
        assert_eq!(exp(0.0), 1.0);
        assert_eq!(exp(-87.0), (-87.0f32).exp());
        assert_eq!(exp(-1000.0), exp(-87.0), "clamped below");
        assert_eq!(exp(f32::NEG_INFINITY), exp(-87.0));
    }
}
