//! What the binary's exit status says, shared by the commands that return it and the docs that
//! quote it.

/// Exit status of a failure while running, or of a regression `compare` found.
pub const EXIT_FAILED: u8 = 1;
/// Exit status of bad input: a config, a flag, a results file or a block.
pub const EXIT_BAD_INPUT: u8 = 2;
/// Exit status of a command stopped by Ctrl-C or SIGTERM.
pub const EXIT_INTERRUPTED: u8 = 130;
