//! Rational functions of a scheme's params, dt and t: a polynomial over a product of
//! polynomial factors. Zero is exact (a zero numerator); no multivariate gcd is taken, a
//! factor is cancelled only where it divides the numerator exactly.

use super::super::rational::{GiveUp, Rat, Res};
use super::poly::{Poly, Var};

/// num / Π den, every factor non-zero.
#[derive(Clone, Debug, PartialEq)]
pub struct RatFn {
    num: Poly,
    den: Vec<Poly>,
}

impl RatFn {
    pub fn poly(p: Poly) -> RatFn {
        RatFn { num: p, den: Vec::new() }
    }

    pub fn constant(c: Rat) -> RatFn {
        RatFn::poly(Poly::constant(c))
    }

    pub fn zero() -> RatFn {
        RatFn::poly(Poly::zero())
    }

    pub fn one() -> RatFn {
        RatFn::poly(Poly::one())
    }

    pub fn var(v: Var) -> RatFn {
        RatFn::poly(Poly::var(v))
    }

    pub fn is_zero(&self) -> bool {
        self.num.is_zero()
    }

    pub fn numerator(&self) -> &Poly {
        &self.num
    }

    pub fn denominator(&self) -> &[Poly] {
        &self.den
    }

    /// The constant it is, if it is one.
    pub fn as_constant(&self) -> Option<Rat> {
        let mut c = self.num.as_constant()?;
        for f in &self.den {
            c = c.mul(f.as_constant()?.inv().ok()?).ok()?;
        }
        Some(c)
    }

    /// The product of the factors.
    fn den_product(&self) -> Res<Poly> {
        self.den.iter().try_fold(Poly::one(), |p, f| p.mul(f))
    }

    /// Cancels the factors that divide the numerator, and folds constant factors into it.
    fn reduced(mut self) -> Res<RatFn> {
        if self.num.is_zero() {
            return Ok(RatFn::zero());
        }
        let mut kept = Vec::new();
        for f in std::mem::take(&mut self.den) {
            if let Some(c) = f.as_constant() {
                self.num = self.num.scale(c.inv()?)?;
            } else if let Some(q) = self.num.divide(&f)? {
                self.num = q;
            } else {
                kept.push(f);
            }
        }
        kept.sort();
        self.den = kept;
        Ok(self)
    }

    pub fn add(&self, o: &RatFn) -> Res<RatFn> {
        // Over the factors of both, each as often as the larger count.
        let mut den = self.den.clone();
        let mut rest_of_other = Vec::new();
        let mut mine = self.den.clone();
        for f in &o.den {
            match mine.iter().position(|g| g == f) {
                Some(i) => {
                    mine.swap_remove(i);
                }
                None => {
                    den.push(f.clone());
                    rest_of_other.push(f.clone());
                }
            }
        }
        // self.num · (factors of o not in self) + o.num · (factors of self not in o).
        let a = rest_of_other.iter().try_fold(self.num.clone(), |p, f| p.mul(f))?;
        let b = mine.iter().try_fold(o.num.clone(), |p, f| p.mul(f))?;
        RatFn { num: a.add(&b)?, den }.reduced()
    }

    pub fn neg(&self) -> Res<RatFn> {
        Ok(RatFn { num: self.num.neg()?, den: self.den.clone() })
    }

    pub fn sub(&self, o: &RatFn) -> Res<RatFn> {
        self.add(&o.neg()?)
    }

    pub fn mul(&self, o: &RatFn) -> Res<RatFn> {
        let den = self.den.iter().chain(&o.den).cloned().collect();
        RatFn { num: self.num.mul(&o.num)?, den }.reduced()
    }

    pub fn inv(&self) -> Res<RatFn> {
        if self.num.is_zero() {
            return Err(GiveUp);
        }
        // The numerator's factors become the denominator's, each on its own, so that a later
        // numerator they divide cancels them one by one.
        let (mut pieces, mut constant) = (Vec::new(), Rat::ONE);
        super::poly_factors::split(&self.num, &mut pieces, &mut constant)?;
        let den = pieces.into_iter().flat_map(|(p, e)| std::iter::repeat_n(p, e as usize)).collect();
        RatFn { num: self.den_product()?.scale(constant.inv()?)?, den }.reduced()
    }

