//! Gaussian elimination of a stage's new quantities other than the unknown: each relation,
//! in order, is solved for a quantity it involves that the relations before it left open (its
//! own left-hand side when it can), after a check that the pivot cannot vanish.

use super::affine::Affine;
use super::compiler::Compiler;
use crate::diagnostic::Diagnostic;
use crate::source::Span;

/// A relation `lhs − rhs = 0`.
#[derive(Clone)]
pub(super) struct Equation {
    pub eq: Affine,
    /// The relation (`relate NAME = ...`).
    pub span: Span,
    /// The new quantity on its left-hand side.
    pub own: Option<usize>,
}

impl Compiler<'_> {
    /// Every new quantity (`n_new` of them, the unknown first) in terms of the unknown and the
    /// known levels; `None` after E0812 (a relation that determines nothing) or E0802 (a pivot
    /// that can vanish).
    pub(super) fn eliminate(&mut self, equations: Vec<Equation>, n_new: usize) -> Option<Vec<Affine>> {
        let mut solved: Vec<Option<Affine>> = vec![None; n_new];
        solved[0] = Some(Affine::unknown(&mut self.g));
        let mut pending = equations;
        while let Some(Equation { eq, span, own }) = pending.first().cloned() {
            pending.remove(0);
            let candidates: Vec<usize> = (1..n_new).filter(|&q| solved[q].is_none() && eq.has_new(q)).collect();
            let pivot = own.filter(|o| candidates.contains(o)).or_else(|| candidates.first().copied());
            let Some(q) = pivot else {
                self.determines_nothing(&solved, span);
                return None;
            };
            let c = eq.new_coef(&mut self.g, q);
            if let Err(why) = self.check_pivot(c) {
                self.error(
                    Diagnostic::error(
                        "E0802",
                        format!("solving this relation for `{}` divides by a coefficient that can vanish", self.new[q]),
                        span,
                        why,
                    )
                    .with_help("restrict the parameter range, or relate the quantities differently"),
                );
                return None;
            }
            // q = −(eq − c·q)/c
            let value = eq.solve_for(&mut self.g, q);
            for other in pending.iter_mut() {
                other.eq = other.eq.substitute(&mut self.g, q, &value);
            }
            for s in solved.iter_mut().flatten() {
                *s = s.substitute(&mut self.g, q, &value);
            }
            solved[q] = Some(value);
        }
        Some(solved.into_iter().map(|v| v.expect("every quantity solved")).collect())
    }

    /// E0812: the relation at `span` involves no quantity still open.
    fn determines_nothing(&mut self, solved: &[Option<Affine>], span: Span) {
        let open: Vec<String> =
            (1..solved.len()).filter(|&q| solved[q].is_none()).map(|q| format!("`{}`", self.new[q])).collect();
        self.error(
            Diagnostic::error(
                "E0812",
                "this relation determines no new quantity",
                span,
                "it involves no quantity the relations before it leave open",
            )
            .with_note(format!("still undetermined: {}", open.join(", ")))
            .with_help("each relation must involve a new quantity not yet given by the others"),
        );
    }
}
