//! A derived identity evaluated on one step of a run: the kept energy at the step's start and
//! end, the work of its loads and other slots with the step's own weights, and the
//! dissipation, from the values of the step's free variables (the states at its start, its
//! stages' unknowns, and the previous step's where the identity reads them).

use super::classify::{Block, Identity};
use super::engine::end_level;
use super::window::{Free, Lin};
use crate::scheme::ir::SchemeIr;

/// The matrices and slots an identity is evaluated with.
pub trait Operators {
    fn mass(&self, x: &[f64]) -> Vec<f64>;
    fn stiffness(&self, x: &[f64]) -> Vec<f64>;
    /// A slot other than `mass` and `stiffness`, applied to its arguments at time `t` (a load
    /// has none).
    fn apply(&self, slot: &str, args: &[Vec<f64>], t: f64) -> Vec<f64>;
}

/// One step's balance: Ẽ' − Ẽ = W − D, each side evaluated.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Balance {
    pub kept_before: f64,
    pub kept_after: f64,
    pub work: f64,
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
            let mut e = 0.5 * dot(&v, &ops.mass(&v));
            if self.elastic {
                let u = hat(&now(0), then(0));
                e += 0.5 * dot(&u, &ops.stiffness(&u));
            }
            if let (Some(q), Some(a)) = (&self.acceleration, acceleration) {
                let a = hat(&now(a), then(a));
                e += q.eval(params, dt, t) * 0.5 * dt * dt * dot(&a, &ops.mass(&a));
            }
            if let (Some(q), Some(u_then)) = (&self.step_before, then(0)) {
                let d: Vec<f64> = at(&now(0)).iter().zip(at(&u_then)).map(|(a, b)| a - b).collect();
                e += q.eval(params, dt, t) * 0.5 * dot(&d, &ops.stiffness(&d));
            }
            e
        };
        let kept_after = kept(&|i| end_level(ir, w, i), &|i| Some(w.start[i].clone()));
        let kept_before = kept(&|i| w.start[i].clone(), &before);
        let mut work = 0.0;
        for r in &self.ansatz.residuals {
            let mut test = vec![0.0; x.first().map_or(0, Vec::len)];
            for (j, increment) in self.ansatz.increments.iter().enumerate() {
                let nu = self.ansatz.solved[r.nu[j]].as_ref().map_or(0.0, |u| u.c0.eval(params, dt, t));
                test.iter_mut().zip(at(increment)).for_each(|(s, d)| *s += nu * d);
            }
            for term in r.terms.iter().filter(|t| t.form != "mass" && t.form != "stiffness") {
                let args: Vec<Vec<f64>> = term.args.iter().map(at).collect();
                let f = ops.apply(&term.form, &args, term.time.eval(params, dt, t));
                work -= term.coef.eval(params, dt, t) * dot(&test, &f);
            }
        }
        let mut dissipation = 0.0;
        for s in &self.dissipation.squares {
            let y = at(&s.vector);
            let by = match s.block {
                Block::Mass => ops.mass(&y),
                Block::Stiffness => ops.stiffness(&y),
            };
            dissipation += s.coef.eval(params, dt, t) * dot(&y, &by);
        }
        Balance { kept_before, kept_after, work, dissipation }
    }

    /// The step's free variables, in the order [`Identity::balance`] takes their values.
    pub fn free(&self) -> &[Free] {
        &self.ansatz.window.free
    }
}
