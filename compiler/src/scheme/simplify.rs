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

use std::collections::{BTreeMap, HashMap};

use super::{InitialIr, SchemeIr, StageIr};
use crate::ir::graph::{Graph, Node, NodeId, Sym};

/// The simplification gave up (rational overflow, or a node that is not scheme arithmetic).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GiveUp;

type Res<T> = Result<T, GiveUp>;

/// An exact rational, `d > 0`, in lowest terms.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Rat {
    n: i128,
    d: i128,
}

fn gcd(a: i128, b: i128) -> i128 {
    let (mut a, mut b) = (a.unsigned_abs(), b.unsigned_abs());
    while b != 0 {
        (a, b) = (b, a % b);
    }
    a as i128
}

impl Rat {
    const ZERO: Rat = Rat { n: 0, d: 1 };
    const ONE: Rat = Rat { n: 1, d: 1 };

    fn new(n: i128, d: i128) -> Res<Rat> {
        if d == 0 {
            return Err(GiveUp);
        }
        let g = gcd(n, d).max(1);
        let (n, d) = (n / g, d / g);
        if d < 0 {
            Ok(Rat { n: n.checked_neg().ok_or(GiveUp)?, d: d.checked_neg().ok_or(GiveUp)? })
        } else {
            Ok(Rat { n, d })
        }
    }

    fn int(n: i128) -> Rat {
        Rat { n, d: 1 }
    }

    fn is_zero(self) -> bool {
        self.n == 0
    }

    fn add(self, o: Rat) -> Res<Rat> {
        let g = gcd(self.d, o.d);
        let (a, b) = (self.d / g, o.d / g);
        let n = self.n.checked_mul(b).and_then(|x| o.n.checked_mul(a).and_then(|y| x.checked_add(y))).ok_or(GiveUp)?;
        let d = self.d.checked_mul(b).ok_or(GiveUp)?;
        Rat::new(n, d)
    }

    fn mul(self, o: Rat) -> Res<Rat> {
        // Cross-reduce first to keep the numbers small.
        let g1 = gcd(self.n, o.d).max(1);
        let g2 = gcd(o.n, self.d).max(1);
        let n = (self.n / g1).checked_mul(o.n / g2).ok_or(GiveUp)?;
        let d = (self.d / g2).checked_mul(o.d / g1).ok_or(GiveUp)?;
        Rat::new(n, d)
    }

    fn inv(self) -> Res<Rat> {
        Rat::new(self.d, self.n)
    }

    fn powi(self, k: i32) -> Res<Rat> {
        let base = if k < 0 { self.inv()? } else { self };
        let mut r = Rat::ONE;
        for _ in 0..k.unsigned_abs() {
            r = r.mul(base)?;
        }
        Ok(r)
    }

    fn to_f64(self) -> f64 {
        self.n as f64 / self.d as f64
    }

    /// `v` as a small rational `p/q` (q ≤ 1024, or a power of ten) whose f64 quotient is `v`
    /// exactly: the constants schemes write (`1/3`, `0.05`, `1e-6`) become exact.
    fn from_f64(v: f64) -> Option<Rat> {
        if !v.is_finite() {
            return None;
        }
        let limit = 2f64.powi(62);
        let try_q = |q: i128| {
            let p = (v * q as f64).round();
            (p.abs() < limit && p / q as f64 == v).then(|| Rat::new(p as i128, q).ok()).flatten()
        };
        (1..=1024).chain((4..=18).map(|k| 10i128.pow(k))).find_map(try_q)
    }
}

/// An irreducible factor.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Atom {
    Param(u16),
    Dt,
    Time,
    /// A primitive sum (see the module doc).
    Sum(Box<Expr>),
    Sqrt(Box<Expr>),
    Heaviside(Box<Expr>),
    /// A positive constant that is no small rational (the bits of an f64).
    Float(u64),
}

/// A product of atoms with nonzero exponents, sorted by atom.
type Mono = Vec<(Atom, i32)>;

/// Σ q · monomial, without zero coefficients.
#[derive(Clone, Debug, Default, PartialEq, Eq, PartialOrd, Ord)]
pub struct Expr {
    terms: BTreeMap<Mono, Rat>,
}

fn mono_mul(a: &Mono, b: &Mono) -> Res<Mono> {
    let mut m: BTreeMap<Atom, i32> = a.iter().cloned().collect();
    for (x, e) in b {
        let slot = m.entry(x.clone()).or_insert(0);
        *slot = slot.checked_add(*e).ok_or(GiveUp)?;
    }
    Ok(m.into_iter().filter(|(_, e)| *e != 0).collect())
}

