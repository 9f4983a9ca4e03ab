//! A derived identity evaluated on one step of a run: the kept energy at the step's start and
//! end, the work of its loads and other slots with the step's own weights, and the
//! dissipation, from the values of the step's free variables (the states at its start, its
//! stages' unknowns, and the previous step's where the identity reads them).

use std::borrow::Cow;

use super::classify::{Block, Identity};
use super::engine::end_level;
use super::window::{Free, Lin};
use crate::scheme::ir::SchemeIr;

/// The matrices and slots an identity is evaluated with.
pub trait Operators {
    fn mass(&self, x: &[f64]) -> Vec<f64>;
    fn stiffness(&self, x: &[f64]) -> Vec<f64>;
    /// xᵀMx and xᵀKx: the only way the identity reads M and K (a run has faster ways to them
    /// than the products).
    fn mass_quad(&self, x: &[f64]) -> f64 {
        dot(x, &self.mass(x))
    }
    fn stiffness_quad(&self, x: &[f64]) -> f64 {
        dot(x, &self.stiffness(x))
    }
    /// A slot other than `mass` and `stiffness`, applied to its arguments at time `t` (a load
    /// has none).
    fn apply(&self, slot: &str, args: &[Vec<f64>], t: f64) -> Vec<f64>;
    /// The dot products of that with each of `with`: all the identity reads of a slot.
    fn apply_dots(&self, slot: &str, args: &[&[f64]], t: f64, with: &[&[f64]]) -> Vec<f64> {
        let args: Vec<Vec<f64>> = args.iter().map(|a| a.to_vec()).collect();
        let f = self.apply(slot, &args, t);
        with.iter().map(|w| dot(w, &f)).collect()
    }
}

/// One step's balance: Ẽ' − Ẽ = W − D, each side evaluated.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Balance {
    pub kept_before: f64,
    pub kept_after: f64,
    pub work: f64,
    /// The part of `work` done by the slots applied to no field (the loads).
    pub loads: f64,
    pub dissipation: f64,
}

impl Balance {
    /// Ẽ' − Ẽ − W + D: zero up to the solver's tolerance.
    pub fn gap(&self) -> f64 {
        self.kept_after - self.kept_before - self.work + self.dissipation
    }

    /// The magnitude the gap is measured against.
    pub fn scale(&self) -> f64 {
        self.kept_before.abs() + self.kept_after.abs() + self.work.abs() + self.dissipation.abs()
    }
}

/// The identity's work and dissipation at a point of the params and dt, in floating point: the
/// coefficients a run would otherwise evaluate again at every step.
pub struct Plan {
    /// Per residual, its test vector's coefficients over the free variables, and its terms
    /// other than `mass` and `stiffness`.
    residuals: Vec<(Vec<f64>, Vec<PlannedTerm>)>,
    /// D's squares whose coefficient is not 0 there.
    squares: Vec<(Block, f64, Vec<f64>)>,
    /// Each state's end level's coefficients: an argument that is one is read from the states
    /// the step ended with.
    ends: Vec<Vec<f64>>,
}

/// `coef · form(args)` at `time(t)`.
struct PlannedTerm {
    form: String,
    coef: f64,
    args: Vec<Vec<f64>>,
    time: super::ratfn::RatFn,
    params: Vec<f64>,
    dt: f64,
}

