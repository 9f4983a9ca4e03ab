//! A compiled scheme: per stage, its new quantities as affine combinations of the unknown and
//! the known levels, and its residual as a list of terms `coef · slot(levels)`, every scalar a
//! node of the scheme's coefficient graph.

use super::affine::{self, Affine, Quantity};
use crate::check::{EnergyLaw, SchemeParamInfo};
use crate::ir::graph::{Graph, NodeId};
use crate::source::Span;

/// A slot the scheme applies: a form of a case's files, bound by name.
#[derive(Clone, Debug)]
pub struct SlotUse {
    pub name: String,
    /// Time levels it is applied to; 0 for a load (applied to a time).
    pub fields: usize,
    /// Its name in the `uses` line.
    pub span: Span,
}

/// One form application in a residual: `coef · form(args)` at time `time`.
#[derive(Clone, Debug)]
pub struct Term {
    pub coef: NodeId,
    pub form: String,
    /// Field arguments (empty for loads).
    pub args: Vec<Affine>,
    /// When the form is evaluated.
    pub time: NodeId,
}

#[derive(Clone, Debug)]
pub struct StageIr {
    pub name: String,
    pub time: NodeId,
    /// Names of the stage's new quantities; the unknown is first.
    pub quantities: Vec<String>,
    /// Each new quantity in terms of the unknown and the known quantities.
    pub values: Vec<Affine>,
    /// Residual = Σ terms (the right-hand side moved over with a minus sign).
    pub terms: Vec<Term>,
}

#[derive(Clone, Debug)]
pub struct InitialIr {
    /// The state solved for at the start.
    pub state: usize,
    pub terms: Vec<Term>,
}

#[derive(Clone, Debug)]
pub struct SchemeIr {
    pub name: String,
    /// The declaration (for its doc comment and location).
    pub span: Span,
    pub params: Vec<SchemeParamInfo>,
    /// The slots it applies, in `uses` order.
    pub slots: Vec<SlotUse>,
    pub states: Vec<String>,
    pub graph: Graph,
    pub initial: Option<InitialIr>,
    pub stages: Vec<StageIr>,
    /// For each state, the quantity holding its value at the end of the step.
    pub updates: Vec<Quantity>,
    /// `estimate EXPR`: the step's local error as a combination of its levels (the states at
    /// its start and every stage's quantities), for an adaptive run's step control.
    pub estimate: Option<Affine>,
    /// The author's claims (`claim order = 2`): name and value, a function of the params.
    pub claims: Vec<(String, NodeId)>,
    /// `claim energy = conserving | dissipative`: the energy law the run's guard applies.
    pub energy: Option<EnergyLaw>,
}

impl SchemeIr {
    /// The claims' values at these param values (in `params` order).
    pub fn claims_at(&self, params: &[f64]) -> Vec<(String, f64)> {
        self.claims
            .iter()
            .map(|(name, node)| (name.clone(), affine::eval(&self.graph, *node, params, 1.0, 0.0)))
            .collect()
    }
}
