//! The derivation of a step's energy identity by multipliers. Each residual R_ℓ of the step is
//! tested with w_ℓ = Σ_j ν_ℓj δ_j, δ_j the step's displacement increments; whenever the
//! residuals hold,
//!
//!   Q(x') − Q(x) = −Σ_ℓ w_ℓ·(R_ℓ's other terms) − D,  D = Σ_ℓ w_ℓ·(R_ℓ's M and K terms) − ΔQ,
//!
//! for Q = ½‖v‖²_M + ½‖u‖²_K (+ q_a ½dt²‖a‖²_M). The unknowns ν, q_a are fixed by what D must be:
//! blind to a uniform shift of the displacements, and non-negative, which forces a row whose
//! diagonal is zero to be zero.

use super::super::rational::{GiveUp, Res};
use super::forms::{Form, Unk};
use super::ratfn::RatFn;
use super::window::{ExactTerm, Lin, Window};
use crate::scheme::ir::SchemeIr;

/// A residual of the step: a stage's, or (`stage: None`) the last stage's at the step's start,
/// which holds where the scheme's initial line or the previous step solved it.
pub struct Tested {
    pub stage: Option<usize>,
    pub terms: Vec<ExactTerm>,
    /// Its multipliers' unknowns, per increment.
    pub nu: Vec<usize>,
}

/// The ansatz, built and (by [`Ansatz::solve`]) solved.
pub struct Ansatz {
    pub window: Window,
    /// The step's displacement levels in time order, and their increments.
    pub increments: Vec<Lin>,
    pub residuals: Vec<Tested>,
    /// The kept energy's coefficient of ½dt²‖a‖²_M, when the scheme has an acceleration state.
    pub q_a: Option<usize>,
    pub unknowns: usize,
    pub d_m: Form,
    pub d_k: Form,
    /// The unknowns solved so far, each as affine in the others.
    pub solved: Vec<Option<Unk>>,
}

/// Why no identity was derived.
#[derive(Debug, PartialEq)]
pub enum NoIdentity {
    /// The scheme has no state of this role.
    NoState(&'static str),
    /// The constraints contradict each other: no quadratic energy of this form is kept.
    Inconsistent,
    /// Rational overflow.
    Overflow,
}

impl From<GiveUp> for NoIdentity {
    fn from(_: GiveUp) -> NoIdentity {
        NoIdentity::Overflow
    }
}

fn unit(n: usize, i: usize) -> Lin {
    Lin::unit(n, i)
}

/// State `i` at the step's end, over the window's free variables.
fn end_level(ir: &SchemeIr, window: &Window, i: usize) -> Lin {
    match ir.updates[i] {
        crate::scheme::affine::Quantity::Stage { stage, index } => window.levels[stage][index].clone(),
        crate::scheme::affine::Quantity::State(j) => unit(window.free.len(), j),
    }
}

fn sub(a: &Lin, b: &Lin) -> Res<Lin> {
    Ok(Lin(a.0.iter().zip(&b.0).map(|(x, y)| x.sub(y)).collect::<Res<_>>()?))
}

impl Ansatz {
    /// The ansatz of the step `window` of `ir`.
    pub fn new(ir: &SchemeIr, window: Window) -> Result<Ansatz, NoIdentity> {
        let n = window.free.len();
        let velocity = ir.states.iter().position(|s| s == "v").ok_or(NoIdentity::NoState("velocity `v`"))?;
        let acceleration = ir.initial.as_ref().map(|i| i.state);
        let end = |i: usize| end_level(ir, &window, i);
        // The residuals: each stage's, and the last one's at the step's start where the state
        // invariant holds (an initial line solves it at the start, each step at its end).
        let mut residuals: Vec<(Option<usize>, Vec<ExactTerm>)> =
            window.residuals.iter().enumerate().map(|(k, t)| (Some(k), t.clone())).collect();
        if acceleration.is_some()
            && let Some(last) = window.residuals.last()
        {
            let back = |l: &Lin| (0..ir.states.len()).find(|&i| end(i) == *l).map(|i| unit(n, i));
            let shifted: Option<Vec<ExactTerm>> = last
                .iter()
                .map(|t| {
                    let args = t.args.iter().map(back).collect::<Option<Vec<_>>>()?;
                    Some(ExactTerm { args, ..t.clone() })
                })
                .collect();
            if let Some(terms) = shifted {
                residuals.insert(0, (None, terms));
            }
        }
        // The displacement levels: the start's, each stage's stiffness argument that is one of
        // its levels, the end's.
        let mut levels = vec![unit(n, 0)];
        for (k, terms) in window.residuals.iter().enumerate() {
            for t in terms.iter().filter(|t| t.form == "stiffness") {
                if let [arg] = t.args.as_slice()
                    && window.levels[k].contains(arg)
                    && levels.last() != Some(arg)
                {
                    levels.push(arg.clone());
                }
            }
        }
        if levels.last() != Some(&end(0)) {
            levels.push(end(0));
        }
        let increments: Vec<Lin> = levels.windows(2).map(|w| sub(&w[1], &w[0])).collect::<Res<_>>()?;
        // The unknowns: ν per residual and increment, then q_a.
        let mut unknowns = 0;
        let residuals: Vec<Tested> = residuals
            .into_iter()
            .map(|(stage, terms)| {
                let nu = (unknowns..unknowns + increments.len()).collect();
                unknowns += increments.len();
                Tested { stage, terms, nu }
            })
            .collect();
        let q_a = acceleration.map(|_| {
            unknowns += 1;
            unknowns - 1
        });
        let (mut d_m, mut d_k) = (Form::zero(n, unknowns), Form::zero(n, unknowns));
        for r in &residuals {
            for (j, delta) in increments.iter().enumerate() {
                let nu = Unk::unknown(r.nu[j], unknowns);
                for t in &r.terms {
                    let form = match t.form.as_str() {
                        "mass" => &mut d_m,
                        "stiffness" => &mut d_k,
                        _ => continue,
                    };
                    if let [arg] = t.args.as_slice() {
                        form.add_product(&nu.scale(&t.coef)?, delta, arg)?;
                    }
                }
            }
        }
        // − ΔQ.
        let minus_half = RatFn::constant(crate::scheme::rational::Rat::new(-1, 2)?);
        let half = minus_half.neg()?;
        let change = |form: &mut Form, s: &Unk, i: usize| -> Res<()> {
            form.add_product(&s.scale(&minus_half)?, &end(i), &end(i))?;
            form.add_product(&s.scale(&half)?, &unit(n, i), &unit(n, i))
        };
        let one = Unk::constant(RatFn::one(), unknowns);
        change(&mut d_m, &one, velocity)?;
        // The elastic energy where K is applied; a stiffness of another slot (a discrete
        // gradient) is an opaque force, its work reported.
        if residuals.iter().any(|r| r.terms.iter().any(|t| t.form == "stiffness")) {
            change(&mut d_k, &one, 0)?;
        }
        if let (Some(a), Some(q)) = (acceleration, q_a) {
            let dt2 = RatFn::var(super::poly::DT).powi(2)?;
            change(&mut d_m, &Unk::unknown(q, unknowns).scale(&dt2)?, a)?;
        }
        Ok(Ansatz { window, increments, residuals, q_a, unknowns, d_m, d_k, solved: vec![None; unknowns] })
    }