fn mono_powi(a: &Mono, k: i32) -> Res<Mono> {
    a.iter().map(|(x, e)| Ok((x.clone(), e.checked_mul(k).ok_or(GiveUp)?))).collect()
}

impl Expr {
    fn constant(q: Rat) -> Expr {
        Expr::term(q, Vec::new())
    }

    fn term(q: Rat, m: Mono) -> Expr {
        let mut terms = BTreeMap::new();
        if !q.is_zero() {
            terms.insert(m, q);
        }
        Expr { terms }
    }

    fn atom(a: Atom) -> Expr {
        Expr::term(Rat::ONE, vec![(a, 1)])
    }

    fn is_zero(&self) -> bool {
        self.terms.is_empty()
    }

    fn single(&self) -> Option<(Rat, &Mono)> {
        match self.terms.len() {
            1 => self.terms.iter().next().map(|(m, q)| (*q, m)),
            _ => None,
        }
    }

    fn add(&self, o: &Expr) -> Res<Expr> {
        let mut terms = self.terms.clone();
        for (m, q) in &o.terms {
            let sum = match terms.get(m) {
                Some(p) => p.add(*q)?,
                None => *q,
            };
            if sum.is_zero() {
                terms.remove(m);
            } else {
                terms.insert(m.clone(), sum);
            }
        }
        Ok(Expr { terms })
    }

    /// One term. A sum factor of power one is multiplied out when it is the only sum in the
    /// numerator (`dt·(1 - gs)/(2 - gs)` is the sum `dt/(2 - gs) - gs·dt/(2 - gs)`), so that
    /// such a term has one form; products and powers of sums stay factored.
    fn from_term(q: Rat, m: Mono, depth: u32) -> Res<Expr> {
        let mut sums = m.iter().enumerate().filter(|(_, (a, e))| matches!(a, Atom::Sum(_)) && *e > 0);
        if let (Some((i, (Atom::Sum(s), 1))), None) = (sums.next(), sums.next()) {
            if depth > 64 {
                return Err(GiveUp);
            }
            let mut rest = m.clone();
            rest.remove(i);
            let mut out = Expr::default();
            for (tm, tq) in &s.terms {
                out = out.add(&Expr::from_term(tq.mul(q)?, mono_mul(tm, &rest)?, depth + 1)?)?;
            }
            return Ok(out);
        }
        Ok(Expr::term(q, m))
    }

    /// `self · q · m`, term by term.
    fn scale(&self, q: Rat, m: &Mono) -> Res<Expr> {
        let mut out = Expr::default();
        for (tm, tq) in &self.terms {
            out = out.add(&Expr::from_term(tq.mul(q)?, mono_mul(tm, m)?, 0)?)?;
        }
        Ok(out)
    }

    fn neg(&self) -> Res<Expr> {
        self.scale(Rat::int(-1), &Vec::new())
    }

    /// `self · q · m`: distributed, unless `m` divides by a sum that is a factor of `self`
    /// (then the factored forms multiply, and the sum cancels).
    fn mul_term(&self, q: Rat, m: &Mono) -> Res<Expr> {
        if self.single().is_none() && m.iter().any(|(a, e)| matches!(a, Atom::Sum(_)) && *e < 0) {
            let (qs, ms) = self.factor()?;
            if m.iter().any(|(a, e)| *e < 0 && ms.iter().any(|(b, f)| a == b && *f > 0)) {
                return Expr::from_term(qs.mul(q)?, mono_mul(&ms, m)?, 0);
            }
        }
        self.scale(q, m)
    }

    fn mul(&self, o: &Expr) -> Res<Expr> {
        if self.is_zero() || o.is_zero() {
            return Ok(Expr::default());
        }
        if let Some((q, m)) = o.single() {
            return self.mul_term(q, m);
        }
        if let Some((q, m)) = self.single() {
            return o.mul_term(q, m);
        }
        // Two sums: a product of their factored forms, not expanded.
        let (qa, ma) = self.factor()?;
        let (qb, mb) = o.factor()?;
        Expr::from_term(qa.mul(qb)?, mono_mul(&ma, &mb)?, 0)
    }

    fn powi(&self, k: i32) -> Res<Expr> {
        if k == 0 {
            return Ok(Expr::constant(Rat::ONE));
        }
        if self.is_zero() {
            return if k > 0 { Ok(Expr::default()) } else { Err(GiveUp) };
        }
        if k == 1 {
            return Ok(self.clone());
        }
        let (q, m) = self.factor()?;
        Expr::from_term(q.powi(k)?, mono_powi(&m, k)?, 0)
    }

