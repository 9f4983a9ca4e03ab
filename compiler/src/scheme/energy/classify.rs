//! The derived identity classified: its dissipation D as a sum of squares (an LDLᵀ of each of
//! its blocks on M and on K, over rational functions of the params), the kept energy's terms
//! besides E, and what they prove of the scheme's energy law, at a point of the params (the
//! claim at `check`) and over their declared ranges (`emit --stage energy`).

use super::super::rational::{Rat, Res};
use super::engine::Ansatz;
use super::forms::Form;
use super::poly::DT;
use super::ratfn::RatFn;
use super::sign::{Region, Sign};
use super::window::Lin;
use crate::check::EnergyLaw;
use crate::scheme::ir::SchemeIr;

/// The matrix of a quadratic term.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Block {
    Mass,
    Stiffness,
}

impl Block {
    pub fn letter(self) -> char {
        match self {
            Block::Mass => 'M',
            Block::Stiffness => 'K',
        }
    }
}

/// coef · (vector·x)ᵀ B (vector·x), vector over the step's free variables.
#[derive(Clone, Debug)]
pub struct Square {
    pub block: Block,
    pub coef: RatFn,
    pub vector: Lin,
}

/// D = Σ squares, unless a block has a zero diagonal entry beside a non-zero one off it (at
/// `cross`, free variables (p, q)): then D takes both signs along e_p ± t·e_q, for all params.
#[derive(Clone, Debug)]
pub struct Dissipation {
    pub squares: Vec<Square>,
    pub cross: Option<(Block, usize, usize)>,
}

/// The derived identity: the solved ansatz and what it keeps and dissipates.
pub struct Identity {
    pub ansatz: Ansatz,
    pub dissipation: Dissipation,
    /// The kept energy's coefficient of ½dt²‖a‖²_M, when it has one (and it is not 0).
    pub acceleration: Option<RatFn>,
    /// Its coefficient of ½‖u − u⁻‖²_K.
    pub step_before: Option<RatFn>,
    /// Whether ½‖u‖²_K is in it (K applied by the `stiffness` slot, not an opaque force).
    pub elastic: bool,
    /// The weight θ of its levels, x̂ = (1 − θ)·x + θ·x⁻ (generalized-α's α_m).
    pub weight: Option<RatFn>,
}

/// Whether a claim holds by the identity, fails with a counterexample, or is not decided by it.
#[derive(Clone, Debug, PartialEq)]
pub enum Proof {
    Holds,
    Fails(String),
    Undecided(String),
}

/// A coefficient's value at a point of the params, over dt > 0.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Value {
    Zero,
    Positive,
    Negative,
}

impl Identity {
    /// The identity of `ir`'s step, classified.
    pub fn derive(ir: &SchemeIr) -> Result<Identity, super::engine::NoIdentity> {
        let ansatz = super::engine::derive(ir)?;
        let value = |k: Option<usize>| -> Option<RatFn> {
            let v = ansatz.solved[k?].as_ref()?.c0.clone();
            (!v.is_zero()).then_some(v)
        };
        let (acceleration, step_before) = (value(ansatz.q_a), value(ansatz.q_delta));
        let elastic = ansatz.residuals.iter().any(|r| r.terms.iter().any(|t| t.form == "stiffness"));
        let mut squares = Vec::new();
        let mut cross = None;
        for (block, form) in [(Block::Stiffness, &ansatz.d_k), (Block::Mass, &ansatz.d_m)] {
            let (mine, c) = ldl(form, block)?;
            squares.extend(mine);
            cross = cross.or(c.map(|(p, q)| (block, p, q)));
        }
        let weight = ansatz.weight.clone();
        Ok(Identity { ansatz, dissipation: Dissipation { squares, cross }, acceleration, step_before, elastic, weight })
    }

    /// Whether the kept energy is E itself at `params`: none where that is not decided.
    fn keeps_e_at(&self, params: &[f64]) -> Res<Option<bool>> {
        let mut keeps = Some(true);
        for c in self.acceleration.iter().chain(&self.step_before).chain(&self.weight) {
            match value_at(c, params)? {
                Some(Value::Zero) => {}
                Some(_) => return Ok(Some(false)),
                None => keeps = None,
            }
        }
        Ok(keeps)
    }

