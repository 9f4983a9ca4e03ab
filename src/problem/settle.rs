//! `initial u = settled(GUESS)`: a body that starts at rest on its obstacle, from the static
//! equilibrium with the loads and the obstacle at the start time; and, when there is none,
//! what Newton saw and what it means for the law in use.

use super::ProblemFile;
use crate::driver::FilesInUse;
use crate::error::CaseError;
use crate::runtime::fem::assembly::Assembler;

/// The contact region `settled(GUESS)` rests on (none when the bodies rest on each other through
/// the problem's pairs), after the checks that it can: a contact region or a pair, and
/// Dirichlet values that are zero at the start (they are held at zero while settling).
pub(super) fn contact<'p>(
    pf: &ProblemFile,
    contact: Option<&'p str>,
    pairs: bool,
    held_nonzero: bool,
) -> Result<Option<&'p str>, CaseError> {
    let why = |what: &str| CaseError::Settle(format!("{}: `initial u = settled(...)` {what}", pf.file));
    if contact.is_none() && !pairs {
        return Err(why("needs the problem's contact (an obstacle, `Gamma_C` or a contact pair) to rest on"));
    }
    if held_nonzero {
        return Err(why(
            "holds the Dirichlet values at zero: a value held away from zero at the start needs an initial u of its own",
        ));
    }
    Ok(contact)
}

/// `initial u = settled(GUESS)`: the equilibrium K u + C(u) = F, by the static driver (its loads
/// and obstacle at the start time) from the guess (which a frictional law's `prev` reads: the
/// stick holds the body where the guess put it, along the obstacle). Newton backtracks on ‖R‖
/// there: a full step from a shallow guess can lift a free body off the obstacle, where its
/// stiffness is singular (a disc of h = 0.05 settling did).
pub(super) fn settle(
    pf: &ProblemFile,
    asm: &Assembler,
    problem: crate::simulation::statics::StaticProblem,
    in_use: &FilesInUse,
    guess: Vec<f64>,
) -> Result<Vec<f64>, CaseError> {
    let newton = crate::runtime::nonlinear::newton::NewtonOptions { line_search: true, ..problem.newton };
    let problem = crate::simulation::statics::StaticProblem { newton, ..problem };
    let solution = crate::simulation::statics::solve(asm, problem, &in_use.forms, guess)
        .map_err(|e| unsettled(pf, e, frictional(&in_use.forms)))?;
    Ok(solution.u)
}

/// Whether a contact law in use has friction (it provides `friction_work`).
fn frictional(forms: &crate::driver::FormsInUse) -> bool {
    forms.contact_units().into_iter().any(|i| forms.units[i].slots().iter().any(|s| &*s.name == "friction_work"))
}

/// Why `settled` found no equilibrium: Newton's residuals and active points, and what a
/// singular or non-converging equilibrium means for this law.
fn unsettled(pf: &ProblemFile, e: CaseError, frictional: bool) -> CaseError {
    use crate::runtime::nonlinear::newton::NewtonError;
    let CaseError::Newton(newton) = &e else {
        return CaseError::Settle(format!("{}: `initial u = settled(...)` did not settle: {e}", pf.file));
    };
    let report = newton.report();
    let active = report.history.last().map_or(0, |it| it.active);
    let cause = match (newton, frictional) {
        (NewtonError::Linear { .. }, _) => format!(
            "the equilibrium's tangent is singular at an iterate with {active} active contact point(s): they do not hold the body in every direction (it can pivot about them or slide along the obstacle)"
        ),
        (_, false) => {
            "a frictionless body free to slide along the obstacle has no equilibrium to settle in".to_string()
        }
        (_, true) => "the frictional stick did not hold the body: the load along the obstacle may exceed the friction"
            .to_string(),
    };
    let help = if frictional {
        "press the guess in further so that more of the contact region starts active, or hold the body with a pin (`dirichlet nearest(POINT): u[0] = 0`)"
    } else {
        "hold the body (a pin: `dirichlet nearest(POINT): u[0] = 0`), or give it friction"
    };
    CaseError::Settle(format!(
        "{}: `initial u = settled(...)` did not settle: {newton}\n  Newton: {}\n  {cause}; {help}",
        pf.file,
        report.describe()
    ))
}
