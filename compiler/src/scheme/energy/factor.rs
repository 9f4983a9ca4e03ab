//! Cheap factoring of the identity's coefficients, for printing and for deciding their sign:
//! monomials, the rational content, factors found among the coefficients of the polynomial in
//! each of its variables (β·(γ − ½) + (γ/4 − γ²/2) has the factor γ − ½ of its β
//! coefficient), and the rational roots of a polynomial in one variable. What is left is kept
//! as one factor: the result is exact, only perhaps not fully split.

use super::super::rational::{Rat, Res, gcd};
use super::poly::{Poly, Var};
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

/// Appends the factors of `p` to `out` (merging repeats) and multiplies `constant` by its
/// content.
fn split(p: &Poly, out: &mut Vec<(Poly, u32)>, constant: &mut Rat) -> Res<()> {
    let (monomial, rest) = p.monomial_content();
    for (v, e) in monomial {
        push(out, Poly::var(v), e);
    }
    let (c, mut rest) = primitive(&rest)?;
    *constant = constant.mul(c)?;
    'more: while rest.as_constant().is_none() {
        for candidate in candidates(&rest)? {
            if candidate == rest {
                continue;
            }
            if let Some(q) = rest.divide(&candidate)? {
                push(out, candidate, 1);
                let (c, q) = primitive(&q)?;
                *constant = constant.mul(c)?;
                rest = q;
                continue 'more;
            }
        }
        push(out, rest, 1);
        return Ok(());
    }
    *constant = constant.mul(rest.as_constant().unwrap_or(Rat::ONE))?;
    Ok(())
}

fn push(out: &mut Vec<(Poly, u32)>, f: Poly, e: u32) {
    match out.iter_mut().find(|(g, _)| *g == f) {
        Some((_, k)) => *k += e,
        None => out.push((f, e)),
    }
}

/// (c, q) with p = c·q, q with coprime integer coefficients and a positive leading one.
fn primitive(p: &Poly) -> Res<(Rat, Poly)> {
    if p.is_zero() {
        return Ok((Rat::ZERO, Poly::zero()));
    }
    let (mut den_lcm, mut num_gcd) = (1i128, 0i128);
    for (_, c) in p.terms() {
        den_lcm = den_lcm.checked_mul(c.denom() / gcd(den_lcm, c.denom())).ok_or(super::super::rational::GiveUp)?;
        num_gcd = gcd(num_gcd, c.numer());
    }
    let sign = p.leading_coefficient().signum();
    // p = (num_gcd/den_lcm)·(sign)·q.
    let c = Rat::new(num_gcd * sign, den_lcm)?;
    Ok((c, p.scale(c.inv()?)?))
}

/// Possible factors of `p`: the pieces of its coefficients in each variable, and for a
/// polynomial in one variable the linear factors of its rational roots.
fn candidates(p: &Poly) -> Res<Vec<Poly>> {
    let mut out: Vec<(Poly, u32)> = Vec::new();
    let vars = p.vars();
    for &v in &vars {
        for c in p.coefficients_in(v)? {
            if !c.is_zero() && c.as_constant().is_none() {
                let mut k = Rat::ONE;
                split(&c, &mut out, &mut k)?;
            }
        }
    }
    if let [v] = vars[..] {
        out.extend(rational_roots(p, v)?.into_iter().map(|f| (f, 1)));
    }
    Ok(out.into_iter().map(|(f, _)| f).collect())
}

/// q·v − n for each rational root n/q of `p`, a primitive polynomial in `v` alone (the rational
/// root theorem; coefficients too large to enumerate give none).
fn rational_roots(p: &Poly, v: Var) -> Res<Vec<Poly>> {
    let c = p.coefficients_in(v)?;
    let (Some(low), Some(high)) = (c.first().and_then(Poly::as_constant), c.last().and_then(Poly::as_constant)) else {
        return Ok(Vec::new());
    };
    let divisors = |n: i128| -> Vec<i128> {
        let n = n.abs();
        if n == 0 || n > 1_000_000 {
            return Vec::new();
        }
        (1..=n).filter(|d| n % d == 0).collect()
    };
    let mut out = Vec::new();
    for n in divisors(low.numer()) {
        for q in divisors(high.numer()) {
            for n in [n, -n] {
                if gcd(n, q) != 1 {
                    continue;
                }
                let root = Rat::new(n, q)?;
                if p.eval_exact(&|_| root)?.is_zero() {
                    out.push(Poly::var(v).scale(Rat::int(q))?.sub(&Poly::constant(Rat::int(n)))?);
                }
            }
        }
    }
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
