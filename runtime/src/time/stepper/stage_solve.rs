//! One stage's solve: its terms sorted into the known parts (loads, terms of known levels, the
//! linear terms' constant operator and products) and Newton's (the rest), then Newton on the
//! increment from the stage's reference level.

use std::collections::HashMap;

use signorini_descriptors::{StageDesc, TermDesc};

use super::levels::Levels;
use super::{LOAD_CACHE, StageCache, StepError, Stepper};
use crate::fem::assembly::Assembler;
use crate::fem::bound::BoundForm;
use crate::fem::mesh::inverted::{self, Inverted};
use crate::fem::pair::LostFacing;
use crate::linalg::Matrix;
use crate::linalg::lower_half::{LowerHalf, MAX_FUSED};
use crate::nonlinear::newton::{Newton, NewtonError, NewtonReport};
use crate::nonlinear::statics::Constraints;
use crate::time::stage::{
    ActiveTerm, Linear, NonFiniteTangent, RecordedTangent, StageProblem, Support, tangent_support,
};

/// Linear terms coef·K_j·(α_j w + base_j): their forms and fields j, coefficients and bases.
type LinearTerms<'s> = (Vec<(&'s str, usize)>, Vec<f64>, Vec<Vec<f64>>);

/// A stage's known parts: the constant part of its residual, and the terms Newton evaluates.
struct Known<'s> {
    rhs: Vec<f64>,
    nonlinear: Vec<ActiveTerm<'s>>,
}

