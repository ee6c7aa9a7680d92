//! Standard output for the commands. A closed stdout (the reader left: `placewords run … | head`)
//! is not an error: output stops quietly and the command finishes its other work and exits 0,
//! as ripgrep does. Any other write error is returned.

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