    /// The expression as one term `q · m`: a sum becomes its common factors times a primitive
    /// sum atom.
    fn factor(&self) -> Res<(Rat, Mono)> {
        if self.is_zero() {
            return Ok((Rat::ZERO, Vec::new()));
        }
        if let Some((q, m)) = self.single() {
            return Ok((q, m.clone()));
        }
        // Common factors: each atom to its smallest exponent over the terms (0 where absent).
        // Pulling out a divisor puts the sum over a common denominator, where sums of power one
        // multiply out again, and may cancel: repeat until nothing is common.
        let mut common: Mono = Vec::new();
        let mut rest = self.clone();
        let mut settled = false;
        for _ in 0..16 {
            let mut least: BTreeMap<&Atom, i32> = BTreeMap::new();
            for m in rest.terms.keys() {
                for (a, e) in m {
                    let l = least.entry(a).or_insert(0);
                    *l = (*l).min(*e);
                }
            }
            let first = rest.terms.keys().next().ok_or(GiveUp)?;
            for (a, e) in first {
                if *e > 0 && rest.terms.keys().all(|m| m.iter().any(|(x, f)| x == a && *f > 0)) {
                    let l = rest.terms.keys().filter_map(|m| m.iter().find(|(x, _)| x == a)).map(|(_, f)| *f).min();
                    least.insert(a, l.unwrap_or(0));
                }
            }
            let step: Mono = least.into_iter().filter(|(_, e)| *e != 0).map(|(a, e)| (a.clone(), e)).collect();
            if step.is_empty() {
                settled = true;
                break;
            }
            let inv = mono_powi(&step, -1)?;
            rest = rest.scale(Rat::ONE, &inv)?;
            common = mono_mul(&common, &step)?;
            match rest.single() {
                None if rest.is_zero() => return Ok((Rat::ZERO, Vec::new())),
                None => {}
                Some((q, m)) => return Ok((q, mono_mul(&common, m)?)),
            }
        }
        if !settled {
            return Err(GiveUp);
        }
        let rest = rest.terms;
        // Content: gcd of the numerators over lcm of the denominators, signed like the first
        // term (of the sum without its common factor).
        let mut num = 0i128;
        let mut den = 1i128;
        for q in rest.values() {
            num = gcd(num, q.n);
            den = (den / gcd(den, q.d)).checked_mul(q.d).ok_or(GiveUp)?;
        }
        let lead = *rest.values().next().ok_or(GiveUp)?;
        let content = Rat::new(if lead.n < 0 { -num } else { num }, den)?;
        let inv = content.inv()?;
        let mut primitive = Expr::default();
        for (tm, tq) in rest {
            primitive.terms.insert(tm, tq.mul(inv)?);
        }
        let m = mono_mul(&common, &vec![(Atom::Sum(Box::new(primitive)), 1)])?;
        Ok((content, m))
    }
}

/// Normal forms of graph nodes, memoised (the graph is a DAG).
#[derive(Default)]
struct Normalizer {
    memo: HashMap<NodeId, Res<Expr>>,
}

impl Normalizer {
    fn expr(&mut self, g: &Graph, id: NodeId) -> Res<Expr> {
        if let Some(e) = self.memo.get(&id) {
            return e.clone();
        }
        // Children first, iteratively (ids are topological), so deep DAGs do not recurse.
        for n in g.reachable([id]) {
            if !self.memo.contains_key(&n) {
                let e = self.node(g, n);
                self.memo.insert(n, e);
            }
        }
        self.memo.get(&id).cloned().unwrap_or(Err(GiveUp))
    }

