//! Ctrl-C and SIGTERM: the first asks the running command to stop after the current frame and
//! keep what it finished; a second one quits at once.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// Routes the first interrupt to `stop`. A second interrupt exits with status 130 straight
/// from the signal handler: every results file on disk is whole at any moment (each is
/// renamed into place), so nothing is lost by not unwinding.
pub fn forward_to(stop: Arc<AtomicBool>) {
    // Only one handler per process; a second command in the same process (tests) keeps the first.
    let _ = ctrlc::set_handler(move || {
        if stop.swap(true, Ordering::SeqCst) {
            std::process::exit(130);
        }
        eprintln!("\noceanbench: stopping after the current frame (again to quit now)");
    });
}
