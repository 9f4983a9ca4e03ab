//! Automatic differentiation on the DAG: ∂node/∂sym, with the generalised derivative
//! H' = 0, so that pos, neg, min, max and abs (all built from H) get their semi-smooth
//! Newton derivatives by the product rule alone.

use std::collections::HashMap;

use super::graph::{Func, Graph, Node, NodeId, Sym};

/// Partial derivatives of many nodes with respect to one symbol, sharing work.
pub struct Derivative {
    target: Sym,
    memo: HashMap<NodeId, NodeId>,
}

impl Derivative {
    pub fn new(target: Sym) -> Self {
        Derivative { target, memo: HashMap::new() }
    }

    /// ∂root/∂target. Iterative over the reachable nodes (children have smaller ids), so deep
    /// expressions cannot overflow the stack.
    pub fn of(&mut self, g: &mut Graph, root: NodeId) -> NodeId {
        if let Some(&d) = self.memo.get(&root) {
            return d;
        }
        for id in g.reachable([root]) {
            if self.memo.contains_key(&id) {
                continue;
            }
            let d = self.local(g, id);
            self.memo.insert(id, d);
        }
        self.memo[&root]
    }

    fn local(&self, g: &mut Graph, id: NodeId) -> NodeId {
        let d = |x: NodeId| self.memo[&x];
        match g.node(id) {
            Node::Const(_) | Node::Heaviside(_) | Node::Step(_) => g.zero(),
            Node::Sym(s) => {
                if s == self.target {
                    g.one()
                } else {
                    g.zero()
                }
            }
            Node::Add(a, b) => g.add(d(a), d(b)),
            Node::Neg(a) => g.neg(d(a)),
            Node::Mul(a, b) => {
                let l = g.mul(d(a), b);
                let r = g.mul(a, d(b));
                g.add(l, r)
            }
            Node::Div(a, b) => {
                // (a/b)' = (a' - (a/b) b') / b
                let (da, db) = (d(a), d(b));
                if g.is_zero(db) {
                    return g.div(da, b);
                }
                let q = g.mul(id, db);
                let num = g.sub(da, q);
                g.div(num, b)
            }
            Node::Powi(a, k) => {
                let da = d(a);
                if g.is_zero(da) {
                    return g.zero();
                }
                let p = g.powi(a, k - 1);
                let c = g.constant(k as f64);
                let cp = g.mul(c, p);
                g.mul(cp, da)
            }
            Node::Powf(a, p) => {
                let da = d(a);
                if g.is_zero(da) {
                    return g.zero();
                }
                let p = f64::from_bits(p);
                let q = g.powf(a, p - 1.0);
                let c = g.constant(p);
                let cq = g.mul(c, q);
                g.mul(cq, da)
            }
            Node::Sqrt(a) => {
                // da / (2√a) where a > 0, and 0 at a = 0 (where √ has no derivative): written
                // da·H(a) / (2√a + (1 − H(a))), which has the bits of da / (2√a) where a > 0.
                // The size |x| = √(x·x) then has the generalised derivative 0 at x = 0, an
                // element of its Clarke Jacobian (the unit ball), rather than 0/0.
                let da = d(a);
                if g.is_zero(da) {
                    return g.zero();
                }
                let two = g.constant(2.0);
                let den = g.mul(two, id);
                let on = g.step(a);
                let one = g.one();
                let off = g.sub(one, on);
                let den = g.add(den, off);
                let num = g.mul(da, on);
                g.div(num, den)
            }
            Node::Func(f, a) => {
                let da = d(a);
                if g.is_zero(da) {
                    return g.zero();
                }
                func_derivative(g, f, a, id, da)
            }
            Node::Atan2(y, x) => {
                let (dy, dx) = (d(y), d(x));
                if g.is_zero(dy) && g.is_zero(dx) {
                    return g.zero();
                }
                atan2_derivative(g, y, x, dy, dx)
            }
            // The chain rule through the point: Σ_k ∂_k c(p) dp_k.
            Node::CoefAt { id: coef, comp, dirs, point } => {
                let at = g.point(point).to_vec();
                let mut sum = g.zero();
                for (k, &p) in at.iter().enumerate() {
                    let dp = d(p);
                    if g.is_zero(dp) {
                        continue;
                    }
                    // Past `Dirs::MAX` derivatives (no form takes them: `grad` of a gradient
                    // is refused), a NaN that no kernel reads.
                    let dc = match dirs.and(k as u8) {
                        Some(more) => g.coef_at(coef, comp, more, &at),
                        None => g.constant(f64::NAN),
                    };
                    let term = g.mul(dc, dp);
                    sum = g.add(sum, term);
                }
                sum
            }
        }
    }
}

