//! Time schemes compiled from `.wf` files: the static description a generated scheme provides,
//! and the engine that steps with it.
//!
//! Per stage, the compiler has written every term's arguments as `α·w + Σ βₖ·knownₖ` (w the
//! stage's unknown). The engine precomputes the known parts once per stage, assembles the
//! constant operator Σ coef·α·K of the linear forms once per time step size, and runs Newton on
//! the rest (the contact terms), reusing the factorization while the active set is unchanged.
//!
//! Newton solves for the increment δ = w − w₀ from a known reference level w₀ (the state the
//! unknown updates, e.g. u for u'), and every combination is evaluated in increments: the
//! levels whose coefficients (the unknown's counted at w₀) sum to zero enter as
//! Σ βₖ·(knownₖ − reference). Such sums are zero in exact arithmetic (a' and v' of a rigid
//! translation), but not once the coefficients are rounded: TR-BDF2's BDF2 stage writes
//! a' = 29142·u' + 6036·u − 35178·um + …, whose rounded coefficients sum to 7e-12, a spurious
//! force proportional to the displacement on every step. The increment form drops that sum
//! and cancels the large terms before scaling them (see `zero_sum_groups`).

//!
//! This module holds the stepper and its step; `levels` evaluates the combinations of levels a
//! stage reads, `stage_solve` solves one stage, `pool` keeps spare vectors.

mod levels;
mod pool;
mod stage_solve;

use std::collections::HashMap;
use std::sync::Arc;

use signorini_descriptors::{Borrowed, Level, SchemeDesc, StageDesc};

use crate::fem::assembly::Assembler;
use crate::fem::bound::BoundForm;
use crate::linalg::lower_half::{HalfPattern, LowerHalf};
use crate::linalg::matrix::SYMMETRY_TOLERANCE;
use crate::linalg::{Matrix, Structure};
use crate::nonlinear::newton::{Newton, NewtonError, NewtonOptions, NewtonReport};
use crate::nonlinear::statics::Constraints;
use crate::time::scheme::{StageView, TimeScheme};
use crate::time::stage::{Linear, NonFiniteTangent, RecordedTangent, Support, SwitchMemo, probe_structure};
use levels::Levels;
use pool::Pool;

#[derive(Debug, thiserror::Error)]
pub enum StepError {
    #[error("scheme `{scheme}` applies slot `{form}` ({declared}), which no form file in use provides")]
    MissingForm { scheme: String, form: String, declared: String },
    #[error("form `{form}` takes {expected} field(s), but the scheme applies it to {given}")]
    Arity { form: String, expected: usize, given: usize },
    #[error(
        "the solution is no longer finite at t = {t}: the scheme is unstable with these parameters (Nitsche with θ = 1 needs γ0 large enough for coercivity)"
    )]
    NonFinite { t: f64 },
    #[error("stage `{stage}` at t = {t}: {source}")]
    Newton { stage: String, t: f64, source: NewtonError },
    #[error(
        "stage `{stage}` at t = {t}: {at}: its derivative divides by zero there (0/0 where a `pos`/`neg` clips an expression under a `sqrt` or a negative power; `check` warns of it as W0006): write the power directly, `d^(3/2)` rather than `d*sqrt(d)`"
    )]
    NonFiniteTangent { stage: String, t: f64, at: NonFiniteTangent },
    #[error(
        "stage `{stage}` at t = {t}: {at}: a finite-strain material's stress is not defined there (ln J, F⁻¹); a smaller Δt, or a stiffer or better-shaped mesh where the body is compressed hardest, keeps it positive"
    )]
    Inverted { stage: String, t: f64, at: crate::fem::mesh::inverted::Inverted },
    #[error("stage `{stage}` at t = {t}: {at}")]
    FacingLost { stage: String, t: f64, at: crate::fem::pair::LostFacing },
    #[error(
        "stage `{stage}` of scheme `{scheme}` has no displacement quantity (u', um, ...) that depends on its unknown (a nonzero coefficient at this Δt): a moving held displacement cannot be imposed there"
    )]
    NoDisplacement { scheme: String, stage: String },
}

