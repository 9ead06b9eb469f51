//! The ring every hand-off method implements: `depth` mesh slots, the helper's count of frames
//! published (the tail) and the main thread's count of frames released (the head). Frame k lives
//! in slot k mod depth. Depth 1 is the paper's one-slot loop.

use super::Free;

/// A ring's counters and the shutdown flag, as the lock-based methods keep them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Ring {
    /// Frames the main thread has released.
    pub head: u64,
    /// Frames the helper has published.
    pub tail: u64,
    /// The main thread has stopped the loop.
    pub shutdown: bool,
}

impl Ring {
    /// The helper's wait is over: a slot is free, or the loop is stopped (which wins).
    pub fn free(&self, depth: u64) -> Option<Free> {
        if self.shutdown {
            Some(Free::Shutdown)
        } else if self.tail - self.head < depth {
            Some(Free::Slot)
        } else {
            None
        }
    }

    /// The main thread's wait for frame `frame` is over: it is published.
    pub fn filled(&self, frame: u64) -> Option<()> {
        (self.tail > frame).then_some(())
    }
}
