//! The particle pool: structure-of-arrays storage allocated once at its capacity, the
//! integration step (a plain loop, the reference, and a glam `Vec4` loop, the fast path), the
//! kill pass against the consumed surface and the free list that recycles dead slots.

use crate::ocean::Mesh;
use glam::Vec4;

/// Bytes one particle slot takes: seven `f32` (position, velocity, age), the alive flag and its
/// free-list entry.
pub const BYTES_PER_PARTICLE: usize = 7 * 4 + 1 + 4;

/// Every particle's state, one array per component, all `capacity` long.
#[derive(Clone, Debug, PartialEq)]
pub struct Pool {
    /// Position x (metres, the rest grid's frame).
    pub px: Vec<f32>,
    /// Position y.
    pub py: Vec<f32>,
    /// Height.
    pub pz: Vec<f32>,
    /// Velocity x (m/s).
    pub vx: Vec<f32>,
    /// Velocity y.
    pub vy: Vec<f32>,
    /// Velocity z.
    pub vz: Vec<f32>,
    /// Seconds since the particle was born.
    pub age: Vec<f32>,
    /// Whether the slot holds a live particle.
    pub alive: Vec<bool>,
    /// Dead slots, the next one to reuse last.
    pub free: Vec<u32>,
}

/// One integration step's constants.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Step {
    /// Seconds per step.
    pub dt: f32,
    /// Gravity's change of vertical velocity per step, g·dt (m/s).
    pub gravity_dt: f32,
    /// The factor drag leaves of the velocity per step, exp(−drag·dt).
    pub keep: f32,
}

impl Pool {
    /// `capacity` dead slots (the free list hands out slot 0 first).
    pub fn new(capacity: usize) -> Pool {
        Pool {
            px: vec![0.0; capacity],
            py: vec![0.0; capacity],
            pz: vec![0.0; capacity],
            vx: vec![0.0; capacity],
            vy: vec![0.0; capacity],
            vz: vec![0.0; capacity],
            age: vec![0.0; capacity],
            alive: vec![false; capacity],
            free: (0..capacity as u32).rev().collect(),
        }
    }

    /// The seven `f32` arrays the integration reads and writes: position, velocity, age.
    pub fn floats(&self) -> [&Vec<f32>; 7] {
        [
            &self.px, &self.py, &self.pz, &self.vx, &self.vy, &self.vz, &self.age,
        ]
    }

    /// The same arrays, to write.
    pub fn floats_mut(&mut self) -> [&mut Vec<f32>; 7] {
        [
            &mut self.px,
            &mut self.py,
            &mut self.pz,
            &mut self.vx,
            &mut self.vy,
            &mut self.vz,
            &mut self.age,
        ]
    }

    /// Slots in the pool.
    pub fn capacity(&self) -> usize {
        self.alive.len()
    }

    /// Live particles.
    pub fn live(&self) -> usize {
        self.capacity() - self.free.len()
    }

    /// Integrates slots `range` one at a time: gravity, then drag, then the position, then the
    /// age. Every slot is stepped, dead or alive, so the loop has no branch; a dead slot's values
    /// are overwritten when it is reused. The reference for [`Pool::integrate`].
    pub fn integrate_plain(&mut self, step: Step, range: std::ops::Range<usize>) {
        for i in range {
            self.vz[i] -= step.gravity_dt;
            self.vx[i] *= step.keep;
            self.vy[i] *= step.keep;
            self.vz[i] *= step.keep;
            self.px[i] += self.vx[i] * step.dt;
            self.py[i] += self.vy[i] * step.dt;
            self.pz[i] += self.vz[i] * step.dt;
            self.age[i] += step.dt;
        }
    }

