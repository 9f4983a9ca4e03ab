//! The simulation driver every dynamic case shares: a mesh and the case's data → the forms of
//! the files in use bound by slot name → optional mass redistribution on the contact nodes → a
//! stepper → a time loop that shows each step (and each intermediate stage) to the case's
//! observer, with step cuts after a failed Newton, the energy guard ([`energy_guard`]) and
//! checkpoints. What the observers measure with is bound in [`operators`]; VTU/PVD snapshots are
//! [`Snapshots`]; an explicit scheme's critical step is estimated in [`stability`], and one
//! equilibrium without a stepper is [`statics`].

use std::time::Instant;

use crate::checkpoint::Control;
use crate::compiler::scheme::EnergyLaw;
use crate::driver::FilesInUse;
use crate::error::CaseError;
use crate::guard::{Guard, MAX_STEP_CUTS};
use crate::runtime::fem::assembly::{Assembler, Quadrature};
use crate::runtime::fem::kernel::Coef;
use crate::runtime::linalg::Structure;
use crate::runtime::nonlinear::newton::NewtonOptions;
use crate::runtime::nonlinear::statics::Constraints;
use crate::runtime::time::scheme::StageView;
use crate::runtime::time::stepper::{StepError, StepReport, Stepper};

pub mod adaptive;
mod cursor;
mod energy_guard;
mod ledger;
pub mod operators;
mod snapshots;
pub mod stability;
pub mod statics;
pub mod step_control;

use cursor::Cursor;
use energy_guard::{Ended, EnergyWatch, StepWork};
use operators::Parts;
pub use operators::{AxisMean, Energies, Operators, resultant};
pub use snapshots::Snapshots;

/// What a case gives the driver.
pub struct Problem<'p> {
    /// The case's coefficients by name (`f`, `g`, `nc`, ...).
    pub coefs: &'p dyn Fn(&str) -> Option<Coef>,
    pub quadrature: Quadrature,
    /// The mesh region bound to the forms' `Gamma_C` (none: the contact law integrates over no
    /// facet).
    pub contact: Option<&'p str>,
    /// Other mesh regions the forms may integrate over, bound by their names.
    pub regions: &'p [String],
    /// The contact pairs a pair law integrates over.
    pub pairs: &'p [crate::runtime::fem::pair::PairRegions],
    /// Dirichlet conditions of the dynamics.
    pub constraints: Constraints,
    /// Held displacements that move (among the constraints' fixed dofs).
    pub prescribed: Option<crate::runtime::time::stepper::Prescribed>,
    pub mass: MassChoice,
    pub newton: NewtonOptions,
}

/// The mass a scheme steps with.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum MassChoice {
    /// The material's mass (the default).
    #[default]
    Consistent,
    /// Mass redistribution (docs/mathematics.md §4): no inertia at the contact node.
    Redistributed,
    /// A diagonal mass (row sums on P1, the scaled diagonal on P2), for explicit schemes.
    Lumped,
}

impl MassChoice {
    /// Its name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            MassChoice::Consistent => "consistent",
            MassChoice::Redistributed => "redistributed",
            MassChoice::Lumped => "lumped",
        }
    }
}

/// The stepper, its states and the operators, ready to run.
pub struct Simulation<'m> {
    pub stepper: Stepper<'m>,
    pub ops: Operators<'m>,
    /// One vector per state of the scheme; `states[0]` is the displacement.
    pub states: Vec<Vec<f64>>,
    /// The index of the velocity state `v`, if the scheme has one.
    pub v_index: Option<usize>,
    guard: Guard,
    /// The params in use, for messages.
    params: String,
    /// The energy law the scheme's file claims, which the energy guard applies.
    law: Option<EnergyLaw>,
    /// The critical step of a scheme that claims `cfl` (an explicit one).
    pub stable: Option<stability::StableStep>,
    /// Its estimate along the run, from the current tangent, for a nonlinear stiffness.
    pub tracker: Option<stability::Tracker>,
    /// Whether the scheme applies a mass: without, each step is an equilibrium of its own and
    /// no energy is watched.
    pub inertia: bool,
    /// The scheme's energy identity, where it measures the run's steps for the energy guard.
    ledger: Option<ledger::Ledger>,
    /// The order the scheme claims (2 if none): an adaptive run's error model.
    order: f64,
}

