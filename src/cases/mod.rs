//! Built-in cases (`signorini run NAME`).

pub mod bar;
pub mod disc;
pub mod exact;
pub mod file;
pub mod hertz;
pub mod static_block;

/// Why a case did not run.
#[derive(Debug, thiserror::Error)]
pub enum CaseError {
    #[error("invalid option: {0}")]
    Option(String),
    /// A case file problem, with file and line.
    #[error("{0}")]
    CaseFile(String),
    #[error(transparent)]
    Mesh(#[from] crate::runtime::mesh::MeshError),
    #[error(transparent)]
    Newton(#[from] crate::runtime::newton::NewtonError),
    #[error("time stepping failed: {0}")]
    Step(#[from] crate::runtime::scheme::StepError),
    #[error("cannot write {path}: {source}")]
    Write { path: String, source: std::io::Error },
}
