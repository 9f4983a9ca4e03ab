//! Ctrl-C during a run: Python's SIGINT handler only records the signal, and runs when asked
//! (`check_signals`). The run asks at the end of each step, where the command line looks at
//! SIGINT ([`signorini::interrupt::set_poll`]), and stops there; the KeyboardInterrupt is kept
//! to be raised with the run so far.

use std::sync::Mutex;

use pyo3::prelude::*;

static RAISED: Mutex<Option<PyErr>> = Mutex::new(None);

/// Whether Python saw a signal whose handler raised (KeyboardInterrupt), which is then kept.
pub fn poll() -> bool {
    Python::attach(|py| match py.check_signals() {
        Ok(()) => false,
        Err(e) => {
            *RAISED.lock().unwrap_or_else(|p| p.into_inner()) = Some(e);
            true
        }
    })
}

/// The exception a signal raised during the run, if one did.
pub fn take() -> Option<PyErr> {
    RAISED.lock().unwrap_or_else(|p| p.into_inner()).take()
}