/// One finished step, as the observer sees it.
pub struct Step<'s> {
    /// The step's number (1 for the first) and its end time.
    pub k: usize,
    pub t: f64,
    /// Its size: the nominal Δt, or a fraction of it after a failed Newton.
    pub dt: f64,
    pub states: &'s [Vec<f64>],
    /// The displacement at the start of the step.
    pub before: &'s [f64],
    /// The level a law's `prev` read at the start of the step (the step before's start); none
    /// when no law reads one.
    pub previous: Option<&'s [f64]>,
    pub report: &'s StepReport,
}

impl<'m> Simulation<'m> {
    /// Binds the files in use on `asm`'s mesh, redistributes the mass when asked (the contact
    /// nodes carry none; a⁰ = 0 there), and builds the stepper.
    pub fn new(asm: &'m Assembler<'m>, mut problem: Problem<'_>, in_use: &FilesInUse) -> Result<Self, CaseError> {
        let constraints = problem.constraints.clone();
        let held = constraints.clone();
        let coefs = problem.coefs;
        let newton = problem.newton;
        let prescribed = problem.prescribed.take();
        let Parts { mut ops, forms, inertia } = Parts::build(asm, problem, in_use)?;
        ops.held = prescribed.as_ref().map_or_else(Vec::new, |p| p.dofs.clone());
        let scheme = in_use.time_scheme()?;
        if ops.redistributed && scheme.desc().explicit() {
            return Err(CaseError::Option(format!(
                "--mass redistributed: scheme `{}` is explicit (only `mass` acts on its unknown), and the redistributed mass leaves the contact nodes without inertia: their accelerations cannot be solved for at any Δt; use --mass consistent or --mass lumped",
                scheme.desc().name
            )));
        }
        let mut stepper = Stepper::new(scheme, asm, forms, constraints.clone(), Structure::Auto, newton)?;
        if let Some(p) = prescribed {
            stepper.prescribe(p)?;
        }
        if ops.redistributed {
            let d = asm.mesh().dim();
            let mut initial = constraints;
            for &c in &ops.contact_nodes {
                for k in 0..d {
                    initial.fix(d * c as usize + k);
                }
            }
            stepper.initial_constraints = Some(initial);
        }
        ops.energies = Energies::new(
            asm,
            stepper.half_pattern(),
            ops.nonlinear.is_none().then_some(&ops.stiffness),
            ops.scheme_mass(),
        );
        let n = asm.size();
        let names = &stepper.desc().states;
        let states = names.iter().map(|_| vec![0.0; n]).collect();
        let v_index = names.iter().position(|s| *s == "v");
        let params = in_use.forms.params_text();
        // Without inertia each step is an equilibrium of its own: no energy accumulates to watch.
        let mut guard = in_use.guard;
        if !inertia {
            guard.energy_tolerance = 0.0;
        }
        let energy = in_use.scheme_energy()?;
        let ledger = ledger::Ledger::new(energy.identity.filter(|_| inertia), &ops, &stepper);
        let law = energy.law;
        let order = energy.claims.iter().find(|(c, _)| c == "order").map_or(2.0, |(_, o)| *o);
        let (stable, tracker) = match energy.claims.into_iter().find(|(c, _)| c == "cfl") {
            Some((_, cfl)) => {
                (Some(stability::estimate(&ops, coefs, &held, cfl)?), stability::Tracker::new(&ops, coefs, &held, cfl)?)
            }
            None => (None, None),
        };
        Ok(Simulation { stepper, ops, states, v_index, guard, params, law, stable, tracker, inertia, ledger, order })
    }

    /// Sets the displacement and solves the scheme's initial problem (the acceleration).
    pub fn initialize(&mut self, u0: Vec<f64>) -> Result<(), CaseError> {
        self.states[0] = u0;
        self.stepper.initialize(&mut self.states, 0.0)?;
        Ok(())
    }

