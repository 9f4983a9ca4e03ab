//! A compiled scheme laid out for a stepper: every scalar it needs numbered in one coefficient
//! array (in first-use order), and its description for the runtime (`SchemeDesc`: stages,
//! terms and updates referring to those numbers). Generated Rust prints the description; a
//! scheme interpreted at run time runs with it as built. One numbering, one description.

use std::collections::HashMap;

use signorini_descriptors::{Combination, InitialDesc, List, SchemeDesc, SlotUse, StageDesc, TermDesc};

use super::{Affine, SchemeIr, Term};
use crate::ir::graph::{Graph, NodeId};
use crate::source::SourceMap;

/// A compiled scheme's description, and what it does not say: the graph node of each of its
/// coefficients.
#[derive(Clone, Debug, PartialEq)]
pub struct Layout {
    pub desc: SchemeDesc,
    /// `desc.coefficients` nodes, in the coefficient array's order.
    pub coefficients: Vec<NodeId>,
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
        Combination { unknown, known: a.known.iter().map(|(q, k)| ((*q).into(), self.of(*k))).collect() }
    }

    fn terms(&mut self, g: &Graph, ts: &[Term]) -> List<TermDesc> {
        ts.iter()
            .map(|t| {
                let coef = self.of(t.coef);
                let args = t.args.iter().map(|a| self.combination(g, a)).collect();
                let time = self.of(t.time);
                TermDesc { coef, form: t.form.clone().into(), args, time }
            })
            .collect()
    }
}

/// The layout of a compiled scheme (`sources`: where its `uses` line is).
pub fn layout(s: &SchemeIr, sources: &SourceMap) -> Layout {
    let g = &s.graph;
    let mut n = Numbering::default();
    let initial = s.initial.as_ref().map(|i| InitialDesc { state: i.state, terms: n.terms(g, &i.terms) });
    let stages = s
        .stages
        .iter()
        .map(|st| {
            let time = n.of(st.time);
            let values = st.values.iter().map(|v| n.combination(g, v)).collect();
            StageDesc {
                name: st.name.clone().into(),
                time,
                quantities: st.quantities.iter().map(|q| q.clone().into()).collect(),
                values,
                terms: n.terms(g, &st.terms),
            }
        })
        .collect();
    let uses = s
        .slots
        .iter()
        .map(|u| SlotUse {
            name: u.name.clone().into(),
            fields: u.fields,
            declared: crate::docs::location_col(sources, u.span).into(),
        })
        .collect();
    let desc = SchemeDesc {
        name: s.name.clone().into(),
        uses,
        states: s.states.iter().map(|x| x.clone().into()).collect(),
        initial,
        stages,
        updates: s.updates.iter().map(|&q| q.into()).collect(),
        coefficients: n.order.len(),
    };
    Layout { desc, coefficients: n.order }
}