    fn node(&self, g: &Graph, id: NodeId) -> Res<Expr> {
        let sub = |x: NodeId| self.memo.get(&x).cloned().unwrap_or(Err(GiveUp));
        match g.node(id) {
            Node::Const(b) => {
                let v = f64::from_bits(b);
                if v == 0.0 {
                    Ok(Expr::default())
                } else if let Some(q) = Rat::from_f64(v) {
                    Ok(Expr::constant(q))
                } else if v.is_finite() {
                    let sign = Rat::int(if v < 0.0 { -1 } else { 1 });
                    Ok(Expr::term(sign, vec![(Atom::Float(v.abs().to_bits()), 1)]))
                } else {
                    Err(GiveUp)
                }
            }
            Node::Sym(Sym::Param(i)) => Ok(Expr::atom(Atom::Param(i))),
            Node::Sym(Sym::Dt) => Ok(Expr::atom(Atom::Dt)),
            Node::Sym(Sym::Time) => Ok(Expr::atom(Atom::Time)),
            Node::Sym(_) => Err(GiveUp),
            Node::Add(a, b) => sub(a)?.add(&sub(b)?),
            Node::Mul(a, b) => sub(a)?.mul(&sub(b)?),
            Node::Neg(a) => sub(a)?.neg(),
            Node::Div(a, b) => sub(a)?.mul(&sub(b)?.powi(-1)?),
            Node::Powi(a, k) => sub(a)?.powi(k),
            // Schemes take integer powers only (the checker refuses others there).
            Node::Powf(..) => Err(GiveUp),
            Node::Sqrt(a) => {
                let e = sub(a)?;
                if e.is_zero() { Ok(Expr::default()) } else { Ok(Expr::atom(Atom::Sqrt(Box::new(e)))) }
            }
            Node::Heaviside(a) => {
                let e = sub(a)?;
                if e.is_zero() { Ok(Expr::default()) } else { Ok(Expr::atom(Atom::Heaviside(Box::new(e)))) }
            }
        }
    }
}

/// A user's `let`: `node = q · m`.
struct Named {
    node: NodeId,
    q: Rat,
    m: Mono,
}

struct Builder {
    named: Vec<Named>,
}

