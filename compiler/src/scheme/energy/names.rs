//! The identity in the scheme's own names: its params in rational functions, its levels (the
//! states at the step's start, primed at its end, the stages' quantities, `u⁻` at the previous
//! step's start) in the vectors the identity tests and weighs with.

use super::super::rational::{Rat, Res};
use super::factor::factor;
use super::poly::{DT, Poly, TIME, Var};
use super::ratfn::RatFn;
use super::sign::Region;
use super::window::{Free, Lin, Window};
use crate::scheme::ir::SchemeIr;

/// A rational function in the scheme's param names, `dt` and `t`: expanded when its numerator
/// is one sum or one term over a constant, else as a product of factors.
pub fn ratfn(r: &RatFn, names: &[String]) -> String {
    ratfn_in(r, names, None)
}

/// [`ratfn`], each factor of a product signed to be ≥ 0 over `region` where that is proved
/// (1 - gs, not gs - 1, for gs in (0, 1)).
pub fn ratfn_in(r: &RatFn, names: &[String], region: Option<&Region>) -> String {
    if r.is_zero() {
        return "0".into();
    }
    let Ok(f) = factor(r) else { return poly(r.numerator(), names) };
    let sums = f.num.iter().filter(|(p, _)| p.terms().count() > 1).count();
    let monomials = f.num.iter().any(|(p, _)| p.terms().count() == 1);
    let one_piece = (sums == 0) || (sums == 1 && !monomials && f.num.iter().all(|(_, e)| *e == 1));
    if f.den.is_empty() && one_piece {
        return poly(r.numerator(), names);
    }
    let mut constant = f.constant;
    let (mut num, mut den) = (f.num.clone(), f.den.clone());
    let flip = |p: &mut Poly, e: u32, constant: &mut Rat| {
        if let Ok(q) = p.neg() {
            *p = q;
            if e % 2 == 1 {
                *constant = Rat::ZERO.sub(*constant).unwrap_or(*constant);
            }
        }
    };
    if let Some(region) = region {
        for (p, e) in num.iter_mut().chain(den.iter_mut()) {
            if p.terms().count() > 1 && region.sign(p).is_ok_and(|s| s.nonpositive && !s.nonnegative) {
                flip(p, *e, &mut constant);
            }
        }
    }
    // The params' monomials, the sums, dt's powers.
    num.sort_by_key(|(p, _)| match (p.terms().count() > 1, p.reads(DT)) {
        (false, false) => 0,
        (true, _) => 1,
        (false, true) => 2,
    });
    // A negative constant left goes into a factor of odd power (1 - gam rather than -(gam - 1)),
    // unless the factor is proved ≥ 0 over the region.
    let stays_signed = |p: &Poly| region.is_some_and(|r| r.sign(p).is_ok_and(|s| s.nonnegative));
    if constant.signum() < 0
        && let Some((p, _)) = num.iter_mut().find(|(p, e)| e % 2 == 1 && p.terms().count() > 1 && !stays_signed(p))
    {
        let e = 1;
        flip(p, e, &mut constant);
    }
    let piece = |p: &Poly, e: u32| {
        let text = poly(p, names);
        let text = if p.terms().count() > 1 { format!("({text})") } else { text };
        if e == 1 { text } else { format!("{text}^{e}") }
    };
    let sign = if constant.signum() < 0 { "-" } else { "" };
    let (n, d) = (constant.numer().abs(), constant.denom());
    let mut top: Vec<String> = if n == 1 { Vec::new() } else { vec![n.to_string()] };
    top.extend(num.iter().map(|(p, e)| piece(p, *e)));
    let mut bottom: Vec<String> = if d == 1 { Vec::new() } else { vec![d.to_string()] };
    bottom.extend(den.iter().map(|(p, e)| piece(p, *e)));
    let top = if top.is_empty() { "1".to_string() } else { top.join("*") };
    match bottom.len() {
        0 => format!("{sign}{top}"),
        1 => format!("{sign}{top}/{}", bottom[0]),
        _ => format!("{sign}{top}/({})", bottom.join("*")),
    }
}

/// How coefficients are shown: the params' names, the region whose signs orient factors, and
/// the point (the defaults) whose values orient a combination.
#[derive(Clone, Debug, Default)]
pub struct Style {
    pub params: Vec<String>,
    pub at: Vec<f64>,
    pub region: Option<Region>,
}

impl Style {
    pub fn of(ir: &SchemeIr) -> Style {
        Style {
            params: ir.params.iter().map(|p| p.name.clone()).collect(),
            at: ir.params.iter().map(|p| p.default).collect(),
            region: Some(Region::of(ir)),
        }
    }