impl Stepper<'_> {
    /// Solves a stage for δ = w − reference (`levels.reference`), w its unknown at `t` (the
    /// step's start) + `dt`.
    pub(super) fn solve_stage(
        &mut self,
        stage: &StageDesc,
        cache: usize,
        levels: &Levels,
        dt: f64,
        t: f64,
    ) -> Result<(Vec<f64>, NewtonReport), StepError> {
        let stage_t = self.coefs.get(stage.time).copied().filter(|_| !stage.quantities.is_empty()).unwrap_or(t);
        let known = self.known_parts(stage, cache, levels, dt);
        self.solve_known(stage, cache, levels, known, stage_t)
    }

    /// Sorts the stage's terms: a load or a term of known levels only goes into the constant
    /// residual; a linear term into the constant operator Σ_j coef·α_j·K_j (rebuilt when Δt
    /// changed) and, through its bases, the residual; every other term is Newton's.
    fn known_parts<'s>(&mut self, stage: &'s StageDesc, cache: usize, levels: &Levels, dt: f64) -> Known<'s> {
        let n = self.asm.size();
        // Known parts of every argument, and the constant part of the residual.
        let mut constant_rhs = self.pool.zeros(n);
        let mut nonlinear: Vec<ActiveTerm> = Vec::new();
        let mut linear: LinearTerms = Default::default();
        let rebuild = self.stages[cache].dt != dt || self.stages[cache].constant.is_none();
        let mut constant = if rebuild { Some(self.asm.zero_matrix()) } else { None };
        for term in stage.terms.iter() {
            if term.args.is_empty() {
                self.add_load(term, &mut constant_rhs);
                continue;
            }
            let (bases, alphas) = self.bases(term, levels);
            let coef = self.coefs[term.coef];
            let form = &self.forms[&*term.form];
            let term_t = self.coefs[term.time];
            match self.matrices.get(&*term.form) {
                // A form that reads `prev` has one more argument than fields: Newton's.
                Some(ks) if ks.len() == alphas.len() => {
                    if let Some(c) = constant.as_mut() {
                        ks.iter().zip(&alphas).for_each(|(k, a)| c.add_scaled(coef * a, k));
                    }
                    for (j, base) in bases.into_iter().enumerate() {
                        linear.0.push((&term.form, j));
                        linear.1.push(coef);
                        linear.2.push(base);
                    }
                }
                _ if alphas.iter().all(|a| *a == 0.0) => {
                    let refs: Vec<&[f64]> = bases.iter().map(Vec::as_slice).collect();
                    let mut b = self.pool.zeros(n);
                    form.residual(self.asm, &refs, term_t, &mut b);
                    constant_rhs.iter_mut().zip(&b).for_each(|(r, x)| *r += coef * x);
                    self.pool.give(b);
                    bases.into_iter().for_each(|b| self.pool.give(b));
                }
                _ => nonlinear.push(ActiveTerm { form: &term.form, coef, alphas, bases, t: term_t }),
            }
        }
        self.add_linear(cache, &linear, &mut constant_rhs);
        linear.2.into_iter().for_each(|b| self.pool.give(b));
        if let Some(c) = constant {
            let entry = &mut self.stages[cache];
            entry.constant = Some(Linear::new(c, self.half_pattern.as_ref()));
            entry.dt = dt;
            entry.newton.invalidate();
        }
        Known { rhs: constant_rhs, nonlinear }
    }

    /// Adds coef·b to `rhs`, b a load term's vector at its time. Loads depend on time only:
    /// the one at t + dt this step is the one at t next step, and a steady one is the same at
    /// every time, so the last few are kept.
    fn add_load(&mut self, term: &TermDesc, rhs: &mut [f64]) {
        let n = self.asm.size();
        let coef = self.coefs[term.coef];
        let form = &self.forms[&*term.form];
        let term_t = self.coefs[term.time];
        let bits = if form.time_dependent() { term_t.to_bits() } else { u64::MAX };
        let b = match self.loads.iter().position(|((f, t), _)| *f == term.form && *t == bits) {
            Some(i) => &self.loads[i].1,
            None => {
                let mut b = vec![0.0; n];
                form.residual(self.asm, &[], term_t, &mut b);
                if self.loads.len() == LOAD_CACHE {
                    self.loads.remove(0);
                }
                self.loads.push(((term.form.to_string(), bits), b));
                &self.loads.last().expect("just pushed").1
            }
        };
        rhs.iter_mut().zip(b).for_each(|(r, x)| *r += coef * x);
    }

    /// A term's arguments at w = reference (their known parts), each with its coefficient α of
    /// the unknown; then the previous level, for a form that reads `prev` (α = 0).
    fn bases(&mut self, term: &TermDesc, levels: &Levels) -> (Vec<Vec<f64>>, Vec<f64>) {
        let n = self.asm.size();
        let mut bases: Vec<Vec<f64>> = Vec::with_capacity(term.args.len());
        for c in term.args.iter() {
            let mut b = self.pool.take(n);
            self.combine(c, levels, None, &mut b);
            bases.push(b);
        }
        let mut alphas: Vec<f64> = term.args.iter().map(|c| c.unknown.map_or(0.0, |k| self.coefs[k])).collect();
        if self.forms[&*term.form].previous() {
            let mut b = self.pool.take(n);
            b.copy_from_slice(self.previous_level(term, levels));
            bases.push(b);
            alphas.push(0.0);
        }
        (bases, alphas)
    }

    /// Adds Σ coef·K_j·base over a stage's linear terms (forms and fields, coefficients, bases)
    /// to `rhs`: one pass over the matrices' fused lower halves when they are symmetric.
    fn add_linear(&mut self, cache: usize, (forms, coefs, bases): &LinearTerms, rhs: &mut [f64]) {
        if forms.is_empty() {
            return;
        }
        let mut product = self.pool.take(rhs.len());
        let Some(half) = self.half_pattern.as_ref() else {
            for (((form, j), coef), base) in forms.iter().zip(coefs).zip(bases) {
                self.matrices[*form][*j].mul_vec(base, &mut product);
                rhs.iter_mut().zip(&product).for_each(|(r, x)| *r += coef * x);
            }
            self.pool.give(product);
            return;
        };
        let entry = &mut self.stages[cache];
        if entry
            .linear
            .as_ref()
            .is_none_or(|(cached, _)| !cached.iter().map(|(f, j)| (f.as_str(), *j)).eq(forms.iter().copied()))
        {
            let matrices: Vec<&Matrix> = forms.iter().map(|(f, j)| &self.matrices[*f][*j]).collect();
            let groups = matrices.chunks(MAX_FUSED).map(|g| LowerHalf::fused(g, half)).collect();
            entry.linear = Some((forms.iter().map(|(f, j)| (f.to_string(), *j)).collect(), groups));
        }
        let (_, groups) = entry.linear.as_ref().expect("built above");
        let terms: Vec<(f64, &[f64])> = coefs.iter().zip(bases).map(|(c, b)| (*c, b.as_slice())).collect();
        for (group, terms) in groups.iter().zip(terms.chunks(MAX_FUSED)) {
            group.mul_sum(terms, &mut product);
            rhs.iter_mut().zip(&product).for_each(|(r, x)| *r += x);
        }
        self.pool.give(product);
    }

    /// Newton on the stage's residual, its known parts given, from δ = 0 but on the held dofs.
    fn solve_known(
        &mut self,
        stage: &StageDesc,
        cache: usize,
        levels: &Levels,
        known: Known,
        stage_t: f64,
    ) -> Result<(Vec<f64>, NewtonReport), StepError> {
        let n = self.asm.size();
        let Known { rhs: constant_rhs, nonlinear } = known;
        let piecewise = nonlinear.iter().all(|a| self.forms[a.form].piecewise());
        let StageCache { newton, constant, support, scratch, args, term, switches, recorded, .. } =
            &mut self.stages[cache];
        refresh_support(self.asm, &self.forms, &nonlinear, support, scratch, newton);
        let support = support.as_ref().and_then(|(_, s)| s.as_ref());
        let mut problem = StageProblem {
            asm: self.asm,
            forms: &self.forms,
            constant: constant.as_ref().expect("built above"),
            rhs: constant_rhs,
            terms: nonlinear,
            constraints: &self.constraints,
            structure: self.structure,
            piecewise,
            support,
            scratch,
            args: std::mem::take(args),
            term: std::mem::take(term),
            switches,
            magnitude: 0.0,
            recorded: RecordedTangent { valid: false, ..std::mem::take(recorded) },
            non_finite: None,
        };
        // δ = w − reference, with the constrained values of w imposed: zero but on those.
        let w0 = levels.get(levels.reference);
        let mut delta = self.pool.zeros(n);
        let Constraints { fixed, values } = &self.constraints;
        for (i, _) in fixed.iter().enumerate().filter(|(_, f)| **f) {
            delta[i] = values[i] - w0[i];
        }
        let report = newton.solve(&mut problem, &mut delta);
        let non_finite = if report.is_err() { problem.non_finite.take() } else { None };
        (*args, *term, *recorded) = (problem.args, problem.term, problem.recorded);
        self.pool.give(problem.rhs);
        problem.terms.into_iter().flat_map(|t| t.bases).for_each(|b| self.pool.give(b));
        if let Some(at) = self.lost_facing() {
            return Err(StepError::FacingLost { stage: stage.name.to_string(), t: stage_t, at });
        }
        // A NaN in a failed Newton (its residual, or a tangent) is explained by a cell turned
        // inside out where there is one (answered by a step cut), else it is a law's derivative
        // that is not finite (at any Δt). Both are decided alike by every process.
        let tangent = if report.is_err() { non_finite_anywhere(self.asm, non_finite) } else { None };
        let nan = matches!(report, Err(NewtonError::NonFinite { .. })) || tangent.is_some();
        if nan && let Some(at) = self.inverted_at(stage, levels, &delta) {
            return Err(StepError::Inverted { stage: stage.name.to_string(), t: stage_t, at });
        }
        if let Some(at) = tangent {
            return Err(StepError::NonFiniteTangent { stage: stage.name.to_string(), t: stage_t, at });
        }
        let report =
            report.map_err(|source| StepError::Newton { stage: stage.name.to_string(), t: stage_t, source })?;
        Ok((delta, report))
    }
}

