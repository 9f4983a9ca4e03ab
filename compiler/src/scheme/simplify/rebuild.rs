//! Graph nodes from normal forms, with the user's `let`s put back where a factor of a term is
//! (a power of) one of them.

use super::normal::{Atom, Expr, Mono, Normalizer, mono_mul, mono_powi};
use super::rational::{GiveUp, Rat, Res};
use crate::ir::graph::{Graph, Node, NodeId, Sym};

/// A user's `let`: `node = q · m`.
struct Named {
    node: NodeId,
    q: Rat,
    m: Mono,
}

pub(super) struct Builder {
    named: Vec<Named>,
}

impl Builder {
    /// The named nodes of the graph that are worth putting back: lets whose normal form is not
    /// a bare parameter, dt or t, largest first (in name order among equals, for determinism).
    pub(super) fn new(g: &Graph, norm: &mut Normalizer) -> Builder {
        let mut names: Vec<(&String, NodeId)> = g.names.iter().map(|(id, n)| (n, *id)).collect();
        names.sort();
        let mut named = Vec::new();
        for (_, node) in names {
            if matches!(g.node(node), Node::Sym(_) | Node::Const(_)) {
                continue;
            }
            let Ok((q, m)) = norm.expr(g, node).and_then(|e| e.factor()) else { continue };
            let trivial = match m.as_slice() {
                [] => true,
                [(Atom::Param(_) | Atom::Dt | Atom::Time | Atom::Float(_), e)] => e.abs() == 1,
                _ => false,
            };
            if !trivial && !q.is_zero() {
                named.push(Named { node, q, m });
            }
        }
        named.sort_by_key(|n| std::cmp::Reverse(n.m.iter().map(|(_, e)| e.unsigned_abs()).sum::<u32>()));
        Builder { named }
    }

    pub(super) fn build(&self, g: &mut Graph, e: &Expr) -> Res<NodeId> {
        if e.is_zero() {
            return Ok(g.zero());
        }
        if e.single().is_none() {
            // A sum: a let as a whole, or its common factors times the sum of the rest.
            let (q, m) = e.factor()?;
            if matches!(m.as_slice(), [(Atom::Sum(_), 1)]) && !self.named.iter().any(|n| n.m == m) {
                return self.sum(g, e);
            }
            return self.term(g, q, &m);
        }
        match e.single() {
            Some((q, m)) => self.term(g, q, m),
            None => Err(GiveUp),
        }
    }

    /// A sum term by term.
    fn sum(&self, g: &mut Graph, e: &Expr) -> Res<NodeId> {
        let mut acc: Option<NodeId> = None;
        for (m, q) in &e.terms {
            let t = self.term(g, *q, m)?;
            acc = Some(match acc {
                None => t,
                Some(a) => g.add(a, t),
            });
        }
        Ok(acc.unwrap_or_else(|| g.zero()))
    }

    /// `q · m`, with lets substituted for the factors they cover.
    fn term(&self, g: &mut Graph, q: Rat, m: &Mono) -> Res<NodeId> {
        let mut q = q;
        let mut m = m.clone();
        // (node, exponent) factors, lets first.
        let mut factors: Vec<(NodeId, i32)> = Vec::new();
        for n in &self.named {
            let k = power_in(&m, &n.m);
            if k == 0 {
                continue;
            }
            let (Ok(rest), Ok(coef)) = (mono_mul(&m, &mono_powi(&n.m, -k)?), n.q.powi(k).and_then(|p| q.mul(p.inv()?)))
            else {
                continue;
            };
            m = rest;
            q = coef;
            factors.push((n.node, k));
        }
        for (a, e) in &m {
            let node = self.atom(g, a)?;
            factors.push((node, *e));
        }
        let big = 2f64.powi(53);
        let (qn, qd) = (q.n.unsigned_abs() as f64, q.d as f64);
        let (mut num, mut den): (Option<NodeId>, Option<NodeId>) = (None, None);
        let times = |acc: &mut Option<NodeId>, g: &mut Graph, x: NodeId| {
            *acc = Some(match *acc {
                None => x,
                Some(a) => g.mul(a, x),
            })
        };
        if qn >= big || qd >= big {
            // Too large to split exactly: one rounded constant.
            let c = g.constant(q.to_f64().abs());
            times(&mut num, g, c);
        } else {
            if q.n.unsigned_abs() != 1 || factors.iter().all(|(_, e)| *e < 0) {
                let c = g.constant(qn);
                times(&mut num, g, c);
            }
            if q.d != 1 {
                let c = g.constant(qd);
                times(&mut den, g, c);
            }
        }
        for (node, e) in factors {
            let p = g.powi(node, e.abs());
            if e > 0 {
                times(&mut num, g, p);
            } else {
                times(&mut den, g, p);
            }
        }
        let num = num.unwrap_or_else(|| g.one());
        let v = match den {
            Some(d) => g.div(num, d),
            None => num,
        };
        Ok(if q.n < 0 { g.neg(v) } else { v })
    }

    fn atom(&self, g: &mut Graph, a: &Atom) -> Res<NodeId> {
        Ok(match a {
            Atom::Param(i) => g.sym(Sym::Param(*i)),
            Atom::Dt => g.sym(Sym::Dt),
            Atom::Time => g.sym(Sym::Time),
            Atom::Float(b) => g.constant(f64::from_bits(*b)),
            Atom::Sum(e) => self.build(g, e)?,
            Atom::Sqrt(e) => {
                let x = self.build(g, e)?;
                g.sqrt(x)
            }
            Atom::Heaviside(e) => {
                let x = self.build(g, e)?;
                g.heaviside(x)
            }
        })
    }
}

/// The largest power `k` (of either sign) of `n` that `m` contains: every atom of `n` appears in
/// `m` with the sign of `k·eₙ` and at least its size.
fn power_in(m: &Mono, n: &Mono) -> i32 {
    let mut k: Option<i32> = None;
    for (a, e) in n {
        let Some((_, f)) = m.iter().find(|(x, _)| x == a) else { return 0 };
        let r = f / e;
        if r == 0 {
            return 0;
        }
        k = Some(match k {
            None => r,
            Some(k) if k.signum() != r.signum() => return 0,
            Some(k) => {
                if r.abs() < k.abs() {
                    r
                } else {
                    k
                }
            }
        });
    }
    k.unwrap_or(0)
}
