//! Polynomials in a scheme's params, the step dt and the time t, with exact rational
//! coefficients, kept fully expanded: two polynomials are equal exactly when their terms are,
//! so a coefficient of an energy identity is zero exactly when it is the zero polynomial.

use std::collections::BTreeMap;

use super::super::rational::{GiveUp, Rat, Res};

/// A variable: param `i` of the scheme, dt, or t.
pub type Var = u16;
/// The step's variable.
pub const DT: Var = u16::MAX - 1;
/// The time's variable.
pub const TIME: Var = u16::MAX;

/// A monomial: (variable, exponent ≥ 1), sorted by variable.
type Monomial = Vec<(Var, u32)>;

/// Σ coefficient · monomial, no zero coefficient.
#[derive(Clone, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Poly {
    terms: BTreeMap<Monomial, Rat>,
}

fn times(a: &Monomial, b: &Monomial) -> Monomial {
    let mut out: BTreeMap<Var, u32> = a.iter().copied().collect();
    for &(v, e) in b {
        *out.entry(v).or_insert(0) += e;
    }
    out.into_iter().collect()
}

/// The graded lexicographic order (total degree, then the exponents by variable, the lowest
/// variable first): a monomial order, so division by the leading term terminates.
fn grlex(a: &Monomial, b: &Monomial) -> std::cmp::Ordering {
    let degree = |m: &Monomial| m.iter().map(|&(_, e)| e).sum::<u32>();
    degree(a).cmp(&degree(b)).then_with(|| {
        let exponent = |m: &Monomial, v: Var| m.iter().find(|&&(w, _)| w == v).map_or(0, |&(_, e)| e);
        let mut vars: Vec<Var> = a.iter().chain(b).map(|&(v, _)| v).collect();
        vars.sort_unstable();
        vars.dedup();
        vars.into_iter()
            .map(|v| exponent(a, v).cmp(&exponent(b, v)))
            .find(|o| o.is_ne())
            .unwrap_or(std::cmp::Ordering::Equal)
    })
}

/// `a / b` when b divides a (every exponent of b at most a's).
fn over(a: &Monomial, b: &Monomial) -> Option<Monomial> {
    let mut out: BTreeMap<Var, u32> = a.iter().copied().collect();
    for &(v, e) in b {
        let have = out.get_mut(&v).filter(|h| **h >= e)?;
        *have -= e;
    }
    Some(out.into_iter().filter(|&(_, e)| e > 0).collect())
}

impl Poly {
    pub fn zero() -> Poly {
        Poly::default()
    }

    pub fn constant(c: Rat) -> Poly {
        let mut p = Poly::zero();
        if !c.is_zero() {
            p.terms.insert(Vec::new(), c);
        }
        p
    }

    pub fn one() -> Poly {
        Poly::constant(Rat::ONE)
    }

    pub fn var(v: Var) -> Poly {
        Poly { terms: [(vec![(v, 1)], Rat::ONE)].into_iter().collect() }
    }

    pub fn is_zero(&self) -> bool {
        self.terms.is_empty()
    }

    /// The constant it is, if it is one.
    pub fn as_constant(&self) -> Option<Rat> {
        match self.terms.iter().next() {
            None => Some(Rat::ZERO),
            Some((m, c)) if m.is_empty() && self.terms.len() == 1 => Some(*c),
            _ => None,
        }
    }

    fn insert(&mut self, m: Monomial, c: Rat) -> Res<()> {
        let sum = self.terms.get(&m).map_or(Ok(c), |d| d.add(c))?;
        if sum.is_zero() {
            self.terms.remove(&m);
        } else {
            self.terms.insert(m, sum);
        }
        Ok(())
    }

    pub fn add(&self, o: &Poly) -> Res<Poly> {
        let mut out = self.clone();
        for (m, c) in &o.terms {
            out.insert(m.clone(), *c)?;
        }
        Ok(out)
    }

    pub fn scale(&self, c: Rat) -> Res<Poly> {
        let mut out = Poly::zero();
        for (m, d) in &self.terms {
            out.insert(m.clone(), d.mul(c)?)?;
        }
        Ok(out)
    }

    pub fn neg(&self) -> Res<Poly> {
        self.scale(Rat::int(-1))
    }

    pub fn sub(&self, o: &Poly) -> Res<Poly> {
        self.add(&o.neg()?)
    }

    pub fn mul(&self, o: &Poly) -> Res<Poly> {
        let mut out = Poly::zero();
        for (a, c) in &self.terms {
            for (b, d) in &o.terms {
                out.insert(times(a, b), c.mul(*d)?)?;
            }
        }
        Ok(out)
    }

    pub fn pow(&self, k: u32) -> Res<Poly> {
        let mut out = Poly::one();
        for _ in 0..k {
            out = out.mul(self)?;
        }
        Ok(out)
    }

    /// The quotient when `d` divides it exactly (multivariate division by the leading term in
    /// the monomials' order; a non-zero remainder: none).
    pub fn divide(&self, d: &Poly) -> Res<Option<Poly>> {
        let leading = |p: &Poly| p.terms.iter().max_by(|a, b| grlex(a.0, b.0)).map(|(m, c)| (m.clone(), *c));
        let Some((lead, lc)) = leading(d) else { return Err(GiveUp) };
        let mut rest = self.clone();
        let mut quotient = Poly::zero();
        while let Some((m, c)) = leading(&rest) {
            let Some(q) = over(&m, &lead) else { return Ok(None) };
            let qc = c.mul(lc.inv()?)?;
            let step = Poly { terms: [(q.clone(), qc)].into_iter().collect() };
            rest = rest.sub(&d.mul(&step)?)?;
            quotient.insert(q, qc)?;
        }
        Ok(Some(quotient))
    }