    /// Sets the displacement and the velocity (if the scheme has one) at time `t0`, and solves
    /// the initial problem.
    pub fn initialize_at(&mut self, t0: f64, u0: Vec<f64>, v0: Vec<f64>) -> Result<(), CaseError> {
        self.states[0] = u0;
        if let Some(i) = self.v_index {
            self.states[i] = v0;
        }
        self.stepper.initialize(&mut self.states, t0)?;
        Ok(())
    }

    /// The velocity state, if the scheme has one.
    pub fn velocity(&self) -> Option<&[f64]> {
        self.v_index.map(|i| self.states[i].as_slice())
    }

    /// Runs `steps` steps of `dt` from `t0`, showing every accepted step to `on_step` and every
    /// intermediate stage of a multi-stage scheme to `on_stage`.
    ///
    /// A step whose Newton fails is retried from its start with Δt halved, up to
    /// `guard.max_step_cuts` halvings; the step size then doubles back after two accepted steps
    /// that end on a multiple of the doubled size, so the run returns to the nominal time levels.
    /// After every step the energy guard compares E_aug with E_aug(0) + the work of the loads
    /// so far: a growth beyond `guard.energy_tolerance` × the problem's energy scale (see
    /// [`EnergyWatch`]) stops the run before the observer sees that step. A run that cannot go on ends with `Outcome::stopped` set, after the observer saw every good
    /// step, so that the case can write its results up to there; an observer's error ends it at
    /// once.
    ///
    /// Checkpoints (`control`, see [`crate::checkpoint`]): after a nominal step that ends a
    /// checkpoint period or an interrupt, `on_step` gets a buffer for its own record of the run
    /// so far (the case restores it from `control.observer()` before calling `run`). A run with
    /// `control.resume` starts from that checkpoint's states and counters.
    pub fn run(
        &mut self,
        span: Span,
        progress: bool,
        control: &mut Control,
        watch: Watch,
    ) -> Result<Outcome, CaseError> {
        self.check_stable(span.dt)?;
        let intermediate = self.intermediate_stages();
        let mut outcome = Outcome::new(span.steps);
        let mut bar = crate::progress::Progress::new(span.steps, progress);
        let mut energy = EnergyWatch::new(&self.ops, &self.states, self.v_index, span.t0);
        // Progress through a nominal step in units of dt / 2^max_cuts.
        let max_cuts = self.guard.max_step_cuts.min(MAX_STEP_CUTS);
        let full: u64 = 1 << max_cuts;
        let mut at = Cursor::default();
        let crash_at = crash_after_step();
        if let Some((saved, _)) = &control.resume {
            if saved.adaptive.is_some() {
                return Err(CaseError::Option(
                    "the checkpoint is of an adaptive run: resume it with --adaptive".into(),
                ));
            }
            (at, energy) = self.resume(saved, &mut outcome)?;
        }
        // A nonlinear stiffness's tangent at the first state, which may be strained.
        if let Some(refused) = self.check_current_tangent(span.dt, span.t0 + at.first as f64 * span.dt)? {
            return Err(refused);
        }
        'steps: for k in at.first..span.steps {
            bar.tick(k);
            let mut done: u64 = 0;
            while done < full {
                let units = full >> at.level;
                let h = span.dt * units as f64 / full as f64;
                let t = span.t0 + (k as f64 + done as f64 / full as f64) * span.dt;
                let (result, start, seen, clock) = self.attempt(watch.stage, &intermediate, t, h, max_cuts);
                let report = match result {
                    Ok(report) => report,
                    Err(e) => match at.cut(e, t, h, max_cuts, &mut outcome) {
                        Some(stop) => {
                            outcome.stopped = Some(stop);
                            break 'steps;
                        }
                        None => continue,
                    },
                };
                outcome.step_seconds.push(clock.elapsed().as_secs_f64());
                done += units;
                at.accepted += 1;
                let whole = done == full;
                let t_end = if whole { span.t0 + (k + 1) as f64 * span.dt } else { t + h };
                let taken = Taken { k, whole, t, h, t_end, start, seen, report: &report };
                let (energy, outcome, control) = (&mut energy, &mut outcome, &mut *control);
                let mut walk = Walk { at: &mut at, energy, outcome, control, crash_at, adaptive: None };
                if let Some(stop) = self.accept(&mut walk, span.steps, taken, watch.step)? {
                    outcome.stopped = Some(stop);
                    break 'steps;
                }
                at.accept(done, units);
                if whole
                    && self.tracker.as_mut().is_some_and(stability::Tracker::due)
                    && let Some(stop) = self.check_current_tangent(span.dt, t_end)?
                {
                    outcome.stopped = Some(stop);
                    break 'steps;
                }
            }
        }
        bar.finish();
        Ok(outcome)
    }

    /// The stages before the last, whose quantities the observers measure too.
    fn intermediate_stages(&self) -> Vec<String> {
        self.stepper.desc().stages.iter().rev().skip(1).map(|s| s.name.to_string()).collect()
    }

    /// After an accepted step: the energy guard, the observer, the checkpoint if one is due;
    /// why the run stops here, if it does (an observer's error ends it at once).
    fn accept(
        &mut self,
        walk: &mut Walk,
        steps: usize,
        taken: Taken,
        on_step: &mut OnStep,
    ) -> Result<Option<CaseError>, CaseError> {
        let Taken { k, whole, t, h, t_end, start, seen, report } = taken;
        let due = Due::at(walk.control, k, steps, whole)?;
        let mut record = due.record.then(Vec::new);
        let (ops, states, v_index) = (&self.ops, &self.states, self.v_index);
        let own = add_work(walk.energy, ops, Interval { start: &start, states, v_index, t, h }, seen.stages);
        let exact = self.ledger.as_ref().and_then(|l| {
            let start = start.saved.as_deref()?;
            l.balance((ops, &self.stepper), start, &seen.unknowns, states, t, h)
        });
        // Checked before the observer sees the step: the outputs end at the last good one.
        let ended = Ended { states, v_index, before: &start.before, h, t: t_end };
        let tolerance = self.guard.energy_tolerance;
        if let Some(grown) = walk.energy.check(ops, &ended, tolerance, self.law, (own, exact)) {
            let by_identity = exact.is_some();
            return Ok(Some(grown.stop(t_end, tolerance, &self.params, self.law, by_identity)));
        }
        walk.outcome.energy_growth = walk.energy.growth;
        let (before, previous) = (&start.before, start.before_previous.as_deref());
        let step = Step { k: walk.at.accepted, t: t_end, dt: h, states, before, previous, report };
        on_step(ops, &step, record.as_mut())?;
        if let Some(record) = record {
            let previous = self.stepper.previous();
            let cuts = walk.outcome.cuts;
            let mut driver = walk.at.driver_state(k + 1, cuts, walk.energy, states, previous, !due.interrupted);
            driver.adaptive = walk.adaptive.clone();
            // The outputs up to here are still written.
            if let Err(e) = self.checkpoint(walk.control, driver, record) {
                return Ok(Some(e));
            }
        }
        // A stop asked for while the step was shown (a host's watcher of the rows) ends the run
        // here, unless the stop's own checkpoint is due, which the next step writes. One
        // process only: the processes of an MPI run agree on a stop in `Due::at`.
        let own_checkpoint = walk.control.every == 0 && walk.control.dir.is_some();
        if whole
            && !due.interrupted
            && !own_checkpoint
            && crate::runtime::linalg::ranks::world().1 == 1
            && crate::interrupt::requested()
        {
            return Ok(Some(CaseError::Interrupted { t: t_end }));
        }
        // Fault injection for the restart tests (`Walk::crash_at`).
        if walk.crash_at == Some(walk.at.accepted) {
            std::process::abort();
        }
        // An interrupt lets the nominal step finish, so that its checkpoint is on the nominal
        // time levels.
        Ok((due.interrupted && whole).then_some(CaseError::Interrupted { t: t_end }))
    }

    /// Takes one step of `h` from `t`, showing its intermediate stages to `on_stage`; a failed
    /// step leaves the states as they were at its start (when a cut may follow). Returns the
    /// step's start, its intermediate stages' displacements and velocities (for the held dofs'
    /// work) and when it began.
    fn attempt(
        &mut self,
        on_stage: &mut OnStage,
        intermediate: &[String],
        t: f64,
        h: f64,
        max_cuts: usize,
    ) -> (Result<StepReport, StepError>, Start, Seen, Instant) {
        let Simulation { stepper, ops, states, v_index, ledger, .. } = self;
        let start = Start::of(states, stepper, *v_index, ops, max_cuts > 0 || ledger.is_some());
        let clock = Instant::now();
        let mut seen = Seen::default();
        let result = stepper.step_observed(states, t, h, &mut |stage| {
            if ledger.is_some() {
                seen.unknowns.push(stage.values[0].clone());
            }
            if intermediate.iter().any(|name| name == stage.name) {
                on_stage(ops, stage, *v_index, &start.before);
                if !ops.held.is_empty()
                    && let Some(u) = stage.value_of("u")
                {
                    seen.stages.push((stage.time, u.to_vec(), stage.value_of("v").map(<[f64]>::to_vec)));
                }
            }
        });
        // A finite-strain material's step may converge where the stiffness's quadrature points
        // see a positive J but the body is inside out at the stored energy's (a NaN energy):
        // the step fails, and a cut may mend it.
        let result = result.and_then(|report| match ops.nonlinear.is_some() && !ops.elastic(&states[0]).is_finite() {
            true => match crate::runtime::fem::mesh::inverted::anywhere(ops.asm, &states[0]) {
                Some(at) => Err(StepError::Inverted { stage: "the step's end".into(), t: t + h, at }),
                None => Err(StepError::NonFinite { t: t + h }),
            },
            false => Ok(report),
        });
        if result.is_err()
            && let Some(saved) = &start.saved
        {
            states.clone_from_slice(saved);
        }
        (result, start, seen, clock)
    }

    /// Writes a due checkpoint. After a periodic one (not an interrupt's) the stepper forgets
    /// its factorizations, so that the run goes on as a run resumed from it would, bit for bit.
    fn checkpoint(
        &mut self,
        control: &mut Control,
        driver: crate::checkpoint::DriverState,
        record: Vec<u8>,
    ) -> Result<(), CaseError> {
        let periodic = driver.periodic;
        control.write(driver, record)?;
        if periodic {
            self.stepper.forget();
        }
        Ok(())
    }

    /// Restores a checkpoint's states (and the previous level, when a law reads it), its
    /// counters and its energy watch.
    fn resume(
        &mut self,
        saved: &crate::checkpoint::DriverState,
        outcome: &mut Outcome,
    ) -> Result<(Cursor, EnergyWatch), CaseError> {
        let Simulation { stepper, ops, states, .. } = self;
        // The scheme's states, then the previous level when a law reads it (`prev`).
        let count = states.len() + usize::from(stepper.reads_previous());
        if saved.states.len() != count || saved.states.iter().any(|s| s.len() != ops.asm.size()) {
            return Err(CaseError::Option("the checkpoint's states do not fit this run's scheme and mesh".into()));
        }
        let scheme_states = states.len();
        states.clone_from_slice(&saved.states[..scheme_states]);
        if let Some(previous) = saved.states.get(scheme_states) {
            stepper.set_previous(previous.clone());
        }
        let at = Cursor { first: saved.steps_done, accepted: saved.accepted, level: saved.level, streak: saved.streak };
        outcome.cuts = saved.cuts;
        let energy = EnergyWatch {
            initial: saved.energy_initial,
            u0: saved.energy_u0.clone(),
            work: saved.energy_work,
            varying_work: saved.energy_varying_work,
            law_work: saved.energy_law_work,
            dissipated: saved.energy_dissipated,
            kinetic: saved.energy_kinetic,
            growth: saved.energy_growth,
            made: saved.energy_made,
            lowest: saved.energy_lowest,
            last: saved.energy_last,
            external: saved.energy_external,
            switches: saved.energy_switches.clone(),
        };
        outcome.resumed = Some(Resumed { step: saved.steps_done, bit_for_bit: saved.periodic });
        stepper.forget();
        Ok((at, energy))
    }
}