    /// Fixes the unknowns: D blind to a uniform shift of the displacements (`shift`, over the
    /// free variables), and every row of D whose diagonal is zero zero, until nothing changes.
    /// `negative(r)`: whether r < 0 for every param in range and dt > 0.
    pub fn solve(&mut self, shift: &Lin, negative: &dyn Fn(&RatFn) -> bool) -> Result<(), NoIdentity> {
        let n = self.d_m.n;
        let mut equations: Vec<Unk> = Vec::new();
        for form in [&self.d_m, &self.d_k] {
            for p in 0..n {
                let mut row = Unk::constant(RatFn::zero(), self.unknowns);
                for q in 0..n {
                    if !shift.0[q].is_zero() {
                        row = row.add(&form.at(p, q).scale(&shift.0[q])?)?;
                    }
                }
                equations.push(row);
            }
        }
        loop {
            while let Some(e) = equations.pop() {
                self.impose(e, &mut equations)?;
            }
            for form in [&self.d_m, &self.d_k] {
                for p in 0..n {
                    if form.at(p, p).is_zero() {
                        equations.extend((0..n).map(|q| form.at(p, q).clone()).filter(|e| !e.is_zero()));
                    }
                }
            }
            if equations.is_empty() {
                for form in [&self.d_m, &self.d_k] {
                    if let Some(e) = negative_square_minor(form, negative)? {
                        equations.push(e);
                        break;
                    }
                }
            }
            if equations.is_empty() {
                return Ok(());
            }
        }
    }

