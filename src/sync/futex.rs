//! `futex`: the ring's counters as futex words, every wait a sleep in the kernel and every
//! change a wake-up call: the thinnest OS-backed hand-off, the yardstick for what `condvar`
//! costs above the kernel's own primitive. The syscall is made directly (through libc) because
//! the ring's contract needs timed waits, which `atomic-wait` does not offer.
//!
//! Each word is re-read after the value it was seen with; `FUTEX_WAIT` returns at once when the
//! word no longer holds that value, so a change between the look and the sleep is never lost.
//! A stop sets the top bit of the helper's word for the same reason.

use super::{Free, Handoff, TimedOut};
use std::sync::atomic::{AtomicU32, AtomicU64, Ordering};
use std::time::Instant;

/// Set in `head` when the loop is stopped.
const STOPPED: u32 = 1 << 31;
/// The release count's bits in `head` (it counts modulo 2^31).
const COUNT: u32 = STOPPED - 1;

/// The ring as futex words.
pub struct FutexRing {
    /// Frames released modulo 2^31, and the stop bit: the helper sleeps on it.
    head: AtomicU32,
    /// Bumped on every publication: the main thread sleeps on it.
    tail: AtomicU32,
    published: AtomicU64,
    depth: u32,
}

impl FutexRing {
    /// A ring of `depth` free slots.
    pub fn new(depth: u64) -> Self {
        FutexRing {
            head: AtomicU32::new(0),
            tail: AtomicU32::new(0),
            published: AtomicU64::new(0),
            depth: depth as u32,
        }
    }
}

impl Handoff for FutexRing {
    fn wait_free(&self, deadline: Instant) -> Result<Free, TimedOut> {
        // Only the helper publishes, so its relaxed read of its own count is current.
        let tail = self.published.load(Ordering::Relaxed) as u32 & COUNT;
        loop {
            let head = self.head.load(Ordering::Acquire);
            if head & STOPPED != 0 {
                return Ok(Free::Shutdown);
            }
            if tail.wrapping_sub(head) & COUNT < self.depth {
                return Ok(Free::Slot);
            }
            sleep(&self.head, head, deadline)?;
        }
    }

    fn publish(&self) {
        self.published.fetch_add(1, Ordering::Release);
        self.tail.fetch_add(1, Ordering::Release);
        wake(&self.tail);
    }

    fn wait_published(&self, frame: u64, deadline: Instant) -> Result<(), TimedOut> {
        loop {
            // The word before the count: a publication after this look changes the word.
            let word = self.tail.load(Ordering::Acquire);
            if self.published.load(Ordering::Acquire) > frame {
                return Ok(());
            }
            sleep(&self.tail, word, deadline)?;
        }
    }

    fn release(&self) {
        // The count wraps inside its 31 bits; the stop bit is never carried into.
        let _ = self
            .head
            .fetch_update(Ordering::Release, Ordering::Relaxed, |h| {
                Some((h & STOPPED) | (h.wrapping_add(1) & COUNT))
            });
        wake(&self.head);
    }

    fn shutdown(&self) {
        self.head.fetch_or(STOPPED, Ordering::Release);
        wake(&self.head);
    }

    fn published(&self) -> u64 {
        self.published.load(Ordering::Acquire)
    }
}

/// Sleeps while `word` holds `seen`, until woken or `deadline`; `TimedOut` once it has passed.
fn sleep(word: &AtomicU32, seen: u32, deadline: Instant) -> Result<(), TimedOut> {
    let left = deadline
        .checked_duration_since(Instant::now())
        .filter(|d| !d.is_zero())
        .ok_or(TimedOut)?;
    futex_wait(word, seen, left);
    Ok(())
}

#[cfg(target_os = "linux")]
fn futex_wait(word: &AtomicU32, seen: u32, left: std::time::Duration) {
    let timeout = libc::timespec {
        tv_sec: left.as_secs().min(i32::MAX as u64) as libc::time_t,
        tv_nsec: left.subsec_nanos() as libc::c_long,
    };
    // SAFETY: the word lives as long as the ring, which outlives this call; FUTEX_WAIT only
    // reads it, and a spurious return is handled by the caller's loop.
    unsafe {
        libc::syscall(
            libc::SYS_futex,
            word.as_ptr(),
            libc::FUTEX_WAIT | libc::FUTEX_PRIVATE_FLAG,
            seen,
            &timeout as *const libc::timespec,
        );
    }
}

#[cfg(target_os = "linux")]
fn wake(word: &AtomicU32) {
    // SAFETY: as above; FUTEX_WAKE does not touch the word's value.
    unsafe {
        libc::syscall(
            libc::SYS_futex,
            word.as_ptr(),
            libc::FUTEX_WAKE | libc::FUTEX_PRIVATE_FLAG,
            i32::MAX,
        );
    }
}

/// Without futexes the wait degrades to a yield and the wake to nothing: correct, not thin.
#[cfg(not(target_os = "linux"))]
fn futex_wait(_: &AtomicU32, _: u32, _: std::time::Duration) {
    std::thread::yield_now();
}

#[cfg(not(target_os = "linux"))]
fn wake(_: &AtomicU32) {}