/// Fault injection for the restart tests: the process aborts, as if killed, right after this
/// accepted step (and its checkpoint, if one is due). Read once per run, not every step.
fn crash_after_step() -> Option<usize> {
    std::env::var("SIGNORINI_CRASH_AFTER_STEP").ok().and_then(|s| s.parse().ok())
}

/// The steps a run takes: `steps` nominal steps of `dt` from `t0`.
#[derive(Clone, Copy)]
pub struct Span {
    pub t0: f64,
    pub dt: f64,
    pub steps: usize,
}

/// What a run shows its intermediate stages and its accepted steps to.
pub struct Watch<'w, 'a> {
    pub stage: &'w mut OnStage<'a>,
    pub step: &'w mut OnStep<'a>,
}

/// The run's state an accepted step moves on.
struct Walk<'w> {
    at: &'w mut Cursor,
    /// The accepted step after which the process aborts (`SIGNORINI_CRASH_AFTER_STEP`).
    crash_at: Option<usize>,
    energy: &'w mut EnergyWatch,
    outcome: &'w mut Outcome,
    control: &'w mut Control,
    /// An adaptive run's state after this step, for its checkpoint.
    adaptive: Option<adaptive::AdaptiveState>,
}

/// An accepted step of nominal step `k` (`whole` when it ends one): from `t` by `h` to `t_end`.
struct Taken<'s> {
    k: usize,
    whole: bool,
    t: f64,
    h: f64,
    t_end: f64,
    start: Start,
    seen: Seen,
    report: &'s StepReport,
}