/// A linear form's field: the form's name and the field's index (its matrix K_j).
type FormField = (String, usize);

/// Displacements held at values that change with time (a moving Dirichlet condition): the
/// held dofs (among the constraints' fixed ones) and their values at a time, in that order.
/// Each stage holds its unknown where its displacement quantity takes the values at the stage's
/// time, through the stage's own relation (u' = w for most schemes; an acceleration unknown is
/// solved for from u' = u + Δt v + ... + c a').
pub struct Prescribed {
    pub dofs: Vec<usize>,
    pub values: HeldValues,
}

/// Writes the held values at a time, in the order of [`Prescribed::dofs`].
pub type HeldValues = Box<dyn Fn(f64, &mut [f64]) + Send + Sync>;

/// How many load vectors the stepper remembers (a step evaluates loads at two or three times).
const LOAD_CACHE: usize = 4;

/// Statistics of one step.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct StepReport {
    /// Newton report per stage.
    pub stages: Vec<NewtonReport>,
}

impl StepReport {
    pub fn iterations(&self) -> usize {
        self.stages.iter().map(NewtonReport::iterations).sum()
    }
}

/// Steps a scheme on a mesh with bound forms.
pub struct Stepper<'a> {
    pub scheme: Box<dyn TimeScheme + 'a>,
    /// The scheme's description, shared with the step being taken (which iterates its stages
    /// while it updates the stepper).
    desc: Arc<SchemeDesc>,
    asm: &'a Assembler<'a>,
    forms: HashMap<String, Box<dyn BoundForm + 'a>>,
    pub constraints: Constraints,
    /// Extra Dirichlet conditions for the initial problem only (e.g. a⁰ = 0 on massless
    /// contact dofs after mass redistribution).
    pub initial_constraints: Option<Constraints>,
    /// Held displacements that move: see [`Stepper::prescribe`].
    prescribed: Option<Prescribed>,
    structure: Structure,
    pub newton_options: NewtonOptions,
    /// Per stage: its Newton (keeps its factorization) and the constant operator for `dt`.
    stages: Vec<StageCache>,
    /// Linear forms' matrices (assembled once), one per field: the residual of a form linear in
    /// its fields w₁ … w_k is Σ K_j w_j.
    matrices: HashMap<String, Vec<Matrix>>,
    /// The pattern's lower half, when the stage matrices are symmetric.
    half_pattern: Option<Arc<HalfPattern>>,
    /// Recently assembled loads, by (form, time).
    loads: Vec<((String, u64), Vec<f64>)>,
    coefs: Vec<f64>,
    /// Whether a form reads the previous time level (`prev`), and that level: the displacement
    /// at the start of the last accepted step (u⁰ before the first). See [`Stepper::solve_stage`].
    reads_previous: bool,
    previous: Option<Vec<f64>>,
    /// Vectors of the problem's size no longer in use (states replaced, bases, products), for
    /// the next step: a step allocates none once the first has run.
    pool: Pool,
    /// The last step's local error (the scheme's `estimate`), when asked for: see
    /// [`Stepper::estimate`].
    estimate: Option<Vec<f64>>,
}

struct StageCache {
    newton: Newton,
    dt: f64,
    constant: Option<Linear>,
    /// The nonlinear terms' forms, and the entries their tangents add to (None: anywhere).
    support: Option<(Vec<String>, Option<Support>)>,
    /// Scratch for the nonlinear terms' tangents: zero outside `support`.
    scratch: Option<Matrix>,
    /// The linear terms' forms, and their matrices' lower halves fused for one product (in
    /// groups of at most `MAX_FUSED`), when the matrices are symmetric.
    linear: Option<(Vec<FormField>, Vec<LowerHalf>)>,
    /// The nonlinear terms' arguments and residual, kept from one step to the next.
    args: Vec<Vec<f64>>,
    term: Vec<f64>,
    switches: SwitchMemo,
    /// The last Jacobian assembly's recorded tangent, its storage kept from one step to the
    /// next (a new stage problem starts it invalid: its coefficients and times may differ).
    recorded: RecordedTangent,
}

