//! Why a run did not run or did not finish: the one error type of the facade, from a bad option
//! or file to a step that failed, an energy that grew, an interrupt. Every layer returns it (the
//! driver, the simulation, problems, the cases, `verify`, the report); its messages are what the
//! command line prints.

/// Why a run did not run, or stopped.
#[derive(Debug, thiserror::Error)]
pub enum CaseError {
    #[error("invalid option: {0}")]
    Option(String),
    /// A form that takes tangential parts (a frictional law) bound on a 1D mesh, located.
    #[error("{0}")]
    NoTangentSpace(String),
    /// A case file problem, with file and line.
    #[error("{0}")]
    CaseFile(String),
    /// A .wf file that does not check (or a problem's line its binding refuses): the
    /// diagnostics rendered as the compiler prints them, and located.
    #[error("{}", .0.rendered.trim_end())]
    Wf(crate::compiler::Failure),
    /// Files that check but lack what a run needs of them (a nonlinear stiffness without its
    /// stored energy).
    #[error("the files in use: {0}")]
    Incomplete(String),
    /// A static equilibrium Newton did not reach, with where it went wrong (an inverted cell).
    #[error("{0}")]
    Diverged(String),
    /// `initial u = settled(...)` found no equilibrium: what Newton saw, and why it may be.
    #[error("{0}")]
    Settle(String),
    #[error(transparent)]
    Mesh(#[from] crate::runtime::fem::mesh::MeshError),
    #[error(transparent)]
    Newton(#[from] crate::runtime::nonlinear::newton::NewtonError),
    #[error("time stepping failed: {0}")]
    Step(#[from] crate::runtime::time::stepper::StepError),
    #[error("cannot write {path}: {source}")]
    Write { path: String, source: std::io::Error },
    /// Newton failed at a step even after `cuts` halvings of Δt.
    #[error(
        "stopped at t = {at} after {cuts} step cuts (Δt = {dt:.3e}): {cause}\n{history}  results up to the last good step are written; more cuts: --max-step-cuts, or try a smaller Δt",
        at = at(.t)
    )]
    Stopped { t: f64, cuts: usize, dt: f64, cause: String, history: String },
    /// An adaptive run's step control needed a step below its minimum.
    #[error(
        "stopped at t = {at}: the step size control needs Δt = {dt:.3e}, below the minimum {dt_min:.3e}: {cause}\n  results up to the last accepted step are written; a larger --adaptive tolerance, or a smaller --dt-min",
        at = at(.t)
    )]
    StepTooSmall { t: f64, dt: f64, dt_min: f64, cause: String },
    /// A step failed in a way no smaller Δt mends.
    #[error("stopped at t = {at}: {cause}\n  results up to the last good step are written", at = at(.t))]
    Failed { t: f64, cause: String },
    /// The energy grew past what a stable scheme allows.
    #[error(
        "stopped at t = {at}: the energy E_aug = W(u) + ½vᵀMv + contact energy = {energy:.6e} (W the stored energy: ½uᵀKu for a linear material) exceeds E_aug(0) + the work of the loads = {bound:.6e} by {} % of the problem's energy scale {scale:.4e} (the largest of |E_aug(0)|, the work and the kinetic energy reached); the tolerance is {} %{law}: the discrete problem is unstable.\n  Params: {params}.\n  Likely causes: Δt beyond a conditionally stable scheme's limit (an explicit scheme, an explicit contact term), Nitsche with γ0 too small for its θ (coercivity), a penalty too stiff for Δt, a contact parameter so large (γ0 or ε ≳ 1e12 × E) that the contact rows' round-off swamps the solve, or degenerate cells. Results up to the last good step are written; --energy-tolerance sets the tolerance (0 turns this check off)",
        percent(100.0 * (energy - bound) / scale),
        percent(100.0 * tolerance),
        at = at(.t)
    )]
    BlowUp { t: f64, energy: f64, bound: f64, scale: f64, tolerance: f64, law: String, params: String },
    /// The potential energy went negative: the contact law is not coercive for its params.
    #[error(
        "stopped at t = {at}: the potential energy W(u) + contact energy = {potential:.6e} is negative, beyond {} % of the problem's energy scale {scale:.4e}: the discrete problem is not stable. Most likely the contact law is not coercive for these params (Nitsche θ = 1 or 0 with γ0 too small against the material's stiffness; θ = −1 is coercive for any γ0), and the motion grows without bound while E_aug is kept; otherwise the steps' solutions diverge (an iterative solve that is not accurate enough: try --solver direct).\n  Params: {params}.\n  Results up to the last good step are written; --energy-tolerance 0 turns this check off",
        percent(100.0 * tolerance),
        at = at(.t)
    )]
    NotCoercive { t: f64, potential: f64, scale: f64, tolerance: f64, params: String },
    /// The contact law's own work outgrew the energy from outside.
    #[error(
        "stopped at t = {at}: the contact law's own work (the part of the law the energy does not keep, `contact_work`: Nitsche with θ ≠ 1) = {work:.6e} exceeds the energy that came from outside, {outside:.6e} (the largest of |E_aug(0)| and the loads' work): the law drives the motion, which grows without bound (γ0 far too small for θ ≠ 1).\n  Params: {params}.\n  Results up to the last good step are written; --energy-tolerance 0 turns this check off",
        at = at(.t)
    )]
    LawWork { t: f64, work: f64, outside: f64, params: String },
    /// An explicit scheme asked to step beyond its critical step.
    #[error(
        "Δt = {dt} is beyond the stable step of scheme `{scheme}`: Δt_c ≈ {stable:.6e} = cfl {cfl} / ω_max {omega_max:.6e}, with ω_max² the largest eigenvalue of M⁻¹(K + the contact stiffness; {active} of {points} contact points active), {mass} mass, estimated by power iteration. Use --dt {stable:.3e} or smaller (a lumped mass raises Δt_c over a consistent one; a smaller γ0 lowers the contact's stiffness), or --allow-unstable-dt to run it anyway (the energy guard still watches)"
    )]
    UnstableStep {
        dt: f64,
        scheme: String,
        stable: f64,
        cfl: f64,
        omega_max: f64,
        active: usize,
        points: usize,
        mass: String,
    },
    /// An explicit scheme's step beyond the critical step of the current tangent: a
    /// finite-strain material stiffened along the run.
    #[error(
        "stopped at t = {at}: Δt = {dt} is now beyond the stable step of scheme `{scheme}`: Δt_c ≈ {stable:.6e} = cfl {cfl} / ω_max {omega_max:.6e}, with ω_max² the largest eigenvalue of M⁻¹(K_T(u) + the contact stiffness) at this state, K_T the material's tangent, which has stiffened (Δt_c is {initial:.6e} for the body at rest, u = 0). Results up to here are written; use --dt {stable:.3e} or smaller, or --allow-unstable-dt to run it anyway (the energy guard still watches)",
        at = at(.t)
    )]
    Stiffened { t: f64, dt: f64, scheme: String, stable: f64, cfl: f64, omega_max: f64, initial: f64 },
    /// SIGINT or SIGTERM.
    #[error("interrupted at t = {at}: results up to there are written", at = at(.t))]
    Interrupted { t: f64 },
}

/// A percentage in a message: one decimal, or two significant digits below 0.1 % (a tolerance
/// of 1e-7 % is not "0.0 %").
fn percent(x: f64) -> String {
    if x == 0.0 || x.abs() >= 0.1 || !x.is_finite() { format!("{x:.1}") } else { format!("{x:.1e}") }
}

/// A time in a message: six significant digits (`t = 4.475`, not `4.4750000000000005`).
fn at(t: &f64) -> String {
    crate::numbers::readable(*t)
}
