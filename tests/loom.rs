//! Model-checks every hand-off method's ring at depths 1, 2 and 3 with loom: over several frames
//! the consumer sees each frame exactly once and in order, the producer never writes a slot while
//! it is being read (loom flags the data race on its `UnsafeCell`), no interleaving deadlocks, and
//! a shutdown reaches a producer waiting for a free slot.
//!
//! The in-house `latest` mailbox (`atomic`'s atomic index swap) is checked too: every mesh the
//! reader takes is one the writer finished, never one it is writing, and the frames taken never
//! go back.
//!
//! `adaptive` is checked on the protocol it runs: each side bumps its counter with a plain store
//! and looks for sleepers after a `fence(SeqCst)`, a sleeper registers and looks at the counters
//! after one. Its spin and yield phases are a few looks without a pause under loom, so a waiter
//! does reach its sleep before the other side has changed the counters: the lost wake-up the
//! fences prevent is within the model's reach (dropping either fence, or the wake-up after a
//! publish, makes it report a deadlock).
//!
//! loom sees only what is built on the crate's loom facade. The crate-backed methods
//! (crossbeam, std-channel, flume, rtrb, triple-buffer) use their crates' own atomics, and
//! `futex` and `park` call the kernel and std's parker, none of which loom can model; those are
//! checked by the bit-identity tests and the soak instead.
//!
//! Run with `RUSTFLAGS="--cfg loom" cargo test --release --test loom`.
#![cfg(loom)]

use loom::cell::UnsafeCell;
use loom::sync::Arc;
use oceanbench::sync::{Free, SyncMethod};
use std::time::{Duration, Instant};

const FRAMES: u64 = 3;

fn far() -> Instant {
    Instant::now() + Duration::from_secs(3600)
}

fn model(f: impl Fn() + Sync + Send + 'static) {
    let mut builder = loom::model::Builder::new();
    builder.preemption_bound = Some(3);
    builder.check(f);
}

/// FRAMES frames through a ring of `depth` slots: the producer waits for a free slot, writes
/// frame k into slot k mod depth and publishes it; the consumer waits, reads and releases. loom
/// flags any write to a slot still being read (a data race on its `UnsafeCell`).
fn frames_in_order(method: SyncMethod, depth: usize) {
    model(move || {
        let handoff = Arc::new(method.handoff(depth));
        let slots: Arc<Vec<UnsafeCell<u64>>> =
            Arc::new((0..depth).map(|_| UnsafeCell::new(u64::MAX)).collect());
        let producer = {
            let (handoff, slots) = (Arc::clone(&handoff), Arc::clone(&slots));
            loom::thread::spawn(move || {
                for frame in 0..FRAMES {
                    assert_eq!(handoff.wait_free(far()), Ok(Free::Slot), "{method:?}");
                    let slot = &slots[frame as usize % depth];
                    // SAFETY: loom checks it: a free slot is the producer's until it publishes.
                    slot.with_mut(|p| unsafe { *p = frame });
                    handoff.publish();
                }
            })
        };
        let mut seen = Vec::new();
        for frame in 0..FRAMES {
            handoff.wait_published(frame, far()).expect("published");
            let slot = &slots[frame as usize % depth];
            // SAFETY: loom checks it: a published slot is the consumer's until it releases.
            seen.push(slot.with(|p| unsafe { *p }));
            handoff.release();
        }
        producer.join().unwrap();
        assert_eq!(
            seen,
            (0..FRAMES).collect::<Vec<_>>(),
            "{method:?} depth {depth}"
        );
    });
}

/// The producer fills slots until none is free; the consumer takes one frame and stops the loop
/// instead of releasing it: the producer, whether it is still filling or already waiting for a
/// slot that never frees, must learn of the shutdown.
fn shutdown_reaches_the_producer(method: SyncMethod, depth: usize) {
    model(move || {
        let handoff = Arc::new(method.handoff(depth));
        let producer = {
            let handoff = Arc::clone(&handoff);
            loom::thread::spawn(move || {
                for _ in 0..=depth {
                    match handoff.wait_free(far()) {
                        Ok(Free::Slot) => handoff.publish(),
                        other => return other,
                    }
                }
                unreachable!("a ring of {depth} slots took {} frames", depth + 1)
            })
        };
        handoff.wait_published(0, far()).expect("published");
        handoff.shutdown();
        assert_eq!(
            producer.join().unwrap(),
            Ok(Free::Shutdown),
            "{method:?} depth {depth}"
        );
    });
}

macro_rules! loom_tests {
    ($($name:ident: $method:expr,)*) => {$(
        mod $name {
            use super::*;

            #[test]
            fn frames_arrive_once_in_order_without_races() {
                for depth in 1..=3 {
                    frames_in_order($method, depth);
                }
            }

            #[test]
            fn shutdown_reaches_a_waiting_producer() {
                for depth in 1..=3 {
                    shutdown_reaches_the_producer($method, depth);
                }
            }
        }
    )*};
}

loom_tests! {
    atomic: SyncMethod::Atomic,
    spin: SyncMethod::Spin,
    mutex: SyncMethod::Mutex,
    condvar: SyncMethod::Condvar,
    mutex_std: SyncMethod::MutexStd,
    condvar_std: SyncMethod::CondvarStd,
    adaptive: SyncMethod::Adaptive,
}

/// The `latest` mailbox of `atomic`: the writer publishes frames 1 to FRAMES, the reader takes
/// the newest whenever it looks. loom flags a buffer written while it is read; the values the
/// reader holds never decrease, and once the writer is done a last look finds the final frame.
#[test]
fn atomic_mailbox_hands_over_finished_frames_newest_last() {
    model(|| {
        let (mut input, mut output) = SyncMethod::Atomic
            .mailbox(&0u64)
            .expect("atomic serves latest");
        let writer = loom::thread::spawn(move || {
            for frame in 1..=FRAMES {
                *input.buffer() = frame;
                input.publish();
            }
        });
        let mut seen = vec![*output.buffer()];
        for _ in 0..FRAMES {
            if output.update() {
                seen.push(*output.buffer());
            }
        }
        writer.join().unwrap();
        output.update();
        seen.push(*output.buffer());
        assert!(seen.windows(2).all(|w| w[0] <= w[1]), "{seen:?}");
        assert_eq!(seen.last(), Some(&FRAMES), "{seen:?}");
    });
}
