//! A lowered value read at another time level (`prev`) or on the facing surface of a contact
//! pair (`opposite`), and the node-by-node map they and `derivative` share.

use super::{Jet, Lowerer, Val};
use crate::ir::graph::{Dirs, Facing, Graph, NodeId, Sym};

impl Lowerer<'_> {
    /// `a` with every field argument, value and gradient, read at the previous time level: the
    /// form's field `previous`.
    /// A seed of a `derivative` being lowered is 0 there: the previous level does not vary with
    /// the unknown.
    pub(super) fn previous_level(&mut self, a: &Val, previous: u8) -> Val {
        let map = |g: &mut Graph, s: Sym| match s {
            Sym::Field { comp, .. } => Some(g.sym(Sym::Field { arg: previous, comp })),
            Sym::FieldGrad { comp, dir, .. } => Some(g.sym(Sym::FieldGrad { arg: previous, comp, dir })),
            Sym::Opposite(Facing::Field { comp, .. }) => {
                Some(g.sym(Sym::Opposite(Facing::Field { arg: previous, comp })))
            }
            Sym::Opposite(Facing::FieldGrad { comp, dir, .. }) => {
                Some(g.sym(Sym::Opposite(Facing::FieldGrad { arg: previous, comp, dir })))
            }
            Sym::Seed(_) => Some(g.zero()),
            _ => None,
        };
        self.map_nodes(a, |g, x| g.replace(x, &map))
    }

    /// `a` read on the facing surface of a contact pair: every leaf of the own side (fields,
    /// test function, normal, point, cell size) by the facing one, and every coef at the facing
    /// point. Params, the time and a derivative's seeds are the same on both sides; a leaf read
    /// there already stays (`opposite(opposite(u))` is `opposite(u)`: the facing side's facing
    /// point is not searched).
    pub(super) fn opposite_side(&mut self, a: &Val) -> Val {
        let d = self.d;
        let map = |g: &mut Graph, s: Sym| match s {
            Sym::Coef { id, comp } => {
                let at: Vec<NodeId> = (0..d).map(|k| g.sym(Sym::Opposite(Facing::Coord(k as u8)))).collect();
                Some(g.coef_at(id, comp, Dirs::default(), &at))
            }
            s => s.facing().map(|f| g.sym(Sym::Opposite(f))),
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
