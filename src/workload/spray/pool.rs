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
    /// or below `surface`; returns how many it killed, each slot pushed on the free list in slot
    /// order. Eight slots at a time where the CPU has AVX2 (the heights gathered, the verdicts
    /// a mask, a block with no live slot skipped), bit for bit [`Pool::kill_plain`]'s result.
    pub fn kill(
        &mut self,
        surface: &Surface<'_>,
        lifetime: f32,
        range: std::ops::Range<usize>,
    ) -> u32 {
        #[cfg(target_arch = "x86_64")]
        {
            if is_x86_feature_detected!("avx2") && surface.gathers_in_bounds() {
                // SAFETY: the CPU has AVX2, checked above, and every index the pass gathers
                // is inside the heights (`gathers_in_bounds`).
                return unsafe { self.kill_avx2(surface, lifetime, range) };
            }
        }
        self.kill_plain(surface, lifetime, range)
    }

    /// [`Pool::kill`] eight slots at a time: the same IEEE operations in the same order as
    /// [`Surface::height`] (no fused multiply-add), lanes outside the patch read vertex 0 and
    /// are killed whatever it holds.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn kill_avx2(
        &mut self,
        surface: &Surface<'_>,
        lifetime: f32,
        range: std::ops::Range<usize>,
    ) -> u32 {
        use std::arch::x86_64::*;
        const LANES: usize = 8;
        let n = surface.n;
        let whole = range.start..range.start + (range.len() / LANES) * LANES;
        let spacing = _mm256_set1_ps(surface.spacing);
        let last = _mm256_set1_ps((n - 1) as f32);
        let zero = _mm256_setzero_ps();
        let life = _mm256_set1_ps(lifetime);
        let row = _mm256_set1_epi32(n as i32);
        let one = _mm256_set1_epi32(1);
        let z = surface.z.as_ptr();
        let mut killed = 0;
        for b in whole.clone().step_by(LANES) {
            // The block's live lanes as a bit mask: a block with none alive costs nothing more.
            let alive_lanes = self.alive[b..b + LANES]
                .iter()
                .enumerate()
                .fold(0u32, |m, (k, &a)| m | u32::from(a) << k);
            if alive_lanes == 0 {
                continue;
            }
            let load = |a: &[f32]| _mm256_loadu_ps(a[b..b + LANES].as_ptr());
            let fx = _mm256_div_ps(load(&self.px), spacing);
            let fy = _mm256_div_ps(load(&self.py), spacing);
            // Ordered compares: a NaN position is outside, as in `Surface::height`.
            let inside = _mm256_and_ps(
                _mm256_and_ps(
                    _mm256_cmp_ps::<_CMP_GE_OQ>(fx, zero),
                    _mm256_cmp_ps::<_CMP_GE_OQ>(fy, zero),
                ),
                _mm256_and_ps(
                    _mm256_cmp_ps::<_CMP_LT_OQ>(fx, last),
                    _mm256_cmp_ps::<_CMP_LT_OQ>(fy, last),
                ),
            );
            let (fx, fy) = (_mm256_and_ps(fx, inside), _mm256_and_ps(fy, inside));
            let (j, i) = (_mm256_cvttps_epi32(fx), _mm256_cvttps_epi32(fy));
            let tx = _mm256_sub_ps(fx, _mm256_cvtepi32_ps(j));
            let ty = _mm256_sub_ps(fy, _mm256_cvtepi32_ps(i));
            let at = _mm256_add_epi32(_mm256_mullo_epi32(i, row), j);
            let below = _mm256_add_epi32(at, row);
            let z00 = _mm256_i32gather_ps::<4>(z, at);
            let z01 = _mm256_i32gather_ps::<4>(z, _mm256_add_epi32(at, one));
            let z10 = _mm256_i32gather_ps::<4>(z, below);
            let z11 = _mm256_i32gather_ps::<4>(z, _mm256_add_epi32(below, one));
            let low = _mm256_add_ps(z00, _mm256_mul_ps(_mm256_sub_ps(z01, z00), tx));
            let high = _mm256_add_ps(z10, _mm256_mul_ps(_mm256_sub_ps(z11, z10), tx));
            let h = _mm256_add_ps(low, _mm256_mul_ps(_mm256_sub_ps(high, low), ty));
            let stays = _mm256_andnot_ps(
                _mm256_cmp_ps::<_CMP_GT_OQ>(load(&self.age), life),
                _mm256_andnot_ps(_mm256_cmp_ps::<_CMP_LT_OQ>(load(&self.pz), h), inside),
            );
            let mut dies = alive_lanes & !(_mm256_movemask_ps(stays) as u32);
            while dies != 0 {
                let i = b + dies.trailing_zeros() as usize;
                self.alive[i] = false;
                self.free.push(i as u32);
                killed += 1;
                dies &= dies - 1;
            }
        }
        killed + self.kill_plain(surface, lifetime, whole.end..range.end)
    }

    /// The kill pass one slot at a time: the reference for [`Pool::kill`].
    pub fn kill_plain(
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

    /// Whether every cell of an n×n grid's heights can be read, so that a vector pass may
    /// gather a cell's four corners without a check per lane (and n fits its 32-bit indices).
    pub fn gathers_in_bounds(&self) -> bool {
        self.n >= 2 && self.z.len() >= self.n * self.n && self.n * self.n < i32::MAX as usize
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
        mesh.z
            .copy_from_slice(&[0.0, 1.0, 2.0, 2.0, 3.0, 4.0, 4.0, 5.0, 6.0]);
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

    #[test]
    fn the_kill_pass_frees_the_plain_loops_slots_in_its_order() {
        let n = 16;
        let mut mesh = Mesh::new(Grid::new(n, 1.0).unwrap());
        let mut rng = SplitMix64(11);
        let mut unit = move || (rng.next_u64() >> 40) as f32 / (1u64 << 24) as f32;
        for z in mesh.z.iter_mut() {
            *z = unit() - 0.5;
        }
        let surface = Surface::of(&mesh, 1.25);
        let patch = 1.25 * (n - 1) as f32;
        for (capacity, range) in [(1037, 0..1037), (1037, 3..1030), (64, 5..13), (64, 0..0)] {
            let mut pool = Pool::new(capacity);
            for i in 0..capacity {
                // Positions a little past the patch on every side, heights about the sea's,
                // ages about the lifetime, a few NaNs, a third of the slots dead.
                pool.px[i] = (unit() * 1.2 - 0.1) * patch;
                pool.py[i] = (unit() * 1.2 - 0.1) * patch;
                pool.pz[i] = unit() - 0.5;
                pool.age[i] = 3.0 * unit();
                let nan = [&mut pool.px, &mut pool.py, &mut pool.pz, &mut pool.age];
                if i % 97 < 4 {
                    nan[i % 97][i] = f32::NAN;
                }
                pool.alive[i] = i % 3 != 0;
            }
            pool.free = (0..capacity as u32).filter(|&i| i % 3 == 0).rev().collect();
            let mut plain = pool.clone();
            let killed = pool.kill(&surface, 2.0, range.clone());
            let want = plain.kill_plain(&surface, 2.0, range.clone());
            assert_eq!(killed, want, "capacity {capacity}, range {range:?}");
            assert_eq!(
                pool.alive, plain.alive,
                "capacity {capacity}, range {range:?}"
            );
            assert_eq!(
                pool.free, plain.free,
                "the same slots freed in the same order"
            );
            if range.len() > 100 {
                let live = plain.alive[range.clone()].iter().filter(|&&a| a).count();
                assert!(
                    want > 100 && live > 100,
                    "some die and some live: {want} died, {live} live"
                );
            }
        }
    }
}
