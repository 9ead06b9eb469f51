//! The fog's loops compiled once per instruction set: each is plain Rust over slices, inlined
//! into one `#[target_feature]` entry point per set so that LLVM vectorises it with that set's
//! registers (and FMA), the widest the CPU has picked at run time with the fast ocean kernel's
//! [`Isa`].

pub use crate::ocean::sines::fast::Isa;

/// A loop to compile per instruction set; `run` is `#[inline(always)]` in implementations.
pub trait Loop {
    /// What the loop returns.
    type Output;
    /// Runs the loop.
    fn run(self) -> Self::Output;
}

/// Runs `work` with `isa`, which must come from [`Isa::available`].
pub fn run<L: Loop>(isa: Isa, work: L) -> L::Output {
    match isa {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: `isa` comes from `Isa::available`, so the CPU has these features.
        Isa::Avx512 => unsafe { avx512(work) },
        #[cfg(target_arch = "x86_64")]
        // SAFETY: as above.
        Isa::Avx2 => unsafe { avx2(work) },
        _ => work.run(),
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx2,fma")]
fn avx512<L: Loop>(work: L) -> L::Output {
    work.run()
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn avx2<L: Loop>(work: L) -> L::Output {
    work.run()
}
