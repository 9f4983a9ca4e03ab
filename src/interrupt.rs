//! SIGINT and SIGTERM: the first asks the run to stop after its current step (it then writes
//! its results up to there and exits with [`EXIT_CODE`]); a second one ends the process at once.

use std::sync::OnceLock;
use std::sync::atomic::{AtomicBool, Ordering};

/// The exit status of an interrupted run (128 + SIGINT, as shells report it).
pub const EXIT_CODE: u8 = 130;

static REQUESTED: AtomicBool = AtomicBool::new(false);

/// A host's own check for a stop (Python's signal handlers, which run only when asked).
static POLL: OnceLock<fn() -> bool> = OnceLock::new();

extern "C" fn on_signal(signal: libc::c_int) {
    REQUESTED.store(true, Ordering::SeqCst);
    // SAFETY: signal() is async-signal-safe; the next such signal takes the default action.
    unsafe {
        libc::signal(signal, libc::SIG_DFL);
    }
}

/// Installs the handlers (once, at start-up).
pub fn install() {
    #[cfg(unix)]
    // SAFETY: the handler only stores to an atomic and resets its own disposition.
    unsafe {
        libc::signal(libc::SIGINT, on_signal as *const () as libc::sighandler_t);
        libc::signal(libc::SIGTERM, on_signal as *const () as libc::sighandler_t);
    }
}

/// Whether a stop was asked for (here, or to the host's [`set_poll`] check).
pub fn requested() -> bool {
    if !REQUESTED.load(Ordering::SeqCst) && POLL.get().is_some_and(|poll| poll()) {
        REQUESTED.store(true, Ordering::SeqCst);
    }
    REQUESTED.load(Ordering::SeqCst)
}

/// Has [`requested`] ask `poll` too: a host that handles SIGINT itself (Python) says there
/// whether one came. The first call counts.
pub fn set_poll(poll: fn() -> bool) {
    let _ = POLL.set(poll);
}

/// Whether a stop was asked for on any process of the run (collective: the processes of an MPI
/// run stop after the same step, though the signal may reach them one by one).
pub fn agreed() -> Result<bool, crate::runtime::linalg::LinalgError> {
    let any = crate::runtime::linalg::ranks::any(requested())?;
    if any {
        REQUESTED.store(true, Ordering::SeqCst);
    }
    Ok(any)
}

/// Asks the run to stop after its current step, as SIGINT does (a host's watcher of the rows).
pub fn request() {
    REQUESTED.store(true, Ordering::SeqCst);
}

/// Forgets a stop asked for: a host that runs again in the same process starts afresh.
pub fn clear() {
    REQUESTED.store(false, Ordering::SeqCst);
}