/// An intermediate stage's time, displacement and velocity (if the scheme has one).
type StageSeen = (f64, Vec<f64>, Option<Vec<f64>>);

/// What a step showed of its stages: the intermediate ones' (for the held dofs' work), and every
/// stage's unknown (for the energy identity).
#[derive(Default)]
struct Seen {
    stages: Vec<StageSeen>,
    unknowns: Vec<Vec<f64>>,
}

/// What a step keeps of its start: the states (for a retry when a cut may follow, and the
/// energy identity's free variables), the
/// displacement, the level a law's `prev` read, and the velocity when held dofs take the
/// change of velocity over the step into their reaction.
struct Start {
    saved: Option<Vec<Vec<f64>>>,
    before: Vec<f64>,
    before_previous: Option<Vec<f64>>,
    v_before: Option<Vec<f64>>,
}

impl Start {
    fn of(states: &[Vec<f64>], stepper: &Stepper, v_index: Option<usize>, ops: &Operators, keep: bool) -> Self {
        Start {
            saved: keep.then(|| states.to_vec()),
            before: states[0].clone(),
            before_previous: stepper.previous().map(<[f64]>::to_vec),
            v_before: v_index.filter(|_| !ops.held.is_empty()).map(|i| states[i].clone()),
        }
    }
}

