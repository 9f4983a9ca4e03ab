//! Built-in cases (`signorini run NAME`).

pub mod bar;
pub mod disc;
pub mod file;

/// Reads a Gmsh file, showing on stderr what the reader skipped (also logged as a warning).
pub fn read_mesh(path: &std::path::Path) -> Result<crate::runtime::mesh::Mesh, crate::runtime::mesh::MeshError> {
    let mesh = crate::runtime::mesh::gmsh::read(path)?;
    for w in &mesh.warnings {
        eprintln!("warning: {w}");
    }
    Ok(mesh)
}

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
    /// Newton failed at a step even after `cuts` halvings of Δt.
    #[error(
        "stopped at t = {t} after {cuts} step cuts (Δt = {dt:.3e}): {cause}\n  Newton: {history}\n  results up to the last good step are written; more cuts: --max-step-cuts, or try a smaller Δt"
    )]
    Stopped { t: f64, cuts: usize, dt: f64, cause: String, history: String },
    /// The energy grew past what a stable scheme allows.
    #[error(
        "stopped at t = {t}: the energy ½uᵀKu + ½vᵀMv = {energy:.3e} exceeds {growth} × {bound:.3e} (its initial value plus the work of the loads): the discrete problem is unstable.\n  Params: {params}.\n  Likely causes: Nitsche with γ0 too small for its θ (coercivity), a penalty too stiff for Δt with an explicit contact treatment, Δt beyond a conditionally stable scheme's limit, a contact parameter so large (γ0 or ε ≳ 1e12 × E) that the contact rows' round-off swamps the solve, or degenerate cells. Results up to here are written; --max-energy-growth 0 turns this check off"
    )]
    BlowUp { t: f64, energy: f64, bound: f64, growth: f64, params: String },
    /// SIGINT or SIGTERM.
    #[error("interrupted at t = {t}: results up to there are written")]
    Interrupted { t: f64 },
}
