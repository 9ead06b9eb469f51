//! The instruction sets kernels are compiled for, which of them this CPU has, and plain loops
//! compiled once per set: each loop is Rust over slices, inlined into one `#[target_feature]`
//! entry point per set so that LLVM vectorises it with that set's registers (and FMA). The fog's
//! passes run with the set their caller picked ([`run`]); the FFT ocean's fill and sampling and
//! the projected grid's placement with the widest this CPU has ([`run_widest`]). The fast sines
//! kernel's loops, generic over a vector type, have entry points of their own (its `ForIsa`).

use std::sync::OnceLock;

/// An instruction set a kernel's loops are compiled for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Isa {
    /// 512-bit vectors (AVX-512F) with FMA.
    Avx512,
    /// 256-bit vectors (AVX2) with FMA.
    Avx2,
    /// The target's baseline (SSE2 on x86-64), no FMA.
    Portable,
}

impl Isa {
    /// The widest instruction set this CPU supports.
    pub fn detect() -> Isa {
        Isa::available()[0]
    }

    /// Every instruction set this CPU supports, widest first (tests run them all).
    pub fn available() -> Vec<Isa> {
        let mut out = Vec::new();
        #[cfg(target_arch = "x86_64")]
        {
            let fma_avx2 = is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma");
            if fma_avx2 && is_x86_feature_detected!("avx512f") {
                out.push(Isa::Avx512);
            }
            if fma_avx2 {
                out.push(Isa::Avx2);
            }
        }
        out.push(Isa::Portable);
        out
    }

    /// Name for reports.
    pub fn name(self) -> &'static str {
        match self {
            Isa::Avx512 => "avx512",
            Isa::Avx2 => "avx2",
            Isa::Portable => "portable",
        }
    }
}

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

/// Runs `work` with the widest instruction set this CPU has, found once per process: its
/// callers run many times a frame, some for a microsecond.
pub fn run_widest<L: Loop>(work: L) -> L::Output {
    static WIDEST: OnceLock<Isa> = OnceLock::new();
    run(*WIDEST.get_or_init(Isa::detect), work)
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
