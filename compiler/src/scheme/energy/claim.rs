//! A scheme's `claim energy = …` checked by its derived identity at the params' defaults: a
//! claim the identity refutes is E0821, with the identity's term that refutes it; a claim no
//! identity can be derived for is E0822, with what blocks the derivation. A claim the identity
//! does not decide (a kept energy that is not E, dissipated) passes: `verify --scheme` still
//! samples it.

use super::classify::{Identity, Proof};
use super::print::Printer;
use crate::check::EnergyLaw;
use crate::diagnostic::Diagnostic;
use crate::scheme::ir::SchemeIr;
use crate::source::Span;

/// The error of `ir`'s claim `law` at `span`, if the identity refutes it or none is derived.
pub fn check(ir: &SchemeIr, law: EnergyLaw, span: Span) -> Option<Diagnostic> {
    let id = match Identity::derive(ir) {
        Ok(id) => id,
        Err(e) => {
            return Some(
                Diagnostic::error(
                    "E0822",
                    format!("the claim `energy = {}` cannot be proved", law.name()),
                    span,
                    format!("no energy identity: {}", super::why(ir, &e)),
                )
                .with_help("remove the claim, or write the step so that its relations are rational in the params"),
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