    /// The same steps as [`Pool::integrate_plain`], in the same order (so bit for bit the same
    /// results: no fused multiply-add), four slots at a time in glam's SIMD `Vec4`.
    pub fn integrate(&mut self, step: Step, range: std::ops::Range<usize>) {
        let (dt, g, keep) = (
            Vec4::splat(step.dt),
            Vec4::splat(step.gravity_dt),
            Vec4::splat(step.keep),
        );
        let whole = range.start..range.start + (range.len() & !3);
        let r = whole.clone();
        let lanes = itertools::izip!(
            self.px[r.clone()].chunks_exact_mut(4),
            self.py[r.clone()].chunks_exact_mut(4),
            self.pz[r.clone()].chunks_exact_mut(4),
            self.vx[r.clone()].chunks_exact_mut(4),
            self.vy[r.clone()].chunks_exact_mut(4),
            self.vz[r.clone()].chunks_exact_mut(4),
            self.age[r].chunks_exact_mut(4),
        );
        for (px, py, pz, vx, vy, vz, age) in lanes {
            let vx4 = Vec4::from_slice(vx) * keep;
            let vy4 = Vec4::from_slice(vy) * keep;
            let vz4 = (Vec4::from_slice(vz) - g) * keep;
            (Vec4::from_slice(px) + vx4 * dt).write_to_slice(px);
            (Vec4::from_slice(py) + vy4 * dt).write_to_slice(py);
            (Vec4::from_slice(pz) + vz4 * dt).write_to_slice(pz);
            vx4.write_to_slice(vx);
            vy4.write_to_slice(vy);
            vz4.write_to_slice(vz);
            (Vec4::from_slice(age) + dt).write_to_slice(age);
        }
        self.integrate_plain(step, whole.end..range.end);
    }

    /// Kills the live particles of `range` older than `lifetime`, outside the surface's patch,
    /// or below `surface`; returns how many it killed, each slot pushed on the free list.
    pub fn kill(
        &mut self,
        surface: &Surface<'_>,
        lifetime: f32,
        range: std::ops::Range<usize>,
    ) -> u32 {
        let mut killed = 0;
        for i in range {
            if !self.alive[i] {
                continue;
            }
            let under = surface.height(self.px[i], self.py[i]);
            if self.age[i] > lifetime || under.is_none_or(|h| self.pz[i] < h) {
                self.alive[i] = false;
                self.free.push(i as u32);
                killed += 1;
            }
        }
        killed
    }

    /// Brings a free slot to life at `p` with velocity `v`; `false` when none is free.
    pub fn spawn(&mut self, p: [f32; 3], v: [f32; 3]) -> bool {
        let Some(i) = self.free.pop() else {
            return false;
        };
        let i = i as usize;
        [self.px[i], self.py[i], self.pz[i]] = p;
        [self.vx[i], self.vy[i], self.vz[i]] = v;
        self.age[i] = 0.0;
        self.alive[i] = true;
        true
    }
}

/// The consumed mesh's heights over its rest grid: vertex (i, j) rests at (j·s, i·s).
#[derive(Clone, Copy, Debug)]
pub struct Surface<'a> {
    /// Heights, row-major.
    pub z: &'a [f32],
    /// Vertices per side.
    pub n: usize,
    /// Rest spacing s (metres).
    pub spacing: f32,
}