    pub fn ratfn(&self, r: &RatFn) -> String {
        ratfn_in(r, &self.params, self.region.as_ref())
    }

    /// [`Style::ratfn`], parenthesised when a sum.
    pub fn coefficient(&self, r: &RatFn) -> String {
        parenthesised(self.ratfn(r))
    }

    /// Whether `r` is written with a minus in front.
    pub fn negative(&self, r: &RatFn) -> bool {
        self.ratfn(r).starts_with('-')
    }
}

/// `text` in parentheses when it is a sum outside any parentheses of its own.
pub fn parenthesised(text: String) -> String {
    let mut depth = 0i32;
    let bytes = text.as_bytes();
    let sum = (0..bytes.len()).any(|i| {
        match bytes[i] {
            b'(' => depth += 1,
            b')' => depth -= 1,
            _ => {}
        }
        depth == 0 && i > 0 && bytes[i] == b' ' && matches!(bytes.get(i + 1), Some(b'+' | b'-'))
    });
    if sum { format!("({text})") } else { text }
}

fn var_name(v: Var, names: &[String]) -> String {
    match v {
        DT => "dt".into(),
        TIME => "t".into(),
        i => names.get(i as usize).cloned().unwrap_or_else(|| format!("p{i}")),
    }
}

/// A polynomial, its terms by degree (the time's first), starting with a positive term where
/// it has one.
pub fn poly(p: &Poly, names: &[String]) -> String {
    let mut terms: Vec<(&[(Var, u32)], Rat)> = p.terms().collect();
    if terms.is_empty() {
        return "0".into();
    }
    let degree = |m: &[(Var, u32)]| m.iter().map(|&(_, e)| e).sum::<u32>();
    terms.sort_by_key(|(m, _)| (!m.iter().any(|&(v, _)| v == TIME), std::cmp::Reverse(degree(m)), m.to_vec()));
    if let Some(k) = terms.iter().position(|(_, c)| c.signum() > 0) {
        terms.rotate_left(k);
    }
    let mut out = String::new();
    for (i, (m, c)) in terms.iter().enumerate() {
        let negative = c.signum() < 0;
        let (n, d) = (c.numer().abs(), c.denom());
        let mut vars: Vec<(Var, u32)> = m.to_vec();
        vars.sort_by_key(|&(v, _)| (v == TIME, v == DT, v));
        let mono: Vec<String> = vars
            .iter()
            .map(|&(v, e)| if e == 1 { var_name(v, names) } else { format!("{}^{e}", var_name(v, names)) })
            .collect();
        let mut text = match (n, mono.is_empty()) {
            (_, true) => n.to_string(),
            (1, false) => mono.join("*"),
            _ => format!("{n}*{}", mono.join("*")),
        };
        if d != 1 {
            text = format!("{text}/{d}");
        }
        match (i, negative) {
            (0, false) => out.push_str(&text),
            (0, true) => out.push_str(&format!("-{text}")),
            (_, false) => out.push_str(&format!(" + {text}")),
            (_, true) => out.push_str(&format!(" - {text}")),
        }
    }
    out
}

/// The step's named levels over its free variables.
pub struct Levels {
    pub named: Vec<(Lin, String)>,
    /// The free variables' names, in order.
    pub free: Vec<String>,
    pub style: Style,
}

impl Levels {
    pub fn new(ir: &SchemeIr, window: &Window) -> Levels {
        let n = window.free.len();
        let stages = ir.stages.len();
        let free: Vec<String> = window
            .free
            .iter()
            .map(|f| match *f {
                Free::State(s) => ir.states[s].clone(),
                Free::Unknown(k) => ir.stages[k].quantities[0].clone(),
                Free::Previous(s) => format!("{}⁻", ir.states[s]),
                Free::PreviousUnknown(k) => format!("{}⁻", ir.stages[k].quantities[0]),
            })
            .collect();
        let mut named: Vec<(Lin, String)> = Vec::new();
        let mut push = |l: Lin, name: String| {
            if !named.iter().any(|(m, _)| *m == l) {
                named.push((l, name));
            }
        };
        // The states at the step's start first: the previous step's end levels are these.
        for (l, name) in window.start.iter().zip(&ir.states) {
            push(l.clone(), name.clone());
        }
        for (i, name) in free.iter().enumerate() {
            push(Lin::unit(n, i), name.clone());
        }
        for (k, levels) in window.levels.iter().enumerate() {
            let (stage, back) = if k < window.offset { (k, "⁻") } else { (k - window.offset, "") };
            if stage < stages {
                for (l, name) in levels.iter().zip(&ir.stages[stage].quantities) {
                    push(l.clone(), format!("{name}{back}"));
                }
            }
        }
        Levels { named, free, style: Style::of(ir) }
    }

