//! The one-frame buffer shared by the helper and the main thread.

use std::cell::UnsafeCell;

/// A value written by the helper and read by the main thread, never at the same time: the
/// [`Handoff`](super::Handoff) protocol decides who owns it, as the paper's shared vertex buffer.
pub struct Slot<T> {
    cell: UnsafeCell<T>,
}

// SAFETY: access is serialised by the hand-off protocol (see `get_mut`/`get`), whose
// release/acquire edges also make each side's writes visible to the other.
unsafe impl<T: Send> Sync for Slot<T> {}

impl<T> Slot<T> {
    /// Wraps the initial value.
    pub fn new(value: T) -> Self {
        Slot {
            cell: UnsafeCell::new(value),
        }
    }

    /// The helper's view of the slot.
    ///
    /// # Safety
    /// The caller must own the slot: it is the helper, and since it last waited, the main thread
    /// has released the slot (or it was never published), so no reference from `get` is alive.
    #[allow(clippy::mut_from_ref)]
    pub unsafe fn get_mut(&self) -> &mut T {
        unsafe { &mut *self.cell.get() }
    }

    /// The main thread's view of the slot.
    ///
    /// # Safety
    /// The caller must be the main thread between `wait_published` returning and `release`, so the
    /// helper is not writing.
    pub unsafe fn get(&self) -> &T {
        unsafe { &*self.cell.get() }
    }
}