    /// D at `params`: its squares, each with its coefficient's value there, or where it takes
    /// both signs. Exactly where the params are small rationals (D's blocks factored again with
    /// the params put in, so that a pivot that vanishes there does not hide a square), else from
    /// the squares in floating point.
    fn at(&self, params: &[f64]) -> Res<AtPoint> {
        let exact: Option<Vec<Rat>> = params.iter().map(|&p| Rat::from_f64(p)).collect();
        if let Some(exact) = exact
            && let Ok(at) = self.at_exactly(&exact)
        {
            return Ok(at);
        }
        // Floating point (irrational params, or exact values too large): the squares' signs.
        let mut squares = Vec::new();
        for s in &self.dissipation.squares {
            squares.push((s.clone(), value_at(&s.coef, params)?));
        }
        Ok(AtPoint { squares, cross: self.dissipation.cross.map(|(b, ..)| b), undefined: false })
    }

    /// [`Identity::at`] at exact params; each square shown as the symbolic square of the same
    /// sign there where there is one (the identity's own, with its coefficient in the params).
    fn at_exactly(&self, exact: &[Rat]) -> Res<AtPoint> {
        let mut squares = Vec::new();
        for (block, form) in [(Block::Stiffness, &self.ansatz.d_k), (Block::Mass, &self.ansatz.d_m)] {
            let mut entries = Vec::new();
            for e in &form.entries {
                match e.c0.at_params(exact)? {
                    Some(v) => entries.push(super::forms::Unk::constant(v, 0)),
                    None => return Ok(AtPoint { squares: Vec::new(), cross: None, undefined: true }),
                }
            }
            let (mine, cross) = ldl(&Form { n: form.n, entries }, block)?;
            if cross.is_some() {
                return Ok(AtPoint { squares: Vec::new(), cross: Some(block), undefined: false });
            }
            for s in mine {
                let value = sign_in_dt(&s.coef)?;
                let symbolic = self.dissipation.squares.iter().find(|q| {
                    q.block == s.block
                        && q.coef
                            .at_params(exact)
                            .ok()
                            .flatten()
                            .is_some_and(|c| sign_in_dt(&c).ok().flatten() == value)
                });
                squares.push((symbolic.cloned().unwrap_or(s), value));
            }
        }
        Ok(AtPoint { squares, cross: None, undefined: false })
    }

    /// What the identity proves of `law` at `params` (E conserved: D ≡ 0 and the kept energy
    /// E; E dissipated: D ⪰ 0 and the kept energy E); `shown` prints a square of D.
    pub fn proves(&self, law: EnergyLaw, params: &[f64], shown: &dyn Fn(&Square) -> String) -> Res<Proof> {
        let d = self.at(params)?;
        if d.undefined {
            return Ok(Proof::Undecided("D is not defined at these params (a denominator of it vanishes)".into()));
        }
        if let Some(block) = d.cross {
            return Ok(Proof::Fails(format!(
                "D's part on {} has a zero diagonal entry beside a non-zero one at these params: it takes both signs",
                block.letter()
            )));
        }
        let mut positive = None;
        let mut undecided = None;
        for (s, value) in &d.squares {
            match value {
                Some(Value::Negative) => {
                    return Ok(Proof::Fails(format!(
                        "D has the term {} with a negative coefficient at these params: a step along it, with the \
                         loads that make it one, gains energy beyond their work",
                        shown(s)
                    )));
                }
                Some(Value::Positive) if positive.is_none() => positive = Some(s),
                None if undecided.is_none() => undecided = Some(s),
                _ => {}
            }
        }
        if let Some(s) = undecided {
            return Ok(Proof::Undecided(format!(
                "D's term {} has a coefficient whose sign at these params depends on dt, or is not defined there",
                shown(s)
            )));
        }
        let Some(keeps_e) = self.keeps_e_at(params)? else {
            return Ok(Proof::Undecided("whether the energy kept is E depends on dt at these params".into()));
        };
        let correction = || {
            let mut parts = Vec::new();
            if self.acceleration.is_some() {
                parts.push("½dt²‖a‖²_M");
            }
            if self.step_before.is_some() {
                parts.push("½‖u - u⁻‖²_K");
            }
            if self.weight.is_some() {
                parts.push("the previous step's states");
            }
            parts.join(" and ")
        };
        Ok(match law {
            EnergyLaw::Conserving => match (positive, keeps_e) {
                (Some(s), _) => Proof::Fails(format!("D has the term {}, positive at these params", shown(s))),
                (None, false) => Proof::Fails(format!(
                    "D ≡ 0, but the energy kept is not E: it has terms in {}, so E changes by their change",
                    correction()
                )),
                (None, true) => Proof::Holds,
            },
            EnergyLaw::Dissipative => match (positive, keeps_e) {
                (_, true) => Proof::Holds,
                (None, false) => Proof::Fails(format!(
                    "D ≡ 0, but the energy kept is not E: it has terms in {}, so E changes by their change, of \
                     either sign",
                    correction()
                )),
                (Some(_), false) => Proof::Undecided(format!(
                    "D ⪰ 0 dissipates the kept energy, which has terms in {} besides E",
                    correction()
                )),
            },
        })
    }
}

