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

/// The kept energy's terms besides E: q_a ½dt²‖a‖²_M, q_δ ½‖u − u⁻‖²_K; and its levels'
/// weight θ (x̂ = (1 − θ)·x + θ·x⁻), if not 0.
#[derive(Clone, Debug, PartialEq)]
pub struct Terms {
    pub acceleration: bool,
    pub step_before: bool,
    pub weight: Option<RatFn>,
}

/// The ansatz, built and (by [`Ansatz::solve`]) solved.
pub struct Ansatz {
    pub window: Window,
    /// The step's displacement levels in time order, and their increments.
    pub levels: Vec<Lin>,
    pub increments: Vec<Lin>,
    pub residuals: Vec<Tested>,
    /// The kept energy's coefficient of ½dt²‖a‖²_M, when the scheme has an acceleration state.
    pub q_a: Option<usize>,
    /// Its coefficient of ½‖u − u⁻‖²_K, with the previous step's displacement u⁻.
    pub q_delta: Option<usize>,
    /// The weight θ of its levels, x̂ = (1 − θ)·x + θ·x⁻.
    pub weight: Option<RatFn>,
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
    /// The constraints leave a family of identities: none is chosen silently.
    NotUnique,
    /// A scalar of the scheme is no rational function of its params.
    NotRational(super::exact::Refusal),
    /// A coefficient of the step depends on the time t (only a load's time may).
    ReadsTime,
    /// Rational overflow.
    Overflow,
}

impl From<GiveUp> for NoIdentity {
    fn from(_: GiveUp) -> NoIdentity {
        NoIdentity::Overflow
    }
}

/// The energy identity of one step of `ir`, with the residuals at the step's ends: the kept
/// energy E if it closes, else E + q_a ½dt²‖a‖²_M. The ansatz's rules read the sign of a
/// coefficient at samples of the params' ranges and of dt (they choose the multipliers; the
/// identity holds exactly whatever they choose).
pub fn derive(ir: &SchemeIr) -> Result<Ansatz, NoIdentity> {
    let window = super::window::window(ir).map_err(NoIdentity::NotRational)?;
    // A coefficient that changes with t would differ between the step and the previous one the
    // identity reads: only the times a load is applied at may depend on t.
    let t = super::poly::TIME;
    let reads_time = |l: &Lin| l.0.iter().any(|c| c.reads(t));
    if window.levels.iter().flatten().any(reads_time)
        || window.residuals.iter().flatten().any(|term| term.coef.reads(t) || term.args.iter().any(reads_time))
    {
        return Err(NoIdentity::ReadsTime);
    }
    // With the previous step's displacement and the states its residual reads at the start.
    let read: Vec<usize> = (0..ir.states.len())
        .filter(|&i| {
            i == 0 || window.residuals.last().is_some_and(|r| r.iter().flat_map(|t| &t.args).any(|l| !l.0[i].is_zero()))
        })
        .collect();
    let (history, variables) = window.with_previous(&read);
    let previous: Vec<(usize, usize)> = read.iter().copied().zip(variables).collect();
    let samples: Vec<Vec<f64>> = (0..=4)
        .map(|i| {
            let along = |p: &crate::check::SchemeParamInfo| match &p.range {
                Some(r) if r.lo.is_finite() && r.hi.is_finite() => r.lo + (r.hi - r.lo) * (0.1 + 0.2 * i as f64),
                _ => p.default,
            };
            ir.params.iter().map(along).collect()
        })
        .chain([ir.params.iter().map(|p| p.default).collect()])
        .collect();
    // ≤ 0 at every sample and < 0 at one: a minor −s·L² with such an s asks L = 0 wherever
    // s > 0 (at γ = ½ Newmark's s vanishes).
    let negative = |r: &RatFn| {
        let values: Vec<f64> = samples.iter().flat_map(|p| [1e-2, 1.0, 1e2].map(|dt| r.eval(p, dt, 0.0))).collect();
        values.iter().all(|v| *v <= 0.0) && values.iter().any(|v| *v < 0.0)
    };
    let mut last = NoIdentity::Inconsistent;
    let mut attempt =
        |w: Window, terms: Terms, previous: &[(usize, usize)], s: &Lin| -> Result<Option<Ansatz>, NoIdentity> {
            let mut a = Ansatz::new(ir, w, terms, previous)?;
            match a.solve(s, &negative) {
                Ok(()) if a.solved.iter().all(|v| v.as_ref().is_some_and(Unk::is_known)) => return Ok(Some(a)),
                Ok(()) => last = NoIdentity::NotUnique,
                Err(e) => last = e,
            }
            Ok(None)
        };
    // One step first, E before its corrections.
    let tries = [
        (false, false, false),
        (false, true, false),
        (true, false, false),
        (true, true, false),
        (true, false, true),
        (true, true, true),
    ];
    for (with_previous, acceleration, step_before) in tries {
        let (w, previous) = if with_previous { (history.clone(), &previous[..]) } else { (window.clone(), &[][..]) };
        let s = shift(ir, &w, previous)?;
        if let Some(a) = attempt(w, Terms { acceleration, step_before, weight: None }, previous, &s)? {
            return Ok(a);
        }
    }
    // A residual that weighs its inertia over the step's start and end (generalized-α): the
    // previous step's kinematics too, and the kept energy's levels weighted alike.
    if let Some(theta) = inertia_weight(ir, &window)? {
        let states = ir.states.len();
        let ends: Vec<Lin> = (0..states).map(|i| end_level(ir, &window, i)).collect();
        let two = window.two_steps(states, &ends)?;
        let one = shift(ir, &window, &[])?;
        let s = Lin(one.0.iter().chain(&one.0[states..]).cloned().collect());
        let previous: Vec<(usize, usize)> = (0..states).map(|i| (i, i)).collect();
        for (acceleration, step_before) in [(false, false), (true, false), (false, true), (true, true)] {
            let terms = Terms { acceleration, step_before, weight: Some(theta.clone()) };
            if let Some(a) = attempt(two.clone(), terms, &previous, &s)? {
                return Ok(a);
            }
        }
    }
    Err(last)
}

