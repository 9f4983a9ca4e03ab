//! `signorini bench ...`: timings with medians of repeated runs, written as JSON.

pub mod adaptive;
pub mod assemble;
pub mod balls;
pub mod bandwidth;
pub mod disc;
pub mod search;
pub mod sphere;

pub use assemble::assemble;

use std::path::Path;
use std::process::Command;

use crate::error::CaseError;

/// Runs `command` (a `run` of this binary writing to `out`) and reads the summary.json it
/// wrote; `what` names the run in the error of a run that failed.
fn run_summary(command: &mut Command, what: &str, out: &Path) -> Result<serde_json::Value, CaseError> {
    let ran = command
        .output()
        .map_err(|e| CaseError::Option(format!("cannot run {}: {e}", command.get_program().to_string_lossy())))?;
    if !ran.status.success() {
        return Err(CaseError::Option(format!("{what} failed: {}", String::from_utf8_lossy(&ran.stderr).trim())));
    }
    let path = out.join("summary.json");
    let text = std::fs::read_to_string(&path)
        .map_err(|source| CaseError::Write { path: path.display().to_string(), source })?;
    serde_json::from_str(&text).map_err(|e| CaseError::Option(format!("{}: {e}", path.display())))
}
