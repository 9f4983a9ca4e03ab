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

    /// Whether the kept energy is E itself at `params`.
    fn keeps_e_at(&self, params: &[f64]) -> Res<bool> {
        for c in self.acceleration.iter().chain(&self.step_before).chain(&self.weight) {
            if value_at(c, params)? != Value::Zero {
                return Ok(false);
            }
        }
        Ok(true)
    }

    /// What the identity proves of `law` at `params` (E conserved: D ≡ 0 and the kept energy
    /// E; E dissipated: D ⪰ 0 and the kept energy E); `shown` prints a square of D.
    pub fn proves(&self, law: EnergyLaw, params: &[f64], shown: &dyn Fn(&Square) -> String) -> Res<Proof> {
        if let Some((block, ..)) = self.dissipation.cross {
            return Ok(Proof::Fails(format!(
                "D's part on {} has a zero diagonal entry beside a non-zero one: it takes both signs",
                block.letter()
            )));
        }
        let mut positive = None;
        for s in &self.dissipation.squares {
            match value_at(&s.coef, params)? {
                Value::Negative => {
                    return Ok(Proof::Fails(format!(
                        "D has the term {} with a negative coefficient at these params: a step along it, with the \
                         loads that make it one, gains energy beyond their work",
                        shown(s)
                    )));
                }
                Value::Positive if positive.is_none() => positive = Some(s),
                _ => {}
            }
        }
        let keeps_e = self.keeps_e_at(params)?;
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

/// `r`'s value at `params` for every dt > 0 it was sampled at (dt = 1/100, 1, 100): exactly
/// where the params are small rationals, else in floating point to a relative 1e-12.
fn value_at(r: &RatFn, params: &[f64]) -> Res<Value> {
    if r.is_zero() {
        return Ok(Value::Zero);
    }
    let exact: Option<Vec<Rat>> = params.iter().map(|&p| Rat::from_f64(p)).collect();
    let mut seen = Vec::new();
    for dt in [Rat::new(1, 100)?, Rat::ONE, Rat::int(100)] {
        let v = match &exact {
            Some(p)
                if let Ok(v) =
                    r.eval_exact(&|v| if v == DT { dt } else { p.get(v as usize).copied().unwrap_or(Rat::ZERO) }) =>
            {
                match v {
                    Some(v) => v.signum(),
                    None => continue,
                }
            }
            _ => {
                let v = r.eval(params, dt.to_f64(), 0.0);
                let scale = r.numerator().terms().map(|(_, c)| c.to_f64().abs()).sum::<f64>().max(1.0);
                if v.abs() <= 1e-12 * scale { 0 } else { v.signum() as i128 }
            }
        };
        seen.push(v);
    }
    Ok(if seen.iter().any(|&s| s < 0) {
        Value::Negative
    } else if seen.iter().all(|&s| s == 0) {
        Value::Zero
    } else {
        Value::Positive
    })
}

/// The sign of `r` over `region` (dt > 0): factor by factor where each factor's is certified,
/// else of num · Π den as a whole, with a witness where one is found.
pub fn sign_over(r: &RatFn, region: &Region) -> Res<Sign> {
    let f = super::factor::factor(r)?;
    let mut negative = f.constant.signum() < 0;
    let mut certified = true;
    for (p, e) in f.num.iter().chain(&f.den) {
        let s = region.sign(p)?;
        if e % 2 == 0 {
            continue;
        }
        match (s.nonnegative, s.nonpositive) {
            (true, _) => {}
            (false, true) => negative = !negative,
            (false, false) => certified = false,
        }
    }
    let whole = region.sign(&r.sign_polynomial()?)?;
    if certified {
        // A witness where it is negative, when it is.
        let negative_at = if negative { whole.negative_at } else { None };
        return Ok(Sign { nonnegative: !negative, nonpositive: negative, negative_at });
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
