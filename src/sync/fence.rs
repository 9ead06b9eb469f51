//! An asymmetric StoreLoad fence (the pattern of liburcu and folly's `asymmetricHeavyBarrier`):
//! the side that runs often pays only a compiler barrier, the side that runs rarely asks the
//! kernel, through Linux's `membarrier(MEMBARRIER_CMD_PRIVATE_EXPEDITED)`, to run a full memory
//! barrier on every core that runs a thread of this process. A [`light`] fence and a [`heavy`]
//! one then order a store before a load on each side, as two `fence(SeqCst)` would.
//!
//! Where `membarrier` is missing (another OS, a kernel before 4.14, a seccomp filter), both are
//! `fence(SeqCst)`. Under loom both are `fence(SeqCst)` too: loom cannot model `membarrier`, and
//! the full fence is what the pair stands for.

#[cfg(loom)]
use loom::sync::atomic::{fence, Ordering};
#[cfg(not(loom))]
use std::sync::atomic::{compiler_fence, fence, AtomicBool, Ordering};

/// Whether this process registered for `membarrier`'s private expedited command.
#[cfg(not(loom))]
static EXPEDITED: AtomicBool = AtomicBool::new(false);

/// Registers the process for the heavy fence once (a system call the first time; later calls
/// cost a load). Call before the first [`light`] or [`heavy`] fence that pairs with another.
pub fn register() {
    #[cfg(all(target_os = "linux", not(loom)))]
    {
        static ONCE: std::sync::Once = std::sync::Once::new();
        ONCE.call_once(|| EXPEDITED.store(linux::register(), Ordering::SeqCst));
    }
}

/// The frequent side's fence: a compiler barrier when the heavy side can reach this core
/// through `membarrier`, else a full fence.
#[inline]
pub fn light() {
    #[cfg(not(loom))]
    if EXPEDITED.load(Ordering::Relaxed) {
        compiler_fence(Ordering::SeqCst);
        return;
    }
    fence(Ordering::SeqCst);
}

/// The rare side's fence: a full barrier on every core running a thread of this process (and
/// on this one), or a full fence where `membarrier` is unavailable.
pub fn heavy() {
    #[cfg(all(target_os = "linux", not(loom)))]
    if EXPEDITED.load(Ordering::Relaxed) {
        // The light side has already left out its fence, so a fence of our own would not do:
        // the barrier must run. After registration the kernel refuses it only for want of a
        // temporary CPU mask, which passes.
        for _ in 0..1_000 {
            if linux::private_expedited() {
                return;
            }
            std::thread::yield_now();
        }
        panic!("membarrier(MEMBARRIER_CMD_PRIVATE_EXPEDITED) kept failing after registration");
    }
    fence(Ordering::SeqCst);
}

#[cfg(all(target_os = "linux", not(loom)))]
mod linux {
    // From <linux/membarrier.h>; part of the kernel's ABI since 4.14.
    const MEMBARRIER_CMD_PRIVATE_EXPEDITED: libc::c_long = 1 << 3;
    const MEMBARRIER_CMD_REGISTER_PRIVATE_EXPEDITED: libc::c_long = 1 << 4;

    fn membarrier(cmd: libc::c_long) -> bool {
        // SAFETY: membarrier takes two integers and touches no memory of ours.
        unsafe { libc::syscall(libc::SYS_membarrier, cmd, 0 as libc::c_long) == 0 }
    }

    /// Whether the kernel registered this process for the private expedited command.
    pub fn register() -> bool {
        membarrier(MEMBARRIER_CMD_REGISTER_PRIVATE_EXPEDITED)
    }

    /// Runs the barrier; false if the kernel refused it.
    pub fn private_expedited() -> bool {
        membarrier(MEMBARRIER_CMD_PRIVATE_EXPEDITED)
    }
}

#[cfg(all(test, not(loom)))]
mod tests {
    use super::*;

    #[test]
    fn both_fences_run_registered_or_not() {
        light();
        heavy();
        register();
        register();
        #[cfg(target_os = "linux")]
        assert!(
            !EXPEDITED.load(Ordering::SeqCst) || linux::private_expedited(),
            "a registered process may run the expedited barrier"
        );
        light();
        heavy();
    }
}
