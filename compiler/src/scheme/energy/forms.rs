//! The ansatz's algebra: scalars affine in its unknowns (the residuals' multipliers, the kept
//! energy's free coefficients), and symmetric quadratic forms over a step's free variables with
//! such entries: the parts of the dissipation on M and on K.

use super::super::rational::Res;
use super::ratfn::RatFn;
use super::window::Lin;

/// c0 + Σ c_k · unknown_k.
#[derive(Clone, Debug, PartialEq)]
pub struct Unk {
    pub c0: RatFn,
    pub c: Vec<RatFn>,
}

impl Unk {
    pub fn constant(c0: RatFn, unknowns: usize) -> Unk {
        Unk { c0, c: vec![RatFn::zero(); unknowns] }
    }

    pub fn unknown(k: usize, unknowns: usize) -> Unk {
        let mut u = Unk::constant(RatFn::zero(), unknowns);
        u.c[k] = RatFn::one();
        u
    }

    pub fn is_zero(&self) -> bool {
        self.c0.is_zero() && self.c.iter().all(RatFn::is_zero)
    }

    /// Whether it reads no unknown.
    pub fn is_known(&self) -> bool {
        self.c.iter().all(RatFn::is_zero)
    }

    pub fn add(&self, o: &Unk) -> Res<Unk> {
        let c = self.c.iter().zip(&o.c).map(|(a, b)| a.add(b)).collect::<Res<_>>()?;
        Ok(Unk { c0: self.c0.add(&o.c0)?, c })
    }

    pub fn scale(&self, s: &RatFn) -> Res<Unk> {
        let c = self.c.iter().map(|a| a.mul(s)).collect::<Res<_>>()?;
        Ok(Unk { c0: self.c0.mul(s)?, c })
    }

    /// It with unknown `k` replaced by `value` (itself affine in the others).
    pub fn substitute(&self, k: usize, value: &Unk) -> Res<Unk> {
        if self.c[k].is_zero() {
            return Ok(self.clone());
        }
        let mut rest = self.clone();
        rest.c[k] = RatFn::zero();
        rest.add(&value.scale(&self.c[k])?)
    }
}

/// A symmetric n × n form over the free variables, entries affine in the unknowns.
#[derive(Clone, Debug, PartialEq)]
pub struct Form {
    pub n: usize,
    pub entries: Vec<Unk>,
}

impl Form {
    pub fn zero(n: usize, unknowns: usize) -> Form {
        Form { n, entries: vec![Unk::constant(RatFn::zero(), unknowns); n * n] }
    }

    pub fn at(&self, p: usize, q: usize) -> &Unk {
        &self.entries[p * self.n + q]
    }

    /// self += s · ½(a bᵀ + b aᵀ): the bilinear term s · a·A·b, symmetrized.
    pub fn add_product(&mut self, s: &Unk, a: &Lin, b: &Lin) -> Res<()> {
        let half = RatFn::constant(super::super::rational::Rat::new(1, 2)?);
        for p in 0..self.n {
            for q in 0..self.n {
                let both = a.0[p].mul(&b.0[q])?.add(&a.0[q].mul(&b.0[p])?)?;
                if both.is_zero() {
                    continue;
                }
                let term = s.scale(&both.mul(&half)?)?;
                let e = &mut self.entries[p * self.n + q];
                *e = e.add(&term)?;
            }
        }
        Ok(())
    }

    /// Every entry with unknown `k` replaced by `value`.
    pub fn substitute(&mut self, k: usize, value: &Unk) -> Res<()> {
        for e in &mut self.entries {
            *e = e.substitute(k, value)?;
        }
        Ok(())
    }

    /// The form's value at the free variables' values `x`, the unknowns' values `unknowns`.
    pub fn eval(&self, x: &[f64], unknowns: &[f64], params: &[f64], dt: f64) -> f64 {
        let entry = |u: &Unk| {
            let at = |r: &RatFn| if r.is_zero() { 0.0 } else { r.eval(params, dt, 0.0) };
            at(&u.c0) + u.c.iter().zip(unknowns).map(|(c, v)| at(c) * v).sum::<f64>()
        };
        let mut sum = 0.0;
        for p in 0..self.n {
            for q in 0..self.n {
                sum += x[p] * entry(self.at(p, q)) * x[q];
            }
        }
        sum
    }
}

/// The coefficients c with l = Σ c_i·basis_i, when there are (exact elimination; a free
/// coefficient is 0).
pub fn solve(l: &Lin, basis: &[Lin]) -> Res<Option<Vec<RatFn>>> {
    let m = basis.len();
    let mut equations: Vec<Unk> = (0..l.0.len())
        .map(|row| -> Res<Unk> { Ok(Unk { c0: l.0[row].neg()?, c: basis.iter().map(|b| b.0[row].clone()).collect() }) })
        .collect::<Res<_>>()?;
    let mut value: Vec<Option<Unk>> = vec![None; m];
    while let Some(e) = equations.pop() {
        let Some(k) = (0..m).find(|&k| !e.c[k].is_zero()) else {
            if e.c0.is_zero() {
                continue;
            }
            return Ok(None);
        };
        let mut others = e.clone();
        others.c[k] = RatFn::zero();
        let v = others.scale(&e.c[k].inv()?.neg()?)?;
        for r in equations.iter_mut() {
            *r = r.substitute(k, &v)?;
        }
        for s in value.iter_mut().flatten() {
            *s = s.substitute(k, &v)?;
        }
        value[k] = Some(v);
    }
    Ok(Some(value.into_iter().map(|v| v.map_or(RatFn::zero(), |v| v.c0)).collect()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scheme::rational::Rat;

    #[test]
    fn a_product_is_symmetric_and_evaluates_to_its_value() {
        // s · a·b with s = 2 + ν, a = (1, x), b = (dt, 0) over two variables.
        let dt = RatFn::var(super::super::poly::DT);
        let a = Lin(vec![RatFn::one(), RatFn::var(0)]);
        let b = Lin(vec![dt, RatFn::zero()]);
        let s = Unk::constant(RatFn::constant(Rat::int(2)), 1).add(&Unk::unknown(0, 1)).unwrap();
        let mut f = Form::zero(2, 1);
        f.add_product(&s, &a, &b).unwrap();
        assert_eq!(f.at(0, 1), f.at(1, 0));
        let (x, nu, p, dt) = ([0.3, -0.7], [0.5], [1.5], 0.2);
        let want = (2.0 + 0.5) * (0.3 + 1.5 * -0.7) * (dt * 0.3);
        assert!((f.eval(&x, &nu, &p, dt) - want).abs() < 1e-14);
        // ν = 1 − 2·(the constant part): 2 + ν becomes 3.
        f.substitute(0, &Unk::constant(RatFn::one(), 1)).unwrap();
        assert!(f.entries.iter().all(Unk::is_known));
        assert!((f.eval(&x, &[0.0], &p, dt) - 3.0 * (0.3 + 1.5 * -0.7) * (dt * 0.3)).abs() < 1e-14);
    }
}
