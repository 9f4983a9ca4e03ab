//! A scheme's `claim energy = …` checked by its derived identity at the params' defaults: a
//! claim the identity refutes is E0821, with the identity's term that refutes it; a claim no
//! identity can be derived for is the warning W0007, with what blocks the derivation. A claim
//! the identity does not decide (a kept energy that is not E, dissipated) passes: `verify
//! --scheme` still samples it.

use super::classify::{Identity, Proof};
use super::print::Printer;
use crate::check::EnergyLaw;
use crate::diagnostic::Diagnostic;
use crate::scheme::ir::SchemeIr;
use crate::source::Span;

/// The error of `ir`'s claim `law` at `span` if the identity refutes it, the warning if none is
/// derived.
pub fn check(ir: &SchemeIr, law: EnergyLaw, span: Span) -> Option<Diagnostic> {
    let id = match Identity::derive(ir) {
        Ok(id) => id,
        Err(e) => {
            return Some(
                Diagnostic::warning(
                    "W0007",
                    format!("the claim `energy = {}` cannot be proved", law.name()),
                    span,
                    format!("no energy identity: {}", super::why(ir, &e)),
                )
                .with_note("`signorini verify --scheme` still samples it on the oscillator"),
            );
        }
    };
    let printer = Printer::new(ir, &id);
    let defaults: Vec<f64> = ir.params.iter().map(|p| p.default).collect();
    let why = match id.proves(law, &defaults, &|s| printer.described(s)) {
        Ok(Proof::Fails(why)) => why,
        Ok(Proof::Holds | Proof::Undecided(_)) | Err(_) => return None,
    };
    let at: Vec<String> = ir.params.iter().map(|p| format!("{} = {}", p.name, p.default)).collect();
    let at = if at.is_empty() { String::new() } else { format!(" at {}", at.join(", ")) };
    Some(
        Diagnostic::error(
            "E0821",
            format!("the claim `energy = {}` is refuted by the scheme's energy identity{at}", law.name()),
            span,
            why,
        )
        .with_note(format!("the identity: {}", printer.summary()))
        .with_help(
            "`signorini emit` this file with `--stage energy` for the identity over the params' ranges; \
             claim what it proves, or drop the claim",
        ),
    )
}

/// The energy law a run at `params` holds `ir` to, from its claim `claimed`: the claim where the
/// identity proves it or does not decide it there; where it refutes it, the law it proves
/// instead (Newmark claims `conserving` at its defaults and dissipates with gam > 1/2), or none.
pub fn law_at(ir: &SchemeIr, claimed: EnergyLaw, params: &[f64]) -> Option<EnergyLaw> {
    law_by(Identity::derive(ir).ok().as_ref(), claimed, params)
}

/// As [`law_at`], from the scheme's identity already derived (none: there is none).
pub fn law_by(id: Option<&Identity>, claimed: EnergyLaw, params: &[f64]) -> Option<EnergyLaw> {
    let Some(id) = id else { return Some(claimed) };
    let shown = |_: &super::classify::Square| String::new();
    match id.proves(claimed, params, &shown) {
        Ok(Proof::Holds | Proof::Undecided(_)) | Err(_) => Some(claimed),
        Ok(Proof::Fails(_)) => {
            EnergyLaw::ALL.into_iter().find(|&law| law != claimed && id.proves(law, params, &shown) == Ok(Proof::Holds))
        }
    }
}

/// What the identity says of `law` at `params`, in a sentence: proved, refuted (why),
/// undecided (why), or why there is no identity.
pub fn verdict(ir: &SchemeIr, law: EnergyLaw, params: &[f64]) -> String {
    let id = match Identity::derive(ir) {
        Ok(id) => id,
        Err(e) => return format!("no energy identity: {}", super::why(ir, &e)),
    };
    let printer = Printer::new(ir, &id);
    match id.proves(law, params, &|s| printer.described(s)) {
        Ok(Proof::Holds) => "proved".into(),
        Ok(Proof::Fails(why)) => format!("refuted: {why}"),
        Ok(Proof::Undecided(why)) => format!("undecided: {why}"),
        Err(_) => "undecided: the exact coefficients overflow".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Newmark claims `conserving` at β = ¼, γ = ½; a run at γ = 0.6 is held to `dissipative`
    /// where β = γ/2 proves it, and to no law where β = ¼ makes D indefinite.
    #[test]
    fn a_run_is_held_to_the_law_its_params_prove() {
        let (_, ir) = super::super::library_schemes().into_iter().find(|(n, _)| n == "newmark").unwrap();
        let claimed = ir.energy.expect("newmark claims an energy law");
        assert_eq!(law_at(&ir, claimed, &[0.25, 0.5]), Some(EnergyLaw::Conserving));
        assert_eq!(law_at(&ir, claimed, &[0.3, 0.6]), Some(EnergyLaw::Dissipative));
        assert_eq!(law_at(&ir, claimed, &[0.25, 0.6]), None);
    }

    /// A Newmark-like step whose γ is `gam`, claiming `law`: the check's diagnostics.
    fn checked(gam: &str, law: &str) -> Vec<crate::diagnostic::Diagnostic> {
        let text = format!(
            "scheme probe(beta = 1/4 in (0, 1/2]) {{
  uses mass, stiffness, load
  state u, v, a
  claim energy = {law}
  let gam = {gam}
  initial a: mass(a) + stiffness(u) == load(t)
  unknown u'
  relate u' = u + dt*v + dt^2/2*((1 - gam)*a + gam*a')
  relate v' = v + dt*((1 - gam)*a + gam*a')
  residual mass(a') + stiffness(u') == load(t + dt)
}}
"
        );
        match crate::check_text(std::path::Path::new("probe.wf"), &text, &crate::MemLoader::default()) {
            Ok(p) => p.warnings.clone(),
            Err((d, _)) => d,
        }
    }

    /// Claims the identity cannot settle pass (a coefficient whose sign changes with dt at the
    /// defaults) or warn (one that depends on t); claims it refutes are errors; none is proved
    /// from a few samples of dt.
    #[test]
    fn what_depends_on_dt_or_t_is_never_proved() {
        // D = (dt − 2)(dt − 3)‖Δu‖²_K: negative for dt in (2, 3), so not proved, not refuted.
        assert!(checked("1/2 + (dt - 2)*(dt - 3)", "dissipative").is_empty());
        // D = t²‖Δu‖²_K: no identity for coefficients that change with t.
        let d = checked("1/2 + t^2", "conserving");
        assert!(d.len() == 1 && d[0].code == "W0007", "{d:?}");
        // γ = 0.6 at every dt: refuted.
        let d = checked("0.6", "conserving");
        assert!(d.len() == 1 && d[0].code == "E0821", "{d:?}");
    }
}