/// θ where the last stage's residual weighs its inertia as (1 − θ)·mass(a') + θ·mass(a)
/// (in one term or two), θ ≠ 0, between the acceleration's end and start levels.
fn inertia_weight(ir: &SchemeIr, window: &Window) -> Result<Option<RatFn>, NoIdentity> {
    let Some(a) = ir.initial.as_ref().map(|i| i.state) else { return Ok(None) };
    let Some(last) = window.residuals.last() else { return Ok(None) };
    let (at_start, at_end) = (window.start[a].clone(), end_level(ir, window, a));
    let (mut start, mut end) = (RatFn::zero(), RatFn::zero());
    for t in last.iter().filter(|t| t.form == "mass") {
        // Its argument as x·a' + y·a (`mass((1 - am)*a' + am*a)` as well as two terms).
        let [arg] = t.args.as_slice() else { return Ok(None) };
        let Some(c) = super::forms::solve(arg, &[at_end.clone(), at_start.clone()])? else { return Ok(None) };
        let back = Lin(at_end
            .0
            .iter()
            .zip(&at_start.0)
            .map(|(e, s)| e.mul(&c[0])?.add(&s.mul(&c[1])?))
            .collect::<Res<_>>()?);
        if back != *arg && !sub(&back, arg)?.0.iter().all(RatFn::is_zero) {
            return Ok(None);
        }
        end = end.add(&t.coef.mul(&c[0])?)?;
        start = start.add(&t.coef.mul(&c[1])?)?;
    }
    let total = start.add(&end)?;
    if start.is_zero() || total.is_zero() {
        return Ok(None);
    }
    Ok(Some(start.div(&total)?))
}

fn unit(n: usize, i: usize) -> Lin {
    Lin::unit(n, i)
}

/// State `i` at the step's end, over the window's free variables.
pub fn end_level(ir: &SchemeIr, window: &Window, i: usize) -> Lin {
    match ir.updates[i] {
        crate::scheme::affine::Quantity::Stage { stage, index } => window.levels[window.offset + stage][index].clone(),
        crate::scheme::affine::Quantity::State(j) => window.start[j].clone(),
    }
}