impl Stepper<'_> {
    /// A contact pair's point that faces nothing at the stage's last iterate though it faced
    /// the other surface (its force gone without the bodies parting): answered by a step cut.
    /// In a split run every process says so when one saw it.
    fn lost_facing(&self) -> Option<LostFacing> {
        let mut searching = self.forms.values().filter(|f| f.searches()).peekable();
        searching.peek()?;
        let here = searching.find_map(|f| f.lost_facing());
        let anywhere = match self.asm.pattern().ownership() {
            Some(o) => o.any(here.is_some()),
            None => here.is_some(),
        };
        anywhere.then(|| {
            here.unwrap_or_else(|| LostFacing {
                form: "(seen by another process)".into(),
                point: Vec::new(),
                distance: f64::NAN,
                reach: f64::NAN,
            })
        })
    }

    /// After a failed Newton, the most inverted cell of the stage's displacement quantity (u',
    /// um, ...) at its last iterate, if one is inverted. In a split run every process says so
    /// when one saw it (each decides alike what follows: a step cut).
    fn inverted_at(&self, stage: &StageDesc, levels: &Levels, delta: &[f64]) -> Option<Inverted> {
        let q = self.displacement(stage)?;
        let mut u = vec![0.0; self.asm.size()];
        self.combine(&stage.values[q], levels, Some(delta), &mut u);
        inverted::anywhere(self.asm, &u)
    }
}

/// The entries the nonlinear terms' tangents add to, found again when the terms' forms are
/// not those they were found for. The same forms at every step in practice; should they
/// change, so may the entries where J varies, and the references compared there only are
/// dropped.
fn refresh_support<'a>(
    asm: &Assembler,
    forms: &HashMap<String, Box<dyn BoundForm + 'a>>,
    nonlinear: &[ActiveTerm],
    support: &mut Option<(Vec<String>, Option<Support>)>,
    scratch: &mut Option<Matrix>,
    newton: &mut Newton,
) {
    if support
        .as_ref()
        .is_none_or(|(cached, _)| !cached.iter().map(String::as_str).eq(nonlinear.iter().map(|a| a.form)))
    {
        let names = nonlinear.iter().map(|a| a.form.to_string()).collect();
        *support = Some((names, tangent_support(asm, forms, nonlinear)));
        *scratch = None;
        newton.invalidate();
    }
}

/// After a failed Newton, the non-finite tangent (0/0 in a law's derivative) it met, which is
/// said as such, not as the singular matrix it makes. In a split run every process says so when
/// one saw it (each decides alike what follows).
fn non_finite_anywhere(asm: &Assembler, here: Option<NonFiniteTangent>) -> Option<NonFiniteTangent> {
    let anywhere = match asm.pattern().ownership() {
        Some(o) => o.any(here.is_some()),
        None => here.is_some(),
    };
    anywhere.then(|| {
        here.unwrap_or_else(|| NonFiniteTangent {
            form: "(seen by another process)".into(),
            level: 0,
            nodes: Vec::new(),
        })
    })
}
