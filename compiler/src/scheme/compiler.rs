//! The compiler of one scheme: its declarations (parameters, slots, states, lets) into names
//! of the coefficient graph, then its initial problem and stages, each state's update, the
//! slots it applies and its claims. The rules of its names and slots are `check::schemes`'s.

use std::collections::HashMap;

use super::affine::{Affine, Quantity};
use super::ir::{SchemeIr, SlotUse, StageIr};
use crate::check::schemes::{self, Applications, Claim};
use crate::check::{EnergyLaw, SchemeDef, SchemeParamInfo, Unit};
use crate::diagnostic::Diagnostic;
use crate::ir::graph::{Graph, NodeId, Sym};
use crate::syntax::ast::{Expr, Ident};

/// A scheme's `claim energy`: the law, and where it is written.
type EnergyClaim = (EnergyLaw, crate::source::Span);

/// What a name means inside a scheme.
#[derive(Clone, Debug)]
pub(super) enum Value {
    Scalar(NodeId),
    Vector(Affine),
}

pub(super) struct Compiler<'a> {
    pub(super) prog: &'a Unit,
    pub(super) def: &'a SchemeDef,
    pub(super) g: Graph,
    pub(super) params: Vec<SchemeParamInfo>,
    /// Errors of this scheme.
    pub(super) diags: Vec<Diagnostic>,
    pub(super) warnings: &'a mut Vec<Diagnostic>,
    /// Names visible in the current stage: scalars and known or new vectors.
    pub(super) scope: HashMap<String, Value>,
    /// Quantities of the stage being compiled, in index order (the unknown first).
    pub(super) new: Vec<String>,
    pub(super) stage_index: usize,
    /// How the slots have been applied so far.
    pub(super) applied: Applications,
}

impl<'a> Compiler<'a> {
    pub(super) fn new(prog: &'a Unit, def: &'a SchemeDef, warnings: &'a mut Vec<Diagnostic>) -> Self {
        Compiler {
            prog,
            def,
            g: Graph::default(),
            params: Vec::new(),
            diags: Vec::new(),
            warnings,
            scope: HashMap::new(),
            new: Vec::new(),
            stage_index: 0,
            applied: Applications::new(def),
        }
    }

    pub(super) fn error(&mut self, d: Diagnostic) {
        self.diags.push(d);
    }

    pub(super) fn run(mut self) -> Result<SchemeIr, Vec<Diagnostic>> {
        let def = self.def;
        if !self.declarations() {
            return Err(self.diags);
        }
        let initial = def.initial.as_ref().and_then(|i| self.initial(i));
        let stages = self.stages();
        let updates = self.updates(&stages);
        let estimate = if self.diags.is_empty() { self.estimate() } else { None };
        schemes::initial_values(def, self.warnings, &mut self.diags);
        let complete = self.diags.is_empty();
        let slots = self
            .applied
            .applied(def, complete, &mut self.diags)
            .into_iter()
            .map(|(u, fields)| SlotUse { name: u.name.clone(), fields, span: u.span })
            .collect();
        let (claims, energy) = self.claims();
        if !self.diags.is_empty() {
            return Err(self.diags);
        }
        let ir = SchemeIr {
            name: def.name.name.clone(),
            span: def.span,
            params: self.params,
            slots,
            states: def.states.iter().map(|s| s.name.clone()).collect(),
            graph: self.g,
            initial,
            stages,
            updates,
            estimate,
            claims,
            energy: energy.map(|(law, _)| law),
        };
        if let Some((law, span)) = energy
            && let Some(d) = super::energy::claim::check(&ir, law, span)
        {
            if d.is_error() {
                return Err(vec![d]);
            }
            self.warnings.push(d);
        }
        Ok(ir)
    }

    /// The parameters, the `uses` line, the states and the scheme's lets: their names in
    /// scope. `false` when one of them is wrong (the stages are not compiled then).
    fn declarations(&mut self) -> bool {
        let def = self.def;
        self.params = schemes::params(self.prog, def, &mut self.diags);
        for (i, p) in def.params.iter().enumerate() {
            let node = self.g.sym(Sym::Param(i as u16));
            self.g.name(node, &p.name.name);
            self.scope.insert(p.name.name.clone(), Value::Scalar(node));
        }
        schemes::uses(def, &mut self.diags);
        let dt = self.g.sym(Sym::Dt);
        let t = self.g.sym(Sym::Time);
        self.scope.insert("dt".into(), Value::Scalar(dt));
        self.scope.insert("t".into(), Value::Scalar(t));
        let pi = self.g.constant(std::f64::consts::PI);
        self.scope.insert("pi".into(), Value::Scalar(pi));
        if !schemes::states(def, &mut self.diags) {
            return false;
        }
        for (i, s) in def.states.iter().enumerate() {
            self.scope.insert(s.name.clone(), Value::Vector(Affine::known(&mut self.g, Quantity::State(i))));
        }
        for (name, value) in &def.lets {
            self.bind_let(name, value);
        }
        self.diags.is_empty()
    }