    pub fn div(&self, o: &RatFn) -> Res<RatFn> {
        self.mul(&o.inv()?)
    }

    pub fn powi(&self, k: i32) -> Res<RatFn> {
        let base = if k < 0 { self.inv()? } else { self.clone() };
        (0..k.unsigned_abs()).try_fold(RatFn::one(), |p, _| p.mul(&base))
    }

    /// Its value at `params`, `dt` and `t`.
    pub fn eval(&self, params: &[f64], dt: f64, t: f64) -> f64 {
        self.num.eval(params, dt, t) / self.den.iter().map(|f| f.eval(params, dt, t)).product::<f64>()
    }

    /// Its exact value with every variable given by `value`; none where the denominator is 0.
    pub fn eval_exact(&self, value: &dyn Fn(super::poly::Var) -> Rat) -> Res<Option<Rat>> {
        let mut d = Rat::ONE;
        for f in &self.den {
            d = d.mul(f.eval_exact(value)?)?;
        }
        if d.is_zero() {
            return Ok(None);
        }
        Ok(Some(self.num.eval_exact(value)?.mul(d.inv()?)?))
    }

    /// It with the params (variables 0..) given exact values: a function of dt and t alone;
    /// none where its denominator vanishes there.
    pub fn at_params(&self, params: &[Rat]) -> Res<Option<RatFn>> {
        let put = |p: &Poly| -> Res<Poly> {
            let mut out = p.clone();
            for (i, v) in params.iter().enumerate() {
                out = out.substitute(i as super::poly::Var, &Poly::constant(*v))?;
            }
            Ok(out)
        };
        let num = put(&self.num)?;
        let mut den = Vec::new();
        for f in &self.den {
            let f = put(f)?;
            if f.is_zero() {
                return Ok(None);
            }
            den.push(f);
        }
        Ok(Some(RatFn { num, den }.reduced()?))
    }

    /// num · Π den: of the same sign wherever it is defined.
    pub fn sign_polynomial(&self) -> Res<Poly> {
        self.num.mul(&self.den_product()?)
    }

    /// Whether it reads variable `v`.
    pub fn reads(&self, v: Var) -> bool {
        self.num.reads(v) || self.den.iter().any(|f| f.reads(v))
    }
}

#[cfg(test)]
mod tests {
    use super::super::poly::DT;
    use super::*;

    #[test]
    fn a_fraction_and_its_inverse_multiply_to_one() {
        // (gs·dt)²/4 · 4/(gs·dt)², the pivot the simplifier had to special-case.
        let gsdt = RatFn::var(0).mul(&RatFn::var(DT)).unwrap();
        let pivot = gsdt.powi(2).unwrap().div(&RatFn::constant(Rat::int(4))).unwrap();
        assert_eq!(pivot.mul(&pivot.inv().unwrap()).unwrap().as_constant(), Some(Rat::ONE));
    }

    #[test]
    fn sums_over_different_denominators_cancel_exactly() {
        // 1/(2 − g) + (1 − g)/(2 − g) − 1 − ... : (2 − g)/(2 − g) − 1 = 0.
        let g = RatFn::var(0);
        let two_minus = RatFn::constant(Rat::int(2)).sub(&g).unwrap();
        let a = RatFn::one().div(&two_minus).unwrap();
        let b = RatFn::one().sub(&g).unwrap().div(&two_minus).unwrap();
        assert!(a.add(&b).unwrap().sub(&RatFn::one()).unwrap().is_zero());
        // 1/g − 1/(2 − g) ≠ 0, and its value is right.
        let c = RatFn::one().div(&g).unwrap().sub(&a).unwrap();
        assert!(!c.is_zero());
        assert!((c.eval(&[0.5], 1.0, 0.0) - (2.0 - 1.0 / 1.5)).abs() < 1e-15);
    }
}
