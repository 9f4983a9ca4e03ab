//! A stage, and the initial problem: the stage's lets and time, its new quantities (the
//! unknown, the relations' left-hand sides, `new` names and the primed levels the relations
//! introduce), its relations as equations, their elimination, and its residual with every new
//! quantity in terms of the unknown.

use super::affine::{Affine, Quantity};
use super::compiler::{Compiler, Value};
use super::elimination::Equation;
use super::ir::{InitialIr, StageIr, Term};
use crate::check::schemes;
use crate::diagnostic::Diagnostic;
use crate::ir::graph::{NodeId, Sym};
use crate::syntax::ast::{self, Expr, ExprKind, Ident};

impl Compiler<'_> {
    pub(super) fn initial(&mut self, init: &ast::Initial) -> Option<InitialIr> {
        let state = match schemes::initial_state(self.def, init) {
            Ok(s) => s,
            Err(d) => {
                self.error(*d);
                return None;
            }
        };
        let saved = self.scope.clone();
        // Within the initial problem the state is the unknown.
        self.new = vec![init.unknown.name.clone()];
        let unknown = Affine::unknown(&mut self.g);
        self.scope.insert(init.unknown.name.clone(), Value::Vector(unknown));
        let time = self.g.sym(Sym::Time);
        let terms = self.residual(&init.residual, time);
        self.scope = saved;
        let terms = terms?;
        if !self.applies_unknown(&terms) {
            self.error(Diagnostic::error(
                "E0809",
                "the initial residual does not depend on its unknown",
                init.residual.span,
                format!("no form is applied to `{}`", init.unknown.name),
            ));
            return None;
        }
        Some(InitialIr { state, terms })
    }

    /// Whether a form is applied to a level containing the unknown.
    fn applies_unknown(&self, terms: &[Term]) -> bool {
        terms.iter().any(|t| t.args.iter().any(|a| !self.g.is_zero(a.unknown)))
    }

    pub(super) fn stage(&mut self, st: &ast::Stage) -> Option<StageIr> {
        let name = st.name.as_ref().map_or_else(|| format!("stage{}", self.stage_index + 1), |n| n.name.clone());
        let (unknown, residual) = self.stage_parts(st, &name)?;
        let saved = self.scope.clone();
        for (n, v) in &st.lets {
            self.bind_let(n, v);
        }
        // A wrong stage time ends the stage with its lets still in scope.
        let time = self.stage_time(st, &name)?;
        self.new_quantities(st, unknown);
        let n_new = self.new.len();
        for (i, q) in self.new.clone().iter().enumerate() {
            let v = if i == 0 { Affine::unknown(&mut self.g) } else { Affine::new_quantity(&mut self.g, i) };
            self.scope.insert(q.clone(), Value::Vector(v));
        }
        let equations = self.equations(st);
        if !self.diags.is_empty() {
            self.scope = saved;
            return None;
        }
        if equations.len() + 1 != n_new {
            self.missing_relations(st, unknown, &name, equations.len());
            self.scope = saved;
            return None;
        }
        let Some(values) = self.eliminate(equations, n_new) else {
            self.scope = saved;
            return None;
        };
        for (i, q) in self.new.clone().iter().enumerate() {
            self.scope.insert(q.clone(), Value::Vector(values[i].clone()));
        }
        let terms = self.residual(residual, time);
        let quantities = self.new.clone();
        self.scope = saved;
        let terms = terms?;
        if !self.applies_unknown(&terms) {
            self.error(Diagnostic::error(
                "E0809",
                "the residual does not depend on the unknown",
                residual.span,
                format!("no form is applied to a level containing `{}`", unknown.name),
            ));
            return None;
        }
        // Later stages see this stage's quantities as known values.
        for (i, q) in quantities.iter().enumerate() {
            let v = Affine::known(&mut self.g, Quantity::Stage { stage: self.stage_index, index: i });
            self.scope.insert(q.clone(), Value::Vector(v));
        }
        Some(StageIr { name, time, quantities, values, terms })
    }

    /// The stage's unknown and residual (E0805 without either).
    fn stage_parts<'s>(&mut self, st: &'s ast::Stage, name: &str) -> Option<(&'s Ident, &'s ast::Residual)> {
        let at_span = st.span.unwrap_or(self.def.name.span);
        let Some(unknown) = &st.unknown else {
            self.error(
                Diagnostic::error("E0805", format!("stage `{name}` has no unknown"), at_span, "no `unknown` line")
                    .with_help(format!(
                        "`unknown {}'` names the quantity Newton solves for",
                        self.def.states.first().map_or("u", |s| s.name.as_str())
                    )),
            );
            return None;
        };
        let Some(residual) = &st.residual else {
            self.error(Diagnostic::error(
                "E0805",
                format!("stage `{name}` has no residual"),
                at_span,
                "no `residual ... == ...` line",
            ));
            return None;
        };
        Some((unknown, residual))
    }

    /// The stage's time: `at EXPR`, a scalar finite over the parameter ranges (E0301, E0818),
    /// or t + dt.
    fn stage_time(&mut self, st: &ast::Stage, name: &str) -> Option<NodeId> {
        let time = match &st.at {
            Some(e) => match self.value(e) {
                Some(Value::Scalar(n)) => n,
                Some(Value::Vector(_)) => {
                    self.error(Diagnostic::error(
                        "E0301",
                        "a stage time must be a scalar",
                        e.span,
                        "a combination of time levels",
                    ));
                    return None;
                }
                None => return None,
            },
            None => {
                let (t, dt) = (self.g.sym(Sym::Time), self.g.sym(Sym::Dt));
                self.g.add(t, dt)
            }
        };
        if let (Some(e), Some(at)) = (&st.at, self.not_finite_at(time)) {
            self.error(
                Diagnostic::error("E0818", format!("the time of stage `{name}` is not finite"), e.span, at)
                    .with_help("a stage time is t plus a finite multiple of dt for every parameter value in range"),
            );
            return None;
        }
        Some(time)
    }

    /// The stage's new quantities in `self.new`: the unknown, the relations' left-hand sides,
    /// the `new` names, and the new levels their right-hand sides introduce (E0810 for a name
    /// related twice or already known).
    fn new_quantities(&mut self, st: &ast::Stage, unknown: &Ident) {
        self.new = vec![unknown.name.clone()];
        for r in &st.relates {
            if r.name.name == unknown.name {
                // A relation for the unknown determines one of the other new quantities.
                continue;
            }
            if self.new.contains(&r.name.name) {
                self.error(
                    Diagnostic::error(
                        "E0810",
                        format!("`{}` is related twice", r.name.name),
                        r.name.span,
                        "second relation",
                    )
                    .with_help("one relation per new quantity"),
                );
            } else if self.scope.contains_key(&r.name.name) {
                self.error(Diagnostic::error(
                    "E0810",
                    format!("`{}` is already known", r.name.name),
                    r.name.span,
                    "cannot be related here",
                ));
            } else {
                self.new.push(r.name.name.clone());
            }
        }
        for n in &st.news {
            if st.relates.iter().any(|r| r.name.name == n.name && r.name.name != unknown.name) {
                // Declared and related: new either way.
                continue;
            }
            if self.new.contains(&n.name) || self.scope.contains_key(&n.name) {
                self.error(Diagnostic::error(
                    "E0810",
                    format!("`{}` is already a quantity of this stage or a name of the scheme", n.name),
                    n.span,
                    "declared again here",
                ));
            } else {
                self.new.push(n.name.clone());
            }
        }
        for r in &st.relates {
            self.collect_new_names(&r.value);
        }
    }

    /// The relations as equations lhs − rhs = 0, affine in the new quantities (E0301 for a
    /// scalar right-hand side).
    fn equations(&mut self, st: &ast::Stage) -> Vec<Equation> {
        let mut equations = Vec::new();
        for r in &st.relates {
            let Some(Value::Vector(lhs)) = self.scope.get(&r.name.name).cloned() else {
                continue;
            };
            match self.value(&r.value) {
                Some(Value::Vector(rhs)) => {
                    let eq = lhs.sub(&mut self.g, &rhs);
                    let own = self.new.iter().position(|q| *q == r.name.name);
                    equations.push(Equation { eq, span: r.span, own });
                }
                Some(Value::Scalar(_)) => self.error(
                    Diagnostic::error(
                        "E0301",
                        "a relation must give a combination of time levels",
                        r.value.span,
                        "this is a scalar",
                    )
                    .with_label(r.name.span, "a vector quantity"),
                ),
                None => {}
            }
        }
        equations
    }

    /// E0811: fewer relations than new quantities besides the unknown.
    fn missing_relations(&mut self, st: &ast::Stage, unknown: &Ident, name: &str, relations: usize) {
        let n_new = self.new.len();
        let missing: Vec<String> =
            self.new[1..].iter().filter(|q| !st.relates.iter().any(|r| r.name.name == **q)).cloned().collect();
        self.error(
            Diagnostic::error(
                "E0811",
                format!(
                    "stage `{name}` has {} new quantities besides its unknown but {relations} relations",
                    n_new - 1
                ),
                st.name.as_ref().map_or(unknown.span, |n| n.span),
                "the relations do not determine the new quantities",
            )
            .with_note(format!("quantities without a relation: {}", missing.join(", "))),
        );
    }

    /// The new level `s'` of a state `s` on a right-hand side is a new quantity (`a'` in
    /// Newmark's relations). Every other name must be declared (a state, a param, a `let`, the
    /// unknown, a relation's left-hand side or a `new` quantity): an unknown one is an error
    /// with the closest names, reported when the relation is evaluated.
    fn collect_new_names(&mut self, e: &Expr) {
        match &e.kind {
            ExprKind::Name(id) => {
                if !self.scope.contains_key(&id.name)
                    && !self.new.contains(&id.name)
                    && schemes::is_new_level(self.def, &id.name)
                    && schemes::may_be_quantity(self.prog, &id.name)
                {
                    self.new.push(id.name.clone());
                }
            }
            ExprKind::Call(_, args) => args.iter().for_each(|a| self.collect_new_names(a)),
            ExprKind::Neg(a) => self.collect_new_names(a),
            ExprKind::Binary(_, a, b) | ExprKind::Index(a, b) => {
                self.collect_new_names(a);
                self.collect_new_names(b);
            }
            ExprKind::Vector(items) => items.iter().for_each(|a| self.collect_new_names(a)),
            ExprKind::Number(_) => {}
        }
    }

    /// The names a scheme's expression may use here, for "did you mean".
    pub(super) fn visible_names(&self) -> Vec<String> {
        let mut names: Vec<String> = self.scope.keys().cloned().collect();
        names.extend(self.new.iter().cloned());
        names.extend(self.def.states.iter().map(|s| format!("{}'", s.name)));
        names.extend(self.def.uses.iter().map(|u| u.name.clone()));
        names.sort();
        names.dedup();
        names
    }
}