    /// A `let` of the scheme or of a stage: a scalar, named in the graph.
    pub(super) fn bind_let(&mut self, name: &Ident, value: &Expr) {
        if let Some(w) = schemes::let_hides(self.prog, self.def, name) {
            self.warnings.push(w);
        }
        if let Some(v) = self.value(value) {
            match v {
                Value::Scalar(n) => {
                    self.g.name(n, &name.name);
                    self.scope.insert(name.name.clone(), Value::Scalar(n));
                }
                Value::Vector(_) => self.error(
                    Diagnostic::error(
                        "E0807",
                        "a scheme `let` must be a scalar",
                        value.span,
                        "this is a combination of time levels",
                    )
                    .with_help("introduce a new quantity with `relate NAME = ...` instead"),
                ),
            }
        }
    }

    /// Every stage that compiles; a scheme without any is E0805.
    fn stages(&mut self) -> Vec<StageIr> {
        let def = self.def;
        let mut stages = Vec::new();
        for (s, stage) in def.stages.iter().enumerate() {
            self.stage_index = s;
            if let Some(ir) = self.stage(stage) {
                stages.push(ir);
            }
        }
        if stages.is_empty() && self.diags.is_empty() {
            self.error(Diagnostic::error(
                "E0805",
                format!("scheme `{}` has no stage", def.name.name),
                def.name.span,
                "no unknown, relations or residual",
            ));
        }
        stages
    }

    /// Each state's value at the end of the step: its primed quantity in the last stage
    /// (E0806 without one).
    fn updates(&mut self, stages: &[StageIr]) -> Vec<Quantity> {
        let def = self.def;
        let mut updates = Vec::new();
        let Some(last) = stages.last() else { return updates };
        for s in &def.states {
            let primed = format!("{}'", s.name);
            match last.quantities.iter().position(|q| *q == primed) {
                Some(index) => updates.push(Quantity::Stage { stage: stages.len() - 1, index }),
                None => {
                    let last = def.stages.last().and_then(|s| s.name.as_ref().map(|n| n.span)).unwrap_or(def.name.span);
                    self.error(
                        Diagnostic::error(
                            "E0806",
                            format!("state `{}` gets no new value", s.name),
                            s.span,
                            format!("declared here, but there is no `{primed}` in the last stage"),
                        )
                        .with_label(last, "the last stage")
                        .with_help(format!("relate `{primed}` to the other quantities, or make it the unknown")),
                    );
                }
            }
        }
        updates
    }

    /// `estimate EXPR`: one per scheme (E0823), a combination of the step's levels (E0824)
    /// that reads at least one quantity the step computes (E0825), compiled in the scope the
    /// last stage leaves: the states at the step's start and every stage's quantities.
    fn estimate(&mut self) -> Option<Affine> {
        let def = self.def;
        let (first, rest) = def.estimates.split_first()?;
        if let Some(second) = rest.first() {
            self.error(
                Diagnostic::error("E0823", "a scheme has one `estimate`", second.span, "a second estimate")
                    .with_label(first.span, "the first")
                    .with_help("combine them into one expression of the step's levels"),
            );
            return None;
        }
        match self.value(first)? {
            Value::Scalar(_) => {
                self.error(
                    Diagnostic::error(
                        "E0824",
                        "an estimate is a combination of the step's levels",
                        first.span,
                        "this is a scalar",
                    )
                    .with_help(
                        "e.g. `estimate dt^2*(beta - 1/6)*(a' - a)`: the local error of u' (Zienkiewicz and Xie)",
                    ),
                );
                None
            }
            Value::Vector(a) if a.known.iter().all(|(q, _)| matches!(q, Quantity::State(_))) => {
                let states: Vec<String> = def.states.iter().map(|s| format!("`{}'`", s.name)).collect();
                self.error(
                    Diagnostic::error(
                        "E0825",
                        "the estimate reads nothing the step computes",
                        first.span,
                        "only the states at the step's start",
                    )
                    .with_help(format!(
                        "a local error compares the step's new levels ({}, a stage's quantities) with each other or with the start",
                        states.join(", ")
                    )),
                );
                None
            }
            Value::Vector(a) => Some(a),
        }
    }

    /// `claim NAME = EXPR`: a known property, a scalar of the params (not of t or dt); and
    /// `claim energy = LAW`.
    fn claims(&mut self) -> (Vec<(String, NodeId)>, Option<EnergyClaim>) {
        let mut out: Vec<(String, NodeId)> = Vec::new();
        let mut energy = None;
        for i in 0..self.def.claims.len() {
            let e = match schemes::claim(self.def, i) {
                Err(d) => {
                    self.error(*d);
                    continue;
                }
                Ok(Claim::Energy(law)) => {
                    energy = Some((law, self.def.claims[i].1.span));
                    continue;
                }
                Ok(Claim::Value(e)) => e,
            };
            match self.value(e) {
                Some(Value::Scalar(n)) if !self.g.depends_on(n, |s| matches!(s, Sym::Time | Sym::Dt)) => {
                    out.push((self.def.claims[i].0.name.clone(), n))
                }
                Some(_) => self.error(Diagnostic::error(
                    "E0819",
                    "a claim is a number or a function of the scheme's parameters",
                    e.span,
                    "not a function of the parameters alone",
                )),
                None => {}
            }
        }
        (out, energy)
    }
}