fn sub(a: &Lin, b: &Lin) -> Res<Lin> {
    Ok(Lin(a.0.iter().zip(&b.0).map(|(x, y)| x.sub(y)).collect::<Res<_>>()?))
}

impl Ansatz {
    /// The ansatz of the step `window` of `ir` with the kept energy's `terms` besides E; the
    /// window's `previous` variables (the previous step's states, [`Window::with_previous`])
    /// are where its start's own start levels go back to.
    pub fn new(ir: &SchemeIr, window: Window, terms: Terms, previous: &[(usize, usize)]) -> Result<Ansatz, NoIdentity> {
        let n = window.free.len();
        let start = |i: usize| window.start[i].clone();
        let velocity = ir.states.iter().position(|s| s == "v").ok_or(NoIdentity::NoState("velocity `v`"))?;
        let acceleration = ir.initial.as_ref().map(|i| i.state);
        let end = |i: usize| end_level(ir, &window, i);
        let before = |i: usize| previous.iter().find(|(s, _)| *s == i).map(|&(_, v)| unit(n, v));
        // The residuals: each stage's, and the last one's at the step's start where the state
        // invariant holds (an initial line solves it at the start, each step at its end): its
        // end levels go back to the start, its start levels to the previous step's.
        let mut residuals: Vec<(Option<usize>, Vec<ExactTerm>)> =
            window.residuals.iter().enumerate().map(|(k, t)| (Some(k), t.clone())).collect();
        if acceleration.is_some()
            && window.offset == 0
            && let Some(last) = window.residuals.last()
        {
            let back = |l: &Lin| {
                let states = 0..ir.states.len();
                states
                    .clone()
                    .find(|&i| end(i) == *l)
                    .map(|i| unit(n, i))
                    .or_else(|| states.clone().find(|&i| unit(n, i) == *l).and_then(before))
            };
            let shifted: Option<Vec<ExactTerm>> = last
                .iter()
                .map(|t| {
                    let args = t.args.iter().map(back).collect::<Option<Vec<_>>>()?;
                    // The previous step's: its time one step back.
                    let time = t.time.sub(&RatFn::var(super::poly::DT)).ok()?;
                    Some(ExactTerm { args, time, ..t.clone() })
                })
                .collect();
            if let Some(terms) = shifted {
                residuals.insert(0, (None, terms));
            }
        }
        // The displacement levels: the previous step's start's, each stage's stiffness argument
        // that is one of its levels (the step's start before this step's stages), the end's.
        let mut levels: Vec<Lin> = before(0).into_iter().collect();
        for (k, terms) in window.residuals.iter().enumerate() {
            if k == window.offset && levels.last() != Some(&start(0)) {
                levels.push(start(0));
            }
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
        let q_a = acceleration.filter(|_| terms.acceleration).map(|_| {
            unknowns += 1;
            unknowns - 1
        });
        let q_delta = before(0).filter(|_| terms.step_before).map(|_| {
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
        // Q's levels weighted as the residual weighs its inertia (generalized-α's α_m):
        // x̂ = (1 − θ)·x + θ·x⁻, at the end and at the start.
        let hat = |now: Lin, then: Option<Lin>| -> Res<Lin> {
            match (&terms.weight, then) {
                (Some(theta), Some(then)) => {
                    let mut out = Lin::zero(n);
                    for p in 0..n {
                        let a = now.0[p].mul(&RatFn::one().sub(theta)?)?;
                        out.0[p] = a.add(&then.0[p].mul(theta)?)?;
                    }
                    Ok(out)
                }
                _ => Ok(now),
            }
        };
        let change = |form: &mut Form, s: &Unk, i: usize| -> Res<()> {
            let (at_end, at_start) = (hat(end(i), Some(start(i)))?, hat(start(i), before(i))?);
            form.add_product(&s.scale(&minus_half)?, &at_end, &at_end)?;
            form.add_product(&s.scale(&half)?, &at_start, &at_start)
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
        // q_δ ½‖u − u⁻‖²_K: ½‖u' − u‖² at the end, ½‖u − u⁻‖² at the start.
        if let (Some(q), Some(u_before)) = (q_delta, before(0)) {
            let s = Unk::unknown(q, unknowns);
            let (now, then) = (sub(&end(0), &start(0))?, sub(&start(0), &u_before)?);
            d_k.add_product(&s.scale(&minus_half)?, &now, &now)?;
            d_k.add_product(&s.scale(&half)?, &then, &then)?;
        }
        Ok(Ansatz {
            window,
            levels,
            increments,
            residuals,
            q_a,
            q_delta,
            weight: terms.weight.clone(),
            unknowns,
            d_m,
            d_k,
            solved: vec![None; unknowns],
        })
    }

    /// Fixes the unknowns: D blind to a uniform shift of the displacements (`shift`, over the
    /// free variables), and every row of D whose diagonal is zero zero, until nothing changes.
    /// `negative(r)`: whether r ≤ 0 for every param in range and dt > 0, and not ≡ 0.
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
        let pivot = (0..self.unknowns).filter(|&k| !e.c[k].is_zero()).min_by_key(|&k| e.c[k].as_constant().is_none());
        let Some(k) = pivot else {
            // No unknown left: 0 = 0 holds, c0 = 0 with c0 ≠ 0 does not.
            return if e.c0.is_zero() { Ok(()) } else { Err(NoIdentity::Inconsistent) };
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

/// A 2 × 2 principal minor of `form` that is −s·L², s ≥ 0 (`negative(−s)`), L affine in the
/// unknowns: D ⪰ 0 needs L = 0, returned.
fn negative_square_minor(form: &Form, negative: &dyn Fn(&RatFn) -> bool) -> Res<Option<Unk>> {
    let n = form.n;
    let k = form.entries[0].c.len();
    // z = (unknowns, 1); an entry e is e·z with e = (c, c0).
    let vector = |e: &Unk| -> Vec<RatFn> { e.c.iter().cloned().chain([e.c0.clone()]).collect() };
    for i in 0..n {
        for j in i + 1..n {
            let (a, b, c) = (vector(form.at(i, i)), vector(form.at(j, j)), vector(form.at(i, j)));
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
            // L = 0, the row of S through p over S_pp; a constant L ≠ 0 makes D indefinite
            // whatever the unknowns (an equation no unknown satisfies).
            let row: Vec<RatFn> = (0..=k).map(|q| entry(p, q)).collect::<Res<_>>()?;
            return Ok(Some(Unk { c0: row[k].clone(), c: row[..k].to_vec() }));
        }
    }
    Ok(None)
}

/// The uniform shift of the displacements over the step's free variables: 1 on the
/// displacement state, 0 on the others, and on each stage's unknown what keeps every state's
/// end value shifted as its start (the displacement by 1, the velocity and acceleration by 0).
pub fn shift(ir: &SchemeIr, window: &Window, previous: &[(usize, usize)]) -> Result<Lin, NoIdentity> {
    let states = ir.states.len();
    let n = window.free.len();
    // The stages' unknowns (and the previous step's states, which no end level reads).
    let stages = n - states;
    let end: Vec<Lin> = (0..states).map(|i| end_level(ir, window, i)).collect();
    // end(i)·s = [i = 0], with s = e_0 on the states: Σ_k end(i)[states + k] s_k = [i = 0] − end(i)[0].
    let target = Lin(end
        .iter()
        .enumerate()
        .map(|(i, e)| if i == 0 { RatFn::one() } else { RatFn::zero() }.sub(&e.0[0]))
        .collect::<Res<_>>()?);
    let columns: Vec<Lin> = (0..stages).map(|k| Lin(end.iter().map(|e| e.0[states + k].clone()).collect())).collect();
    // Unknowns no equation fixes do not move (solve leaves them 0).
    let value = super::forms::solve(&target, &columns)?.ok_or(NoIdentity::Inconsistent)?;
    let mut s = unit(n, 0);
    for (k, v) in value.into_iter().enumerate() {
        s.0[states + k] = v;
    }
    // The previous step's displacement moves with the others.
    if let Some(&(_, v)) = previous.iter().find(|(state, _)| *state == 0) {
        s.0[v] = RatFn::one();
    }
    Ok(s)
}

#[cfg(test)]
mod tests;
