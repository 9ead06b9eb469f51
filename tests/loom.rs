//! Model-checks every hand-off method's protocol with loom: over several frames the consumer sees
//! each frame exactly once and in order, the producer never writes the slot while it is being
//! copied (loom flags the data race on its `UnsafeCell`), no interleaving deadlocks, and a
//! shutdown reaches a producer waiting for its release.
//!
//! Run with `RUSTFLAGS="--cfg loom" cargo test --release --test loom`.
#![cfg(loom)]

use loom::cell::UnsafeCell;
use loom::sync::Arc;
use oceanbench::sync::{Released, SyncMethod};
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

/// FRAMES frames through the slot: the producer writes frame k and publishes it, the consumer
/// waits, copies and releases; the producer waits for each release before the next write.
fn frames_in_order(method: SyncMethod) {
    model(move || {
        let handoff = Arc::new(method.handoff());
        let slot = Arc::new(UnsafeCell::new(u64::MAX));
        let producer = {
            let (handoff, slot) = (Arc::clone(&handoff), Arc::clone(&slot));
            loom::thread::spawn(move || {
                for frame in 0..FRAMES {
                    // SAFETY: loom checks it: the slot is the producer's until it publishes.
                    slot.with_mut(|p| unsafe { *p = frame });
                    handoff.publish();
                    if frame + 1 < FRAMES {
                        let released = handoff.wait_released(far());
                        assert_eq!(released, Ok(Released::Next), "{method:?}");
                    }
                }
            })
        };
        let mut seen = Vec::new();
        for _ in 0..FRAMES {
            handoff.wait_published(far()).expect("published");
            // SAFETY: loom checks it: the slot is the consumer's until it releases.
            seen.push(slot.with(|p| unsafe { *p }));
            handoff.release();
        }
        producer.join().unwrap();
        assert_eq!(seen, (0..FRAMES).collect::<Vec<_>>(), "{method:?}");
    });
}

/// The consumer takes one frame and stops the loop instead of releasing: the producer, waiting
/// for the release, must learn of the shutdown, and a publication racing the shutdown must not
/// erase it.
fn shutdown_reaches_the_producer(method: SyncMethod) {
    model(move || {
        let handoff = Arc::new(method.handoff());
        let producer = {
            let handoff = Arc::clone(&handoff);
            loom::thread::spawn(move || {
                handoff.publish();
                handoff.wait_released(far())
            })
        };
        handoff.wait_published(far()).expect("published");
        handoff.shutdown();
        assert_eq!(
            producer.join().unwrap(),
            Ok(Released::Shutdown),
            "{method:?}"
        );
    });
}

macro_rules! loom_tests {
    ($($name:ident: $method:expr,)*) => {$(
        mod $name {
            use super::*;

            #[test]
            fn frames_arrive_once_in_order_without_races() {
                frames_in_order($method);
            }

            #[test]
            fn shutdown_reaches_a_waiting_producer() {
                shutdown_reaches_the_producer($method);
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
}