/// Whether an accepted step writes a checkpoint, and whether the run was interrupted.
struct Due {
    record: bool,
    interrupted: bool,
}

impl Due {
    /// After nominal step `k` (of `steps`), `whole` when the step ended a nominal one.
    fn at(control: &Control, k: usize, steps: usize, whole: bool) -> Result<Due, CaseError> {
        // A checkpoint after the last step would resume nothing.
        let periodic = control.every > 0 && (k + 1).is_multiple_of(control.every) && k + 1 < steps;
        let interrupted = crate::interrupt::agreed().map_err(|e| CaseError::Option(format!("MPI: {e}")))?;
        // With periodic checkpoints an interrupt keeps the last one, which resumes bit
        // for bit; without, it writes one of its own (which resumes to round-off).
        let on_interrupt = interrupted && control.every == 0;
        Ok(Due { record: whole && (periodic || on_interrupt), interrupted })
    }
}

/// One accepted step's interval: its start, the states at its end, its time and size.
struct Interval<'s> {
    start: &'s Start,
    states: &'s [Vec<f64>],
    v_index: Option<usize>,
    t: f64,
    h: f64,
}

/// Adds the step's work to the energy watch: a varying load's, the held dofs' (over each
/// sub-interval between the step's stages), a moving obstacle's, the law's own, and what
/// friction dissipated; returns the step's part of the last two.
fn add_work(energy: &mut EnergyWatch, ops: &Operators, step: Interval, mut stages_seen: Vec<StageSeen>) -> StepWork {
    let Interval { start, states, v_index, t, h } = step;
    let before = &start.before;
    if let Some(load) = &ops.varying_load {
        energy.step_work(ops, load.as_ref(), before, &states[0], t + 0.5 * h);
    }
    if !ops.held.is_empty() {
        // Over each sub-interval between the step's stages.
        let v = v_index.map(|i| states[i].clone());
        let mut points = vec![(t, before.clone(), start.v_before.clone())];
        points.append(&mut stages_seen);
        points.push((t + h, states[0].clone(), v));
        for w in points.windows(2) {
            let ((t0, u0, v0), (t1, u1, v1)) = (&w[0], &w[1]);
            let vs = v0.as_deref().zip(v1.as_deref());
            energy.held_work(ops, u0, u1, vs, t1 - t0, 0.5 * (t0 + t1));
        }
    }
    if ops.probe.as_ref().is_some_and(|p| p.time_dependent()) {
        energy.obstacle_work(ops, before, &states[0], t, h);
    }
    let mut own = StepWork::default();
    if let Some(work) = &ops.contact_work {
        own.law = work.value(ops.asm, &[&states[0], before], t + 0.5 * h);
        energy.law_work += own.law;
    }
    if let Some(work) = &ops.friction_work {
        own.friction = work.value(ops.asm, &[&states[0], before], t + h);
        energy.dissipated += own.friction;
    }
    own
}

