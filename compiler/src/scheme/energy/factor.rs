//! The identity's coefficients factored ([`super::poly_factors`]), for printing and for
//! deciding their sign.

use super::super::rational::{Rat, Res};
use super::poly::{Poly, Var};
use super::poly_factors::split;
use super::ratfn::RatFn;

/// constant · Π num^e / Π den^e, every factor primitive over the integers with a positive
/// leading coefficient.
#[derive(Clone, Debug, PartialEq)]
pub struct Factored {
    pub constant: Rat,
    pub num: Vec<(Poly, u32)>,
    pub den: Vec<(Poly, u32)>,
}

impl Factored {
    /// Its exact value with every variable given by `value`; none where a denominator is zero.
    pub fn eval_exact(&self, value: &dyn Fn(Var) -> Rat) -> Res<Option<Rat>> {
        let mut v = self.constant;
        for (f, e) in &self.num {
            v = v.mul(f.eval_exact(value)?.powi(*e as i32)?)?;
        }
        for (f, e) in &self.den {
            let d = f.eval_exact(value)?;
            if d.is_zero() {
                return Ok(None);
            }
            v = v.mul(d.powi(-(*e as i32))?)?;
        }
        Ok(Some(v))
    }
}

/// `r` factored; a zero `r` has constant 0 and no factor.
pub fn factor(r: &RatFn) -> Res<Factored> {
    let mut out = Factored { constant: Rat::ONE, num: Vec::new(), den: Vec::new() };
    if r.is_zero() {
        out.constant = Rat::ZERO;
        return Ok(out);
    }
    let mut c = Rat::ONE;
    split(r.numerator(), &mut out.num, &mut c)?;
    let mut d = Rat::ONE;
    for f in r.denominator() {
        split(f, &mut out.den, &mut d)?;
    }
    out.constant = c.mul(d.inv()?)?;
    // Cancel what the numerator and denominator share.
    for (f, e) in out.num.iter_mut() {
        if let Some((_, g)) = out.den.iter_mut().find(|(g, _)| g == f) {
            let common = (*e).min(*g);
            *e -= common;
            *g -= common;
        }
    }
    out.num.retain(|(_, e)| *e > 0);
    out.den.retain(|(_, e)| *e > 0);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::super::poly::DT;
    use super::*;

    fn r(n: i128, d: i128) -> Poly {
        Poly::constant(Rat::new(n, d).unwrap())
    }

    #[test]
    fn newmark_s_acceleration_coefficient_splits_into_its_two_conditions() {
        // dt²(γ − ½)(β − γ/2), expanded: dt² (2γ − 1)(2β − γ)/4.
        let (beta, gam, dt) = (Poly::var(0), Poly::var(1), Poly::var(DT));
        let p = dt
            .pow(2)
            .unwrap()
            .mul(&gam.sub(&r(1, 2)).unwrap())
            .unwrap()
            .mul(&beta.sub(&gam.mul(&r(1, 2)).unwrap()).unwrap())
            .unwrap();
        let f = factor(&RatFn::poly(p)).unwrap();
        assert_eq!(f.constant, Rat::new(1, 4).unwrap());
        let two_gam_minus_one = gam.scale(Rat::int(2)).unwrap().sub(&Poly::one()).unwrap();
        let two_beta_minus_gam = beta.scale(Rat::int(2)).unwrap().sub(&gam).unwrap();
        let mut want = vec![(dt, 2), (two_gam_minus_one, 1), (two_beta_minus_gam, 1)];
        let mut got = f.num.clone();
        want.sort();
        got.sort();
        assert_eq!(got, want);
    }

    #[test]
    fn a_cube_over_a_cube_is_found_by_its_roots() {
        // (1 − ρ)³/(1 + ρ)³ expanded both ways: −(ρ − 1)³/(ρ + 1)³.
        let rho = Poly::var(0);
        let num = Poly::one().sub(&rho).unwrap().pow(3).unwrap();
        let den = Poly::one().add(&rho).unwrap().pow(3).unwrap();
        let f = factor(&RatFn::poly(num).div(&RatFn::poly(den)).unwrap()).unwrap();
        assert_eq!(f.constant, Rat::int(-1));
        assert_eq!(f.num, vec![(rho.sub(&Poly::one()).unwrap(), 3)]);
        assert_eq!(f.den, vec![(rho.add(&Poly::one()).unwrap(), 3)]);
        let at = f.eval_exact(&|_| Rat::new(1, 2).unwrap()).unwrap().unwrap();
        assert_eq!(at, Rat::new(1, 27).unwrap());
    }
}