impl<'a> Stepper<'a> {
    /// `forms` binds the form names the scheme uses to bound kernels (a slot may hold any form
    /// of the right arity: `contact` is Nitsche's or the penalty's). `structure`: Cholesky for
    /// symmetric positive definite stage Jacobians, LU otherwise.
    pub fn new<S: Into<String>>(
        scheme: Box<dyn TimeScheme + 'a>,
        asm: &'a Assembler<'a>,
        forms: Vec<(S, Box<dyn BoundForm + 'a>)>,
        constraints: Constraints,
        structure: Structure,
        newton_options: NewtonOptions,
    ) -> Result<Self, StepError> {
        let forms: HashMap<String, Box<dyn BoundForm + 'a>> =
            forms.into_iter().map(|(slot, f)| (slot.into(), f)).collect();
        let desc = Arc::new(scheme.desc().clone());
        check_terms(&desc, &forms)?;
        let mut matrices = HashMap::new();
        let zero = vec![0.0; asm.size()];
        for (name, f) in &forms {
            if f.linear() && f.fields() >= 1 {
                let zeros = vec![zero.as_slice(); f.fields()];
                let per_field = (0..f.fields())
                    .map(|j| {
                        let mut m = asm.zero_matrix();
                        f.tangent(asm, &zeros, j, 0.0, &mut m);
                        m
                    })
                    .collect();
                matrices.insert(name.clone(), per_field);
            }
        }
        let structure = match structure {
            Structure::Auto => probe_structure(asm, &forms, &matrices),
            s => s,
        };
        // The linear forms' matrices are read in lower halves (half the values per product)
        // wherever they are all symmetric, whatever the nonlinear forms' tangents are (a
        // frictional law's is not).
        let symmetric = structure == Structure::SymmetricPositiveDefinite
            || matrices.values().flatten().all(|m| m.is_symmetric(SYMMETRY_TOLERANCE));
        let half_pattern = symmetric.then(|| Arc::new(HalfPattern::new(asm.pattern())));
        let stages = (0..desc.stages.len() + 1)
            .map(|_| StageCache {
                newton: Newton::new(newton_options),
                dt: f64::NAN,
                constant: None,
                support: None,
                scratch: None,
                linear: None,
                args: Vec::new(),
                term: Vec::new(),
                switches: SwitchMemo::default(),
                recorded: RecordedTangent::default(),
            })
            .collect();
        let coefs = vec![0.0; desc.coefficients];
        let reads_previous = forms.values().any(|f| f.previous());
        Ok(Stepper {
            scheme,
            desc,
            asm,
            forms,
            constraints,
            initial_constraints: None,
            prescribed: None,
            structure,
            newton_options,
            stages,
            matrices,
            half_pattern,
            loads: Vec::new(),
            coefs,
            reads_previous,
            previous: None,
            pool: Pool::default(),
            estimate: None,
        })
    }

    /// The residual of the form bound to `slot` at `fields` and time `t`, as the scheme's
    /// residuals apply it (none for a slot the stepper does not bind): what a derived energy
    /// identity evaluates its work and dissipation with.
    pub fn apply(&self, slot: &str, fields: &[&[f64]], t: f64) -> Option<Vec<f64>> {
        let mut out = vec![0.0; self.asm.size()];
        self.apply_into(slot, fields, t, &mut out).then_some(out)
    }

    /// As [`Stepper::apply`], into `out` (zeroed first); false for a slot it does not bind.
    pub fn apply_into(&self, slot: &str, fields: &[&[f64]], t: f64, out: &mut [f64]) -> bool {
        let Some(form) = self.forms.get(slot) else { return false };
        out.fill(0.0);
        form.residual(self.asm, fields, t, out);
        true
    }

    /// Whether the form bound to `slot` changes with time other than through its fields (none
    /// for a slot the stepper does not bind).
    pub fn time_dependent(&self, slot: &str) -> Option<bool> {
        self.forms.get(slot).map(|f| f.time_dependent())
    }

    /// The scheme's description (states, stages, slots).
    /// The lower half of the mesh's pattern (in reverse Cuthill–McKee order) that the stages'
    /// symmetric matrices are stored on, when they are: for other symmetric products on the
    /// same pattern.
    pub fn half_pattern(&self) -> Option<&Arc<HalfPattern>> {
        self.half_pattern.as_ref()
    }

    pub fn desc(&self) -> &SchemeDesc {
        &self.desc
    }

    /// Factorizations and solves of all stages so far.
    pub fn counters(&self) -> crate::linalg::Counters {
        self.stages.iter().map(|s| s.newton.counters()).fold(Default::default(), |a, c| a + c)
    }

    /// What the contact pairs' search and assembly have cost so far, over the scheme's forms.
    pub fn search_cost(&self) -> crate::fem::search_cost::SearchCost {
        self.forms.values().map(|f| f.search_cost()).fold(Default::default(), |a, c| a + c)
    }

    /// The largest stage's Cholesky factor (stored values), if the stages factor by Cholesky.
    pub fn factor_nnz(&self) -> Option<usize> {
        self.stages.iter().filter_map(|s| s.newton.factor_nnz()).max()
    }

    /// The matrix of a linear one-field form (e.g. `mass`, for energies).
    pub fn matrix(&self, form: &str) -> Option<&Matrix> {
        self.matrices.get(form).filter(|m| m.len() == 1).map(|m| &m[0])
    }

    /// Holds `p.dofs` (fixed in the constraints) at the moving values `p.values`: refused when a
    /// stage has no displacement quantity depending on its unknown. The initial problem keeps
    /// its held values (zero: the held motion's acceleration at the start is taken as zero).
    pub fn prescribe(&mut self, p: Prescribed) -> Result<(), StepError> {
        for stage in self.desc.stages.iter() {
            if self.displacement(stage).is_none() {
                return Err(self.no_displacement(stage));
            }
        }
        self.prescribed = Some(p);
        Ok(())
    }

    fn no_displacement(&self, stage: &StageDesc) -> StepError {
        StepError::NoDisplacement { scheme: self.desc.name.to_string(), stage: stage.name.to_string() }
    }

    /// The stage's displacement quantity (named after the first state with a suffix: `u'`,
    /// `um`) when it depends on the unknown.
    fn displacement(&self, stage: &StageDesc) -> Option<usize> {
        let u: &str = self.desc.states.first()?;
        let q = stage.quantities.iter().position(|q| q.starts_with(u) && q.len() > u.len())?;
        stage.values.get(q).filter(|c| c.unknown.is_some()).map(|_| q)
    }

    /// Sets the held values of the stage's unknown so that its displacement quantity takes the
    /// prescribed values at `time`: w = w₀ + (g − u(w₀)) / c_w, u affine in w.
    fn hold(&mut self, stage: &StageDesc, levels: &Levels, time: f64) -> Result<(), StepError> {
        let Some(p) = &self.prescribed else { return Ok(()) };
        let q = self.displacement(stage).ok_or_else(|| self.no_displacement(stage))?;
        let c = &stage.values[q];
        let cw = c.unknown.map_or(0.0, |k| self.coefs[k]);
        if cw == 0.0 || !cw.is_finite() {
            return Err(self.no_displacement(stage));
        }
        let mut g = vec![0.0; p.dofs.len()];
        (p.values)(time, &mut g);
        let mut at_reference = vec![0.0; self.asm.size()];
        self.combine(c, levels, None, &mut at_reference);
        let w0 = levels.get(levels.reference);
        for (&i, gi) in p.dofs.iter().zip(&g) {
            self.constraints.values[i] = w0[i] + (gi - at_reference[i]) / cw;
        }
        Ok(())
    }

    /// Solves the initial problem (e.g. M a⁰ = L⁰ − B(u⁰)) for its state, if the scheme has one.
    pub fn initialize(&mut self, states: &mut [Vec<f64>], t: f64) -> Result<Option<NewtonReport>, StepError> {
        if self.reads_previous {
            self.previous = Some(states[0].clone());
        }
        let Some(init) = &self.desc.initial else { return Ok(None) };
        let state = init.state;
        let stage = StageDesc {
            name: Borrowed("initial"),
            time: 0,
            quantities: Borrowed(&[]),
            values: Borrowed(&[]),
            terms: init.terms.clone(),
        };
        self.scheme.coefficients(1.0, t, &mut self.coefs);
        let reference = Level::State(state);
        let cache = self.stages.len() - 1;
        let saved = self.initial_constraints.as_ref().map(|c| std::mem::replace(&mut self.constraints, c.clone()));
        let levels = Levels { states, quantities: &[], reference };
        let result = self.solve_stage(&stage, cache, &levels, 1.0, t);
        let result = result.map(|(delta, report)| {
            let mut w: Vec<f64> = states[state].iter().zip(&delta).map(|(r, d)| r + d).collect();
            self.constraints.impose(&mut w);
            (w, report)
        });
        if let Some(c) = saved {
            self.constraints = c;
        }
        let (w, report) = result?;
        states[state] = w;
        // The stages' Jacobians have the initial problem's pattern: one ordering and symbolic
        // analysis serves all, and the first stage factors into the initial problem's storage.
        if let Some((initial, stages)) = self.stages.split_last_mut()
            && let Some((first, rest)) = stages.split_first_mut()
        {
            rest.iter_mut().for_each(|s| s.newton.share_analysis(&initial.newton));
            first.newton.inherit(&mut initial.newton);
            // The initial problem is solved once: its operators need not stay (a matrix's worth
            // each, rebuilt if it is solved again).
            (initial.constant, initial.linear, initial.scratch) = (None, None, None);
        }
        Ok(Some(report))
    }

    /// u at the start of the last accepted step (u⁰ before the first), which a term of the
    /// accepted level reads as its `prev` (see `previous_level`), when a form reads `prev`:
    /// state, which a checkpoint keeps with the scheme's states.
    pub fn previous(&self) -> Option<&[f64]> {
        self.previous.as_deref().filter(|_| self.reads_previous)
    }

    /// Whether a form reads the previous time level (then [`Stepper::previous`] is part of the
    /// state).
    pub fn reads_previous(&self) -> bool {
        self.reads_previous
    }

    /// Restores the previous time level (from a checkpoint).
    pub fn set_previous(&mut self, previous: Vec<f64>) {
        self.previous = Some(previous);
    }

    /// Has every step from now on evaluate the scheme's `estimate` (false: none declared).
    pub fn estimate_steps(&mut self) -> bool {
        if self.desc.estimate.is_some() && self.estimate.is_none() {
            self.estimate = Some(vec![0.0; self.asm.size()]);
        }
        self.estimate.is_some()
    }

    /// The local error of the last step taken (its `estimate` combination of the step's levels),
    /// once [`Stepper::estimate_steps`] asked for it.
    pub fn estimate(&self) -> Option<&[f64]> {
        self.estimate.as_deref()
    }

    /// Drops the stages' factorizations, constant operators and loads: the next step runs as in
    /// a new stepper (see [`crate::nonlinear::newton::Newton::forget`]).
    pub fn forget(&mut self) {
        for s in &mut self.stages {
            s.newton.forget();
            s.constant = None;
            s.switches = SwitchMemo::default();
        }
        self.loads.clear();
    }

    /// Advances `states` from t to t + dt.
    pub fn step(&mut self, states: &mut [Vec<f64>], t: f64, dt: f64) -> Result<StepReport, StepError> {
        self.step_observed(states, t, dt, &mut |_| {})
    }

    /// As [`Stepper::step`], showing each stage's quantities to `observe` once solved.
    pub fn step_observed(
        &mut self,
        states: &mut [Vec<f64>],
        t: f64,
        dt: f64,
        observe: &mut dyn FnMut(&StageView),
    ) -> Result<StepReport, StepError> {
        let desc = Arc::clone(&self.desc);
        let n = self.asm.size();
        self.scheme.coefficients(dt, t, &mut self.coefs);
        let mut quantities: Vec<Vec<Vec<f64>>> = Vec::with_capacity(desc.stages.len());
        let mut report = StepReport::default();
        // The displacement at the start of the step: the previous level of the next one.
        let start = self.reads_previous.then(|| self.pool.copy(&states[0]));
        for (s, stage) in desc.stages.iter().enumerate() {
            // Newton starts from the state the unknown updates (u for u'), else the first state.
            let name = &stage.quantities[0];
            let reference =
                Level::State(desc.states.iter().position(|st| name.trim_end_matches('\'') == st).unwrap_or(0));
            let levels = Levels { states, quantities: &quantities, reference };
            if self.prescribed.is_some() {
                let time = self.coefs.get(stage.time).copied().unwrap_or(t + dt);
                self.hold(stage, &levels, time)?;
            }
            let (delta, r) = self.solve_stage(stage, s, &levels, dt, t)?;
            report.stages.push(r);
            let mut values: Vec<Vec<f64>> = Vec::with_capacity(stage.values.len());
            for c in stage.values.iter() {
                let mut v = self.pool.take(n);
                self.combine(c, &levels, Some(&delta), &mut v);
                values.push(v);
            }
            self.pool.give(delta);
            let time = self.coefs.get(stage.time).copied().unwrap_or(t + dt);
            observe(&StageView { name: &stage.name, time, quantities: &stage.quantities, values: &values });
            quantities.push(values);
        }
        if let (Some(c), Some(mut e)) = (&desc.estimate, self.estimate.take()) {
            let reference = Level::State(0);
            self.combine(c, &Levels { states, quantities: &quantities, reference }, None, &mut e);
            self.estimate = Some(e);
        }
        // A stage quantity that becomes one state only is moved there, not copied.
        let uses = |level: &Level| desc.updates.iter().filter(|l| *l == level).count();
        let new_states: Vec<Vec<f64>> = desc
            .updates
            .iter()
            .map(|l| match *l {
                Level::State(i) => self.pool.copy(&states[i]),
                Level::Stage(s, q) if uses(l) == 1 => std::mem::take(&mut quantities[s][q]),
                Level::Stage(s, q) => self.pool.copy(&quantities[s][q]),
            })
            .collect();
        if new_states.iter().flatten().any(|x| !x.is_finite()) {
            return Err(StepError::NonFinite { t: t + dt });
        }
        for (st, v) in states.iter_mut().zip(new_states) {
            self.pool.give(std::mem::replace(st, v));
        }
        if let Some(start) = start
            && let Some(old) = self.previous.replace(start)
        {
            self.pool.give(old);
        }
        quantities.into_iter().flatten().for_each(|v| self.pool.give(v));
        Ok(report)
    }
}

/// Every slot the scheme's stages and initial problem apply is bound, to a form of the arity
/// they apply it with.
fn check_terms<'a>(desc: &SchemeDesc, forms: &HashMap<String, Box<dyn BoundForm + 'a>>) -> Result<(), StepError> {
    let all_terms =
        desc.stages.iter().flat_map(|s| s.terms.iter()).chain(desc.initial.iter().flat_map(|i| i.terms.iter()));
    for term in all_terms {
        let form = forms.get(&*term.form).ok_or_else(|| StepError::MissingForm {
            scheme: desc.name.to_string(),
            form: term.form.to_string(),
            declared: desc
                .uses
                .iter()
                .find(|u| u.name == term.form)
                .map_or_else(String::new, |u| u.declared.to_string()),
        })?;
        if form.fields() != term.args.len() {
            return Err(StepError::Arity {
                form: term.form.to_string(),
                expected: form.fields(),
                given: term.args.len(),
            });
        }
    }
    Ok(())
}
