//! A lowered value read at another time level (`prev`), and the node-by-node map it and
//! `derivative` share.

use super::{Jet, Lowerer, Val};
use crate::ir::graph::{Graph, NodeId, Sym};

impl Lowerer<'_> {
    /// `a` with every field argument, value and gradient, read at the previous time level: the
    /// form's field `previous`.
    /// A seed of a `derivative` being lowered is 0 there: the previous level does not vary with
    /// the unknown.
    pub(super) fn previous_level(&mut self, a: &Val, previous: u8) -> Val {
        let map = |g: &mut Graph, s: Sym| match s {
            Sym::Field { comp, .. } => Some(g.sym(Sym::Field { arg: previous, comp })),
            Sym::FieldGrad { comp, dir, .. } => Some(g.sym(Sym::FieldGrad { arg: previous, comp, dir })),
            Sym::Seed(_) => Some(g.zero()),
            _ => None,
        };
        self.map_nodes(a, |g, x| g.replace(x, &map))
    }

    /// `a` with `f` applied to every node of its components, values and gradients.
    pub(super) fn map_nodes(&mut self, a: &Val, mut f: impl FnMut(&mut Graph, NodeId) -> NodeId) -> Val {
        let c =
            a.c.iter()
                .map(|j| Jet {
                    v: f(&mut self.g, j.v),
                    g: j.g.as_ref().map(|g| g.iter().map(|&x| f(&mut self.g, x)).collect()),
                })
                .collect();
        Val { shape: a.shape, c }
    }
}
