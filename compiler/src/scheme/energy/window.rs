//! A step of a compiled scheme in exact form: every level it computes as an exact linear
//! combination of its free variables (the states at the step's start and each stage's
//! unknown), and every residual term with exact coefficient, arguments and time. The energy
//! identity is derived over these.

use super::exact::{Exact, Refusal};
use super::ratfn::RatFn;
use crate::scheme::affine::{Affine, Quantity};
use crate::scheme::ir::SchemeIr;

/// A free variable of a step: a state at its start, a stage's unknown, a state at the
/// previous step's start (what the α-methods' residuals read at the step's start), or a stage's
/// unknown of the previous step (when the window spans it, [`Window::two_steps`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Free {
    State(usize),
    Unknown(usize),
    Previous(usize),
    PreviousUnknown(usize),
}

/// Σ coefficient · free variable, one coefficient per variable of the window.
#[derive(Clone, Debug, PartialEq)]
pub struct Lin(pub Vec<RatFn>);

impl Lin {
    pub fn zero(n: usize) -> Lin {
        Lin(vec![RatFn::zero(); n])
    }

    /// Free variable `i` alone.
    pub fn unit(n: usize, i: usize) -> Lin {
        let mut l = Lin::zero(n);
        l.0[i] = RatFn::one();
        l
    }

    /// self + c · o.
    fn add_scaled(&mut self, c: &RatFn, o: &Lin) -> Result<(), crate::scheme::rational::GiveUp> {
        for (a, b) in self.0.iter_mut().zip(&o.0) {
            if !b.is_zero() {
                *a = a.add(&c.mul(b)?)?;
            }
        }
        Ok(())
    }

    /// Its value at the free variables' values `x` (and params, dt, t).
    pub fn eval(&self, x: &[f64], params: &[f64], dt: f64, t: f64) -> f64 {
        self.0.iter().zip(x).map(|(c, x)| if c.is_zero() { 0.0 } else { c.eval(params, dt, t) * x }).sum()
    }
}

/// One term `coef · form(args)` of a residual, at `time`, exactly.
#[derive(Clone, Debug)]
pub struct ExactTerm {
    pub coef: RatFn,
    pub form: String,
    pub args: Vec<Lin>,
    pub time: RatFn,
}

/// A step in exact form.
#[derive(Clone)]
pub struct Window {
    pub free: Vec<Free>,
    /// Per stage, its new quantities (the unknown first).
    pub levels: Vec<Vec<Lin>>,
    /// Per stage, its residual's terms.
    pub residuals: Vec<Vec<ExactTerm>>,
    /// Per stage, its time.
    pub times: Vec<RatFn>,
    /// Each state at the step's start: a free variable, or the previous step's end.
    pub start: Vec<Lin>,
    /// The index of this step's first stage in `levels`, `residuals` and `times` (those
    /// before it are the previous step's).
    pub offset: usize,
}

impl Window {
    /// This step with the previous step's states `states` as free variables too (after the
    /// others): their variables, in that order.
    pub fn with_previous(&self, states: &[usize]) -> (Window, Vec<usize>) {
        let n = self.free.len();
        let grow = |l: &Lin| Lin(l.0.iter().cloned().chain(states.iter().map(|_| RatFn::zero())).collect());
        let free = self.free.iter().copied().chain(states.iter().map(|&i| Free::Previous(i))).collect();
        let levels = self.levels.iter().map(|s| s.iter().map(grow).collect()).collect();
        let residuals = self
            .residuals
            .iter()
            .map(|r| r.iter().map(|t| ExactTerm { args: t.args.iter().map(grow).collect(), ..t.clone() }).collect())
            .collect();
        let start = self.start.iter().map(grow).collect();
        let window = Window { free, levels, residuals, times: self.times.clone(), start, offset: self.offset };
        (window, (n..n + states.len()).collect())
    }

    /// The previous step and this one (of a one-step window with `states` states): the free
    /// variables are the states at the previous step's start, its stages' unknowns and this
    /// step's; this step starts where the previous one ends (`ends`: each state's end level
    /// over the one-step window). The previous step's times are one dt back.
    pub fn two_steps(&self, states: usize, ends: &[Lin]) -> Result<Window, crate::scheme::rational::GiveUp> {
        let stages = self.free.len() - states;
        let free: Vec<Free> = (0..states)
            .map(Free::Previous)
            .chain((0..stages).map(Free::PreviousUnknown))
            .chain((0..stages).map(Free::Unknown))
            .collect();
        let n = free.len();
        // The previous step: states → Previous, unknowns → PreviousUnknown.
        let back = |l: &Lin| Lin(l.0.iter().cloned().chain((0..stages).map(|_| RatFn::zero())).collect());
        let start: Vec<Lin> = ends.iter().map(back).collect();
        // This step: state i → the previous step's end of i, unknown k → Unknown(k).
        let now = |l: &Lin| -> Result<Lin, crate::scheme::rational::GiveUp> {
            let mut out = Lin::zero(n);
            for (i, c) in l.0[..states].iter().enumerate() {
                out.add_scaled(c, &start[i])?;
            }
            for (k, c) in l.0[states..].iter().enumerate() {
                out.add_scaled(c, &Lin::unit(n, states + stages + k))?;
            }
            Ok(out)
        };
        let dt = RatFn::var(super::poly::DT);
        let mut levels: Vec<Vec<Lin>> = self.levels.iter().map(|s| s.iter().map(back).collect()).collect();
        let mut residuals: Vec<Vec<ExactTerm>> = Vec::new();
        for r in &self.residuals {
            let mut terms = Vec::new();
            for t in r {
                let args = t.args.iter().map(back).collect();
                terms.push(ExactTerm { args, time: t.time.sub(&dt)?, ..t.clone() });
            }
            residuals.push(terms);
        }
        let mut times: Vec<RatFn> = self.times.iter().map(|t| t.sub(&dt)).collect::<Result<_, _>>()?;
        for s in &self.levels {
            levels.push(s.iter().map(now).collect::<Result<_, _>>()?);
        }
        for r in &self.residuals {
            let mut terms = Vec::new();
            for t in r {
                let args = t.args.iter().map(now).collect::<Result<_, _>>()?;
                terms.push(ExactTerm { args, ..t.clone() });
            }
            residuals.push(terms);
        }
        times.extend(self.times.iter().cloned());
        Ok(Window { free, levels, residuals, times, start, offset: self.levels.len() })
    }
}