impl Builder {
    /// The named nodes of the graph that are worth putting back: lets whose normal form is not
    /// a bare parameter, dt or t, largest first (in name order among equals, for determinism).
    fn new(g: &Graph, norm: &mut Normalizer) -> Builder {
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

    fn build(&self, g: &mut Graph, e: &Expr) -> Res<NodeId> {
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
            Node::Heaviside(x) => (f64::from(c(x).0 > 0.0), 1.0),
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

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;
    use crate::scheme::affine::eval;

    fn library_scheme(name: &str) -> SchemeIr {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../forms/schemes");
        let (prog, _) = crate::check_path(&dir.join(format!("{name}.wf")), &crate::source::FsLoader)
            .unwrap_or_else(|f| panic!("{}", f.rendered));
        prog.schemes.into_iter().next().expect("a scheme")
    }

    const LIBRARY: &[&str] =
        &["central", "genalpha", "hht", "hht_imex", "hht_unweighted", "hybrid", "midpoint", "newmark", "trbdf2"];

    #[test]
    fn trbdf2_pivot_times_its_inverse_is_exactly_minus_one() {
        // -((gs*dt)^2/4*(1/((gs*dt)^2/4))), as the elimination builds it.
        let mut g = Graph::default();
        let (gs, dt) = (g.sym(Sym::Param(0)), g.sym(Sym::Dt));
        let (one, four) = (g.one(), g.constant(4.0));
        let gsdt = g.mul(gs, dt);
        let sq = g.powi(gsdt, 2);
        let pivot = g.div(sq, four);
        let inv = g.div(one, pivot);
        let prod = g.mul(pivot, inv);
        let e = g.neg(prod);
        let s = simplify(&mut g, e);
        assert_eq!(g.as_const(s), Some(-1.0));
        assert_eq!(eval(&g, s, &[2.0 - 2f64.sqrt()], 0.37, 0.0), -1.0);
    }

    #[test]
    fn newmark_ratio_is_one() {
        // dt^2/2*(2*beta)/(beta*dt^2)
        let mut g = Graph::default();
        let (beta, dt) = (g.sym(Sym::Param(0)), g.sym(Sym::Dt));
        let two = g.constant(2.0);
        let dt2 = g.powi(dt, 2);
        let half = g.div(dt2, two);
        let tb = g.mul(two, beta);
        let num = g.mul(half, tb);
        let den = g.mul(beta, dt2);
        let e = g.div(num, den);
        let s = simplify(&mut g, e);
        assert_eq!(g.as_const(s), Some(1.0));
    }

    #[test]
    fn a_sum_times_its_inverse_cancels_in_any_spelling() {
        let mut g = Graph::default();
        let gs = g.sym(Sym::Param(0));
        let (one, two) = (g.one(), g.constant(2.0));
        let a = g.sub(one, gs); // 1 - gs
        let b = g.sub(gs, one); // gs - 1
        let twice = g.mul(two, b); // 2*(gs - 1)
        let e = g.div(a, twice);
        let s = simplify(&mut g, e);
        assert_eq!(g.as_const(s), Some(-0.5));
        // (1 - gs)^2 / (1 - gs) = 1 - gs, one sum.
        let sq = g.powi(a, 2);
        let e = g.div(sq, a);
        let s = simplify(&mut g, e);
        assert_eq!(Normalizer::default().expr(&g, s), Normalizer::default().expr(&g, a));
        assert_eq!(eval(&g, s, &[0.25], 1.0, 0.0), 0.75);
    }

    #[test]
    fn like_terms_combine_and_constants_fold_exactly() {
        let mut g = Graph::default();
        let (gs, dt) = (g.sym(Sym::Param(0)), g.sym(Sym::Dt));
        let (two, three, third) = (g.constant(2.0), g.constant(3.0), g.constant(1.0 / 3.0));
        let x = g.mul(gs, dt);
        let y = g.mul(two, x); // 2·gs·dt
        let z = g.mul(dt, gs); // the same product, other order
        let w = g.mul(three, z);
        let sum = g.add(x, y);
        let e = g.sub(sum, w); // gs·dt + 2·gs·dt − 3·gs·dt
        let s = simplify(&mut g, e);
        assert_eq!(g.as_const(s), Some(0.0));
        // 3·(1/3)·gs = gs: the f64 1/3 is the rational 1/3.
        let p = g.mul(three, third);
        let e = g.mul(p, gs);
        let e = g.add(e, dt);
        let s = simplify(&mut g, e);
        let expected = g.add(gs, dt);
        assert_eq!(s, expected);
    }

    #[test]
    fn overflow_keeps_the_original_node() {
        let mut g = Graph::default();
        let gs = g.sym(Sym::Param(0));
        let c = g.constant(1.0 / 1021.0);
        let sum = g.add(gs, c);
        // (gs + 1/1021)^64: the content 1021^-64 does not fit an i128.
        let e = g.powi(sum, 64);
        assert_eq!(simplify(&mut g, e), e);
    }

    #[test]
    fn lets_come_back_as_names() {
        let s = library_scheme("trbdf2");
        let text = crate::scheme::print::print(&s);
        assert!(text.contains("v' = 1/c·u'"), "{text}");
        let s = library_scheme("hht");
        let text = crate::scheme::print::print(&s);
        assert!(text.contains("a' = 1/(beta*dt^2)·u'"), "{text}");
    }

    /// Every library scheme's coefficients: the TR-BDF2 trapezoidal stage is 4/(gs·dt)² etc.
    #[test]
    fn library_coefficients_are_simplified() {
        let mut s = library_scheme("trbdf2");
        scheme(&mut s);
        let g = &s.graph;
        let am = &s.stages[0].values[2];
        assert_eq!(
            g.as_const(am.known.iter().find(|(q, _)| *q == super::super::Quantity::State(2)).unwrap().1),
            Some(-1.0)
        );
        // vm no longer depends on a (its coefficient cancels exactly).
        let vm = &s.stages[0].values[1];
        assert!(!vm.known.iter().any(|(q, _)| *q == super::super::Quantity::State(2)));
    }

    /// Samples of the scheme parameters inside their ranges.
    fn in_range(p: &super::super::SchemeParamInfo, x: f64) -> f64 {
        match p.range {
            Some(r) if r.lo.is_finite() && r.hi.is_finite() => {
                let v = r.lo + x * (r.hi - r.lo);
                if r.contains(v) { v } else { p.default }
            }
            _ => p.default * (0.5 + x),
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// Every node of every library scheme's coefficient graph (the unsimplified
        /// coefficients and all their subexpressions are still there) simplifies to a node
        /// with the same value: within 1e-12 of the size of the terms that cancel in it.
        #[test]
        fn simplified_nodes_evaluate_like_the_originals(
            which in 0..LIBRARY.len(), xs in prop::collection::vec(0.01f64..0.99, 4), log_dt in -4.0f64..0.5, t in 0.0f64..10.0
        ) {
            let mut s = library_scheme(LIBRARY[which]);
            let params: Vec<f64> = s.params.iter().zip(&xs).map(|(p, x)| in_range(p, *x)).collect();
            let dt = 10f64.powf(log_dt);
            let g = &mut s.graph;
            let mut simp = Simplifier::new(g);
            for id in 0..g.len() as NodeId {
                let new = simp.node(g, id);
                let (x, scale) = value_and_scale(g, id, &params, dt, t);
                let y = eval(g, new, &params, dt, t);
                if x.is_finite() {
                    prop_assert!((x - y).abs() <= 1e-12 * scale.max(y.abs()),
                        "{}: node {id}: {x} became {y} (scale {scale})", LIBRARY[which]);
                }
            }
        }
    }
}
