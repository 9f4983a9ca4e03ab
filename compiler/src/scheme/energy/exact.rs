//! A scheme's scalar (a node of its coefficient graph) as an exact rational function of its
//! params, dt and t; or the node that keeps it from being one, and why.

use std::collections::HashMap;

use super::super::rational::Rat;
use super::poly::{DT, TIME};
use super::ratfn::RatFn;
use crate::ir::graph::{Graph, Node, NodeId, Sym};

/// Why a scalar is no rational function of the params: the node, and what it is.
#[derive(Clone, Debug, PartialEq)]
pub struct Refusal {
    pub node: NodeId,
    pub why: String,
}

/// The scalars of one graph as rational functions, each node converted once.
#[derive(Default)]
pub struct Exact {
    done: HashMap<NodeId, RatFn>,
}

impl Exact {
    /// `node` as a rational function of the params (variables `0..`), dt and t.
    pub fn of(&mut self, g: &Graph, node: NodeId) -> Result<RatFn, Refusal> {
        if let Some(r) = self.done.get(&node) {
            return Ok(r.clone());
        }
        let refuse = |why: &str| Refusal { node, why: why.to_string() };
        let overflow = |_| refuse("its exact coefficients overflow 128-bit rationals");
        let value = match g.node(node) {
            Node::Const(bits) => {
                let v = f64::from_bits(bits);
                RatFn::constant(
                    Rat::from_f64(v).ok_or_else(|| refuse(&format!("the constant {v} is no small rational")))?,
                )
            }
            Node::Sym(Sym::Param(i)) => RatFn::var(i),
            Node::Sym(Sym::Dt) => RatFn::var(DT),
            Node::Sym(Sym::Time) => RatFn::var(TIME),
            Node::Sym(s) => return Err(refuse(&format!("{s:?} is no param, dt or t"))),
            Node::Add(a, b) => self.of(g, a)?.add(&self.of(g, b)?).map_err(overflow)?,
            Node::Mul(a, b) => self.of(g, a)?.mul(&self.of(g, b)?).map_err(overflow)?,
            Node::Neg(a) => self.of(g, a)?.neg().map_err(overflow)?,
            Node::Div(a, b) => {
                let d = self.of(g, b)?;
                if d.is_zero() {
                    return Err(refuse("a division by zero"));
                }
                self.of(g, a)?.div(&d).map_err(overflow)?
            }
            Node::Powi(a, k) => self.of(g, a)?.powi(k).map_err(overflow)?,
            Node::Powf(..) => return Err(refuse("a power with a non-integer exponent")),
            Node::Sqrt(_) => return Err(refuse("a square root")),
            Node::Heaviside(_) | Node::Step(_) => return Err(refuse("a switch (`abs`, `H`, `pos`, `neg`, ...)")),
            Node::Func(..) | Node::Atan2(..) => return Err(refuse("a transcendental function")),
            _ => return Err(refuse("no scheme arithmetic")),
        };
        self.done.insert(node, value.clone());
        Ok(value)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scheme::affine::eval;

    /// Every scalar of every library scheme (the stages' values, the residuals' coefficients
    /// and times, the initial line's) is an exact rational function whose value is the
    /// graph's at random params in their ranges, dt and t.
    #[test]
    fn every_library_scalar_is_an_exact_rational_function() {
        let mut seed = 3u64;
        let mut random = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for (name, ir) in super::super::library_schemes() {
            let mut nodes = Vec::new();
            let affine = |a: &crate::scheme::affine::Affine, out: &mut Vec<NodeId>| {
                out.push(a.unknown);
                out.extend(a.known.iter().map(|(_, c)| *c));
            };
            for s in &ir.stages {
                nodes.push(s.time);
                for v in &s.values {
                    affine(v, &mut nodes);
                }
                for t in &s.terms {
                    nodes.extend([t.coef, t.time]);
                    for a in &t.args {
                        affine(a, &mut nodes);
                    }
                }
            }
            for t in ir.initial.iter().flat_map(|i| &i.terms) {
                nodes.extend([t.coef, t.time]);
            }
            let mut exact = Exact::default();
            for _ in 0..4 {
                let params: Vec<f64> = ir
                    .params
                    .iter()
                    .map(|p| match &p.range {
                        Some(r) if r.lo.is_finite() && r.hi.is_finite() => {
                            r.lo + (r.hi - r.lo) * (0.1 + 0.8 * random())
                        }
                        _ => p.default * (0.5 + random()),
                    })
                    .collect();
                let (dt, t) = (0.01 + random(), 10.0 * random());
                for &n in &nodes {
                    let r = exact.of(&ir.graph, n).unwrap_or_else(|e| panic!("{name}: {e:?}"));
                    let (want, got) = (eval(&ir.graph, n, &params, dt, t), r.eval(&params, dt, t));
                    assert!((want - got).abs() <= 1e-11 * (1.0 + want.abs()), "{name}: {got} against {want}");
                }
            }
        }
    }

    #[test]
    fn a_square_root_is_refused_where_it_is() {
        let mut g = Graph::default();
        let p = g.sym(Sym::Param(0));
        let root = g.sqrt(p);
        let e = g.add(root, p);
        let refusal = Exact::default().of(&g, e).unwrap_err();
        assert_eq!(refusal.node, root);
        assert_eq!(refusal.why, "a square root");
    }
}
