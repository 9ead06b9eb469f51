//! One f32 or one vector register of them, behind the arithmetic the wave and normal formulas
//! need, so each formula is written once and the per-wave loops (one f32 at a time, vectorised
//! by LLVM), the fused loops and the stencil (explicit registers) run the same operations in the
//! same order: their results agree bit for bit on the same instruction set.
//!
//! The x86 vector types wrap `std::arch` registers. Their methods call intrinsics that need
//! the type's target features, so a value of one of them is only ever made inside a
//! `#[target_feature]` entry point that `Isa::available` admitted; the module is private to
//! the fast kernel so nothing else can make one.

use super::math::fma;
use std::ops::{Add, Div, Mul, Neg, Sub};

/// x^E for a compile-time E, by repeated squaring (fully unrolled).
#[inline(always)]
pub fn powi<R: Real, const E: u32>(x: R) -> R {
    let mut r: Option<R> = None;
    let mut b = x;
    let mut e = E;
    while e > 0 {
        if e & 1 == 1 {
            r = Some(match r {
                Some(r) => r * b,
                None => b,
            });
        }
        b = b * b;
        e >>= 1;
    }
    r.unwrap_or(R::splat(1.0))
}

/// Lane-wise f32 arithmetic: `+ − × ÷` and negation are IEEE, single rounding each.
pub trait Real:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// Every lane `x`.
    fn splat(x: f32) -> Self;

    /// self·b + c, one rounding where the instruction set has FMA, two where it has not.
    fn mul_add(self, b: Self, c: Self) -> Self;

    /// |self|.
    fn abs(self) -> Self;

    /// Correctly rounded √self.
    fn sqrt(self) -> Self;

    /// The unit normal (−dx, −dy, 1)/‖·‖ of a surface with slopes dx, dy.
    #[inline(always)]
    fn slope_normal(dx: Self, dy: Self) -> [Self; 3] {
        let one = Self::splat(1.0);
        let inv = one / dx.mul_add(dx, dy.mul_add(dy, one)).sqrt();
        [-dx * inv, -dy * inv, inv]
    }

    /// (x, y, z) scaled to unit length, as glam's `normalize_or` does it (never called on zero);
    /// `zz` is z·z, which callers with a z known ahead compute once.
    #[inline(always)]
    fn unit(x: Self, y: Self, z: Self, zz: Self) -> [Self; 3] {
        let inv = Self::splat(1.0) / (x * x + y * y + zz).sqrt();
        [x * inv, y * inv, z * inv]
    }
}

/// A `Real` held in registers that loops load and store `LANES` at a time.
pub trait Vector: Real {
    /// f32 lanes in one value.
    const LANES: usize;

    /// `LANES` values from `p`.
    ///
    /// # Safety
    /// `p..p + LANES` must be readable.
    unsafe fn read(p: *const f32) -> Self;

    /// Writes the lanes to `p..p + LANES`.
    ///
    /// # Safety
    /// `p..p + LANES` must be writable.
    unsafe fn write(self, p: *mut f32);

    /// The first `LANES` values of `s` (which must hold that many).
    #[inline(always)]
    fn load(s: &[f32]) -> Self {
        assert!(s.len() >= Self::LANES);
        // SAFETY: the assert keeps the read inside `s`.
        unsafe { Self::read(s.as_ptr()) }
    }

    /// Writes the lanes to the first `LANES` values of `s` (which must hold that many).
    #[inline(always)]
    fn store(self, s: &mut [f32]) {
        assert!(s.len() >= Self::LANES);
        // SAFETY: the assert keeps the write inside `s`.
        unsafe { self.write(s.as_mut_ptr()) }
    }

    /// `[prev[LANES − 1], self[0], …, self[LANES − 2]]`: the values one column to the left
    /// when `prev` holds the columns just before `self`'s.
    fn shift_in(self, prev: Self) -> Self;

    /// The first min(`s.len()`, `LANES`) values of `s`, the other lanes `pad` (a row's tail).
    #[inline(always)]
    fn load_padded(s: &[f32], pad: f32) -> Self {
        if s.len() >= Self::LANES {
            Self::load(s)
        } else {
            // Element by element: a library copy would make the caller spill its registers.
            let mut buf = [pad; 16];
            for (b, v) in buf.iter_mut().zip(s) {
                *b = *v;
            }
            Self::load(&buf)
        }
    }