/// What a case does with each intermediate stage: the operators, the stage's quantities, the
/// index of the velocity state (if any), and the displacement at the step's start (what a
/// contact law's `prev` reads there).
pub type OnStage<'a> = dyn FnMut(&Operators, &StageView, Option<usize>, &[f64]) + 'a;

/// What a case does with each accepted step; when a checkpoint is due, it also writes its
/// record of the run so far into the buffer.
pub type OnStep<'a> = dyn FnMut(&Operators, &Step, Option<&mut Vec<u8>>) -> Result<(), CaseError> + 'a;

/// How a run ended.
pub struct Outcome {
    /// Wall time of each accepted step (of this process: not those before a resume).
    pub step_seconds: Vec<f64>,
    /// Step halvings after a failed Newton.
    pub cuts: usize,
    /// Why the run stopped early, if it did (the observer has seen every step before).
    pub stopped: Option<CaseError>,
    /// The checkpoint the run resumed from, if it did.
    pub resumed: Option<Resumed>,
    /// The energy guard's largest growth of E_aug beyond E_aug(0) + work, over the energy scale.
    pub energy_growth: f64,
    /// An adaptive run's steps.
    pub adaptive: Option<adaptive::Steps>,
}

impl Outcome {
    fn new(steps: usize) -> Self {
        Outcome {
            step_seconds: Vec::with_capacity(steps),
            cuts: 0,
            stopped: None,
            resumed: None,
            energy_growth: 0.0,
            adaptive: None,
        }
    }
}

/// Where a resumed run started.
#[derive(Clone, Copy, Debug, serde::Serialize, serde::Deserialize)]
pub struct Resumed {
    /// Nominal steps done before.
    pub step: usize,
    /// From a periodic checkpoint (the bits of an uninterrupted run), or from one written on an
    /// interrupt without periodic ones (agrees to round-off).
    pub bit_for_bit: bool,
}
