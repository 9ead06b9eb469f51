//! The `latest` policy's hand-off (Vulkan's MAILBOX): the helper never waits, writing each frame
//! into a buffer of its own and publishing it; the main thread takes the newest published buffer
//! when it wants one, and keeps the one it has when nothing newer came. Three buffers, as in a
//! triple buffer: one the helper writes, one the main thread reads, one waiting in between.
//!
//! Two implementations: the `triple_buffer` crate, and an in-house swap of one atomic index.

use super::primitives::{AtomicU8, Cell, Ordering};
use std::sync::Arc;

/// The helper's end: a buffer it owns, and the publication that trades it for another.
pub trait MailboxIn<T>: Send {
    /// The buffer to write the next frame into; no one else sees it until it is published.
    fn buffer(&mut self) -> &mut T;
    /// Publishes the buffer just written; the helper gets a free one in exchange.
    fn publish(&mut self);
}

/// The main thread's end.
pub trait MailboxOut<T>: Send {
    /// Takes the newest published buffer if one came since the last take; `false` keeps the
    /// one held.
    fn update(&mut self) -> bool;
    /// The buffer held.
    fn buffer(&self) -> &T;
}

impl<T: Send> MailboxIn<T> for triple_buffer::Input<T> {
    fn buffer(&mut self) -> &mut T {
        self.input_buffer_mut()
    }
    fn publish(&mut self) {
        triple_buffer::Input::publish(self);
    }
}

impl<T: Send> MailboxOut<T> for triple_buffer::Output<T> {
    fn update(&mut self) -> bool {
        triple_buffer::Output::update(self)
    }
    fn buffer(&self) -> &T {
        self.peek_output_buffer()
    }
}

/// Set in the shared index when the buffer there was published and not yet taken.
const FRESH: u8 = 0b100;
const INDEX: u8 = 0b011;

/// Three buffers and the index of the one in between, with its fresh bit.
struct Swap<T> {
    buffers: [Cell<T>; 3],
    between: AtomicU8,
}

// SAFETY: each buffer is touched by one side at a time: the writer owns the index it holds, the
// reader the one it holds, and the third sits in `between`; the swaps hand indices over with
// acquire/release, which also publishes what was written.
unsafe impl<T: Send> Sync for Swap<T> {}

/// The helper's end of the in-house swap.
pub struct SwapIn<T> {
    swap: Arc<Swap<T>>,
    own: u8,
}

/// The main thread's end of the in-house swap.
pub struct SwapOut<T> {
    swap: Arc<Swap<T>>,
    own: u8,
}

/// An in-house mailbox over three copies of `initial`: the writer holds buffer 0, the reader
/// buffer 1, and buffer 2 waits in between, not fresh.
pub fn swap<T: Clone + Send>(initial: &T) -> (SwapIn<T>, SwapOut<T>) {
    let swap = Arc::new(Swap {
        buffers: [0, 1, 2].map(|_| Cell::new(initial.clone())),
        between: AtomicU8::new(2),
    });
    (
        SwapIn {
            swap: Arc::clone(&swap),
            own: 0,
        },
        SwapOut { swap, own: 1 },
    )
}

impl<T: Send> MailboxIn<T> for SwapIn<T> {
    fn buffer(&mut self) -> &mut T {
        // SAFETY: the writer owns buffer `own` until it publishes it.
        unsafe { self.swap.buffers[self.own as usize].get_mut() }
    }
    fn publish(&mut self) {
        let previous = self.swap.between.swap(self.own | FRESH, Ordering::AcqRel);
        self.own = previous & INDEX;
    }
}

impl<T: Send> MailboxOut<T> for SwapOut<T> {
    fn update(&mut self) -> bool {
        if self.swap.between.load(Ordering::Acquire) & FRESH == 0 {
            return false;
        }
        let previous = self.swap.between.swap(self.own, Ordering::AcqRel);
        self.own = previous & INDEX;
        true
    }
    fn buffer(&self) -> &T {
        // SAFETY: the reader owns buffer `own` until its next update.
        unsafe { self.swap.buffers[self.own as usize].get() }
    }
}