impl Plan {
    /// W, the part of it the loads do (slots of no field), and D, of the step from time `t` whose
    /// free variables have the values `x` and that ended with the states `end` (none: their
    /// end levels over `x`). A run gives its own states, so that a slot reads at the step's end
    /// what it reads at the next one's start.
    pub fn step(&self, ops: &dyn Operators, t: f64, x: &[&[f64]], end: Option<&[&[f64]]>) -> (f64, f64, f64) {
        let (mut work, mut loads) = (0.0, 0.0);
        for (test, terms) in &self.residuals {
            // The test vector's free variables: the work is Σ c_p x_p·f, with no vector made.
            let (c, with): (Vec<f64>, Vec<&[f64]>) =
                test.iter().zip(x).filter(|(c, _)| **c != 0.0).map(|(c, x)| (*c, *x)).unzip();
            for term in terms {
                let arg = |a: &Vec<f64>| match (end, self.ends.iter().position(|e| e == a)) {
                    (Some(end), Some(i)) => Cow::Borrowed(end[i]),
                    _ => combined(a, x),
                };
                let args: Vec<Cow<[f64]>> = term.args.iter().map(arg).collect();
                let args: Vec<&[f64]> = args.iter().map(|a| a.as_ref()).collect();
                let time = term.time.eval(&term.params, term.dt, t);
                let dots = ops.apply_dots(&term.form, &args, time, &with);
                let w = -term.coef * c.iter().zip(dots).map(|(c, d)| c * d).sum::<f64>();
                work += w;
                if term.args.is_empty() {
                    loads += w;
                }
            }
        }
        let mut dissipation = 0.0;
        for (block, c, vector) in &self.squares {
            let y = combined(vector, x);
            dissipation += c * match block {
                Block::Mass => ops.mass_quad(&y),
                Block::Stiffness => ops.stiffness_quad(&y),
            };
        }
        (work, loads, dissipation)
    }
}

/// Σ c_p x_p over the free variables, with float coefficients (a free variable alone is
/// borrowed).
fn combined<'x>(c: &[f64], x: &[&'x [f64]]) -> Cow<'x, [f64]> {
    let mut nonzero = c.iter().enumerate().filter(|(_, c)| **c != 0.0);
    if let (Some((p, &1.0)), None) = (nonzero.next(), nonzero.next()) {
        return Cow::Borrowed(x[p]);
    }
    let mut out = vec![0.0; x.first().map_or(0, |x| x.len())];
    for (&c, xp) in c.iter().zip(x) {
        if c != 0.0 {
            out.iter_mut().zip(*xp).for_each(|(o, v)| *o += c * v);
        }
    }
    Cow::Owned(out)
}

fn dot(x: &[f64], y: &[f64]) -> f64 {
    x.iter().zip(y).map(|(a, b)| a * b).sum()
}

/// Σ c_p x_p over the free variables.
fn combine(l: &Lin, x: &[Vec<f64>], params: &[f64], dt: f64, t: f64) -> Vec<f64> {
    let n = x.first().map_or(0, Vec::len);
    let mut out = vec![0.0; n];
    for (c, xp) in l.0.iter().zip(x) {
        if !c.is_zero() {
            let c = c.eval(params, dt, t);
            out.iter_mut().zip(xp).for_each(|(o, v)| *o += c * v);
        }
    }
    out
}

impl Identity {
    /// The kept energy Ẽ of the states `states` (in `ir`'s order), for an identity that keeps
    /// it at one level (none where it weighs or reads the step before's levels).
    pub fn kept_at(
        &self,
        ir: &SchemeIr,
        ops: &dyn Operators,
        params: &[f64],
        dt: f64,
        states: &[Vec<f64>],
    ) -> Option<f64> {
        if self.weight.is_some() || self.step_before.is_some() {
            return None;
        }
        let velocity = ir.states.iter().position(|s| s == "v").unwrap_or(0);
        let mut e = 0.0;
        // The acceleration's first: a run keeps the last quadratic form of each matrix, and
        // reads ½vᵀMv again.
        if let (Some(q), Some(a)) = (&self.acceleration, ir.initial.as_ref().map(|i| i.state)) {
            let q = q.eval(params, dt, 0.0);
            if q != 0.0 {
                e += q * 0.5 * dt * dt * ops.mass_quad(states.get(a)?);
            }
        }
        e += 0.5 * ops.mass_quad(states.get(velocity)?);
        if self.elastic {
            e += 0.5 * ops.stiffness_quad(states.first()?);
        }
        Some(e)
    }