    /// Imposes `e` = 0: solves it for one of its unknowns and substitutes everywhere.
    fn impose(&mut self, e: Unk, rest: &mut [Unk]) -> Result<(), NoIdentity> {
        // A constant pivot first: no condition on the params.
        let pivot = (0..self.unknowns)
            .filter(|&k| !e.c[k].is_zero())
            .min_by_key(|&k| e.c[k].as_constant().is_none())
            .ok_or(if e.c0.is_zero() { NoIdentity::Overflow } else { NoIdentity::Inconsistent });
        let k = match pivot {
            Ok(k) => k,
            Err(NoIdentity::Overflow) => return Ok(()), // 0 = 0
            Err(other) => return Err(other),
        };
        // unknown_k = −(e − c_k unknown_k)/c_k.
        let mut others = e.clone();
        others.c[k] = RatFn::zero();
        let value = others.scale(&e.c[k].inv()?.neg()?)?;
        self.d_m.substitute(k, &value)?;
        self.d_k.substitute(k, &value)?;
        for r in rest.iter_mut() {
            *r = r.substitute(k, &value)?;
        }
        for s in self.solved.iter_mut().flatten() {
            *s = s.substitute(k, &value)?;
        }
        self.solved[k] = Some(value);
        Ok(())
    }
}

/// A 2 × 2 principal minor of `form` that is −s·L², s > 0 (`negative(−s)`) and L affine in
/// the unknowns not zero: D ⪰ 0 needs L = 0, returned.
fn negative_square_minor(form: &Form, negative: &dyn Fn(&RatFn) -> bool) -> Res<Option<Unk>> {
    let n = form.n;
    let k = form.entries[0].c.len();
    // z = (unknowns, 1); an entry e is e·z with e = (c, c0).
    let vector = |e: &Unk| -> Vec<RatFn> { e.c.iter().cloned().chain([e.c0.clone()]).collect() };
    for i in 0..n {
        for j in i + 1..n {
            let (a, b, c) = (vector(form.at(i, i)), vector(form.at(j, j)), vector(form.at(i, j)));
            if c.iter().all(RatFn::is_zero) {
                continue;
            }
            // S = ½(a bᵀ + b aᵀ) − c cᵀ, the minor's matrix in z.
            let half = RatFn::constant(crate::scheme::rational::Rat::new(1, 2)?);
            let entry = |p: usize, q: usize| -> Res<RatFn> {
                a[p].mul(&b[q])?.add(&b[p].mul(&a[q])?)?.mul(&half)?.sub(&c[p].mul(&c[q])?)
            };
            let Some(p) = (0..=k).find(|&p| entry(p, p).is_ok_and(|e| !e.is_zero())) else { continue };
            let spp = entry(p, p)?;
            if !negative(&spp) {
                continue;
            }
            // Rank one: S_qr S_pp = S_qp S_pr for all q, r.
            let mut rank_one = true;
            'check: for q in 0..=k {
                for r in q..=k {
                    if !entry(q, r)?.mul(&spp)?.sub(&entry(q, p)?.mul(&entry(p, r)?)?)?.is_zero() {
                        rank_one = false;
                        break 'check;
                    }
                }
            }
            if !rank_one {
                continue;
            }
            let row: Vec<RatFn> = (0..=k).map(|q| entry(p, q)).collect::<Res<_>>()?;
            if row[..k].iter().all(RatFn::is_zero) {
                continue;
            }
            return Ok(Some(Unk { c0: row[k].clone(), c: row[..k].to_vec() }));
        }
    }
    Ok(None)
}