/// d f(a) for f(a) = `fa`, given da ≠ 0: cos a da, −sin a da, da/cos² a, exp a da, da/a.
pub fn func_derivative(g: &mut Graph, f: Func, a: NodeId, fa: NodeId, da: NodeId) -> NodeId {
    match f {
        Func::Sin => {
            let c = g.func(Func::Cos, a);
            g.mul(c, da)
        }
        Func::Cos => {
            let s = g.func(Func::Sin, a);
            let p = g.mul(s, da);
            g.neg(p)
        }
        Func::Tan => {
            let c = g.func(Func::Cos, a);
            let c2 = g.powi(c, 2);
            g.div(da, c2)
        }
        Func::Exp => g.mul(fa, da),
        Func::Ln => g.div(da, a),
    }
}

/// d atan2(y, x) = (x dy − y dx)/(x² + y²).
pub fn atan2_derivative(g: &mut Graph, y: NodeId, x: NodeId, dy: NodeId, dx: NodeId) -> NodeId {
    let l = g.mul(x, dy);
    let r = g.mul(y, dx);
    let num = g.sub(l, r);
    let (x2, y2) = (g.powi(x, 2), g.powi(y, 2));
    let den = g.add(x2, y2);
    g.div(num, den)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn eval(g: &Graph, id: NodeId, x: f64) -> f64 {
        match g.node(id) {
            Node::Const(b) => f64::from_bits(b),
            Node::Sym(_) => x,
            Node::Add(a, b) => eval(g, a, x) + eval(g, b, x),
            Node::Mul(a, b) => eval(g, a, x) * eval(g, b, x),
            Node::Neg(a) => -eval(g, a, x),
            Node::Div(a, b) => eval(g, a, x) / eval(g, b, x),
            Node::Powi(a, k) => eval(g, a, x).powi(k),
            Node::Powf(a, p) => eval(g, a, x).powf(f64::from_bits(p)),
            Node::Sqrt(a) => eval(g, a, x).sqrt(),
            Node::Heaviside(a) | Node::Step(a) => f64::from((eval(g, a, x) > 0.0) as u8),
            Node::Func(f, a) => f.apply(eval(g, a, x)),
            Node::Atan2(a, b) => eval(g, a, x).atan2(eval(g, b, x)),
            Node::CoefAt { .. } => f64::NAN,
        }
    }

    #[test]
    fn derivative_matches_finite_differences() {
        let mut g = Graph::default();
        let s = Sym::Time;
        let x = g.sym(s);
        // f = x^3 / (1 + x^2) + sqrt(x) * (x * H(x - 0.5))
        let x3 = g.powi(x, 3);
        let x2 = g.powi(x, 2);
        let one = g.one();
        let den = g.add(one, x2);
        let q = g.div(x3, den);
        let r = g.sqrt(x);
        let half = g.constant(0.5);
        let xm = g.sub(x, half);
        let h = g.heaviside(xm);
        let p = g.mul(x, h);
        let rp = g.mul(r, p);
        let f = g.add(q, rp);
        let df = Derivative::new(s).of(&mut g, f);
        for &x0 in &[0.3, 0.7, 1.9] {
            let e = 1e-6;
            let fd = (eval(&g, f, x0 + e) - eval(&g, f, x0 - e)) / (2.0 * e);
            assert!((eval(&g, df, x0) - fd).abs() < 1e-8, "x = {x0}");
        }
    }
}
