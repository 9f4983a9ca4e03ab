//! Polynomials split into factors, cheaply: monomials, the rational content, factors found
//! among the coefficients of the polynomial in each of its variables (β·(γ − ½) + (γ/4 − γ²/2)
//! has the factor γ − ½ of its β coefficient), and the rational roots of a polynomial in one
//! variable. What is left is kept as one factor: exact, only perhaps not fully split.

use super::super::rational::{Rat, Res, gcd};
use super::poly::{Poly, Var};

/// Appends the factors of `p` to `out` (merging repeats) and multiplies `constant` by its
/// content.
pub fn split(p: &Poly, out: &mut Vec<(Poly, u32)>, constant: &mut Rat) -> Res<()> {
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
pub fn primitive(p: &Poly) -> Res<(Rat, Poly)> {
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
    // Divisors up to √n each; coefficients beyond 10⁸ are not enumerated.
    let divisors = |n: i128| -> Vec<i128> {
        let n = n.abs();
        if n == 0 || n > 100_000_000 {
            return Vec::new();
        }
        let mut out: Vec<i128> =
            (1..).take_while(|d| d * d <= n).filter(|d| n % d == 0).flat_map(|d| [d, n / d]).collect();
        out.sort_unstable();
        out.dedup();
        out
    };
    let (lows, highs) = (divisors(low.numer()), divisors(high.numer()));
    let mut out = Vec::new();
    for &n in &lows {
        for &q in &highs {
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
