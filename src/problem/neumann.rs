//! A problem's loads on regions (`neumann REGION: t = EXPR`, a traction; `p = EXPR`, a
//! pressure, the traction −p n): one form file the run writes, whose `load` integrates each
//! over its region and adds to the material's `load` (a slot two files provide is their sum),
//! so the scheme applies it at its time levels and the energy guard counts its work as any
//! load's. Each value is a coef of the problem, a function of `x` and `t`.

use super::ProblemFile;

/// The coef that carries load `k`'s value.
pub fn coef(k: usize) -> String {
    format!("neumann_{k}")
}

/// The form file of the problem's loads, as (name, text); none without `neumann` lines.
pub fn forms(pf: &ProblemFile) -> Option<(String, String)> {
    let loads = &pf.problem().neumann;
    if loads.is_empty() {
        return None;
    }
    let mut text = format!("// The loads of problem `{}` on its regions (its `neumann` lines).\n", pf.name());
    let mut terms = Vec::new();
    for (k, b) in loads.iter().enumerate() {
        let (c, region) = (coef(k), &b.region.name);
        if b.kind.name == "p" {
            text.push_str(&format!("coef {c}\n"));
            terms.push(format!("int({region}) -{c}*dot(n, v)"));
        } else {
            text.push_str(&format!("coef {c}: vector\n"));
            terms.push(format!("int({region}) dot({c}, v)"));
        }
    }
    text.push_str(&format!("form load(; v) = {}\n", terms.join(" + ")));
    Some((format!("{}_neumann.wf", pf.name()), text))
}