impl<'a> Surface<'a> {
    /// The heights of `mesh`, whose rest spacing is `spacing`.
    pub fn of(mesh: &'a Mesh, spacing: f32) -> Surface<'a> {
        Surface {
            z: &mesh.z,
            n: mesh.grid.n,
            spacing,
        }
    }

    /// The height over rest position (x, y): bilinear in the rest-grid cell under it; `None`
    /// outside the grid.
    pub fn height(&self, x: f32, y: f32) -> Option<f32> {
        let (fx, fy) = (x / self.spacing, y / self.spacing);
        let last = (self.n - 1) as f32;
        // Written so that NaN fails too.
        if !(fx >= 0.0 && fy >= 0.0 && fx < last && fy < last) {
            return None;
        }
        let (j, i) = (fx as usize, fy as usize);
        let (tx, ty) = (fx - j as f32, fy - i as f32);
        let at = |i: usize, j: usize| self.z[i * self.n + j];
        let low = at(i, j) + (at(i, j + 1) - at(i, j)) * tx;
        let high = at(i + 1, j) + (at(i + 1, j + 1) - at(i + 1, j)) * tx;
        Some(low + (high - low) * ty)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ocean::Grid;
    use crate::stats::SplitMix64;

    fn random_pool(capacity: usize, seed: u64) -> Pool {
        let mut rng = SplitMix64(seed);
        let mut unit = || (rng.next_u64() >> 40) as f32 / (1u64 << 24) as f32 - 0.5;
        let mut pool = Pool::new(capacity);
        for a in pool.floats_mut() {
            a.iter_mut().for_each(|v| *v = 100.0 * unit());
        }
        pool
    }

    #[test]
    fn the_simd_loop_gives_the_plain_loops_bits_for_every_slot_and_range() {
        let step = Step {
            dt: 1.0 / 60.0,
            gravity_dt: 9.81 / 60.0,
            keep: (-0.3f32 / 60.0).exp(),
        };
        for (capacity, range) in [(1031, 0..1031), (1031, 3..1030), (8, 1..2), (64, 0..0)] {
            let mut plain = random_pool(capacity, 7);
            let mut fast = plain.clone();
            for _ in 0..5 {
                plain.integrate_plain(step, range.clone());
                fast.integrate(step, range.clone());
            }
            assert_eq!(plain, fast, "capacity {capacity}, range {range:?}");
            let untouched = random_pool(capacity, 7);
            if range.start > 0 {
                assert_eq!(fast.px[0], untouched.px[0], "slots outside the range stay");
            }
            if !range.is_empty() {
                assert_ne!(fast.vz[range.start], untouched.vz[range.start]);
            }
        }
    }

    #[test]
    fn a_particle_falls_as_semi_implicit_euler_says() {
        let mut pool = Pool::new(1);
        assert!(pool.spawn([1.0, 2.0, 3.0], [4.0, 0.0, 10.0]));
        let step = Step {
            dt: 0.5,
            gravity_dt: 5.0,
            keep: 0.5,
        };
        pool.integrate(step, 0..1);
        assert_eq!((pool.vx[0], pool.vz[0]), (2.0, 2.5));
        assert_eq!((pool.px[0], pool.pz[0], pool.age[0]), (2.0, 4.25, 0.5));
        assert!(!pool.spawn([0.0; 3], [0.0; 3]), "the one slot is taken");
    }

    #[test]
    fn the_surface_is_bilinear_in_the_rest_cell_and_absent_outside() {
        let mut mesh = Mesh::new(Grid::new(3, 1.0).unwrap());
        mesh.z = vec![0.0, 1.0, 2.0, 2.0, 3.0, 4.0, 4.0, 5.0, 6.0];
        let s = Surface::of(&mesh, 2.0);
        assert_eq!(s.height(0.0, 0.0), Some(0.0));
        assert_eq!(s.height(1.0, 0.0), Some(0.5));
        assert_eq!(s.height(3.0, 3.0), Some(4.5));
        assert_eq!(s.height(2.0, 1.0), Some(2.0));
        for (x, y) in [(-0.1, 1.0), (1.0, 4.0), (4.0, 0.0), (f32::NAN, 1.0)] {
            assert_eq!(s.height(x, y), None, "({x}, {y})");
        }
    }

    #[test]
    fn the_kill_pass_frees_expired_sunk_and_escaped_particles_only() {
        let mesh = Mesh::new(Grid::new(4, 1.0).unwrap());
        let surface = Surface::of(&mesh, 1.0);
        let mut pool = Pool::new(5);
        for (p, age) in [
            ([1.0, 1.0, 0.5], 0.1),  // above the surface, young: lives
            ([1.0, 1.0, -0.5], 0.1), // below: dies
            ([1.0, 1.0, 0.5], 3.0),  // too old: dies
            ([9.0, 1.0, 0.5], 0.1),  // off the patch: dies
        ] {
            assert!(pool.spawn(p, [0.0; 3]));
            let i = pool.live() - 1;
            pool.age[i] = age;
        }
        assert_eq!(pool.live(), 4);
        assert_eq!(pool.kill(&surface, 2.0, 0..5), 3);
        assert_eq!(pool.alive, [true, false, false, false, false]);
        assert_eq!(pool.live(), 1);
        assert_eq!(pool.kill(&surface, 2.0, 0..5), 0, "the dead stay dead");
    }
}
