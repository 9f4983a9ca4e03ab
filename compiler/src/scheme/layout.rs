//! A compiled scheme laid out for a stepper: every scalar it needs numbered in one coefficient
//! array (in first-use order), and its stages, terms and updates referring to those numbers.
//! The generated Rust prints this layout; a scheme interpreted at run time converts it to the
//! runtime's description. One numbering, two backends.

use std::collections::HashMap;

use super::{Affine, Quantity, SchemeIr, Term};
use crate::ir::graph::{Graph, NodeId};

/// `c[unknown]·w + Σ c[k]·level`.
#[derive(Clone, Debug, PartialEq)]
pub struct Combination {
    pub unknown: Option<usize>,
    pub known: Vec<(Quantity, usize)>,
}

/// `c[coef]·slot(args)` at time `c[time]`.
#[derive(Clone, Debug, PartialEq)]
pub struct TermLayout {
    pub coef: usize,
    pub slot: String,
    pub args: Vec<Combination>,
    pub time: usize,
}

#[derive(Clone, Debug, PartialEq)]
pub struct StageLayout {
    pub name: String,
    pub time: usize,
    pub quantities: Vec<String>,
    pub values: Vec<Combination>,
    pub terms: Vec<TermLayout>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Layout {
    /// The graph node of each coefficient.
    pub coefficients: Vec<NodeId>,
    pub initial: Option<(usize, Vec<TermLayout>)>,
    pub stages: Vec<StageLayout>,
}

#[derive(Default)]
struct Numbering {
    index: HashMap<NodeId, usize>,
    order: Vec<NodeId>,
}

impl Numbering {
    fn of(&mut self, n: NodeId) -> usize {
        *self.index.entry(n).or_insert_with(|| {
            self.order.push(n);
            self.order.len() - 1
        })
    }

    fn combination(&mut self, g: &Graph, a: &Affine) -> Combination {
        let unknown = (!g.is_zero(a.unknown)).then(|| self.of(a.unknown));
        Combination { unknown, known: a.known.iter().map(|(q, k)| (*q, self.of(*k))).collect() }
    }

    fn terms(&mut self, g: &Graph, ts: &[Term]) -> Vec<TermLayout> {
        ts.iter()
            .map(|t| {
                let coef = self.of(t.coef);
                let args = t.args.iter().map(|a| self.combination(g, a)).collect();
                let time = self.of(t.time);
                TermLayout { coef, slot: t.form.clone(), args, time }
            })
            .collect()
    }
}

/// The layout of a compiled scheme.
pub fn layout(s: &SchemeIr) -> Layout {
    let g = &s.graph;
    let mut n = Numbering::default();
    let initial = s.initial.as_ref().map(|i| (i.state, n.terms(g, &i.terms)));
    let stages = s
        .stages
        .iter()
        .map(|st| {
            let time = n.of(st.time);
            let values = st.values.iter().map(|v| n.combination(g, v)).collect();
            StageLayout {
                name: st.name.clone(),
                time,
                quantities: st.quantities.clone(),
                values,
                terms: n.terms(g, &st.terms),
            }
        })
        .collect();
    Layout { coefficients: n.order, initial, stages }
}