    /// A level's name, if it is one.
    pub fn name(&self, l: &Lin) -> Option<&str> {
        self.named.iter().find(|(m, _)| m == l).map(|(_, n)| n.as_str())
    }

    /// A vector: a level's name, or the shortest combination of one or two levels found, or
    /// its expansion over the free variables.
    pub fn vector(&self, l: &Lin) -> String {
        if let Some(name) = self.name(l) {
            return name.into();
        }
        let named: Vec<(Lin, String)> = self.named.clone();
        for (i, (a, na)) in named.iter().enumerate() {
            if let Some(c) = multiple(l, a) {
                return combination(&[(c, na.clone())], &self.style);
            }
            for (b, nb) in &named[i + 1..] {
                if let Ok(Some(c)) = super::forms::solve(l, &[a.clone(), b.clone()]) {
                    return combination(&[(c[0].clone(), na.clone()), (c[1].clone(), nb.clone())], &self.style);
                }
            }
        }
        let parts: Vec<(RatFn, String)> =
            l.0.iter().zip(&self.free).filter(|(c, _)| !c.is_zero()).map(|(c, n)| (c.clone(), n.clone())).collect();
        combination(&parts, &self.style)
    }
}

/// c with l = c·a, if there is one.
fn multiple(l: &Lin, a: &Lin) -> Option<RatFn> {
    let k = a.0.iter().position(|c| !c.is_zero())?;
    let c = l.0[k].div(&a.0[k]).ok()?;
    let back: Option<Vec<RatFn>> = a.0.iter().map(|x| x.mul(&c).ok()).collect();
    (back? == l.0 || back_equal(l, a, &c)).then_some(c)
}

fn back_equal(l: &Lin, a: &Lin, c: &RatFn) -> bool {
    l.0.iter().zip(&a.0).all(|(x, y)| y.mul(c).and_then(|p| x.sub(&p)).is_ok_and(|d| d.is_zero()))
}

/// Σ c_i·name_i, its coefficients cleared of their common denominator: `(u + u')/2`,
/// `((gs - 1)*(um - u) + gs*(u' - um))/(gs - 1)`.
pub fn combination(parts: &[(RatFn, String)], style: &Style) -> String {
    let (text, s) = cleared(parts, style);
    // A negative denominator is written as a sign in front.
    let (minus, s) = if style.ratfn(&s).starts_with('-') { ("-", s.neg().unwrap_or(s)) } else { ("", s) };
    let several = parts.iter().filter(|(c, _)| !c.is_zero()).count() > 1;
    let body =
        if several && (!minus.is_empty() || s.as_constant() != Some(Rat::ONE)) { format!("({text})") } else { text };
    if s.as_constant() == Some(Rat::ONE) {
        return format!("{minus}{body}");
    }
    let over = style.coefficient(&s);
    let over = if over.contains(['*', '/']) && !over.starts_with('(') { format!("({over})") } else { over };
    format!("{minus}{body}/{over}")
}

/// s·Σ c_i·name_i as text, and s: the common denominator that makes every coefficient a
/// polynomial with integer coefficients.
pub fn cleared(parts: &[(RatFn, String)], style: &Style) -> (String, RatFn) {
    let parts: Vec<&(RatFn, String)> = parts.iter().filter(|(c, _)| !c.is_zero()).collect();
    if parts.is_empty() {
        return ("0".into(), RatFn::one());
    }
    let s = normalizer(&parts, style).unwrap_or_else(|_| RatFn::one());
    let mut out = String::new();
    for (i, (c, name)) in parts.iter().enumerate() {
        let c = c.mul(&s).unwrap_or_else(|_| c.clone());
        let alone = parts.len() == 1 && c.as_constant() == Some(Rat::ONE);
        let name = if name.contains(' ') && !alone { format!("({name})") } else { name.clone() };
        let text = style.coefficient(&c);
        let (negative, magnitude) = match text.strip_prefix('-') {
            Some(rest) => (true, rest.to_string()),
            None => (false, text),
        };
        let text = if magnitude == "1" { name } else { format!("{magnitude}*{name}") };
        match (i, negative) {
            (0, false) => out.push_str(&text),
            (0, true) => out.push_str(&format!("-{text}")),
            (_, false) => out.push_str(&format!(" + {text}")),
            (_, true) => out.push_str(&format!(" - {text}")),
        }
    }
    (out, s)
}

