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

use std::collections::HashMap;
use std::sync::Arc;

use crate::assembly::{Assembler, Kernel, Quadrature};
use crate::elements::ElementMatrices;
use crate::linalg::{Matrix, Structure};
use crate::lower_half::{HalfPattern, LowerHalf, MAX_FUSED};
use crate::mesh::Facet;
use crate::newton::{Newton, NewtonError, NewtonOptions, NewtonReport, NonlinearProblem};
use crate::pattern::Entries;
use crate::problem::Constraints;

/// A vector known when a stage starts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Level {
    /// A state at the start of the step.
    State(usize),
    /// Quantity `.1` of an earlier stage `.0`.
    Stage(usize, usize),
}

/// `c[unknown]·w + Σ c[k]·level` (indices into the coefficient array; `None`: no unknown).
#[derive(Clone, Copy, Debug)]
pub struct Combination {
    pub unknown: Option<usize>,
    pub known: &'static [(Level, usize)],
}

/// `c[coef] · form(args)` at time `c[time]`.
#[derive(Clone, Copy, Debug)]
pub struct TermDesc {
    pub coef: usize,
    pub form: &'static str,
    pub args: &'static [Combination],
    pub time: usize,
}

#[derive(Clone, Copy, Debug)]
pub struct StageDesc {
    pub name: &'static str,
    pub time: usize,
    /// New quantities, the unknown first.
    pub quantities: &'static [&'static str],
    pub values: &'static [Combination],
    pub terms: &'static [TermDesc],
}

#[derive(Clone, Copy, Debug)]
pub struct InitialDesc {
    pub state: usize,
    pub terms: &'static [TermDesc],
}

#[derive(Clone, Copy, Debug)]
pub struct SchemeDesc {
    pub name: &'static str,
    /// The slots it applies (`uses`), with where they are declared.
    pub uses: &'static [crate::library::SlotUse],
    pub states: &'static [&'static str],
    pub initial: Option<InitialDesc>,
    pub stages: &'static [StageDesc],
    /// The level each state takes at the end of a step.
    pub updates: &'static [Level],
    /// Length of the coefficient array.
    pub coefficients: usize,
}

impl SchemeDesc {
    /// Whether every stage is explicit: only `mass` acts on its unknown, so a step solves with
    /// the mass matrix alone (central differences). A mass with massless dofs (redistributed)
    /// cannot be solved for them.
    pub fn explicit(&self) -> bool {
        !self.stages.is_empty()
            && self.stages.iter().all(|s| {
                s.terms.iter().filter(|t| t.args.iter().any(|c| c.unknown.is_some())).all(|t| t.form == "mass")
            })
    }
}

/// A solved stage: its name, its time and its quantities (the unknown first), named as in the
/// scheme's file.
pub struct StageView<'v> {
    pub name: &'static str,
    pub time: f64,
    pub quantities: &'static [&'static str],
    pub values: &'v [Vec<f64>],
}

impl StageView<'_> {
    /// The stage's value of `state` (u, v, ...): its quantity named after the state, with a
    /// suffix (`um` for `u` in TR-BDF2's `um, vm, am`; `u'` for `u`). The scheme's file names
    /// these; the rule is documented in docs/language.md.
    pub fn value_of(&self, state: &str) -> Option<&[f64]> {
        self.quantities
            .iter()
            .position(|q| q.starts_with(state) && q.len() > state.len())
            .map(|i| self.values[i].as_slice())
    }
}

/// Implemented by every generated scheme, and by schemes interpreted at run time.
pub trait TimeScheme {
    fn desc(&self) -> &SchemeDesc;
    /// Evaluates every coefficient for step size `dt` from time `t`.
    fn coefficients(&self, dt: f64, t: f64, out: &mut [f64]);
}

/// A compiled form bound to a mesh: its kernel, the mesh facets of each boundary region it
/// integrates over, and quadrature degrees. Object-safe, so a scheme's forms may differ in type.
pub trait BoundForm {
    fn name(&self) -> &str;
    fn fields(&self) -> usize;
    fn linear(&self) -> bool;
    fn piecewise(&self) -> bool;
    fn residual(&self, asm: &Assembler, fields: &[&[f64]], t: f64, out: &mut [f64]);
    fn tangent(&self, asm: &Assembler, fields: &[&[f64]], wrt: usize, t: f64, m: &mut Matrix);
    fn switches(&self, asm: &Assembler, fields: &[&[f64]], wrt: usize, t: f64, out: &mut Vec<bool>);
    /// The cells whose element matrices the tangent adds to, if not all of them (a form that
    /// integrates over boundary facets only): the Jacobian changes nowhere else.
    fn support(&self) -> Option<Vec<u32>> {
        None
    }
    /// Appends the tangent's element matrices (unscaled, as `tangent` adds them) if the form
    /// integrates over facets only, and with `m` also adds them into `m` as `tangent` does (one
    /// evaluation for both); false, with nothing done, if it cannot.
    fn tangent_elements(
        &self,
        _asm: &Assembler,
        _fields: &[&[f64]],
        _wrt: usize,
        _t: f64,
        _m: Option<&mut Matrix>,
        _out: &mut ElementMatrices,
    ) -> bool {
        false
    }
    /// Whether the form changes with time other than through its fields.
    fn time_dependent(&self) -> bool {
        true
    }
}

/// A kernel with its integration data.
pub struct Bound<'m, K: Kernel> {
    pub kernel: K,
    pub quadrature: Quadrature,
    /// For each boundary region of the form (by its name in the .wf file), the mesh facets.
    pub regions: Vec<(String, &'m [Facet])>,
}

impl<K: Kernel> BoundForm for Bound<'_, K> {
    fn name(&self) -> &str {
        self.kernel.meta().name
    }
    fn fields(&self) -> usize {
        self.kernel.meta().fields.len()
    }
    fn linear(&self) -> bool {
        self.kernel.meta().linear
    }
    fn piecewise(&self) -> bool {
        self.kernel.meta().piecewise
    }
    fn residual(&self, asm: &Assembler, fields: &[&[f64]], t: f64, out: &mut [f64]) {
        if self.kernel.meta().cell_degree.is_some() {
            asm.cell_residual(&self.kernel, self.quadrature, fields, t, out);
        }
        for (region, facets) in &self.regions {
            asm.facet_residual(&self.kernel, region, facets, self.quadrature, fields, t, out);
        }
    }
    fn tangent(&self, asm: &Assembler, fields: &[&[f64]], wrt: usize, t: f64, m: &mut Matrix) {
        if self.kernel.meta().cell_degree.is_some() {
            asm.cell_tangent(&self.kernel, self.quadrature, fields, wrt, t, m);
        }
        for (region, facets) in &self.regions {
            asm.facet_tangent(&self.kernel, region, facets, self.quadrature, fields, wrt, t, m);
        }
    }
    fn switches(&self, asm: &Assembler, fields: &[&[f64]], wrt: usize, t: f64, out: &mut Vec<bool>) {
        for (region, facets) in &self.regions {
            asm.facet_switches(&self.kernel, region, facets, self.quadrature, fields, wrt, t, out);
        }
    }
    fn support(&self) -> Option<Vec<u32>> {
        if self.kernel.meta().cell_degree.is_some() {
            return None;
        }
        Some(self.regions.iter().flat_map(|(_, facets)| facets.iter().map(|f| f.cell)).collect())
    }
    fn tangent_elements(
        &self,
        asm: &Assembler,
        fields: &[&[f64]],
        wrt: usize,
        t: f64,
        mut m: Option<&mut Matrix>,
        out: &mut ElementMatrices,
    ) -> bool {
        if self.kernel.meta().cell_degree.is_some() {
            return false;
        }
        for (region, facets) in &self.regions {
            let (q, m) = (self.quadrature, m.as_deref_mut());
            asm.facet_tangent_elements(&self.kernel, region, facets, q, fields, wrt, t, m, out);
        }
        true
    }
    fn time_dependent(&self) -> bool {
        self.kernel.time_dependent()
    }
}