/// The step of `ir` in exact form, or the scalar that is no rational function of its params.
pub fn window(ir: &SchemeIr) -> Result<Window, Refusal> {
    let free: Vec<Free> =
        (0..ir.states.len()).map(Free::State).chain((0..ir.stages.len()).map(Free::Unknown)).collect();
    let n = free.len();
    let mut exact = Exact::default();
    let mut levels: Vec<Vec<Lin>> = Vec::new();
    let overflow = |node| Refusal { node, why: "its exact coefficients overflow 128-bit rationals".into() };
    // An affine combination of the stage's unknown and known quantities, over the free variables.
    let lin = |exact: &mut Exact, levels: &[Vec<Lin>], stage: usize, a: &Affine| -> Result<Lin, Refusal> {
        let mut out = Lin::zero(n);
        let c = exact.of(&ir.graph, a.unknown)?;
        out.add_scaled(&c, &Lin::unit(n, ir.states.len() + stage)).map_err(|_| overflow(a.unknown))?;
        for &(q, node) in &a.known {
            let c = exact.of(&ir.graph, node)?;
            let of = match q {
                Quantity::State(i) => Lin::unit(n, i),
                Quantity::Stage { stage, index } => levels[stage][index].clone(),
            };
            out.add_scaled(&c, &of).map_err(|_| overflow(node))?;
        }
        Ok(out)
    };
    let mut residuals = Vec::new();
    let mut times = Vec::new();
    for (k, stage) in ir.stages.iter().enumerate() {
        let mut mine = Vec::new();
        for v in &stage.values {
            let l = lin(&mut exact, &levels, k, v)?;
            mine.push(l);
        }
        levels.push(mine);
        let mut terms = Vec::new();
        for t in &stage.terms {
            let args = t.args.iter().map(|a| lin(&mut exact, &levels, k, a)).collect::<Result<_, _>>()?;
            terms.push(ExactTerm {
                coef: exact.of(&ir.graph, t.coef)?,
                form: t.form.clone(),
                args,
                time: exact.of(&ir.graph, t.time)?,
            });
        }
        residuals.push(terms);
        times.push(exact.of(&ir.graph, stage.time)?);
    }
    let start = (0..ir.states.len()).map(|i| Lin::unit(n, i)).collect();
    Ok(Window { free, levels, residuals, times, start, offset: 0 })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scheme::affine::eval;

    /// Every level of every library scheme's step, in exact form, has the value the compiled
    /// stages give it (evaluated stage by stage from random states and unknowns), and so does
    /// every residual argument.
    #[test]
    fn the_exact_step_has_the_values_of_the_compiled_one() {
        let mut seed = 5u64;
        let mut random = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for (name, ir) in super::super::library_schemes() {
            let w = window(&ir).unwrap_or_else(|e| panic!("{name}: {e:?}"));
            let params: Vec<f64> = ir.params.iter().map(|p| p.default).collect();
            let (dt, t) = (0.05 + random(), random());
            let x: Vec<f64> = w.free.iter().map(|_| random() - 0.5).collect();
            // The compiled stages' values, stage by stage.
            let mut values: Vec<Vec<f64>> = Vec::new();
            let affine = |values: &[Vec<f64>], k: usize, a: &Affine| -> f64 {
                let mut v = eval(&ir.graph, a.unknown, &params, dt, t) * x[ir.states.len() + k];
                for &(q, node) in &a.known {
                    let level = match q {
                        Quantity::State(i) => x[i],
                        Quantity::Stage { stage, index } => values[stage][index],
                    };
                    v += eval(&ir.graph, node, &params, dt, t) * level;
                }
                v
            };
            for (k, stage) in ir.stages.iter().enumerate() {
                let mine: Vec<f64> = stage.values.iter().map(|a| affine(&values, k, a)).collect();
                for (i, want) in mine.iter().enumerate() {
                    let got = w.levels[k][i].eval(&x, &params, dt, t);
                    assert!(
                        (got - want).abs() <= 1e-11 * (1.0 + want.abs()),
                        "{name}: stage {k} level {i}: {got} against {want}"
                    );
                }
                values.push(mine);
                for (term, exact) in stage.terms.iter().zip(&w.residuals[k]) {
                    for (a, l) in term.args.iter().zip(&exact.args) {
                        let (want, got) = (affine(&values, k, a), l.eval(&x, &params, dt, t));
                        assert!((got - want).abs() <= 1e-11 * (1.0 + want.abs()), "{name}: {} argument", term.form);
                    }
                }
            }
        }
    }
}