    /// Its value at `params`, `dt` and `t`.
    pub fn eval(&self, params: &[f64], dt: f64, t: f64) -> f64 {
        let value = |v: Var| match v {
            DT => dt,
            TIME => t,
            i => params.get(i as usize).copied().unwrap_or(f64::NAN),
        };
        self.terms
            .iter()
            .map(|(m, c)| c.to_f64() * m.iter().map(|&(v, e)| value(v).powi(e as i32)).product::<f64>())
            .sum()
    }

    /// Whether it reads variable `v`.
    pub fn reads(&self, v: Var) -> bool {
        self.terms.keys().any(|m| m.iter().any(|&(w, _)| w == v))
    }

    /// The variables it reads, sorted.
    pub fn vars(&self) -> Vec<Var> {
        let mut v: Vec<Var> = self.terms.keys().flat_map(|m| m.iter().map(|&(v, _)| v)).collect();
        v.sort_unstable();
        v.dedup();
        v
    }

    /// Its degree in `v`.
    pub fn degree_in(&self, v: Var) -> u32 {
        self.terms.keys().flat_map(|m| m.iter().filter(|&&(w, _)| w == v).map(|&(_, e)| e)).max().unwrap_or(0)
    }

    /// Its coefficients as a polynomial in `v` (index k: the coefficient of v^k).
    pub fn coefficients_in(&self, v: Var) -> Res<Vec<Poly>> {
        let mut out = vec![Poly::zero(); self.degree_in(v) as usize + 1];
        for (m, c) in &self.terms {
            let k = m.iter().find(|&&(w, _)| w == v).map_or(0, |&(_, e)| e);
            let rest: Monomial = m.iter().copied().filter(|&(w, _)| w != v).collect();
            out[k as usize].insert(rest, *c)?;
        }
        Ok(out)
    }

    /// The largest monomial dividing every term, and the quotient.
    pub fn monomial_content(&self) -> (Vec<(Var, u32)>, Poly) {
        let mut least: Option<BTreeMap<Var, u32>> = None;
        for m in self.terms.keys() {
            let here: BTreeMap<Var, u32> = m.iter().copied().collect();
            least = Some(match least {
                None => here,
                Some(l) => l.into_iter().filter_map(|(v, e)| here.get(&v).map(|&f| (v, e.min(f)))).collect(),
            });
        }
        let common: Monomial = least.unwrap_or_default().into_iter().collect();
        let terms = self.terms.iter().map(|(m, c)| (over(m, &common).unwrap_or_default(), *c)).collect();
        (common, Poly { terms })
    }

    /// It with `v` replaced by `by`.
    pub fn substitute(&self, v: Var, by: &Poly) -> Res<Poly> {
        let mut out = Poly::zero();
        for (k, c) in self.coefficients_in(v)?.iter().enumerate() {
            out = out.add(&c.mul(&by.pow(k as u32)?)?)?;
        }
        Ok(out)
    }

    /// Its exact value with every variable given by `value`.
    pub fn eval_exact(&self, value: &dyn Fn(Var) -> Rat) -> Res<Rat> {
        let mut sum = Rat::ZERO;
        for (m, c) in &self.terms {
            let mut term = *c;
            for &(v, e) in m {
                term = term.mul(value(v).powi(e as i32)?)?;
            }
            sum = sum.add(term)?;
        }
        Ok(sum)
    }

    /// The leading term's coefficient (grlex).
    pub fn leading_coefficient(&self) -> Rat {
        self.terms.iter().max_by(|a, b| grlex(a.0, b.0)).map_or(Rat::ZERO, |(_, c)| *c)
    }

    /// The terms, each as its coefficient and (variable, exponent) list.
    pub fn terms(&self) -> impl Iterator<Item = (&[(Var, u32)], Rat)> {
        self.terms.iter().map(|(m, c)| (m.as_slice(), *c))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn r(n: i128, d: i128) -> Rat {
        Rat::new(n, d).unwrap()
    }

    #[test]
    fn a_square_expanded_two_ways_is_one_polynomial() {
        // (1 − g)² − (1 − 2g + g²) = 0: the form the simplifier could not show zero.
        let (one, g) = (Poly::one(), Poly::var(0));
        let left = one.sub(&g).unwrap().pow(2).unwrap();
        let two_g = g.scale(Rat::int(2)).unwrap();
        let right = one.sub(&two_g).unwrap().add(&g.pow(2).unwrap()).unwrap();
        assert!(left.sub(&right).unwrap().is_zero());
    }

    #[test]
    fn division_is_exact_or_refused() {
        // (β − γ/2)(2 + dt) / (β − γ/2) = 2 + dt; (β + 1) does not divide β² + 1.
        let (beta, gam, dt) = (Poly::var(0), Poly::var(1), Poly::var(DT));
        let factor = beta.sub(&gam.scale(r(1, 2)).unwrap()).unwrap();
        let other = Poly::constant(Rat::int(2)).add(&dt).unwrap();
        let product = factor.mul(&other).unwrap();
        assert_eq!(product.divide(&factor).unwrap(), Some(other));
        let square = beta.pow(2).unwrap().add(&Poly::one()).unwrap();
        assert_eq!(square.divide(&beta.add(&Poly::one()).unwrap()).unwrap(), None);
    }

    #[test]
    fn it_evaluates_at_params_dt_and_t() {
        let p = Poly::var(0).mul(&Poly::var(DT).pow(2).unwrap()).unwrap().add(&Poly::var(TIME)).unwrap();
        assert_eq!(p.eval(&[0.25], 2.0, 3.0), 4.0);
        assert!(p.reads(DT) && !p.reads(1));
    }
}