    /// The balance of the step of `ir` whose free variables have the values `x` (in the
    /// window's order, [`Identity::free`]), at `params`, `dt` and the step's start time `t`.
    pub fn balance(
        &self,
        ir: &SchemeIr,
        ops: &dyn Operators,
        params: &[f64],
        dt: f64,
        t: f64,
        x: &[Vec<f64>],
    ) -> Balance {
        let w = &self.ansatz.window;
        let at = |l: &Lin| combine(l, x, params, dt, t);
        let before = |i: usize| w.free.iter().position(|f| *f == Free::Previous(i)).map(|v| Lin::unit(w.free.len(), v));
        let theta = self.weight.as_ref().map_or(0.0, |r| r.eval(params, dt, t));
        let hat = |now: &Lin, then: Option<Lin>| -> Vec<f64> {
            let now = at(now);
            match then {
                Some(then) if theta != 0.0 => {
                    now.iter().zip(at(&then)).map(|(a, b)| (1.0 - theta) * a + theta * b).collect()
                }
                _ => now,
            }
        };
        let velocity = ir.states.iter().position(|s| s == "v").unwrap_or(0);
        let acceleration = ir.initial.as_ref().map(|i| i.state);
        // Ẽ at a boundary, from each state's level there (`now`) and one step before (`then`).
        let kept = |now: &dyn Fn(usize) -> Lin, then: &dyn Fn(usize) -> Option<Lin>| -> f64 {
            let v = hat(&now(velocity), then(velocity));
            let mut e = 0.5 * ops.mass_quad(&v);
            if self.elastic {
                let u = hat(&now(0), then(0));
                e += 0.5 * ops.stiffness_quad(&u);
            }
            if let (Some(q), Some(a)) = (&self.acceleration, acceleration) {
                let a = hat(&now(a), then(a));
                e += q.eval(params, dt, t) * 0.5 * dt * dt * ops.mass_quad(&a);
            }
            if let (Some(q), Some(u_then)) = (&self.step_before, then(0)) {
                let d: Vec<f64> = at(&now(0)).iter().zip(at(&u_then)).map(|(a, b)| a - b).collect();
                e += q.eval(params, dt, t) * 0.5 * ops.stiffness_quad(&d);
            }
            e
        };
        let kept_after = kept(&|i| end_level(ir, w, i), &|i| Some(w.start[i].clone()));
        let kept_before = kept(&|i| w.start[i].clone(), &before);
        let x: Vec<&[f64]> = x.iter().map(Vec::as_slice).collect();
        let (work, loads, dissipation) = self.plan(ir, params, dt).step(ops, t, &x, None);
        Balance { kept_before, kept_after, work, loads, dissipation }
    }

    /// The work and dissipation of its steps at `params` and `dt` ([`Plan::step`]). Its
    /// coefficients do not read t (an identity whose do is refused), only its terms' times.
    pub fn plan(&self, ir: &SchemeIr, params: &[f64], dt: f64) -> Plan {
        let coefficients = |l: &Lin| -> Vec<f64> {
            l.0.iter().map(|c| if c.is_zero() { 0.0 } else { c.eval(params, dt, 0.0) }).collect()
        };
        let n = self.ansatz.window.free.len();
        let residuals = self
            .ansatz
            .residuals
            .iter()
            .map(|r| {
                let mut test = vec![0.0; n];
                for (j, increment) in self.ansatz.increments.iter().enumerate() {
                    let nu = self.ansatz.solved[r.nu[j]].as_ref().map_or(0.0, |u| u.c0.eval(params, dt, 0.0));
                    if nu != 0.0 {
                        test.iter_mut().zip(coefficients(increment)).for_each(|(s, c)| *s += nu * c);
                    }
                }
                let terms = r
                    .terms
                    .iter()
                    .filter(|t| t.form != "mass" && t.form != "stiffness")
                    .map(|t| PlannedTerm {
                        form: t.form.clone(),
                        coef: t.coef.eval(params, dt, 0.0),
                        args: t.args.iter().map(coefficients).collect(),
                        time: t.time.clone(),
                        params: params.to_vec(),
                        dt,
                    })
                    .filter(|t| t.coef != 0.0)
                    .collect();
                (test, terms)
            })
            .collect();
        let squares = self
            .dissipation
            .squares
            .iter()
            .map(|s| (s.block, s.coef.eval(params, dt, 0.0), coefficients(&s.vector)))
            // A square whose coefficient vanishes here (Newmark's at gam = 1/2) costs nothing.
            .filter(|(_, c, _)| *c != 0.0)
            .collect();
        let ends = (0..ir.states.len()).map(|i| coefficients(&end_level(ir, &self.ansatz.window, i))).collect();
        Plan { residuals, squares, ends }
    }

    /// The step's free variables, in the order [`Identity::balance`] takes their values.
    pub fn free(&self) -> &[Free] {
        &self.ansatz.window.free
    }
}
