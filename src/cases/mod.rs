//! Typed views of the library's bar, disc and sphere runs for the report, `verify`, the
//! benchmarks and the tests (the problems themselves are files, run by [`crate::problem::run`]),
//! and case files (`signorini run case.toml`).

pub mod bar;
pub mod disc;
pub mod file;