/// D at a point of the params: its squares with their coefficients' signs there (none where
/// not decided), or the block where it takes both signs.
struct AtPoint {
    squares: Vec<(Square, Option<Value>)>,
    cross: Option<Block>,
    /// A denominator of D vanishes at the point.
    undefined: bool,
}

/// The sign for every dt > 0 of a rational function of dt alone: decided where dt enters as
/// a power only, none otherwise.
fn sign_in_dt(r: &RatFn) -> Res<Option<Value>> {
    if r.is_zero() {
        return Ok(Some(Value::Zero));
    }
    let f = super::factor::factor(r)?;
    let dt_power = |p: &super::poly::Poly| p.terms().count() == 1 && p.vars().iter().all(|&v| v == DT);
    if !f.num.iter().chain(&f.den).all(|(p, _)| dt_power(p)) {
        return Ok(None);
    }
    Ok(Some(if f.constant.signum() < 0 { Value::Negative } else { Value::Positive }))
}

/// `r`'s value at `params` for every dt > 0: exactly where the params are small rationals and
/// dt enters as a power only; else in floating point (to a relative 1e-12) where `r` does not
/// read dt but as a power. None where that does not decide it (dt or t otherwise, a value not
/// defined there).
fn value_at(r: &RatFn, params: &[f64]) -> Res<Option<Value>> {
    if r.is_zero() {
        return Ok(Some(Value::Zero));
    }
    if r.reads(super::poly::TIME) {
        return Ok(None);
    }
    let exact: Option<Vec<Rat>> = params.iter().map(|&p| Rat::from_f64(p)).collect();
    if let Some(p) = exact
        && let Ok(at) = r.at_params(&p)
    {
        return match at {
            Some(v) => sign_in_dt(&v),
            None => Ok(None),
        };
    }
    // Floating point: only where dt is a factor of every term.
    let f = super::factor::factor(r)?;
    if f.num.iter().chain(&f.den).any(|(p, _)| p.reads(DT) && !(p.terms().count() == 1 && p.vars() == [DT])) {
        return Ok(None);
    }
    let v = r.eval(params, 1.0, 0.0);
    let scale = r.numerator().terms().map(|(_, c)| c.to_f64().abs()).sum::<f64>().max(1.0);
    Ok(if !v.is_finite() {
        None
    } else if v.abs() <= 1e-12 * scale {
        Some(Value::Zero)
    } else if v < 0.0 {
        Some(Value::Negative)
    } else {
        Some(Value::Positive)
    })
}

/// The sign of `r` over `region` (dt > 0): factor by factor where each factor's is certified,
/// else of num · Π den as a whole, with a witness where one is found.
pub fn sign_over(r: &RatFn, region: &Region) -> Res<Sign> {
    let f = super::factor::factor(r)?;
    let mut negative = f.constant.signum() < 0;
    let mut certified = true;
    for (p, e) in f.num.iter().chain(&f.den) {
        if e % 2 == 0 {
            continue;
        }
        let s = region.sign(p)?;
        match (s.nonnegative, s.nonpositive) {
            (true, _) => {}
            (false, true) => negative = !negative,
            (false, false) => certified = false,
        }
    }
    if certified && !negative {
        return Ok(Sign { nonnegative: true, nonpositive: false, negative_at: None });
    }
    let whole = region.sign(&r.sign_polynomial()?)?;
    if certified {
        // A witness where it is negative.
        return Ok(Sign { nonnegative: false, nonpositive: true, negative_at: whole.negative_at });
    }
    Ok(whole)
}

