//! The compiler's example-based tests, in one binary: snapshots of every stage for the form
//! library, the rendered diagnostics of the bad-input corpus, and the limits on oversized input.

mod forms;
mod limits;
mod ui;
