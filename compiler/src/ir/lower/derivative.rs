//! `derivative(e, u, d)`: the Gateaux derivative of `e` with respect to `u` in the direction
//! `d` (UFL's `derivative`), lowered in forward mode: `e` is lowered with `u` bound to u + s·d
//! for a fresh seed s, differentiated in s, and read at s = 0. `u` may be a field or a
//! function's argument bound to any expression (`derivative(pn(w), w, v)` called at a midpoint).

use super::{Jet, Lowerer, Res, Val};
use crate::ir::derive::Derivative;
use crate::ir::graph::{Graph, Sym};
use crate::syntax::ast::{Expr, ExprKind};

impl Lowerer<'_> {
    pub(super) fn derivative(&mut self, args: &[Expr]) -> Res<Val> {
        let ExprKind::Name(varied) = &args[1].kind else {
            unreachable!("the checker allows only a name as what `derivative` varies")
        };
        let at = self.expr(&args[1])?;
        let direction = self.expr(&args[2])?;
        let seed = Sym::Seed(self.seeds);
        let s = Jet { v: self.g.sym(seed), g: self.zero_grad() };
        let c =
            at.c.iter()
                .zip(&direction.c)
                .map(|(a, d)| {
                    let sd = self.jmul(&s, d);
                    self.jadd(a, &sd)
                })
                .collect();
        self.scope.push((varied.name.clone(), Val { shape: at.shape, c }));
        self.seeds += 1;
        let value = self.expr(&args[0]);
        self.seeds -= 1;
        self.scope.pop();
        let mut ds = Derivative::new(seed);
        let at_zero = |g: &mut Graph, x: Sym| (x == seed).then(|| g.zero());
        Ok(self.map_nodes(&value?, |g, x| {
            let dx = ds.of(g, x);
            g.replace(dx, &at_zero)
        }))
    }
}
