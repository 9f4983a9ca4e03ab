//! A coef read at a point of the form's own (`g(x + u)`: contact on the deformed configuration).

use super::{Jet, Lowerer, Val, components};
use crate::ir::graph::NodeId;

impl Lowerer<'_> {
    /// Coef `id` at the point `at`, with the chain rule's gradient Σ_k ∂_k c(p) ∇p_k where the
    /// point has one.
    pub(super) fn coef_at(&mut self, id: u16, at: &Val) -> Val {
        use crate::ir::graph::Dirs;
        let d = self.d;
        let shape = self.prog.coefs[id as usize].shape;
        let point: Vec<NodeId> = at.c.iter().map(|j| j.v).collect();
        let grads: Option<Vec<&Vec<NodeId>>> = at.c.iter().map(|j| j.g.as_ref()).collect();
        let c = (0..components(shape, d))
            .map(|comp| {
                let v = self.g.coef_at(id, comp as u8, Dirs::default(), &point);
                let g = grads.as_ref().map(|grads| {
                    (0..d)
                        .map(|l| {
                            let mut sum = self.g.zero();
                            for (k, gp) in grads.iter().enumerate() {
                                let dirs = Dirs::default().and(k as u8).expect("one derivative");
                                let dc = self.g.coef_at(id, comp as u8, dirs, &point);
                                let term = self.g.mul(dc, gp[l]);
                                sum = self.g.add(sum, term);
                            }
                            sum
                        })
                        .collect()
                });
                Jet { v, g }
            })
            .collect();
        Val { shape, c }
    }
}
