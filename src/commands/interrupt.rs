//! Ctrl-C and SIGTERM: the first asks the running command to stop after the current frame and
//! keep what it finished; a second one quits at once.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, OnceLock};

/// The flag the first interrupt raises, with the handler installed on first use (before a
/// command's slow set-up, so an early signal is not the default kill). A second interrupt exits
/// with status 130 straight from the handler: every results file on disk is whole at any moment
/// (each is renamed into place), so nothing is lost by not unwinding.
pub fn flag() -> Arc<AtomicBool> {
    static FLAG: OnceLock<Arc<AtomicBool>> = OnceLock::new();
    Arc::clone(FLAG.get_or_init(|| {
        let stop = Arc::new(AtomicBool::new(false));
        let raised = Arc::clone(&stop);
        // A handler already set (a test running several commands in one process) keeps its own.
        let _ = ctrlc::set_handler(move || {
            if raised.swap(true, Ordering::SeqCst) {
                std::process::exit(super::EXIT_INTERRUPTED.into());
            }
            eprintln!("\noceanbench: stopping after the current frame (again to quit now)");
        });
        stop
    }))
}
