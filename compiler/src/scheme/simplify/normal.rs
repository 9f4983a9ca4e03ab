//! The normal form: sums of terms `q · Π aᵢ^eᵢ` over irreducible atoms, its arithmetic, and
//! the normal forms of graph nodes.

use std::collections::{BTreeMap, HashMap};

use super::rational::{GiveUp, Rat, Res, gcd};
use crate::ir::graph::{Graph, Node, NodeId, Sym};

/// An irreducible factor.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub(super) enum Atom {
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
pub(super) type Mono = Vec<(Atom, i32)>;

/// Σ q · monomial, without zero coefficients.
#[derive(Clone, Debug, Default, PartialEq, Eq, PartialOrd, Ord)]
pub(super) struct Expr {
    pub(super) terms: BTreeMap<Mono, Rat>,
}

pub(super) fn mono_mul(a: &Mono, b: &Mono) -> Res<Mono> {
    let mut m: BTreeMap<Atom, i32> = a.iter().cloned().collect();
    for (x, e) in b {
        let slot = m.entry(x.clone()).or_insert(0);
        *slot = slot.checked_add(*e).ok_or(GiveUp)?;
    }
    Ok(m.into_iter().filter(|(_, e)| *e != 0).collect())
}

pub(super) fn mono_powi(a: &Mono, k: i32) -> Res<Mono> {
    a.iter().map(|(x, e)| Ok((x.clone(), e.checked_mul(k).ok_or(GiveUp)?))).collect()
}

impl Expr {
    pub(super) fn constant(q: Rat) -> Expr {
        Expr::term(q, Vec::new())
    }

    pub(super) fn term(q: Rat, m: Mono) -> Expr {
        let mut terms = BTreeMap::new();
        if !q.is_zero() {
            terms.insert(m, q);
        }
        Expr { terms }
    }

    pub(super) fn atom(a: Atom) -> Expr {
        Expr::term(Rat::ONE, vec![(a, 1)])
    }

    pub(super) fn is_zero(&self) -> bool {
        self.terms.is_empty()
    }

    pub(super) fn single(&self) -> Option<(Rat, &Mono)> {
        match self.terms.len() {
            1 => self.terms.iter().next().map(|(m, q)| (*q, m)),
            _ => None,
        }
    }

    pub(super) fn add(&self, o: &Expr) -> Res<Expr> {
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
    pub(super) fn from_term(q: Rat, m: Mono, depth: u32) -> Res<Expr> {
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
    pub(super) fn scale(&self, q: Rat, m: &Mono) -> Res<Expr> {
        let mut out = Expr::default();
        for (tm, tq) in &self.terms {
            out = out.add(&Expr::from_term(tq.mul(q)?, mono_mul(tm, m)?, 0)?)?;
        }
        Ok(out)
    }

    pub(super) fn neg(&self) -> Res<Expr> {
        self.scale(Rat::int(-1), &Vec::new())
    }

    /// `self · q · m`: distributed, unless `m` divides by a sum that is a factor of `self`
    /// (then the factored forms multiply, and the sum cancels).
    pub(super) fn mul_term(&self, q: Rat, m: &Mono) -> Res<Expr> {
        if self.single().is_none() && m.iter().any(|(a, e)| matches!(a, Atom::Sum(_)) && *e < 0) {
            let (qs, ms) = self.factor()?;
            if m.iter().any(|(a, e)| *e < 0 && ms.iter().any(|(b, f)| a == b && *f > 0)) {
                return Expr::from_term(qs.mul(q)?, mono_mul(&ms, m)?, 0);
            }
        }
        self.scale(q, m)
    }

    pub(super) fn mul(&self, o: &Expr) -> Res<Expr> {
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

    pub(super) fn powi(&self, k: i32) -> Res<Expr> {
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
    pub(super) fn factor(&self) -> Res<(Rat, Mono)> {
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
pub(super) struct Normalizer {
    memo: HashMap<NodeId, Res<Expr>>,
}

impl Normalizer {
    pub(super) fn expr(&mut self, g: &Graph, id: NodeId) -> Res<Expr> {
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

    pub(super) fn node(&self, g: &Graph, id: NodeId) -> Res<Expr> {
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
            // Nor do they take transcendental functions.
            Node::Func(..) | Node::Atan2(..) | Node::CoefAt { .. } => Err(GiveUp),
            Node::Sqrt(a) => {
                let e = sub(a)?;
                if e.is_zero() { Ok(Expr::default()) } else { Ok(Expr::atom(Atom::Sqrt(Box::new(e)))) }
            }
            // Scheme coefficients have no built-in steps; one would read as H.
            Node::Heaviside(a) | Node::Step(a) => {
                let e = sub(a)?;
                if e.is_zero() { Ok(Expr::default()) } else { Ok(Expr::atom(Atom::Heaviside(Box::new(e)))) }
            }
        }
    }
}