/// A block's squares, and the free variables (p, q) of a zero diagonal entry beside a non-zero one.
type Squares = (Vec<Square>, Option<(usize, usize)>);

/// LDLᵀ of `form` (entries known): its squares, or where a zero diagonal entry sits beside a
/// non-zero one.
fn ldl(form: &Form, block: Block) -> Res<Squares> {
    let n = form.n;
    let mut m: Vec<RatFn> = form.entries.iter().map(|e| e.c0.clone()).collect();
    let mut squares = Vec::new();
    loop {
        // The simplest non-zero diagonal entry as the pivot.
        let pivot = (0..n).filter(|&p| !m[p * n + p].is_zero()).min_by_key(|&p| {
            let d = &m[p * n + p];
            (d.denominator().len(), d.numerator().terms().count())
        });
        let Some(p) = pivot else {
            let cross = (0..n).flat_map(|p| (0..n).map(move |q| (p, q))).find(|&(p, q)| !m[p * n + q].is_zero());
            return Ok((squares, cross));
        };
        let d = m[p * n + p].clone();
        let inv = d.inv()?;
        let vector = Lin((0..n).map(|q| m[p * n + q].mul(&inv)).collect::<Res<_>>()?);
        for i in 0..n {
            for j in 0..n {
                if vector.0[i].is_zero() || vector.0[j].is_zero() {
                    continue;
                }
                let e = d.mul(&vector.0[i])?.mul(&vector.0[j])?;
                m[i * n + j] = m[i * n + j].sub(&e)?;
            }
        }
        squares.push(Square { block, coef: d, vector });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn identity(name: &str) -> (SchemeIr, Identity) {
        let (_, ir) = super::super::library_schemes().into_iter().find(|(n, _)| n == name).expect("a library scheme");
        let id = Identity::derive(&ir).unwrap_or_else(|e| panic!("{name}: {e:?}"));
        (ir, id)
    }

    /// Newmark's D: one square on K with coefficient γ − ½, one on M with
    /// dt²(γ − ½)(β − γ/2); conserving at the defaults, dissipative at γ = 0.6 with β = γ/2,
    /// undecided with β > γ/2 (the kept energy is not E), refuted as dissipative at β = ¼ (an acceleration square of negative coefficient).
    #[test]
    fn newmark_s_law_follows_its_params() {
        let (ir, id) = identity("newmark");
        let printer = super::super::print::Printer::new(&ir, &id);
        let names = |s: &Square| printer.described(s);
        assert_eq!(id.dissipation.squares.len(), 2, "{:?}", id.dissipation.squares);
        assert!(id.dissipation.cross.is_none());
        assert_eq!(id.proves(EnergyLaw::Conserving, &[0.25, 0.5], &names).unwrap(), Proof::Holds);
        assert_eq!(id.proves(EnergyLaw::Dissipative, &[0.25, 0.5], &names).unwrap(), Proof::Holds);
        assert!(matches!(id.proves(EnergyLaw::Conserving, &[0.3, 0.6], &names).unwrap(), Proof::Fails(_)));
        // β = γ/2 = 0.3: the kept energy is E, and D = (γ − ½)‖Δu‖²_K ⪰ 0.
        assert_eq!(id.proves(EnergyLaw::Dissipative, &[0.3, 0.6], &names).unwrap(), Proof::Holds);
        // β = 0.4 > γ/2: D ⪰ 0, but the kept energy is E + ½dt²(β − γ/2)‖a‖²_M.
        assert!(matches!(id.proves(EnergyLaw::Dissipative, &[0.4, 0.6], &names).unwrap(), Proof::Undecided(_)));
        let Proof::Fails(why) = id.proves(EnergyLaw::Dissipative, &[0.25, 0.6], &names).unwrap() else {
            panic!("β = ¼, γ = 0.6 is not dissipative")
        };
        assert!(why.contains("negative coefficient") && why.contains("‖a' - a‖²_M"), "{why}");
    }
}