/// s with the coefficients times s polynomials with integer coefficients and no common factor,
/// summing to a positive value at the defaults; 1/c for one coefficient c.
pub fn normalizer(parts: &[&(RatFn, String)], style: &Style) -> Res<RatFn> {
    if let [(c, _)] = parts {
        return c.inv();
    }
    let s = common_denominator(parts.iter().map(|(c, _)| c))?;
    let scaled: Vec<super::factor::Factored> = parts.iter().map(|(c, _)| factor(&c.mul(&s)?)).collect::<Res<_>>()?;
    // Their greatest common factor: the constants' gcd, each factor at its least power.
    let mut g = RatFn::constant(Rat::int(
        scaled.iter().fold(0i128, |g, f| super::super::rational::gcd(g, f.constant.numer())).max(1),
    ));
    for (p, _) in &scaled[0].num {
        let least = scaled.iter().map(|f| f.num.iter().find(|(q, _)| q == p).map_or(0, |(_, e)| *e)).min().unwrap_or(0);
        g = g.mul(&RatFn::poly(p.clone()).powi(least as i32)?)?;
    }
    let s = s.div(&g)?;
    // Signed so that the coefficients sum to a positive value at the defaults.
    let mut sum = 0.0;
    for (c, _) in parts {
        sum += c.mul(&s)?.eval(&style.at, 1.0, 0.0);
    }
    if sum < 0.0 { s.neg() } else { Ok(s) }
}

/// s with every coefficient times s a polynomial with integer coefficients: the product of
/// their denominators, as stored, and of their coefficients' denominators.
fn common_denominator<'a>(cs: impl Iterator<Item = &'a RatFn>) -> Res<RatFn> {
    let mut s = RatFn::one();
    for c in cs {
        let scaled = c.mul(&s)?;
        for p in scaled.denominator() {
            s = s.mul(&RatFn::poly(p.clone()))?;
        }
        let lcm = scaled
            .numerator()
            .terms()
            .fold(1i128, |l, (_, c)| l / super::super::rational::gcd(l, c.denom()) * c.denom());
        s = s.mul(&RatFn::constant(Rat::int(lcm)))?;
    }
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names() -> Vec<String> {
        vec!["beta".into(), "gam".into()]
    }

    #[test]
    fn coefficients_print_as_a_reader_writes_them() {
        let (beta, gam, dt) = (RatFn::var(0), RatFn::var(1), RatFn::var(DT));
        let half = RatFn::constant(Rat::new(1, 2).unwrap());
        let one_minus = RatFn::one().sub(&gam).unwrap();
        assert_eq!(ratfn(&one_minus, &names()), "1 - gam");
        let q = beta.sub(&gam.mul(&half).unwrap()).unwrap();
        assert_eq!(ratfn(&q, &names()), "beta - gam/2");
        let d = gam.sub(&half).unwrap().mul(&q).unwrap().mul(&dt.powi(2).unwrap()).unwrap();
        assert_eq!(ratfn(&d, &names()), "(2*gam - 1)*(2*beta - gam)*dt^2/4");
        let time = RatFn::var(TIME).add(&beta.mul(&dt).unwrap()).unwrap();
        assert_eq!(ratfn(&time, &names()), "t + beta*dt");
        let w = one_minus.div(&RatFn::constant(Rat::int(2)).sub(&gam).unwrap()).unwrap();
        assert_eq!(ratfn(&w, &names()), "(gam - 1)/(gam - 2)");
        let unit = super::super::sign::Interval { lo: Rat::ZERO, lo_closed: false, hi: Rat::ONE, hi_closed: false };
        let region = Region(vec![None, Some(unit)]);
        assert_eq!(ratfn_in(&w, &names(), Some(&region)), "(1 - gam)/(2 - gam)");
    }

    #[test]
    fn a_combination_is_cleared_of_its_denominators() {
        let half = RatFn::constant(Rat::new(1, 2).unwrap());
        let style = Style { params: names(), at: vec![0.25, 0.5], region: None };
        assert_eq!(combination(&[(half.clone(), "u".into()), (half, "u'".into())], &style), "(u + u')/2");
        let gam = RatFn::var(1);
        let parts = [
            (RatFn::one(), "um - u".into()),
            (gam.neg().unwrap().div(&RatFn::one().sub(&gam).unwrap()).unwrap(), "u' - um".into()),
        ];
        assert_eq!(combination(&parts, &style), "((gam - 1)*(um - u) + gam*(u' - um))/(gam - 1)");
    }
}
