//! Time schemes: per stage, the affine relations between time levels are solved for the new
//! quantities other than the unknown, and the residual becomes a sum of forms applied to affine
//! combinations `α·unknown + Σ βₖ·knownₖ`, whose tangent is Σ coef·α·(form tangent).
//!
//! Scalars (parameters, lets, dt, t) live in one coefficient DAG; the generated stepper
//! evaluates it for a given dt. A pivot of the elimination is checked not to vanish anywhere in
//! the declared parameter ranges (by sampling them, with dt > 0).
//!
//! Modules, in the order a scheme goes through them: `compiler` (declarations, then each
//! stage), `values` (expressions as scalars or level combinations), `stage` (new quantities and
//! relations), `elimination` and `pivots` (solving the relations), `residual` (slot
//! applications); `affine` and `ir` are what they build, `layout`, `print` and `simplify` what
//! reads the result.

mod affine;
mod compiler;
mod elimination;
pub mod energy;
mod ir;
pub mod layout;
mod pivots;
pub mod print;
mod rational;
mod residual;
pub mod simplify;
mod stage;
mod values;

pub use affine::{Affine, Quantity, eval_all, scheme_leaf};
pub use ir::{InitialIr, SchemeIr, SlotUse, StageIr, Term};

use crate::check::Unit;
pub use crate::check::{CLAIMS, EnergyLaw, SchemeDef, SchemeParamInfo};
use crate::diagnostic::Diagnostic;

/// Compiles the schemes `defs` of `prog`; errors and warnings go to `diags`.
pub fn compile(prog: &Unit, defs: &[&SchemeDef], diags: &mut Vec<Diagnostic>) -> Vec<SchemeIr> {
    let mut out = Vec::new();
    for d in defs {
        let mut warnings = Vec::new();
        let result = compiler::Compiler::new(prog, d, &mut warnings).run();
        diags.append(&mut warnings);
        match result {
            Ok(ir) => out.push(ir),
            Err(mut e) => diags.append(&mut e),
        }
    }
    out
}