    /// The first min(`s.len()`, `LANES`) values of `s`, the other lanes 0 (a row's tail).
    #[inline(always)]
    fn load_prefix(s: &[f32]) -> Self {
        Self::load_padded(s, 0.0)
    }

    /// Slopes (∂f/∂x, ∂f/∂y) in `nx`, `ny` become unit normals along a row: by default one
    /// `Lane<F>` at a time, for LLVM to vectorise (the per-wave path's normalisation pass).
    #[inline(always)]
    fn slopes_to_normals<const F: bool>(nx: &mut [f32], ny: &mut [f32], nz: &mut [f32]) {
        for ((x, y), z) in nx.iter_mut().zip(ny.iter_mut()).zip(nz.iter_mut()) {
            let [a, b, c] = Lane::<F>::slope_normal(Lane(*x), Lane(*y));
            (*x, *y, *z) = (a.0, b.0, c.0);
        }
    }

    /// Writes the first min(`s.len()`, `LANES`) lanes to `s` (a row's tail).
    #[inline(always)]
    fn store_prefix(self, s: &mut [f32]) {
        if s.len() >= Self::LANES {
            self.store(s);
        } else {
            let mut buf = [0.0f32; 16];
            self.store(&mut buf);
            for (d, v) in s.iter_mut().zip(buf) {
                *d = v;
            }
        }
    }
}

/// One f32, fused multiply-add when `F` (the scalar loops LLVM vectorises).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lane<const F: bool>(pub f32);

/// The std::ops impls of a `Real` type (impl generics in braces) from one expression per
/// operator, `$a`/`$b` the operands' inner values.
macro_rules! ops {
    ($gen:tt $t:ty, $a:ident, $b:ident, neg: $neg:expr; $($op:ident $f:ident: $e:expr),+) => {
        $(ops!(@binary $gen $t, $a, $b, $op $f: $e);)+
        ops!(@impl $gen Neg for $t {
            type Output = Self;
            #[inline(always)]
            fn neg(self) -> Self {
                let $a = self.0;
                Self($neg)
            }
        });
    };
    (@binary $gen:tt $t:ty, $a:ident, $b:ident, $op:ident $f:ident: $e:expr) => {
        ops!(@impl $gen $op for $t {
            type Output = Self;
            #[inline(always)]
            fn $f(self, rhs: Self) -> Self {
                let ($a, $b) = (self.0, rhs.0);
                Self($e)
            }
        });
    };
    (@impl {$($gen:tt)*} $tr:ident for $t:ty { $($body:tt)* }) => {
        impl<$($gen)*> $tr for $t { $($body)* }
    };
}

ops!({const F: bool} Lane<F>, a, b, neg: -a;
    Add add: a + b, Sub sub: a - b, Mul mul: a * b, Div div: a / b);

impl<const F: bool> Real for Lane<F> {
    #[inline(always)]
    fn splat(x: f32) -> Self {
        Lane(x)
    }
    #[inline(always)]
    fn mul_add(self, b: Self, c: Self) -> Self {
        Lane(fma::<F>(self.0, b.0, c.0))
    }
    #[inline(always)]
    fn abs(self) -> Self {
        Lane(self.0.abs())
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        Lane(self.0.sqrt())
    }
}

impl<const F: bool> Vector for Lane<F> {
    const LANES: usize = 1;
    #[inline(always)]
    unsafe fn read(p: *const f32) -> Self {
        // SAFETY: the caller's.
        Lane(unsafe { *p })
    }
    #[inline(always)]
    unsafe fn write(self, p: *mut f32) {
        // SAFETY: the caller's.
        unsafe { *p = self.0 }
    }
    #[inline(always)]
    fn shift_in(self, prev: Self) -> Self {
        prev
    }
}

/// The portable instruction set's vector: SSE2 registers on x86-64, one f32 elsewhere.
#[cfg(target_arch = "x86_64")]
pub type Portable = x86::Sse2;
/// The portable instruction set's vector: SSE2 registers on x86-64, one f32 elsewhere.
#[cfg(not(target_arch = "x86_64"))]
pub type Portable = Lane<false>;

