//! A normal form for scheme coefficients, and the simplification of a compiled scheme through it.
//!
//! An expression is a sum of terms `q · Π aᵢ^eᵢ`: `q` an exact rational (i128 over i128), the
//! `aᵢ` atoms with nonzero integer exponents. Atoms are the parameters, dt, t, constants that are
//! no small rational (π), and the irreducible subexpressions: `sqrt(E)`, `H(E)`, and sums of two
//! or more terms that are multiplied by other sums, raised to a power or divided by. A sum atom
//! is stored primitive: common factors pulled out, integer coprime coefficients, the first term
//! positive, so that `1 - gs`, `-gs + 1` and `(2 - 2*gs)/2` are one atom.
//!
//! Products of a single term and a sum are distributed (this keeps the cancellation structure
//! of the sum); products and powers of sums are not expanded (`(1 - gs)^2` stays one factor:
//! expanding it would cancel catastrophically near gs = 1). Like terms combine, constants fold
//! exactly, and exponents add, so `x·x⁻¹` cancels. Cancelling assumes the cancelled factor is
//! nonzero: the result is exact wherever the original expression is defined (the compiler
//! checks that every pivot of the elimination keeps away from zero over the parameter ranges).
//!
//! Rebuilding a node from the normal form puts the user's `let`s back where a factor of a term
//! is (a power of) one of them, so that the printed scheme and the generated code read like the
//! source. Any overflow of the rationals, or any node outside scheme arithmetic, leaves the
//! original node in place.

mod normal;
use super::rational;
mod rebuild;
#[cfg(test)]
mod tests;

use std::collections::HashMap;

use normal::Normalizer;
pub use rational::GiveUp;
use rebuild::Builder;

use super::{InitialIr, SchemeIr, StageIr};
use crate::ir::graph::{Graph, Node, NodeId, Sym};

/// Simplifies coefficient nodes of one graph, sharing the normal forms of common subexpressions.
pub struct Simplifier {
    norm: Normalizer,
    builder: Builder,
    done: HashMap<NodeId, NodeId>,
}

impl Simplifier {
    pub fn new(g: &Graph) -> Simplifier {
        let mut norm = Normalizer::default();
        let builder = Builder::new(g, &mut norm);
        Simplifier { norm, builder, done: HashMap::new() }
    }

    /// The simplified node, or `id` itself when the simplification gives up.
    pub fn node(&mut self, g: &mut Graph, id: NodeId) -> NodeId {
        if let Some(&s) = self.done.get(&id) {
            return s;
        }
        let s = self.norm.expr(g, id).and_then(|e| self.builder.build(g, &e)).unwrap_or(id);
        self.done.insert(id, s);
        s
    }
}

/// Simplifies one node (see [`Simplifier`]).
pub fn simplify(g: &mut Graph, id: NodeId) -> NodeId {
    Simplifier::new(g).node(g, id)
}

/// Simplifies every coefficient of a compiled scheme in place: term coefficients and times,
/// the coefficients of every combination, and stage times. Coefficients that become zero drop
/// out of their combinations. As a guard, a simplified coefficient that does not evaluate to
/// the original (relative 1e-9, at the default parameters and a few dt) is not used.
///
/// This is the scheme as people read it (`emit --stage scheme`). Steppers evaluate the
/// coefficients as the elimination wrote them from the user's operations, so that results do
/// not move by round-off when the simplifier learns a new rule; the two agree to round-off
/// (tested below for every library scheme).
pub fn scheme(s: &mut SchemeIr) {
    let defaults: Vec<f64> = s.params.iter().map(|p| p.default).collect();
    let g = &mut s.graph;
    let mut simp = Simplifier::new(g);
    let mut f = |g: &mut Graph, id: NodeId| {
        let new = simp.node(g, id);
        if new == id || agrees(g, id, new, &defaults) { new } else { id }
    };
    if let Some(InitialIr { terms, .. }) = &mut s.initial {
        for t in terms {
            t.map_coefs(g, &mut f);
        }
    }
    for StageIr { time, values, terms, .. } in &mut s.stages {
        *time = f(g, *time);
        for v in values {
            v.map_coefs(g, &mut f);
        }
        for t in terms {
            t.map_coefs(g, &mut f);
        }
    }
    if let Some(e) = &mut s.estimate {
        e.map_coefs(g, &mut f);
    }
}

fn agrees(g: &Graph, a: NodeId, b: NodeId, params: &[f64]) -> bool {
    [(1e-3, 0.0), (0.05, 0.7), (2.0, 3.0)].iter().all(|&(dt, t)| {
        let (x, scale) = value_and_scale(g, a, params, dt, t);
        let y = super::affine::eval(g, b, params, dt, t);
        // Where the original is undefined, the simplified one extends it; where it cancels,
        // its round-off is relative to the size of what cancelled.
        !x.is_finite() || (x - y).abs() <= 1e-9 * scale.max(y.abs())
    })
}

/// The value of a node, and its size with every sum taken of absolute values (the scale of
/// its round-off).
fn value_and_scale(g: &Graph, id: NodeId, params: &[f64], dt: f64, t: f64) -> (f64, f64) {
    let mut v: HashMap<NodeId, (f64, f64)> = HashMap::new();
    for n in g.reachable([id]) {
        let c = |x: NodeId| v.get(&x).copied().unwrap_or((f64::NAN, f64::NAN));
        let r = match g.node(n) {
            Node::Const(b) => (f64::from_bits(b), f64::from_bits(b).abs()),
            Node::Sym(Sym::Param(i)) => {
                let p = params.get(i as usize).copied().unwrap_or(f64::NAN);
                (p, p.abs())
            }
            Node::Sym(Sym::Dt) => (dt, dt),
            Node::Sym(Sym::Time) => (t, t.abs()),
            Node::Sym(_) => (f64::NAN, f64::NAN),
            Node::Add(x, y) => (c(x).0 + c(y).0, c(x).1 + c(y).1),
            Node::Mul(x, y) => (c(x).0 * c(y).0, c(x).1 * c(y).1),
            Node::Neg(x) => (-c(x).0, c(x).1),
            // A divisor's scale is its value: the pivots are checked to keep away from zero.
            Node::Div(x, y) => (c(x).0 / c(y).0, c(x).1 / c(y).0.abs()),
            Node::Powi(x, k) => (c(x).0.powi(k), if k >= 0 { c(x).1.powi(k) } else { c(x).0.abs().powi(k) }),
            Node::Powf(x, p) => {
                let p = f64::from_bits(p);
                (c(x).0.powf(p), c(x).1.powf(p))
            }
            Node::Sqrt(x) => (c(x).0.sqrt(), c(x).1.sqrt()),
            Node::Heaviside(x) | Node::Step(x) => (f64::from(c(x).0 > 0.0), 1.0),
            // Not in schemes (their values refuse these functions); sized by the value.
            Node::Func(f, x) => (f.apply(c(x).0), f.apply(c(x).0).abs()),
            Node::Atan2(y, x) => (c(y).0.atan2(c(x).0), c(y).0.atan2(c(x).0).abs()),
            Node::CoefAt { .. } => (f64::NAN, f64::NAN),
        };
        v.insert(n, r);
    }
    v.get(&id).copied().unwrap_or((f64::NAN, f64::NAN))
}

impl super::Term {
    fn map_coefs(&mut self, g: &mut Graph, f: &mut impl FnMut(&mut Graph, NodeId) -> NodeId) {
        self.coef = f(g, self.coef);
        self.time = f(g, self.time);
        for a in &mut self.args {
            a.map_coefs(g, f);
        }
    }
}
