//! Polynomial natural log and exp (Cephes single-precision coefficients, about 1 ulp in their
//! reduced ranges), written lane by lane with bit operations so the loops that call them
//! vectorise; they replace `powf` for steepness that is not a half-integer.

/// Fused multiply-add when the caller's target has FMA, else separate operations (a software
/// `fma` call would be far slower than the two roundings it saves).
#[inline(always)]
pub fn fma<const F: bool>(a: f32, b: f32, c: f32) -> f32 {
    if F {
        a.mul_add(b, c)
    } else {
        a * b + c
    }
}

/// ln x for normal x > 0.
#[inline(always)]
pub fn ln<const F: bool>(x: f32) -> f32 {
    let bits = x.to_bits();
    let e = ((bits >> 23) & 0xff) as i32 - 127;
    let m = f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000);
    // Centre the mantissa on 1 ([√½, √2)) so the polynomial's argument stays small.
    let big = m > std::f32::consts::SQRT_2;
    let m = if big { m * 0.5 } else { m };
    let e = (e + big as i32) as f32;
    let f = m - 1.0;
    let z = f * f;
    let mut y = 7.037_683_6e-2;
    y = fma::<F>(y, f, -1.151_461e-1);
    y = fma::<F>(y, f, 1.167_699_9e-1);
    y = fma::<F>(y, f, -1.242_014_1e-1);
    y = fma::<F>(y, f, 1.424_932_3e-1);
    y = fma::<F>(y, f, -1.666_805_8e-1);
    y = fma::<F>(y, f, 2.000_071_4e-1);
    y = fma::<F>(y, f, -2.499_999_4e-1);
    y = fma::<F>(y, f, 3.333_333e-1);
    y *= f * z;
    // ln 2 split in two so e·ln2 adds no rounding error of its own.
    y = fma::<F>(e, -2.121_944_4e-4, y);
    y = fma::<F>(-0.5, z, y);
    fma::<F>(e, 0.693_359_4, f + y)
}

/// e^x, flushed to a tiny positive value below −87 (callers multiply it by a vanishing factor).
#[inline(always)]
pub fn exp<const F: bool>(x: f32) -> f32 {
    const MAGIC: f32 = 12_582_912.0; // 1.5·2^23: adding it rounds to an integer in the low bits.
    let x = x.clamp(-87.0, 88.0);
    let y = fma::<F>(x, std::f32::consts::LOG2_E, MAGIC);
    let n = (y.to_bits() as i32) - 0x4b40_0000;
    let nf = y - MAGIC;
    let r = fma::<F>(nf, -0.693_359_4, x);
    let r = fma::<F>(nf, 2.121_944_4e-4, r);
    let z = r * r;
    let mut p = 1.987_569_1e-4;
    p = fma::<F>(p, r, 1.398_2e-3);
    p = fma::<F>(p, r, 8.333_452e-3);
    p = fma::<F>(p, r, 4.166_579_6e-2);
    p = fma::<F>(p, r, 1.666_666_5e-1);
    p = fma::<F>(p, r, 0.5);
    let p = fma::<F>(p, z, r) + 1.0;
    p * f32::from_bits(((n + 127) << 23) as u32)
}

/// |h|^e for any real e >= 0 (|h| clamped away from zero, where the result only ever multiplies
/// a factor that vanishes with h).
#[inline(always)]
pub fn pow_abs<const F: bool>(h: f32, e: f32) -> f32 {
    exp::<F>(e * ln::<F>(h.abs().max(1e-30)))
}