#[cfg(target_arch = "x86_64")]
pub use x86::{Avx2, Avx512};

#[cfg(target_arch = "x86_64")]
#[allow(unused_unsafe)] // SSE2 intrinsics are safe in the baseline, the wider ones are not.
mod x86 {
    use super::{Real, Vector};
    use std::arch::x86_64::*;
    use std::ops::{Add, Div, Mul, Neg, Sub};

    /// Runs intrinsics of the vector type in scope.
    macro_rules! simd {
        ($e:expr) => {
            // SAFETY: values of the vector types exist only inside `#[target_feature]` entry
            // points whose features `Isa::available` found on this CPU (see the module doc).
            unsafe { $e }
        };
    }

    /// A vector type over `$raw` with its load, store, arithmetic and `Real` methods; the
    /// irregular ones (`mul_add`, `abs`, negation, `shift_in`) are given as expressions.
    macro_rules! vector {
        ($(#[$doc:meta])* $name:ident($raw:ty), lanes: $lanes:literal, set1: $set1:ident,
         loadu: $loadu:ident, storeu: $storeu:ident, add: $add:ident, sub: $sub:ident,
         mul: $mul:ident, div: $div:ident, sqrt: $sqrt:ident,
         mul_add($x:ident, $y:ident, $z:ident): $fma:expr, abs($v:ident): $abs:expr,
         neg($w:ident): $neg:expr, shift_in($cur:ident, $prev:ident): $shift:expr
         $(, normals: { $($normals:item)* })? $(, rows: { $($rows:item)* })?) => {
            $(#[$doc])*
            #[derive(Clone, Copy, Debug)]
            pub struct $name($raw);

            ops!({} $name, a, b, neg: {
                    let $w = a;
                    simd!($neg)
                };
                Add add: simd!($add(a, b)), Sub sub: simd!($sub(a, b)),
                Mul mul: simd!($mul(a, b)), Div div: simd!($div(a, b)));

            impl Real for $name {
                #[inline(always)]
                fn splat(x: f32) -> Self {
                    Self(simd!($set1(x)))
                }
                #[inline(always)]
                fn mul_add(self, b: Self, c: Self) -> Self {
                    let ($x, $y, $z) = (self.0, b.0, c.0);
                    Self(simd!($fma))
                }
                #[inline(always)]
                fn abs(self) -> Self {
                    let $v = self.0;
                    Self(simd!($abs))
                }
                #[inline(always)]
                fn sqrt(self) -> Self {
                    Self(simd!($sqrt(self.0)))
                }
                $($($normals)*)?
            }

            impl Vector for $name {
                const LANES: usize = $lanes;
                #[inline(always)]
                unsafe fn read(p: *const f32) -> Self {
                    // SAFETY: the caller's, for an unaligned load; the features are as for
                    // `simd!`.
                    Self(unsafe { $loadu(p) })
                }
                #[inline(always)]
                unsafe fn write(self, p: *mut f32) {
                    // SAFETY: as for `read`.
                    unsafe { $storeu(p, self.0) }
                }
                #[inline(always)]
                fn shift_in(self, prev: Self) -> Self {
                    let ($cur, $prev) = (self.0, prev.0);
                    Self(simd!($shift))
                }
                $($($rows)*)?
            }
        };
    }

    vector!(
        /// 16 lanes of AVX-512F (with FMA).
        Avx512(__m512), lanes: 16, set1: _mm512_set1_ps, loadu: _mm512_loadu_ps,
        storeu: _mm512_storeu_ps, add: _mm512_add_ps, sub: _mm512_sub_ps, mul: _mm512_mul_ps,
        div: _mm512_div_ps, sqrt: _mm512_sqrt_ps,
        mul_add(a, b, c): _mm512_fmadd_ps(a, b, c),
        abs(v): _mm512_abs_ps(v),
        // AVX-512F has no float xor (that is DQ), so the sign flips in the integer domain.
        neg(v): _mm512_castsi512_ps(_mm512_xor_si512(
            _mm512_castps_si512(v),
            _mm512_set1_epi32(i32::MIN),
        )),
        shift_in(cur, prev): _mm512_castsi512_ps(_mm512_alignr_epi32::<15>(
            _mm512_castps_si512(cur),
            _mm512_castps_si512(prev),
        )),
        // `vsqrtps` plus `vdivps` cost more than all the waves' arithmetic, so AVX-512
        // normalises with `vrsqrt14ps` and one error-compensated Newton step, which is both
        // faster and closer to the correctly rounded 1/√x than sqrt-then-divide.
        normals: {
            /// 1 + q loses q's low bits; Fast2Sum recovers them (q is small next to 1 here).
            #[inline(always)]
            fn slope_normal(dx: Self, dy: Self) -> [Self; 3] {
                simd!({
                    let one = _mm512_set1_ps(1.0);
                    let zero = _mm512_setzero_ps();
                    let q = _mm512_fmadd_ps(dx.0, dx.0, _mm512_mul_ps(dy.0, dy.0));
                    let x = _mm512_add_ps(one, q);
                    let x_lo = _mm512_sub_ps(q, _mm512_sub_ps(x, one));
                    let r = inv_sqrt(x, Some(x_lo));
                    [
                        Self(_mm512_mul_ps(_mm512_sub_ps(zero, dx.0), r)),
                        Self(_mm512_mul_ps(_mm512_sub_ps(zero, dy.0), r)),
                        Self(r),
                    ]
                })
            }

            /// Within an ulp of the sqrt-then-divide `unit`.
            #[inline(always)]
            fn unit(x: Self, y: Self, z: Self, zz: Self) -> [Self; 3] {
                simd!({
                    let yz = _mm512_fmadd_ps(y.0, y.0, zz.0);
                    let r = inv_sqrt(_mm512_fmadd_ps(x.0, x.0, yz), None);
                    [
                        Self(_mm512_mul_ps(x.0, r)),
                        Self(_mm512_mul_ps(y.0, r)),
                        Self(_mm512_mul_ps(z.0, r)),
                    ]
                })
            }
        },
        rows: {
            /// Under a mask: no buffer, so the caller keeps its registers.
            #[inline(always)]
            fn load_padded(s: &[f32], pad: f32) -> Self {
                // SAFETY: the mask covers only lanes inside `s`, masked-off lanes are not
                // accessed; the features are as for `simd!`.
                Self(unsafe { _mm512_mask_loadu_ps(_mm512_set1_ps(pad), lanes(s.len()), s.as_ptr()) })
            }

            /// Under a mask, as `load_padded`.
            #[inline(always)]
            fn store_prefix(self, s: &mut [f32]) {
                // SAFETY: as for `load_padded`.
                unsafe { _mm512_mask_storeu_ps(s.as_mut_ptr(), lanes(s.len()), self.0) }
            }

            /// 16 lanes at a time, the row's tail under a mask so that every vertex gets the
            /// same rounding.
            #[inline(always)]
            fn slopes_to_normals<const F: bool>(nx: &mut [f32], ny: &mut [f32], nz: &mut [f32]) {
                let n = nx.len().min(ny.len()).min(nz.len());
                for j in (0..n).step_by(16) {
                    let r = j..(j + 16).min(n);
                    let (dx, dy) = (Self::load_prefix(&nx[r.clone()]), Self::load_prefix(&ny[r.clone()]));
                    let [x, y, z] = Self::slope_normal(dx, dy);
                    x.store_prefix(&mut nx[r.clone()]);
                    y.store_prefix(&mut ny[r.clone()]);
                    z.store_prefix(&mut nz[r]);
                }
            }
        }
    );

    vector!(
        /// 8 lanes of AVX2 with FMA.
        Avx2(__m256), lanes: 8, set1: _mm256_set1_ps, loadu: _mm256_loadu_ps,
        storeu: _mm256_storeu_ps, add: _mm256_add_ps, sub: _mm256_sub_ps, mul: _mm256_mul_ps,
        div: _mm256_div_ps, sqrt: _mm256_sqrt_ps,
        mul_add(a, b, c): _mm256_fmadd_ps(a, b, c),
        abs(v): _mm256_andnot_ps(_mm256_set1_ps(-0.0), v),
        neg(v): _mm256_xor_ps(v, _mm256_set1_ps(-0.0)),
        // alignr shifts within 128-bit halves, so the half that crosses over comes from
        // [prev's high half, cur's low half].
        shift_in(cur, prev): {
            let mid = _mm256_permute2f128_ps::<0x21>(prev, cur);
            _mm256_castsi256_ps(_mm256_alignr_epi8::<12>(
                _mm256_castps_si256(cur),
                _mm256_castps_si256(mid),
            ))
        },
        rows: {
            /// Under a mask: no buffer, so the caller keeps its registers.
            #[inline(always)]
            fn load_padded(s: &[f32], pad: f32) -> Self {
                let m = prefix_mask(s.len());
                // SAFETY: the mask covers only lanes inside `s`, masked-off lanes are not
                // accessed; the features are as for `simd!`.
                let v = unsafe { _mm256_maskload_ps(s.as_ptr(), m) };
                Self(simd!(_mm256_blendv_ps(_mm256_set1_ps(pad), v, _mm256_castsi256_ps(m))))
            }

            /// Under a mask, as `load_padded`.
            #[inline(always)]
            fn store_prefix(self, s: &mut [f32]) {
                // SAFETY: as for `load_padded`.
                unsafe { _mm256_maskstore_ps(s.as_mut_ptr(), prefix_mask(s.len()), self.0) }
            }
        }
    );

    /// AVX2 lane mask (sign bits) of the first min(len, 8) lanes.
    #[inline(always)]
    fn prefix_mask(len: usize) -> __m256i {
        let len = len.min(8) as i32;
        simd!(_mm256_cmpgt_epi32(
            _mm256_set1_epi32(len),
            _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7)
        ))
    }

    vector!(
        /// 4 lanes of SSE2, the x86-64 baseline, without FMA.
        Sse2(__m128), lanes: 4, set1: _mm_set1_ps, loadu: _mm_loadu_ps,
        storeu: _mm_storeu_ps, add: _mm_add_ps, sub: _mm_sub_ps, mul: _mm_mul_ps,
        div: _mm_div_ps, sqrt: _mm_sqrt_ps,
        mul_add(a, b, c): _mm_add_ps(_mm_mul_ps(a, b), c),
        abs(v): _mm_andnot_ps(_mm_set1_ps(-0.0), v),
        neg(v): _mm_xor_ps(v, _mm_set1_ps(-0.0)),
        // [prev3, prev3, cur0, cur0], then [prev3, cur0, cur1, cur2] (no palignr before SSSE3).
        shift_in(cur, prev): {
            let mid = _mm_shuffle_ps::<0b00_00_11_11>(prev, cur);
            _mm_shuffle_ps::<0b10_01_10_00>(mid, cur)
        }
    );

    /// 1/√(x + x_lo) to about half an ulp: `vrsqrt14ps` (14 bits) then one Newton step whose
    /// residual 1 − x·r² is computed with the product's rounding error and, when given, x's
    /// low part.
    #[inline(always)]
    fn inv_sqrt(x: __m512, x_lo: Option<__m512>) -> __m512 {
        simd!({
            let one = _mm512_set1_ps(1.0);
            let r0 = _mm512_rsqrt14_ps(x);
            let u = _mm512_mul_ps(x, r0);
            let u_lo = _mm512_fmsub_ps(x, r0, u);
            let mut e = _mm512_fnmadd_ps(u, r0, one);
            e = _mm512_fnmadd_ps(u_lo, r0, e);
            if let Some(x_lo) = x_lo {
                e = _mm512_fnmadd_ps(_mm512_mul_ps(x_lo, r0), r0, e);
            }
            _mm512_fmadd_ps(_mm512_mul_ps(r0, _mm512_set1_ps(0.5)), e, r0)
        })
    }

    /// Mask of the first min(left, 16) lanes.
    #[inline(always)]
    fn lanes(left: usize) -> __mmask16 {
        if left >= 16 {
            0xffff
        } else {
            (1u16 << left) - 1
        }
    }
}