/// The uniform shift of the displacements over the step's free variables: 1 on the
/// displacement state, 0 on the others, and on each stage's unknown what keeps every state's
/// end value shifted as its start (the displacement by 1, the velocity and acceleration by 0).
pub fn shift(ir: &SchemeIr, window: &Window) -> Result<Lin, NoIdentity> {
    let states = ir.states.len();
    let n = window.free.len();
    let stages = n - states;
    let end = |i: usize| end_level(ir, window, i);
    // end(i)·s = [i = 0], with s = e_0 on the states: Σ_k end(i)[states + k] s_k = [i = 0] − end(i)[0].
    let mut equations: Vec<Unk> = (0..states)
        .map(|i| -> Res<Unk> {
            let e = end(i);
            let target = if i == 0 { RatFn::one() } else { RatFn::zero() };
            Ok(Unk { c0: e.0[0].sub(&target)?, c: e.0[states..].to_vec() })
        })
        .collect::<Res<_>>()?;
    let mut value: Vec<Option<Unk>> = vec![None; stages];
    while let Some(e) = equations.pop() {
        let Some(k) = (0..stages).find(|&k| !e.c[k].is_zero()) else {
            if e.c0.is_zero() {
                continue;
            }
            return Err(NoIdentity::Inconsistent);
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
    let mut s = unit(n, 0);
    for (k, v) in value.into_iter().enumerate() {
        // Unknowns no equation fixes do not move.
        s.0[states + k] = v.map_or(RatFn::zero(), |v| v.c0);
    }
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scheme::rational::Rat;

    fn derived(name: &str) -> (SchemeIr, Ansatz) {
        let (_, ir) = super::super::library_schemes().into_iter().find(|(n, _)| n == name).expect("a library scheme");
        let w = super::super::window::window(&ir).unwrap();
        let s = shift(&ir, &w).unwrap();
        let mut a = Ansatz::new(&ir, w).unwrap();
        // Signs sampled over the params' ranges and dt.
        let samples: Vec<Vec<f64>> = (0..6)
            .map(|i| {
                let along = |p: &crate::check::SchemeParamInfo| match &p.range {
                    Some(r) if r.lo.is_finite() && r.hi.is_finite() => r.lo + (r.hi - r.lo) * (0.1 + 0.15 * i as f64),
                    _ => p.default,
                };
                ir.params.iter().map(along).collect()
            })
            .collect();
        let negative = |r: &RatFn| samples.iter().all(|p| [0.01, 1.0, 10.0].iter().all(|&dt| r.eval(p, dt, 0.0) < 0.0));
        a.solve(&s, &negative).unwrap();
        (ir, a)
    }

    /// `form` equals Σ coef · l⊗l over `parts`, exactly, with no unknown left.
    fn assert_form(form: &Form, parts: &[(RatFn, Lin)], what: &str) {
        let unknowns = form.entries[0].c.len();
        let mut want = Form::zero(form.n, unknowns);
        for (c, l) in parts {
            want.add_product(&Unk::constant(c.clone(), unknowns), l, l).unwrap();
        }
        for (got, want) in form.entries.iter().zip(&want.entries) {
            assert!(got.is_known(), "{what}: an unknown is left");
            assert!(got.c0.sub(&want.c0).unwrap().is_zero(), "{what}: not the expected form");
        }
    }

    /// Newmark at symbolic β, γ: the multipliers (1 − γ, γ) of the residuals at t and t + dt on
    /// Δu, the kept energy's ½dt²(β − γ/2)‖a‖²_M, and D = (γ − ½)‖Δu‖²_K +
    /// (γ − ½)(β − γ/2)dt²‖Δa‖²_M (Krenk's form of the Newmark energy balance), exactly.
    #[test]
    fn newmark_s_identity_is_krenk_s() {
        let (ir, a) = derived("newmark");
        let (beta, gam, dt) = (RatFn::var(0), RatFn::var(1), RatFn::var(super::super::poly::DT));
        let half = RatFn::constant(Rat::new(1, 2).unwrap());
        let value = |k: usize| a.solved[k].as_ref().filter(|u| u.is_known()).map(|u| u.c0.clone()).expect("solved");
        let start = a.residuals.iter().position(|r| r.stage.is_none()).expect("the residual at t");
        let end = a.residuals.iter().position(|r| r.stage == Some(0)).expect("the residual at t + dt");
        assert!(value(a.residuals[start].nu[0]).sub(&RatFn::one().sub(&gam).unwrap()).unwrap().is_zero());
        assert!(value(a.residuals[end].nu[0]).sub(&gam).unwrap().is_zero());
        let q_a = gam.mul(&half).unwrap();
        let q_a = beta.sub(&q_a).unwrap();
        assert!(value(a.q_a.unwrap()).sub(&q_a).unwrap().is_zero());
        let n = a.window.free.len();
        let acceleration = ir.initial.as_ref().unwrap().state;
        let end_of = |i: usize| end_level(&ir, &a.window, i);
        let du = sub(&end_of(0), &unit(n, 0)).unwrap();
        let da = sub(&end_of(acceleration), &unit(n, acceleration)).unwrap();
        let g = gam.sub(&half).unwrap();
        assert_form(&a.d_k, &[(g.clone(), du)], "D on K");
        let m = g.mul(&q_a).unwrap().mul(&dt.powi(2).unwrap()).unwrap();
        assert_form(&a.d_m, &[(m, da)], "D on M");
    }

    /// The midpoint rule tests its one residual with Δu whole, keeps E, and dissipates nothing:
    /// D ≡ 0. So does the hybrid scheme's part (its contact is the law's), and energy–momentum,
    /// whose discrete-gradient stiffness is a force whose work it reports.
    #[test]
    fn the_midpoint_schemes_dissipate_nothing() {
        for name in ["midpoint", "hybrid", "energy_momentum"] {
            let (_, a) = derived(name);
            let [r] = a.residuals.as_slice() else { panic!("{name}: one residual") };
            let nu = a.solved[r.nu[0]].as_ref().expect("solved");
            assert_eq!(nu.c0.as_constant(), Some(Rat::ONE), "{name}: w = Δu");
            for form in [&a.d_m, &a.d_k] {
                assert!(form.entries.iter().all(Unk::is_zero), "{name}: D ≢ 0");
            }
        }
    }
}
