//! Standard output and standard error for every command: the one writer. A closed stdout (the
//! reader left: `placewords run … | head`) is not an error: output stops quietly and the command
//! finishes its other work and exits with its own code, as ripgrep does. Any other write error
//! is returned. Messages on a closed stderr are dropped (there is nowhere left to say so); the
//! exit code still tells.

use std::io::{ErrorKind, Write};
use std::sync::atomic::{AtomicBool, Ordering};

/// Set once stdout has been found closed; later output is dropped.
static CLOSED: AtomicBool = AtomicBool::new(false);

/// Writes `args` to stdout (use through `out!` / `outln!`).
pub fn write(args: std::fmt::Arguments) -> std::io::Result<()> {
    if CLOSED.load(Ordering::Relaxed) {
        return Ok(());
    }
    let mut stdout = std::io::stdout().lock();
    match stdout.write_fmt(args).and_then(|()| stdout.flush()) {
        Err(e) if e.kind() == ErrorKind::BrokenPipe => {
            CLOSED.store(true, Ordering::Relaxed);
            Ok(())
        }
        r => r,
    }
}

/// Writes `args` to stderr, dropping them when stderr is closed or full (use through `errln!`):
/// `eprintln!` would panic.
pub fn write_err(args: std::fmt::Arguments) {
    let mut stderr = std::io::stderr().lock();
    let _ = stderr.write_fmt(args).and_then(|()| stderr.flush());
}