/// A linear form given by its matrix (e.g. a redistributed mass matrix).
pub struct MatrixForm {
    pub name: String,
    pub matrix: Matrix,
}

impl BoundForm for MatrixForm {
    fn name(&self) -> &str {
        &self.name
    }
    fn fields(&self) -> usize {
        1
    }
    fn linear(&self) -> bool {
        true
    }
    fn piecewise(&self) -> bool {
        true
    }
    fn residual(&self, _asm: &Assembler, fields: &[&[f64]], _t: f64, out: &mut [f64]) {
        let mut y = vec![0.0; out.len()];
        self.matrix.mul_vec(fields[0], &mut y);
        out.iter_mut().zip(&y).for_each(|(o, v)| *o += v);
    }
    fn tangent(&self, _asm: &Assembler, _fields: &[&[f64]], _wrt: usize, _t: f64, m: &mut Matrix) {
        m.add_scaled(1.0, &self.matrix);
    }
    fn switches(&self, _asm: &Assembler, _fields: &[&[f64]], _wrt: usize, _t: f64, _out: &mut Vec<bool>) {}
    fn time_dependent(&self) -> bool {
        false
    }
}

#[derive(Debug, thiserror::Error)]
pub enum StepError {
    #[error("scheme `{scheme}` applies slot `{form}` ({declared}), which no form file in use provides")]
    MissingForm { scheme: &'static str, form: String, declared: &'static str },
    #[error("form `{form}` takes {expected} field(s), but the scheme applies it to {given}")]
    Arity { form: String, expected: usize, given: usize },
    #[error(
        "the solution is no longer finite at t = {t}: the scheme is unstable with these parameters (Nitsche with θ = 1 needs γ0 large enough for coercivity)"
    )]
    NonFinite { t: f64 },
    #[error("stage `{stage}` at t = {t}: {source}")]
    Newton { stage: &'static str, t: f64, source: NewtonError },
    #[error(
        "stage `{stage}` at t = {t}: {at}: its derivative divides by zero there (0/0 where a `pos`/`neg` clips an expression under a `sqrt` or a negative power; `check` warns of it as W0006): write the power directly, `d^(3/2)` rather than `d*sqrt(d)`"
    )]
    NonFiniteTangent { stage: &'static str, t: f64, at: NonFiniteTangent },
    #[error(
        "stage `{stage}` of scheme `{scheme}` has no displacement quantity (u', um, ...) that depends on its unknown (a nonzero coefficient at this Δt): a moving held displacement cannot be imposed there"
    )]
    NoDisplacement { scheme: &'static str, stage: &'static str },
}

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
    desc: SchemeDesc,
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
    /// Linear forms' matrices (assembled once).
    matrices: HashMap<String, Matrix>,
    /// The pattern's lower half, when the stage matrices are symmetric.
    half_pattern: Option<Arc<HalfPattern>>,
    /// Recently assembled loads, by (form, time).
    loads: Vec<((&'static str, u64), Vec<f64>)>,
    coefs: Vec<f64>,
    /// Vectors of the problem's size no longer in use (states replaced, bases, products), for
    /// the next step: a step allocates none once the first has run.
    pool: Pool,
}

/// Spare vectors, reused.
#[derive(Default)]
struct Pool(Vec<Vec<f64>>);

impl Pool {
    /// A vector of length `n`, contents unspecified.
    fn take(&mut self, n: usize) -> Vec<f64> {
        let mut v = self.0.pop().unwrap_or_default();
        v.resize(n, 0.0);
        v
    }

    /// A vector of `n` zeros.
    fn zeros(&mut self, n: usize) -> Vec<f64> {
        let mut v = self.take(n);
        v.fill(0.0);
        v
    }

    /// A copy of `x`.
    fn copy(&mut self, x: &[f64]) -> Vec<f64> {
        let mut v = self.take(x.len());
        v.copy_from_slice(x);
        v
    }

    fn give(&mut self, v: Vec<f64>) {
        // Bounded, should a scheme give back more than it takes.
        if v.capacity() > 0 && self.0.len() < 64 {
            self.0.push(v);
        }
    }
}

struct StageCache {
    newton: Newton,
    dt: f64,
    constant: Option<Linear>,
    /// The nonlinear terms' forms, and the entries their tangents add to (None: anywhere).
    support: Option<(Vec<&'static str>, Option<Support>)>,
    /// Scratch for the nonlinear terms' tangents: zero outside `support`.
    scratch: Option<Matrix>,
    /// The linear terms' forms, and their matrices' lower halves fused for one product (in
    /// groups of at most [`MAX_FUSED`]), when the matrices are symmetric.
    linear: Option<(Vec<&'static str>, Vec<LowerHalf>)>,
    /// The nonlinear terms' arguments and residual, kept from one step to the next.
    args: Vec<Vec<f64>>,
    term: Vec<f64>,
    switches: SwitchMemo,
    /// The last Jacobian assembly's recorded tangent, its storage kept from one step to the
    /// next (a new stage problem starts it invalid: its coefficients and times may differ).
    recorded: RecordedTangent,
}

/// The last active set a stage's terms gave, and what it is a function of: the terms' forms,
/// times (for forms that change with time) and arguments at the support's dofs. A stage whose
/// Newton starts where the last one ended (Newmark's u' = u + δ at δ = 0 is the last iterate,
/// bit for bit) finds its active set here instead of evaluating the contact facets again.
#[derive(Default)]
struct SwitchMemo {
    /// The forms, then per term its time, the arguments it is differentiated by, and its
    /// arguments at the support's dofs, as bits.
    forms: Vec<&'static str>,
    key: Vec<u64>,
    set: Vec<bool>,
    /// Scratch for the key being compared.
    next: Vec<u64>,
}

impl<'a> Stepper<'a> {
    /// `forms` binds the form names the scheme uses to bound kernels (a slot may hold any form
    /// of the right arity: `contact` is Nitsche's or the penalty's). `structure`: Cholesky for
    /// symmetric positive definite stage Jacobians, LU otherwise.
    pub fn new(
        scheme: Box<dyn TimeScheme + 'a>,
        asm: &'a Assembler<'a>,
        forms: Vec<(&'static str, Box<dyn BoundForm + 'a>)>,
        constraints: Constraints,
        structure: Structure,
        newton_options: NewtonOptions,
    ) -> Result<Self, StepError> {
        let forms: HashMap<String, Box<dyn BoundForm + 'a>> =
            forms.into_iter().map(|(slot, f)| (slot.to_string(), f)).collect();
        let desc = *scheme.desc();
        let all_terms =
            desc.stages.iter().flat_map(|s| s.terms.iter()).chain(desc.initial.iter().flat_map(|i| i.terms.iter()));
        for term in all_terms {
            let form = forms.get(term.form).ok_or_else(|| StepError::MissingForm {
                scheme: desc.name,
                form: term.form.to_string(),
                declared: desc.uses.iter().find(|u| u.name == term.form).map_or("", |u| u.declared),
            })?;
            if form.fields() != term.args.len() {
                return Err(StepError::Arity {
                    form: term.form.to_string(),
                    expected: form.fields(),
                    given: term.args.len(),
                });
            }
        }
        let mut matrices = HashMap::new();
        let zero = vec![0.0; asm.size()];
        for (name, f) in &forms {
            if f.linear() && f.fields() == 1 {
                let mut m = asm.zero_matrix();
                f.tangent(asm, &[&zero], 0, 0.0, &mut m);
                matrices.insert(name.clone(), m);
            }
        }
        let structure = match structure {
            Structure::Auto => probe_structure(asm, &forms, &matrices),
            s => s,
        };
        let half_pattern =
            (structure == Structure::SymmetricPositiveDefinite).then(|| Arc::new(HalfPattern::new(asm.pattern())));
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
            coefs: vec![0.0; desc.coefficients],
            pool: Pool::default(),
        })
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

    /// The largest stage's Cholesky factor (stored values), if the stages factor by Cholesky.
    pub fn factor_nnz(&self) -> Option<usize> {
        self.stages.iter().filter_map(|s| s.newton.factor_nnz()).max()
    }

    /// The matrix of a linear one-field form (e.g. `mass`, for energies).
    pub fn matrix(&self, form: &str) -> Option<&Matrix> {
        self.matrices.get(form)
    }

    /// Holds `p.dofs` (fixed in the constraints) at the moving values `p.values`: refused when a
    /// stage has no displacement quantity depending on its unknown. The initial problem keeps
    /// its held values (zero: the held motion's acceleration at the start is taken as zero).
    pub fn prescribe(&mut self, p: Prescribed) -> Result<(), StepError> {
        for stage in self.desc.stages {
            if self.displacement(stage).is_none() {
                return Err(StepError::NoDisplacement { scheme: self.desc.name, stage: stage.name });
            }
        }
        self.prescribed = Some(p);
        Ok(())
    }

    /// The stage's displacement quantity (named after the first state with a suffix: `u'`,
    /// `um`) when it depends on the unknown.
    fn displacement(&self, stage: &StageDesc) -> Option<usize> {
        let u = self.desc.states.first()?;
        let q = stage.quantities.iter().position(|q| q.starts_with(u) && q.len() > u.len())?;
        stage.values.get(q).filter(|c| c.unknown.is_some()).map(|_| q)
    }

    /// Sets the held values of the stage's unknown so that its displacement quantity takes the
    /// prescribed values at `time`: w = w₀ + (g − u(w₀)) / c_w, u affine in w.
    fn hold(
        &mut self,
        stage: &StageDesc,
        reference: Level,
        states: &[Vec<f64>],
        quantities: &[Vec<Vec<f64>>],
        time: f64,
    ) -> Result<(), StepError> {
        let Some(p) = &self.prescribed else { return Ok(()) };
        let q =
            self.displacement(stage).ok_or(StepError::NoDisplacement { scheme: self.desc.name, stage: stage.name })?;
        let c = &stage.values[q];
        let cw = c.unknown.map_or(0.0, |k| self.coefs[k]);
        if cw == 0.0 || !cw.is_finite() {
            return Err(StepError::NoDisplacement { scheme: self.desc.name, stage: stage.name });
        }
        let mut g = vec![0.0; p.dofs.len()];
        (p.values)(time, &mut g);
        let mut at_reference = vec![0.0; self.asm.size()];
        self.combine(c, reference, None, states, quantities, &mut at_reference);
        let w0 = match reference {
            Level::State(i) => &states[i],
            Level::Stage(s, k) => &quantities[s][k],
        };
        for (&i, gi) in p.dofs.iter().zip(&g) {
            self.constraints.values[i] = w0[i] + (gi - at_reference[i]) / cw;
        }
        Ok(())
    }

    /// Solves the initial problem (e.g. M a⁰ = L⁰ − B(u⁰)) for its state, if the scheme has one.
    pub fn initialize(&mut self, states: &mut [Vec<f64>], t: f64) -> Result<Option<NewtonReport>, StepError> {
        let Some(init) = self.desc.initial else { return Ok(None) };
        self.scheme.coefficients(1.0, t, &mut self.coefs);
        let reference = Level::State(init.state);
        let stage = StageDesc { name: "initial", time: 0, quantities: &[], values: &[], terms: init.terms };
        let cache = self.stages.len() - 1;
        let saved = self.initial_constraints.as_ref().map(|c| std::mem::replace(&mut self.constraints, c.clone()));
        let result = self.solve_stage(&stage, cache, states, &[], reference, 1.0, t);
        let result = result.map(|(delta, report)| {
            let mut w: Vec<f64> = states[init.state].iter().zip(&delta).map(|(r, d)| r + d).collect();
            self.constraints.impose(&mut w);
            (w, report)
        });
        if let Some(c) = saved {
            self.constraints = c;
        }
        let (w, report) = result?;
        states[init.state] = w;
        // The stages' Jacobians have the initial problem's pattern: one ordering and symbolic
        // analysis serves all, and the first stage factors into the initial problem's storage.
        if let Some((initial, stages)) = self.stages.split_last_mut()
            && let Some((first, rest)) = stages.split_first_mut()
        {
            rest.iter_mut().for_each(|s| s.newton.share_analysis(&initial.newton));
            first.newton.inherit(&mut initial.newton);
        }
        Ok(Some(report))
    }

    /// Drops the stages' factorizations, constant operators and loads: the next step runs as in
    /// a new stepper (see [`crate::newton::Newton::forget`]).
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
        let desc = self.desc;
        let n = self.asm.size();
        self.scheme.coefficients(dt, t, &mut self.coefs);
        let mut quantities: Vec<Vec<Vec<f64>>> = Vec::with_capacity(desc.stages.len());
        let mut report = StepReport::default();
        for (s, stage) in desc.stages.iter().enumerate() {
            // Newton starts from the state the unknown updates (u for u'), else the first state.
            let name = stage.quantities[0];
            let reference =
                Level::State(desc.states.iter().position(|st| name.trim_end_matches('\'') == *st).unwrap_or(0));
            if self.prescribed.is_some() {
                let time = self.coefs.get(stage.time).copied().unwrap_or(t + dt);
                self.hold(stage, reference, states, &quantities, time)?;
            }
            let (delta, r) = self.solve_stage(stage, s, states, &quantities, reference, dt, t)?;
            report.stages.push(r);
            let mut values: Vec<Vec<f64>> = Vec::with_capacity(stage.values.len());
            for c in stage.values {
                let mut v = self.pool.take(n);
                self.combine(c, reference, Some(&delta), states, &quantities, &mut v);
                values.push(v);
            }
            self.pool.give(delta);
            let time = self.coefs.get(stage.time).copied().unwrap_or(t + dt);
            observe(&StageView { name: stage.name, time, quantities: stage.quantities, values: &values });
            quantities.push(values);
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
        quantities.into_iter().flatten().for_each(|v| self.pool.give(v));
        Ok(report)
    }

    /// `c_w·w + Σ c·level` with the unknown w = reference + δ (δ = 0 if `delta` is `None`):
    /// `c_w·δ`, plus the levels (the reference with c_w added to its coefficient) grouped by
    /// [`zero_sum_groups`], each group as Σ c·(level − its reference level), each other level as
    /// c·level.
    fn combine(
        &self,
        c: &Combination,
        reference: Level,
        delta: Option<&[f64]>,
        states: &[Vec<f64>],
        quantities: &[Vec<Vec<f64>>],
        out: &mut [f64],
    ) {
        let level = |l: Level| -> &[f64] {
            match l {
                Level::State(i) => &states[i],
                Level::Stage(s, q) => &quantities[s][q],
            }
        };
        let mut terms: Vec<(Level, f64)> = Vec::with_capacity(c.known.len() + 1);
        let mut add = |l: Level, a: f64| match terms.iter_mut().find(|(m, _)| *m == l) {
            Some((_, b)) => *b += a,
            None => terms.push((l, a)),
        };
        // The sum's parts in order: out += a·x, or out += a·(x − y).
        let mut parts: Vec<Part> = Vec::new();
        if let Some(k) = c.unknown {
            let a = self.coefs[k];
            if let Some(d) = delta {
                parts.push((a, d, None));
            }
            add(reference, a);
        }
        for &(l, k) in c.known {
            add(l, self.coefs[k]);
        }
        terms.retain(|(_, a)| *a != 0.0);
        let coefs: Vec<f64> = terms.iter().map(|(_, a)| *a).collect();
        for group in zero_sum_groups(&coefs) {
            if group.len() == 1 {
                let (l, a) = terms[group[0]];
                parts.push((a, level(l), None));
                continue;
            }
            let r = group.iter().copied().find(|&i| terms[i].0 == reference).unwrap_or(group[0]);
            let x0 = level(terms[r].0);
            for &i in group.iter().filter(|&&i| i != r) {
                let (l, a) = terms[i];
                parts.push((a, level(l), Some(x0)));
            }
        }
        // Strip by strip, each part in turn: one pass over memory, the same sums as part by part.
        const STRIP: usize = 512;
        for (k, o) in out.chunks_mut(STRIP).enumerate() {
            let range = k * STRIP..k * STRIP + o.len();
            o.fill(0.0);
            for &(a, x, y) in &parts {
                match y {
                    None => o.iter_mut().zip(&x[range.clone()]).for_each(|(o, x)| *o += a * x),
                    Some(y) => o
                        .iter_mut()
                        .zip(&x[range.clone()])
                        .zip(&y[range.clone()])
                        .for_each(|((o, x), y)| *o += a * (x - y)),
                }
            }
        }
    }

    /// Adds Σ coef·K·base over a stage's linear terms (forms, coefficients, bases) to `rhs`:
    /// one pass over the matrices' fused lower halves when they are symmetric.
    fn add_linear(
        &mut self,
        cache: usize,
        (forms, coefs, bases): &(Vec<&'static str>, Vec<f64>, Vec<Vec<f64>>),
        rhs: &mut [f64],
    ) {
        if forms.is_empty() {
            return;
        }
        let mut product = self.pool.take(rhs.len());
        let Some(half) = self.half_pattern.as_ref() else {
            for ((form, coef), base) in forms.iter().zip(coefs).zip(bases) {
                self.matrices[*form].mul_vec(base, &mut product);
                rhs.iter_mut().zip(&product).for_each(|(r, x)| *r += coef * x);
            }
            self.pool.give(product);
            return;
        };
        let entry = &mut self.stages[cache];
        if entry.linear.as_ref().is_none_or(|(cached, _)| cached != forms) {
            let matrices: Vec<&Matrix> = forms.iter().map(|f| &self.matrices[*f]).collect();
            let groups = matrices.chunks(MAX_FUSED).map(|g| LowerHalf::fused(g, half)).collect();
            entry.linear = Some((forms.clone(), groups));
        }
        let (_, groups) = entry.linear.as_ref().expect("built above");
        let terms: Vec<(f64, &[f64])> = coefs.iter().zip(bases).map(|(c, b)| (*c, b.as_slice())).collect();
        for (group, terms) in groups.iter().zip(terms.chunks(MAX_FUSED)) {
            group.mul_sum(terms, &mut product);
            rhs.iter_mut().zip(&product).for_each(|(r, x)| *r += x);
        }
        self.pool.give(product);
    }

    #[allow(clippy::too_many_arguments)]
    fn solve_stage(
        &mut self,
        stage: &StageDesc,
        cache: usize,
        states: &[Vec<f64>],
        quantities: &[Vec<Vec<f64>>],
        reference: Level,
        dt: f64,
        t: f64,
    ) -> Result<(Vec<f64>, NewtonReport), StepError> {
        let n = self.asm.size();
        let stage_t = self.coefs.get(stage.time).copied().filter(|_| !stage.quantities.is_empty()).unwrap_or(t);
        // Known parts of every argument, and the constant part of the residual.
        let mut constant_rhs = self.pool.zeros(n);
        let mut nonlinear: Vec<ActiveTerm> = Vec::new();
        // Linear terms coef·K·(α w + base): their forms, coefficients and bases.
        let mut linear: (Vec<&'static str>, Vec<f64>, Vec<Vec<f64>>) = Default::default();
        let rebuild = self.stages[cache].dt != dt || self.stages[cache].constant.is_none();
        let mut constant = if rebuild { Some(self.asm.zero_matrix()) } else { None };
        for term in stage.terms {
            let coef = self.coefs[term.coef];
            let form = &self.forms[term.form];
            let term_t = self.coefs[term.time];
            if term.args.is_empty() {
                // Loads depend on time only: the one at t + dt this step is the one at t next step,
                // and a steady one is the same at every time.
                let key = (term.form, if form.time_dependent() { term_t.to_bits() } else { u64::MAX });
                let b = match self.loads.iter().position(|(k, _)| *k == key) {
                    Some(i) => &self.loads[i].1,
                    None => {
                        let mut b = vec![0.0; n];
                        form.residual(self.asm, &[], term_t, &mut b);
                        if self.loads.len() == LOAD_CACHE {
                            self.loads.remove(0);
                        }
                        self.loads.push((key, b));
                        &self.loads.last().expect("just pushed").1
                    }
                };
                constant_rhs.iter_mut().zip(b).for_each(|(r, x)| *r += coef * x);
                continue;
            }
            let mut bases: Vec<Vec<f64>> = Vec::with_capacity(term.args.len());
            for c in term.args {
                let mut b = self.pool.take(n);
                self.combine(c, reference, None, states, quantities, &mut b);
                bases.push(b);
            }
            let alphas: Vec<f64> = term.args.iter().map(|c| c.unknown.map_or(0.0, |k| self.coefs[k])).collect();
            match self.matrices.get(term.form) {
                Some(k) if alphas.len() == 1 => {
                    if let Some(c) = constant.as_mut() {
                        c.add_scaled(coef * alphas[0], k);
                    }
                    linear.0.push(term.form);
                    linear.1.push(coef);
                    linear.2.extend(bases);
                }
                _ if alphas.iter().all(|a| *a == 0.0) => {
                    let refs: Vec<&[f64]> = bases.iter().map(Vec::as_slice).collect();
                    let mut b = self.pool.zeros(n);
                    form.residual(self.asm, &refs, term_t, &mut b);
                    constant_rhs.iter_mut().zip(&b).for_each(|(r, x)| *r += coef * x);
                    self.pool.give(b);
                    bases.into_iter().for_each(|b| self.pool.give(b));
                }
                _ => nonlinear.push(ActiveTerm { form: term.form, coef, alphas, bases, t: term_t }),
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
        let piecewise = nonlinear.iter().all(|a| self.forms[a.form].piecewise());
        let StageCache { newton, constant, support, scratch, args, term, switches, recorded, .. } =
            &mut self.stages[cache];
        // The same forms at every step in practice; should they change, so may the entries where
        // J varies, and the references compared there only are dropped.
        if support.as_ref().is_none_or(|(forms, _)| !forms.iter().eq(nonlinear.iter().map(|a| &a.form))) {
            let forms = nonlinear.iter().map(|a| a.form).collect();
            *support = Some((forms, tangent_support(self.asm, &self.forms, &nonlinear)));
            *scratch = None;
            newton.invalidate();
        }
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
        let w0 = match reference {
            Level::State(i) => &states[i],
            Level::Stage(s, q) => &quantities[s][q],
        };
        let mut delta = self.pool.zeros(n);
        let Constraints { fixed, values } = &self.constraints;
        for (i, _) in fixed.iter().enumerate().filter(|(_, f)| **f) {
            delta[i] = values[i] - w0[i];
        }
        let report = newton.solve(&mut problem, &mut delta);
        // A NaN or infinite tangent (0/0 in a law's derivative) is said as such, not as the
        // singular matrix it makes.
        if report.is_err()
            && let Some(at) = problem.non_finite.take()
        {
            return Err(StepError::NonFiniteTangent { stage: stage.name, t: stage_t, at });
        }
        (*args, *term, *recorded) = (problem.args, problem.term, problem.recorded);
        self.pool.give(problem.rhs);
        problem.terms.into_iter().flat_map(|t| t.bases).for_each(|b| self.pool.give(b));
        let report = report.map_err(|source| StepError::Newton { stage: stage.name, t: stage_t, source })?;
        Ok((delta, report))
    }
}

/// The first element whose tangent entries of `form` are not finite: its nodes' positions
/// (none when the form cannot give its element matrices).
fn locate_non_finite(
    asm: &Assembler,
    form: &dyn BoundForm,
    fields: &[&[f64]],
    wrt: usize,
    t: f64,
    name: &str,
) -> NonFiniteTangent {
    let mut elements = ElementMatrices::default();
    let mut nodes = Vec::new();
    if form.tangent_elements(asm, fields, wrt, t, None, &mut elements) && elements.size > 0 {
        let (size, per) = (elements.size, elements.size * elements.size);
        let d = asm.mesh().dim();
        if let Some(e) = elements.values.chunks(per).position(|m| m.iter().any(|v| !v.is_finite())) {
            let mut seen: Vec<usize> = elements.dofs[e * size..(e + 1) * size].iter().map(|dof| dof / d).collect();
            seen.dedup();
            nodes = seen.iter().map(|&node| asm.mesh().node(node).to_vec()).collect();
        }
    }
    NonFiniteTangent { form: name.to_string(), level: wrt, nodes }
}

/// Largest |Σ c| / Σ |c| of a group of coefficients treated as summing to zero: a few roundings
/// of each coefficient. A sum that is zero in exact arithmetic evaluates to ~1e-16 of Σ |c|;
/// dropping a sum this small that is not exactly zero perturbs the combination by no more than
/// rounding its terms does.
const ZERO_SUM: f64 = 64.0 * f64::EPSILON;

/// Partitions coefficients (nonzero) into groups: subsets of at least two whose sum is zero to
/// [`ZERO_SUM`], taken greedily (smallest first, then in index order), and singletons.
/// Beyond 10 coefficients every one is a singleton.
fn zero_sum_groups(coefs: &[f64]) -> Vec<Vec<usize>> {
    let n = coefs.len();
    if n > 10 {
        return (0..n).map(|i| vec![i]).collect();
    }
    let members = |mask: u32| (0..n).filter(move |i| mask & (1 << i) != 0);
    let zero_sum = |mask: u32| {
        let (sum, abs) = members(mask).fold((0.0, 0.0), |(s, a), i| (s + coefs[i], a + f64::abs(coefs[i])));
        sum.abs() <= ZERO_SUM * abs
    };
    let mut left: u32 = (1 << n) - 1;
    let mut groups = Vec::new();
    // The smallest zero-sum subset of what is left, the first in index order.
    while let Some(mask) = (2..=left.count_ones())
        .find_map(|size| (1..=left).find(|&m| m & !left == 0 && m.count_ones() == size && zero_sum(m)))
    {
        groups.push(members(mask).collect());
        left &= !mask;
    }
    groups.extend(members(left).map(|i| vec![i]));
    groups
}

/// Cholesky if every form's tangent is symmetric, LU otherwise. Nonlinear tangents are probed at
/// pseudo-random states ±s, larger than the mesh, so that a switched term (a contact law's
/// active set) is active at each point in one of them.
fn probe_structure(
    asm: &Assembler,
    forms: &HashMap<String, Box<dyn BoundForm + '_>>,
    matrices: &HashMap<String, Matrix>,
) -> Structure {
    if matrices.values().any(|m| !m.is_symmetric(1e-12)) {
        return Structure::General;
    }
    let n = asm.size();
    let scale = 10.0 * asm.mesh().max_diameter() * asm.mesh().num_cells().max(1) as f64;
    let mut seed = 0x9E37_79B9_7F4A_7C15u64;
    let mut random = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        scale * ((seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5)
    };
    let mut names: Vec<&String> = forms.keys().filter(|k| !matrices.contains_key(*k)).collect();
    names.sort();
    for name in names {
        let form = &forms[name];
        if form.fields() == 0 {
            continue;
        }
        for _ in 0..2 {
            let state: Vec<Vec<f64>> = (0..form.fields()).map(|_| (0..n).map(|_| random()).collect()).collect();
            for sign in [1.0, -1.0] {
                let fields: Vec<Vec<f64>> = state.iter().map(|f| f.iter().map(|x| sign * x).collect()).collect();
                let refs: Vec<&[f64]> = fields.iter().map(Vec::as_slice).collect();
                for wrt in 0..form.fields() {
                    let mut m = asm.zero_matrix();
                    form.tangent(asm, &refs, wrt, 0.0, &mut m);
                    if !m.is_symmetric(1e-12) {
                        return Structure::General;
                    }
                }
            }
        }
    }
    Structure::SymmetricPositiveDefinite
}

/// A stage matrix; a symmetric one (under Cholesky) also as its lower half, whose products
/// read half the values.
struct Linear {
    matrix: Matrix,
    half: Option<LowerHalf>,
}

impl Linear {
    fn new(matrix: Matrix, half_pattern: Option<&Arc<HalfPattern>>) -> Linear {
        let half = half_pattern.map(|h| LowerHalf::new(&matrix, h));
        Linear { matrix, half }
    }

    /// `y = A x`.
    fn mul(&self, x: &[f64], y: &mut [f64]) {
        match &self.half {
            Some(h) => h.mul_vec(x, y),
            None => self.matrix.mul_vec(x, y),
        }
    }
}

/// A part of a combination: a·x, or a·(x − y).
type Part<'v> = (f64, &'v [f64], Option<&'v [f64]>);

/// A nonlinear term of a stage: coef·form(α₁w + b₁, ...).
struct ActiveTerm {
    form: &'static str,
    coef: f64,
    alphas: Vec<f64>,
    bases: Vec<Vec<f64>>,
    t: f64,
}

impl ActiveTerm {
    /// Writes the arguments α w + b into `out` (resized, reused across calls): at `dofs` only,
    /// if given (the rest is never read).
    fn args_into(&self, w: &[f64], out: &mut Vec<Vec<f64>>, dofs: Option<&[usize]>) {
        out.resize_with(self.alphas.len(), Vec::new);
        for ((o, a), b) in out.iter_mut().zip(&self.alphas).zip(&self.bases) {
            match dofs {
                Some(dofs) => {
                    o.resize(w.len(), 0.0);
                    dofs.iter().for_each(|&i| o[i] = b[i] + a * w[i]);
                }
                None => {
                    o.clear();
                    o.extend(b.iter().zip(w).map(|(bi, wi)| bi + a * wi));
                }
            }
        }
    }
}

struct StageProblem<'p, 'a> {
    asm: &'p Assembler<'a>,
    forms: &'p HashMap<String, Box<dyn BoundForm + 'a>>,
    constant: &'p Linear,
    rhs: Vec<f64>,
    terms: Vec<ActiveTerm>,
    constraints: &'p Constraints,
    structure: Structure,
    piecewise: bool,
    /// Where the nonlinear terms' residuals and tangents can be nonzero, if known.
    support: Option<&'p Support>,
    /// Reused for the nonlinear terms' tangents, arguments and residuals.
    scratch: &'p mut Option<Matrix>,
    args: Vec<Vec<f64>>,
    term: Vec<f64>,
    switches: &'p mut SwitchMemo,
    /// The largest term of the last residual.
    magnitude: f64,
    recorded: RecordedTangent,
    /// The first non-finite entry of a nonlinear term's tangent: where it is.
    non_finite: Option<NonFiniteTangent>,
}

/// Where a tangent is not finite: the form, the time level it is differentiated by, and the
/// nodes of the first element (cell or facet) with a non-finite entry.
#[derive(Clone, Debug)]
pub struct NonFiniteTangent {
    pub form: String,
    pub level: usize,
    pub nodes: Vec<Vec<f64>>,
}

impl std::fmt::Display for NonFiniteTangent {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let at: Vec<String> = self
            .nodes
            .iter()
            .map(|x| format!("({})", x.iter().map(|c| format!("{c:.6}")).collect::<Vec<_>>().join(", ")))
            .collect();
        write!(f, "the tangent of form `{}` (by its field {}) is not finite", self.form, self.level + 1)?;
        if at.is_empty() { Ok(()) } else { write!(f, " on the element with nodes at {}", at.join(", ")) }
    }
}

/// The nonlinear terms' tangent as element matrices, recorded by the last Jacobian assembly
/// (unscaled, with each term's first element and scale) at the arguments it had (`key`, their
/// bits at the support's dofs): `tangent_elements` at the same arguments reads them rather
/// than evaluating the kernels a second time.
#[derive(Default)]
struct RecordedTangent {
    valid: bool,
    key: Vec<u64>,
    parts: Vec<(usize, f64)>,
    elements: ElementMatrices,
}

impl StageProblem<'_, '_> {
    /// Adds the nonlinear terms at w to `r` (on the support only, if known).
    fn add_terms(&mut self, w: &[f64], r: &mut [f64]) {
        use crate::newton::norm_inf;
        let dofs = self.support.map(|s| s.dofs.as_slice());
        for term in &self.terms {
            term.args_into(w, &mut self.args, dofs);
            let refs: Vec<&[f64]> = self.args.iter().map(Vec::as_slice).collect();
            // The term is nonzero at the support's dofs only, if there is one.
            match dofs {
                Some(dofs) => {
                    self.term.resize(r.len(), 0.0);
                    dofs.iter().for_each(|&i| self.term[i] = 0.0);
                }
                None => {
                    self.term.clear();
                    self.term.resize(r.len(), 0.0);
                }
            }
            self.forms[term.form].residual(self.asm, &refs, term.t, &mut self.term);
            let largest = match dofs {
                // A NaN reaches r, where Newton sees it; the magnitude only sets a floor.
                Some(dofs) => dofs.iter().map(|&i| self.term[i].abs()).fold(0.0, f64::max),
                None => norm_inf(&self.term),
            };
            self.magnitude = self.magnitude.max(term.coef.abs() * largest);
            match dofs {
                Some(dofs) => dofs.iter().for_each(|&i| r[i] += term.coef * self.term[i]),
                None => r.iter_mut().zip(&self.term).for_each(|(ri, x)| *ri += term.coef * x),
            }
        }
    }

    /// Adds the nonlinear terms' tangents at w to `j` (on the support only, if known).
    fn add_tangents(&mut self, w: &[f64], j: &mut Matrix) {
        let dofs = self.support.map(|s| s.dofs.as_slice());
        let rec = &mut self.recorded;
        rec.valid = true;
        rec.key.clear();
        rec.parts.clear();
        rec.elements.dofs.clear();
        rec.elements.values.clear();
        for term in &self.terms {
            term.args_into(w, &mut self.args, dofs);
            push_key(&self.args, dofs, &mut rec.key);
            let refs: Vec<&[f64]> = self.args.iter().map(Vec::as_slice).collect();
            for (k, a) in term.alphas.iter().enumerate() {
                if *a != 0.0 {
                    // Kernels add unscaled: assemble into the scratch matrix, then scale in
                    // (only where the tangent can be nonzero, when that is known).
                    let m = self.scratch.get_or_insert_with(|| self.asm.zero_matrix());
                    match self.support {
                        Some(s) => s.entries.indices.iter().for_each(|&i| m.values[i] = 0.0),
                        None => m.values.iter_mut().for_each(|v| *v = 0.0),
                    }
                    let c = term.coef * a;
                    let form = &self.forms[term.form];
                    rec.parts.push((rec.elements.len(), c));
                    rec.valid = rec.valid
                        && form.tangent_elements(self.asm, &refs, k, term.t, Some(&mut *m), &mut rec.elements);
                    if !rec.valid {
                        form.tangent(self.asm, &refs, k, term.t, m);
                    }
                    if self.non_finite.is_none() && m.values.iter().any(|v| !v.is_finite()) {
                        self.non_finite = Some(locate_non_finite(self.asm, &**form, &refs, k, term.t, term.form));
                    }
                    match self.support {
                        Some(s) => s.entries.indices.iter().for_each(|&i| j.values[i] += c * m.values[i]),
                        None => j.add_scaled(c, m),
                    }
                }
            }
        }
    }
}

impl NonlinearProblem for StageProblem<'_, '_> {
    fn residual(&mut self, w: &[f64], r: &mut [f64]) {
        use crate::newton::norm_inf;
        // Newton starts from δ = 0 unless a constraint moves: no product then.
        self.magnitude = norm_inf(&self.rhs);
        if w.iter().all(|x| *x == 0.0) {
            r.copy_from_slice(&self.rhs);
        } else {
            self.constant.mul(w, r);
            self.magnitude = self.magnitude.max(norm_inf(r));
            r.iter_mut().zip(&self.rhs).for_each(|(ri, c)| *ri += c);
        }
        self.add_terms(w, r);
        self.constraints.zero(r);
    }

    fn residual_on_support(&mut self, w: &[f64], r: &mut [f64]) -> bool {
        // (A w)ᵢ from A's lower triangle, as `residual`'s lower-half product reads it (A is
        // symmetric where it has one, to round-off: its two triangles may differ in their
        // last bits).
        let Some(support) = self.support.filter(|_| self.constant.half.is_some()) else { return false };
        let a = &self.constant.matrix;
        let p = &a.pattern;
        r.fill(0.0);
        let mut largest = 0.0f64;
        for (&i, left) in support.dofs.iter().zip(&support.lower_rows) {
            let below = p.col_ptr[i]..p.col_ptr[i + 1];
            let mut aw: f64 = left.iter().map(|&(k, j)| a.values[k] * w[j]).sum();
            for (v, &j) in a.values[below.clone()].iter().zip(&p.row_idx[below]) {
                if j > i {
                    aw += v * w[j];
                }
            }
            largest = largest.max(aw.abs());
            r[i] = aw + self.rhs[i];
        }
        self.magnitude = self.magnitude.max(largest);
        self.add_terms(w, r);
        self.constraints.zero(r);
        // Test builds check it against the whole residual there, to round-off.
        if cfg!(debug_assertions) {
            let magnitude = self.magnitude;
            let mut full = vec![0.0; r.len()];
            self.residual(w, &mut full);
            self.magnitude = magnitude;
            let scale = a.norm_inf() * crate::newton::norm_inf(w) + magnitude;
            for &i in &support.dofs {
                let err = (full[i] - r[i]).abs();
                assert!(err <= 64.0 * f64::EPSILON * scale, "residual_on_support differs at {i} by {err:e}");
            }
        }
        true
    }

    fn magnitude(&self) -> f64 {
        self.magnitude
    }

    fn active_set(&mut self, w: &[f64], out: &mut Vec<bool>) -> bool {
        let dofs = self.support.map(|s| s.dofs.as_slice());
        // The set is a function of the forms, times and arguments at the support's dofs: the
        // last one evaluated is reused if those are the same bits.
        let memo = &mut *self.switches;
        if let Some(dofs) = dofs {
            memo.next.clear();
            for term in &self.terms {
                term.args_into(w, &mut self.args, Some(dofs));
                // A steady form's set does not depend on the time.
                let steady = !self.forms[term.form].time_dependent();
                memo.next.push(if steady { u64::MAX } else { term.t.to_bits() });
                memo.next.extend(term.alphas.iter().map(|a| u64::from(*a != 0.0)));
                push_key(&self.args, Some(dofs), &mut memo.next);
            }
            if memo.key == memo.next && memo.forms.iter().eq(self.terms.iter().map(|t| &t.form)) {
                out.extend_from_slice(&memo.set);
                return self.piecewise;
            }
        }
        let start = out.len();
        for term in &self.terms {
            term.args_into(w, &mut self.args, dofs);
            let refs: Vec<&[f64]> = self.args.iter().map(Vec::as_slice).collect();
            for (k, a) in term.alphas.iter().enumerate() {
                if *a != 0.0 {
                    self.forms[term.form].switches(self.asm, &refs, k, term.t, out);
                }
            }
        }
        if dofs.is_some() {
            std::mem::swap(&mut memo.key, &mut memo.next);
            memo.forms.clear();
            memo.forms.extend(self.terms.iter().map(|t| t.form));
            memo.set.clear();
            memo.set.extend_from_slice(&out[start..]);
        }
        self.piecewise
    }

    fn jacobian(&mut self, w: &[f64], j: &mut Matrix) {
        j.values.copy_from_slice(&self.constant.matrix.values);
        self.add_tangents(w, j);
        self.constraints.apply(j);
    }

    fn update_jacobian(&mut self, w: &[f64], j: &mut Matrix) -> bool {
        // Outside the support, J is the constant part (with the constraints) at every w.
        let Some(s) = self.support else { return false };
        s.entries.indices.iter().for_each(|&i| j.values[i] = self.constant.matrix.values[i]);
        self.add_tangents(w, j);
        self.constraints.apply(j);
        true
    }

    fn jacobian_product(&mut self, j: &Matrix, x: &[f64], y: &mut [f64]) -> bool {
        // J = P (A + T) P + I_c: A the constant part (its lower half), T the tangents on the
        // support's entries (J − A there), P zeroing the constrained dofs.
        let (Some(s), Some(_)) = (self.support, self.constant.half.as_ref()) else { return false };
        let constrained = self.constraints.fixed.iter().any(|f| *f);
        // x with its constrained entries zeroed, in the terms' residual buffer: with a support,
        // `residual` zeroes and reads that buffer at the support's dofs only, so what this
        // leaves elsewhere is never read (and no vector is allocated per check).
        let x_free = if constrained {
            self.term.clear();
            self.term.extend_from_slice(x);
            self.constraints.zero(&mut self.term);
            self.term.as_slice()
        } else {
            x
        };
        self.constant.mul(x_free, y);
        let (a, rows) = (&self.constant.matrix.values, &j.pattern.row_idx);
        for (&k, &col) in s.entries.indices.iter().zip(&s.entries.columns) {
            y[rows[k]] += (j.values[k] - a[k]) * x_free[col as usize];
        }
        if constrained {
            y.iter_mut().zip(x).zip(&self.constraints.fixed).filter(|(_, f)| **f).for_each(|((y, x), _)| *y = *x);
        }
        true
    }

    fn jacobian_matrix(&self) -> Matrix {
        self.asm.zero_matrix()
    }

    fn structure(&self) -> Structure {
        self.structure
    }

    fn varying_entries(&self) -> Option<&Entries> {
        self.support.map(|s| &s.entries)
    }

    fn tangent_elements(&mut self, w: &[f64]) -> Option<ElementMatrices> {
        let Some(recorded) = self.recorded_elements(w) else { return self.evaluate_elements(w) };
        // Test builds check the recording against an evaluation, bit for bit.
        if cfg!(debug_assertions) {
            assert_eq!(self.evaluate_elements(w).as_ref(), Some(&recorded), "recorded tangent elements");
        }
        Some(recorded)
    }
}

impl StageProblem<'_, '_> {
    /// The elements the last Jacobian assembly recorded, scaled as `evaluate_elements` scales
    /// them, if it was at w's arguments.
    fn recorded_elements(&mut self, w: &[f64]) -> Option<ElementMatrices> {
        if !self.recorded.valid {
            return None;
        }
        let dofs = self.support.map(|s| s.dofs.as_slice());
        let mut key = Vec::with_capacity(self.recorded.key.len());
        for term in &self.terms {
            term.args_into(w, &mut self.args, dofs);
            push_key(&self.args, dofs, &mut key);
        }
        let rec = &self.recorded;
        if key != rec.key {
            return None;
        }
        let mut out = rec.elements.clone();
        let size = out.size * out.size;
        for (p, &(from, c)) in rec.parts.iter().enumerate() {
            let to = rec.parts.get(p + 1).map_or(out.len(), |next| next.0);
            out.values[from * size..to * size].iter_mut().for_each(|v| *v *= c);
        }
        out.zero_fixed(&self.constraints.fixed);
        Some(out)
    }

    /// The nonlinear terms' tangent at w as element matrices, each term's scaled by its
    /// coefficient; None if a form cannot give them.
    fn evaluate_elements(&mut self, w: &[f64]) -> Option<ElementMatrices> {
        let dofs = self.support.map(|s| s.dofs.as_slice());
        let mut out = ElementMatrices::default();
        for term in &self.terms {
            term.args_into(w, &mut self.args, dofs);
            let refs: Vec<&[f64]> = self.args.iter().map(Vec::as_slice).collect();
            for (k, a) in term.alphas.iter().enumerate() {
                if *a != 0.0 {
                    let from = out.len();
                    if !self.forms[term.form].tangent_elements(self.asm, &refs, k, term.t, None, &mut out) {
                        return None;
                    }
                    out.scale_from(from, term.coef * a);
                }
            }
        }
        out.zero_fixed(&self.constraints.fixed);
        Some(out)
    }
}

/// Appends the bits of `args` at `dofs` (everywhere if None).
fn push_key(args: &[Vec<f64>], dofs: Option<&[usize]>, key: &mut Vec<u64>) {
    for arg in args {
        match dofs {
            Some(dofs) => key.extend(dofs.iter().map(|&i| arg[i].to_bits())),
            None => key.extend(arg.iter().map(|x| x.to_bits())),
        }
    }
}

/// The entries the stage's nonlinear terms' tangents add to: those coupling the nodes of the
/// cells of their supports (None if one of them has none).
fn tangent_support(
    asm: &Assembler,
    forms: &HashMap<String, Box<dyn BoundForm + '_>>,
    terms: &[ActiveTerm],
) -> Option<Support> {
    let mut nodes = vec![false; asm.mesh().num_nodes()];
    for term in terms {
        for cell in forms[term.form].support()? {
            asm.mesh().cell(cell as usize).iter().for_each(|&n| nodes[n as usize] = true);
        }
    }
    let d = asm.pattern().dim();
    let dofs: Vec<usize> = (0..nodes.len()).filter(|&j| nodes[j]).flat_map(|j| j * d..(j + 1) * d).collect();
    let p = asm.pattern();
    let lower_rows = dofs
        .iter()
        .map(|&i| {
            // The pattern is symmetric: row i's columns are column i's rows.
            let columns = &p.row_idx[p.col_ptr[i]..p.col_ptr[i + 1]];
            columns
                .iter()
                .filter(|&&j| j <= i)
                .map(|&j| {
                    let rows = &p.row_idx[p.col_ptr[j]..p.col_ptr[j + 1]];
                    let k = rows.binary_search(&i).expect("a symmetric pattern");
                    (p.col_ptr[j] + k, j)
                })
                .collect()
        })
        .collect();
    Some(Support { entries: asm.pattern().entries_among(&nodes), dofs, lower_rows })
}

/// Where a stage's nonlinear terms live when they integrate over facets only: the dofs of
/// their cells (the only ones their residuals touch and their arguments are read at) and the
/// entries coupling them (the only ones their tangents add to).
struct Support {
    entries: Entries,
    dofs: Vec<usize>,
    /// For each of `dofs` (row i), where the pattern's lower triangle holds row i left of and
    /// on the diagonal: (entry index, column j ≤ i). With column i below the diagonal, these
    /// read row i of a symmetric matrix from its lower triangle alone, as its lower-half
    /// products do (`residual_on_support`).
    lower_rows: Vec<Vec<(usize, usize)>>,
}

#[cfg(test)]
mod tests {
    use super::zero_sum_groups;

    #[test]
    fn zero_sum_groups_of_trbdf2_and_newmark() {
        // TR-BDF2's a' at Δt = 0.02 (u', u, v, um, vm): the displacement levels sum to 7e-12.
        let a = [29142.13562373094, 6035.533905932739, 35.355339059327385, -35177.669529663675, -206.06601717798208];
        assert_eq!(zero_sum_groups(&a), vec![vec![0, 1, 3], vec![2], vec![4]]);
        // Newmark's v' (u' merged into u, v, a): no group.
        assert_eq!(zero_sum_groups(&[1.0, -1.0 / 3.0, 0.01]), vec![vec![0], vec![1], vec![2]]);
        // Two groups, the smaller first.
        assert_eq!(zero_sum_groups(&[1.0, 2.0, -3.0, 0.5, -0.5]), vec![vec![3, 4], vec![0, 1, 2]]);
        assert_eq!(zero_sum_groups(&[]), Vec::<Vec<usize>>::new());
        // Too many to search: singletons.
        let many = [1.0, -1.0, 2.0, -2.0, 3.0, -3.0, 4.0, -4.0, 5.0, -5.0, 6.0];
        assert_eq!(zero_sum_groups(&many), (0..11).map(|i| vec![i]).collect::<Vec<_>>());
    }
}
