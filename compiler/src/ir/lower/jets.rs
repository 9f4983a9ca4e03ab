//! Scalar operations on jets: a value and its spatial gradient together (forward mode), each
//! gradient component by the chain rule of the operation.

use super::{Jet, Lowerer, Val};
use crate::ir::derive::{atan2_derivative, func_derivative};
use crate::ir::graph::{Func, Graph, NodeId};

impl Lowerer<'_> {
    pub(super) fn grads(
        &mut self,
        a: &Jet,
        b: &Jet,
        f: impl Fn(&mut Graph, NodeId, NodeId) -> NodeId,
    ) -> Option<Vec<NodeId>> {
        let (ga, gb) = (a.g.as_ref()?, b.g.as_ref()?);
        Some(ga.iter().zip(gb).map(|(&x, &y)| f(&mut self.g, x, y)).collect())
    }

    pub(super) fn jadd(&mut self, a: &Jet, b: &Jet) -> Jet {
        let v = self.g.add(a.v, b.v);
        let g = self.grads(a, b, |g, x, y| g.add(x, y));
        Jet { v, g }
    }

    pub(super) fn jsub(&mut self, a: &Jet, b: &Jet) -> Jet {
        let v = self.g.sub(a.v, b.v);
        let g = self.grads(a, b, |g, x, y| g.sub(x, y));
        Jet { v, g }
    }

    pub(super) fn jneg(&mut self, a: &Jet) -> Jet {
        let v = self.g.neg(a.v);
        let g = a.g.as_ref().map(|ga| ga.iter().map(|&x| self.g.neg(x)).collect());
        Jet { v, g }
    }

    pub(super) fn jmul(&mut self, a: &Jet, b: &Jet) -> Jet {
        let v = self.g.mul(a.v, b.v);
        let (av, bv) = (a.v, b.v);
        let g = self.grads(a, b, |g, x, y| {
            let l = g.mul(x, bv);
            let r = g.mul(av, y);
            g.add(l, r)
        });
        Jet { v, g }
    }

    pub(super) fn jdiv(&mut self, a: &Jet, b: &Jet) -> Jet {
        let v = self.g.div(a.v, b.v);
        let bv = b.v;
        let g = self.grads(a, b, |g, x, y| {
            // (a/b)' = (a' − (a/b)·b') / b
            let q = g.mul(v, y);
            let num = g.sub(x, q);
            g.div(num, bv)
        });
        Jet { v, g }
    }

    pub(super) fn jpowi(&mut self, a: &Jet, k: i32) -> Jet {
        let v = self.g.powi(a.v, k);
        let g = a.g.as_ref().map(|ga| {
            let p = self.g.powi(a.v, k - 1);
            let c = self.g.constant(k as f64);
            let cp = self.g.mul(c, p);
            ga.iter().map(|&x| self.g.mul(cp, x)).collect()
        });
        Jet { v, g }
    }

    pub(super) fn jpowf(&mut self, a: &Jet, p: f64) -> Jet {
        let v = self.g.powf(a.v, p);
        let g = a.g.as_ref().map(|ga| {
            let q = self.g.powf(a.v, p - 1.0);
            let c = self.g.constant(p);
            let cq = self.g.mul(c, q);
            ga.iter().map(|&x| if self.g.is_zero(x) { x } else { self.g.mul(cq, x) }).collect()
        });
        Jet { v, g }
    }

    pub(super) fn jsqrt(&mut self, a: &Jet) -> Jet {
        let v = self.g.sqrt(a.v);
        let g = a.g.as_ref().map(|ga| {
            let two = self.g.constant(2.0);
            let den = self.g.mul(two, v);
            // A constant's gradient is zero even where the root is (sqrt(0)), not 0/0.
            ga.iter().map(|&x| if self.g.is_zero(x) { x } else { self.g.div(x, den) }).collect()
        });
        Jet { v, g }
    }

    /// The Euclidean (Frobenius) size of a vector (tensor).
    pub(super) fn jnorm(&mut self, a: &Val) -> Jet {
        let square = self.jinner(a, a);
        self.jsqrt(&square)
    }

    /// The full contraction Σ aᵢ bᵢ, summed in component order.
    pub(super) fn jinner(&mut self, a: &Val, b: &Val) -> Jet {
        let mut acc = self.constant(0.0);
        for (x, y) in a.c.iter().zip(&b.c) {
            let p = self.jmul(x, y);
            acc = self.jadd(&acc, &p);
        }
        acc
    }

    /// sin, cos, tan, exp or ln of a scalar: the gradient by the chain rule with the
    /// derivative the tangent takes (`derive::func_derivative`).
    pub(super) fn jfunc(&mut self, f: Func, a: &Jet) -> Jet {
        let v = self.g.func(f, a.v);
        let g = a.g.as_ref().map(|ga| {
            ga.iter().map(|&x| if self.g.is_zero(x) { x } else { func_derivative(&mut self.g, f, a.v, v, x) }).collect()
        });
        Jet { v, g }
    }

    /// atan2(y, x), its gradient (x ∇y − y ∇x)/(x² + y²).
    pub(super) fn jatan2(&mut self, y: &Jet, x: &Jet) -> Jet {
        let v = self.g.atan2(y.v, x.v);
        let (yv, xv) = (y.v, x.v);
        let g = self.grads(y, x, |g, dy, dx| {
            if g.is_zero(dy) && g.is_zero(dx) { g.zero() } else { atan2_derivative(g, yv, xv, dy, dx) }
        });
        Jet { v, g }
    }

    /// H as a built-in's inner step: not a switch (see `Node::Step`).
    pub(super) fn jstep(&mut self, a: &Jet) -> Jet {
        let v = self.g.step(a.v);
        Jet { v, g: self.zero_grad() }
    }

    pub(super) fn jheaviside(&mut self, a: &Jet) -> Jet {
        let v = self.g.heaviside(a.v);
        Jet { v, g: self.zero_grad() }
    }
}
