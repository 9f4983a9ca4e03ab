//! The simulation driver every dynamic case shares: a mesh and the case's data → the forms of
//! the files in use bound by slot name → optional mass redistribution on the contact nodes → a
//! stepper → a time loop that shows each step (and each intermediate stage) to the case's
//! observer. A case (bar, disc, ...) is its mesh, its data, its initial state and what it
//! measures; VTU/PVD snapshots are [`Snapshots`].

use std::path::PathBuf;
use std::time::Instant;

use crate::checkpoint::Control;
use crate::compiler::scheme::EnergyLaw;
use crate::driver::Active;
use crate::error::CaseError;
use crate::guard::{ENERGY_TOLERANCE, Guard, MAX_STEP_CUTS};
use crate::runtime::fem::assembly::{Assembler, Quadrature};
use crate::runtime::fem::bound::{BoundForm, BoundFunctional, MatrixForm};
use crate::runtime::fem::kernel::Coef;
use crate::runtime::fem::mesh::{Facet, Mesh};
use crate::runtime::library::Binding;
use crate::runtime::linalg::lower_half::{HalfPattern, LowerHalf};
use crate::runtime::linalg::{Matrix, Structure};
use crate::runtime::nonlinear::newton::NewtonOptions;
use crate::runtime::nonlinear::statics::Constraints;
use crate::runtime::time::scheme::StageView;
use crate::runtime::time::stepper::{StepReport, Stepper};
use std::sync::Arc;

pub mod stability;
pub mod statics;

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
    /// Dirichlet conditions of the dynamics.
    pub constraints: Constraints,
    /// Held displacements that move (among the constraints' fixed dofs).
    pub prescribed: Option<crate::runtime::time::stepper::Prescribed>,
    pub mass: MassChoice,
    pub newton: NewtonOptions,
}

/// The mass a scheme steps with.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum MassChoice {
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

/// What the observers measure with: bound functionals, a fresh contact form, and the linear
/// operators.
pub struct Tools<'m> {
    pub asm: &'m Assembler<'m>,
    pub contact_facets: &'m [Facet],
    /// The `contact` slot, for its residual (the contact force) and its switches (the active set).
    pub probe: Option<Box<dyn BoundForm + 'm>>,
    pub contact_energy: Option<Box<dyn BoundFunctional + 'm>>,
    /// The most a conserving scheme's E_aug may jump where contact starts or ends (the energy
    /// guard's allowance).
    pub contact_jump: Option<Box<dyn BoundFunctional + 'm>>,
    /// The work over a step of the part of the law the energy does not keep (Nitsche θ ≠ 1),
    /// a functional of the step's end and start displacements.
    pub contact_work: Option<Box<dyn BoundFunctional + 'm>>,
    pub contact_pressure: Option<Box<dyn BoundFunctional + 'm>>,
    pub contact_trial: Option<Box<dyn BoundFunctional + 'm>>,
    pub von_mises: Option<Box<dyn BoundFunctional + 'm>>,
    pub cell_measure: Option<Box<dyn BoundFunctional + 'm>>,
    /// The consistent mass, the mass the scheme steps with (redistributed or not), the
    /// stiffness and the load vector at t = 0.
    pub mass: Matrix,
    pub scheme_mass: Matrix,
    pub stiffness: Matrix,
    pub load: Vec<f64>,
    /// The `load` slot when it changes with time (a traction p(t)): the energy check then sums
    /// its work step by step instead of taking the load at t = 0.
    pub varying_load: Option<Box<dyn BoundForm + 'm>>,
    /// The nodes of the contact region.
    pub contact_nodes: Vec<u32>,
    /// The mass is redistributed: the contact nodes carry none.
    pub redistributed: bool,
    /// The mass the scheme steps with.
    pub mass_choice: MassChoice,
    /// The dofs held at moving values: the energy check adds the work of their reactions.
    pub held: Vec<usize>,
    /// The energies' quadratic forms, ½uᵀKu and ½vᵀMv with the scheme's mass, evaluated every
    /// step by the observers.
    pub energies: Energies,
    /// The last `contact_switches` asked for: u, t's bits and the answer.
    last_switches: std::sync::Mutex<Option<Kept<Vec<bool>>>>,
}

/// A value kept for the vector and the time (its bits) it was computed at.
type Kept<T> = (Vec<f64>, u64, T);

/// The last vector and value of each energy form (stiffness, mass).
type LastQuads = [Option<(Vec<f64>, f64)>; 2];

/// The lower halves of the stiffness and of the scheme's mass, for the energies the observers
/// take every step: a product with a lower half reads half the bytes of the full one, and a mass
/// matrix's identity blocks one value each. At 12 490 unknowns the full products took a third
/// of a disc run and pushed the factor out of the cache between steps. A matrix that is not
/// symmetric (to the stepper's 10⁻¹² test) keeps the full product.
///
/// The energy guard and the observers ask for the same energies of the same step: the last
/// vector and value of each form are kept, and a query with equal values reuses them.
pub struct Energies {
    stiffness: Option<LowerHalf>,
    mass: Option<LowerHalf>,
    work: std::sync::Mutex<Vec<f64>>,
    last: std::sync::Mutex<LastQuads>,
}

impl Energies {
    /// Without lower halves: the full products.
    pub fn full() -> Energies {
        Energies { stiffness: None, mass: None, work: Default::default(), last: Default::default() }
    }

    /// With the stepper's lower-half pattern when it has one (the same pattern).
    pub fn new(asm: &Assembler, half: Option<&Arc<HalfPattern>>, stiffness: &Matrix, mass: &Matrix) -> Energies {
        let half = half.cloned().unwrap_or_else(|| Arc::new(HalfPattern::new(asm.pattern())));
        let lower = |a: &Matrix| a.is_symmetric(1e-12).then(|| LowerHalf::new(a, &half));
        Energies { stiffness: lower(stiffness), mass: lower(mass), work: Default::default(), last: Default::default() }
    }

    /// xᵀAx for A the stiffness (`which` 0) or the mass (1): the last value again for the
    /// same x, else from A's lower half when there is one, else from `a`.
    fn quad(&self, which: usize, a: &Matrix, x: &[f64]) -> f64 {
        let mut last = self.last.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((kept, value)) = &last[which]
            && kept.as_slice() == x
        {
            return *value;
        }
        let half = if which == 0 { &self.stiffness } else { &self.mass };
        let value = match half {
            None => Tools::quad(a, x, x),
            Some(half) => {
                let mut y = self.work.lock().unwrap_or_else(|e| e.into_inner());
                y.resize(x.len(), 0.0);
                half.mul_vec(x, &mut y);
                y.iter().zip(x).map(|(p, q)| p * q).sum()
            }
        };
        match &mut last[which] {
            Some((kept, v)) => {
                kept.clear();
                kept.extend_from_slice(x);
                *v = value;
            }
            none => *none = Some((x.to_vec(), value)),
        }
        value
    }
}

impl Tools<'_> {
    /// xᵀ A y ([`Matrix::quad`]).
    pub fn quad(a: &Matrix, x: &[f64], y: &[f64]) -> f64 {
        a.quad(x, y)
    }

    /// ½vᵀMv with the scheme's mass (0 without a velocity).
    pub fn kinetic(&self, v: Option<&[f64]>) -> f64 {
        v.map_or(0.0, |v| 0.5 * self.energies.quad(1, &self.scheme_mass, v))
    }

    /// E = ½uᵀKu + ½vᵀMv − Fᵀu.
    pub fn energy(&self, u: &[f64], v: Option<&[f64]>) -> f64 {
        self.energy_with_kinetic(u, self.kinetic(v))
    }

    /// E = ½uᵀKu + `kinetic` − Fᵀu, with ½vᵀMv already computed.
    pub fn energy_with_kinetic(&self, u: &[f64], kinetic: f64) -> f64 {
        self.elastic(u) + kinetic - self.load.iter().zip(u).map(|(l, x)| l * x).sum::<f64>()
    }

    /// ½uᵀKu.
    pub fn elastic(&self, u: &[f64]) -> f64 {
        0.5 * self.energies.quad(0, &self.stiffness, u)
    }

    /// The resultant of the contact term on the body along each axis (zeros without a
    /// `contact` slot).
    pub fn contact_force(&self, u: &[f64], t: f64) -> Vec<f64> {
        let mut c = vec![0.0; u.len()];
        if let Some(probe) = &self.probe {
            probe.residual(self.asm, &[u], t, &mut c);
        }
        resultant(&c, self.asm.mesh().dim())
    }

    /// The contact slot's switch at each of its quadrature points (none without the slot).
    ///
    /// The energy guard and the observers ask for the same step's: the last answer is kept and
    /// reused for the same u and t.
    pub fn contact_switches(&self, u: &[f64], t: f64) -> Vec<bool> {
        let mut last = self.last_switches.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((kept, at, switches)) = &*last
            && *at == t.to_bits()
            && kept.as_slice() == u
        {
            return switches.clone();
        }
        let mut switches = Vec::new();
        if let Some(probe) = &self.probe {
            probe.switches(self.asm, &[u], 0, t, &mut switches);
        }
        *last = Some((u.to_vec(), t.to_bits(), switches.clone()));
        switches
    }

    /// The mass-weighted mean along `axis` (of the displacement: the centre of mass's).
    pub fn axis_mean(&self, axis: usize) -> AxisMean {
        let d = self.asm.mesh().dim();
        let e: Vec<f64> = (0..self.mass.size()).map(|i| if i % d == axis { 1.0 } else { 0.0 }).collect();
        let mut weights = vec![0.0; e.len()];
        self.mass.mul_vec(&e, &mut weights);
        let total = weights.iter().zip(&e).map(|(a, b)| a * b).sum();
        AxisMean { weights, total }
    }

    /// The value of a functional at u (NaN when the files in use do not provide it).
    pub fn value(&self, f: &Option<Box<dyn BoundFunctional + '_>>, u: &[f64]) -> f64 {
        f.as_ref().map_or(f64::NAN, |f| f.value(self.asm, &[u], 0.0))
    }
}

/// eᵀ M x / eᵀ M e for the unit field e along one axis.
pub struct AxisMean {
    weights: Vec<f64>,
    total: f64,
}

impl AxisMean {
    pub fn of(&self, x: &[f64]) -> f64 {
        self.weights.iter().zip(x).map(|(a, b)| a * b).sum::<f64>() / self.total
    }
}

/// The force on the body along each axis from a contact residual C(u): C(u) tested with e_k
/// is minus the force along e_k.
pub fn resultant(c: &[f64], d: usize) -> Vec<f64> {
    (0..d).map(|k| -c.iter().skip(k).step_by(d).sum::<f64>()).collect()
}

/// What a run binds before it steps: the tools, the scheme's forms, and whether the scheme
/// has inertia.
struct Parts<'m> {
    tools: Tools<'m>,
    forms: Vec<(&'static str, Box<dyn BoundForm + 'm>)>,
    inertia: bool,
}

impl<'m> Parts<'m> {
    fn build(asm: &'m Assembler<'m>, problem: Problem<'_>, active: &Active) -> Result<Self, CaseError> {
        let mesh: &Mesh = asm.mesh();
        let n = asm.size();
        let contact_facets = match problem.contact {
            Some(name) => asm.region(name)?,
            None => &[],
        };
        let mut regions = vec![("Gamma_C".to_string(), contact_facets)];
        for name in problem.regions {
            regions.push((name.clone(), asm.region(name)?));
        }
        let binding = Binding { quadrature: problem.quadrature, regions, dim: mesh.dim() };
        let mut inst = active.forms.instantiate(problem.coefs, &binding)?;
        let mut forms = active.scheme_forms(&mut inst)?;
        let missing = |what: &str| {
            CaseError::Option(format!("the case needs `{what}`, which the form files in use do not provide"))
        };
        let slot = |forms: &[(&str, Box<dyn BoundForm + 'm>)], name: &str| {
            forms.iter().position(|(s, _)| *s == name).ok_or_else(|| missing(name))
        };
        let zero = vec![0.0; n];
        let mut mass = asm.zero_matrix();
        // A scheme without inertia (quasi-static: equilibrium at every step) does not apply the
        // mass; the material's still weighs the means and the figures.
        let inertia = forms.iter().any(|(s, _)| *s == "mass");
        match forms.iter().find(|(s, _)| *s == "mass") {
            Some((_, f)) => f.tangent(asm, &[&zero], 0, 0.0, &mut mass),
            None => {
                let material = active.forms.instantiate(problem.coefs, &binding)?.take_form("mass");
                material.ok_or_else(|| missing("mass"))?.tangent(asm, &[&zero], 0, 0.0, &mut mass);
            }
        }
        let mut stiffness = asm.zero_matrix();
        forms[slot(&forms, "stiffness")?].1.tangent(asm, &[&zero], 0, 0.0, &mut stiffness);
        let mut load = vec![0.0; n];
        forms[slot(&forms, "load")?].1.residual(asm, &[], 0.0, &mut load);
        let contact_nodes = match problem.contact {
            Some(name) => mesh.region_nodes(mesh.region(name)?),
            None => Vec::new(),
        };
        let redistributed = problem.mass == MassChoice::Redistributed;
        if problem.mass != MassChoice::Consistent && !inertia {
            return Err(CaseError::Option(format!(
                "--mass {}: the scheme has no inertia (it applies no `mass`)",
                problem.mass.name()
            )));
        }
        // The scheme's mass replaces the material's in its `mass` slot.
        let scheme_mass = match problem.mass {
            MassChoice::Consistent => None,
            MassChoice::Redistributed => Some(
                crate::runtime::fem::redistribute::redistribute(mesh, &mass, &contact_nodes)
                    .map_err(|e| CaseError::Option(e.to_string()))?
                    .matrix,
            ),
            MassChoice::Lumped => Some(crate::runtime::fem::lumping::lumped(&mass, mesh.kind.degree(), mesh.dim())),
        };
        let scheme_mass = match scheme_mass {
            Some(matrix) => {
                let i = slot(&forms, "mass")?;
                forms[i] = ("mass", Box::new(MatrixForm { name: "mass".into(), matrix: matrix.clone() }));
                matrix
            }
            None => mass.clone(),
        };
        let mut tools = Tools {
            asm,
            contact_facets,
            probe: active.forms.instantiate(problem.coefs, &binding)?.take_form("contact"),
            contact_energy: inst.take_functional("contact_energy"),
            contact_jump: inst.take_functional("contact_jump"),
            contact_work: inst.take_functional("contact_work").filter(|f| f.fields() == 2),
            contact_pressure: inst.take_functional("contact_pressure"),
            contact_trial: inst.take_functional("contact_trial"),
            von_mises: inst.take_functional("von_mises"),
            cell_measure: inst.take_functional("measure"),
            // The full products until a stepper gives its lower-half pattern.
            energies: Energies::full(),
            last_switches: Default::default(),
            mass,
            scheme_mass,
            stiffness,
            load,
            varying_load: active
                .forms
                .instantiate(problem.coefs, &binding)?
                .take_form("load")
                .filter(|f| f.time_dependent() && f.fields() == 0),
            contact_nodes,
            redistributed,
            mass_choice: problem.mass,
            // The held dofs: the stepper's, set with it.
            held: Vec::new(),
        };
        // A law that does no work of its own (Nitsche θ = 1: its factor 1 − θ is zero) costs the
        // energy guard nothing per step. Probed from rest to the body pushed into the obstacle
        // and strained every way, where any other law's work is not zero.
        if let Some(work) = &tools.contact_work {
            let pushed = stability::pushed_into_obstacle(&tools, problem.coefs);
            let size = pushed.iter().fold(0.0f64, |m, x| m.max(x.abs())).max(1.0);
            let strained: Vec<f64> =
                pushed.iter().zip(stability::scattered(n)).map(|(p, r)| p + 1e-3 * size * r).collect();
            if work.value(asm, &[&strained, &vec![0.0; n]], 0.0) == 0.0 {
                tools.contact_work = None;
            }
        }
        Ok(Parts { tools, forms, inertia })
    }
}

impl<'m> Tools<'m> {
    /// The tools of a problem solved without a stepper (one equilibrium, `run static`).
    pub fn bind(asm: &'m Assembler<'m>, problem: Problem<'_>, active: &Active) -> Result<Self, CaseError> {
        Ok(Parts::build(asm, problem, active)?.tools)
    }
}

/// The stepper, its states and the tools, ready to run.
pub struct Simulation<'m> {
    pub stepper: Stepper<'m>,
    pub tools: Tools<'m>,
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
    pub report: &'s StepReport,
}

impl<'m> Simulation<'m> {
    /// Binds the files in use on `asm`'s mesh, redistributes the mass when asked (the contact
    /// nodes carry none; a⁰ = 0 there), and builds the stepper.
    pub fn new(asm: &'m Assembler<'m>, mut problem: Problem<'_>, active: &Active) -> Result<Self, CaseError> {
        let constraints = problem.constraints.clone();
        let held = constraints.clone();
        let coefs = problem.coefs;
        let newton = problem.newton;
        let prescribed = problem.prescribed.take();
        let Parts { mut tools, forms, inertia } = Parts::build(asm, problem, active)?;
        tools.held = prescribed.as_ref().map_or_else(Vec::new, |p| p.dofs.clone());
        let scheme = active.time_scheme()?;
        if tools.redistributed && scheme.desc().explicit() {
            return Err(CaseError::Option(format!(
                "--mass redistributed: scheme `{}` is explicit (only `mass` acts on its unknown), and the redistributed mass leaves the contact nodes without inertia: their accelerations cannot be solved for at any Δt; use --mass consistent or --mass lumped",
                scheme.desc().name
            )));
        }
        let mut stepper = Stepper::new(scheme, asm, forms, constraints.clone(), Structure::Auto, newton)?;
        if let Some(p) = prescribed {
            stepper.prescribe(p)?;
        }
        if tools.redistributed {
            let d = asm.mesh().dim();
            let mut initial = constraints;
            for &c in &tools.contact_nodes {
                for k in 0..d {
                    initial.fix(d * c as usize + k);
                }
            }
            stepper.initial_constraints = Some(initial);
        }
        tools.energies = Energies::new(asm, stepper.half_pattern(), &tools.stiffness, &tools.scheme_mass);
        let n = asm.size();
        let names = stepper.desc().states;
        let states = names.iter().map(|_| vec![0.0; n]).collect();
        let v_index = names.iter().position(|s| *s == "v");
        let params = active
            .forms
            .params
            .values()
            .iter()
            .map(|(name, p)| format!("{name} = {}", p.value))
            .collect::<Vec<_>>()
            .join(", ");
        // Without inertia each step is an equilibrium of its own: no energy accumulates to watch.
        let mut guard = active.guard;
        if !inertia {
            guard.energy_tolerance = 0.0;
        }
        let (claims, law) = active.scheme_claims_and_law()?;
        let stable = match claims.into_iter().find(|(c, _)| c == "cfl") {
            Some((_, cfl)) => Some(stability::estimate(&tools, coefs, &held, cfl)?),
            None => None,
        };
        Ok(Simulation { stepper, tools, states, v_index, guard, params, law, stable })
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
    #[allow(clippy::too_many_arguments)]
    pub fn run(
        &mut self,
        t0: f64,
        dt: f64,
        steps: usize,
        progress: bool,
        control: &mut Control,
        on_stage: &mut dyn FnMut(&Tools, &StageView, Option<usize>),
        on_step: &mut OnStep,
    ) -> Result<Outcome, CaseError> {
        if let Some(stable) = self.stable
            && dt > stable.dt
            && !self.guard.allow_unstable_dt
        {
            return Err(CaseError::UnstableStep {
                dt,
                scheme: self.stepper.desc().name.to_string(),
                stable: stable.dt,
                cfl: stable.cfl,
                omega_max: stable.omega_max,
                active: stable.active,
                points: stable.points,
                mass: self.tools.mass_choice.name().to_string(),
            });
        }
        let stages = self.stepper.desc().stages;
        let intermediate: Vec<&str> = stages.iter().rev().skip(1).map(|s| s.name).collect();
        let mut outcome = Outcome {
            step_seconds: Vec::with_capacity(steps),
            cuts: 0,
            stopped: None,
            resumed: None,
            energy_growth: 0.0,
        };
        let mut bar = crate::progress::Progress::new(steps, progress);
        let guard = self.guard;
        let mut energy = EnergyWatch::new(&self.tools, &self.states, self.v_index, t0);
        let Simulation { stepper, tools, states, v_index, params, law, .. } = self;
        // Progress through a nominal step in units of dt / 2^max_cuts.
        let max_cuts = guard.max_step_cuts.min(MAX_STEP_CUTS);
        let full: u64 = 1 << max_cuts;
        let (mut level, mut streak, mut accepted, mut first) = (0usize, 0usize, 0usize, 0usize);
        if let Some((saved, _)) = &control.resume {
            if saved.states.len() != states.len() || saved.states.iter().any(|s| s.len() != tools.asm.size()) {
                return Err(CaseError::Option("the checkpoint's states do not fit this run's scheme and mesh".into()));
            }
            states.clone_from_slice(&saved.states);
            (first, accepted, level, streak) = (saved.steps_done, saved.accepted, saved.level, saved.streak);
            outcome.cuts = saved.cuts;
            energy = EnergyWatch {
                initial: saved.energy_initial,
                u0: saved.energy_u0.clone(),
                work: saved.energy_work,
                varying_work: saved.energy_varying_work,
                law_work: saved.energy_law_work,
                kinetic: saved.energy_kinetic,
                growth: saved.energy_growth,
                lowest: saved.energy_lowest,
                allowance: saved.energy_allowance,
                switches: saved.energy_switches.clone(),
            };
            outcome.resumed = Some(Resumed { step: saved.steps_done, bit_for_bit: saved.periodic });
            stepper.forget();
        }
        // Fault injection for the restart tests: the process aborts, as if killed, right after
        // this accepted step (and its checkpoint, if one is due).
        let crash_at: Option<usize> = std::env::var("SIGNORINI_CRASH_AFTER_STEP").ok().and_then(|s| s.parse().ok());
        'steps: for k in first..steps {
            bar.tick(k);
            let mut done: u64 = 0;
            while done < full {
                let units = full >> level;
                let h = dt * units as f64 / full as f64;
                let t = t0 + (k as f64 + done as f64 / full as f64) * dt;
                let saved = (max_cuts > 0).then(|| states.to_vec());
                let before = states[0].clone();
                // The held dofs' reaction takes the change of velocity over the step.
                let v_before = v_index.filter(|_| !tools.held.is_empty()).map(|i| states[i].clone());
                let clock = Instant::now();
                // The intermediate stages' displacements and velocities, for the held dofs' work.
                let mut stages_seen: Vec<(f64, Vec<f64>, Option<Vec<f64>>)> = Vec::new();
                let result = stepper.step_observed(states, t, h, &mut |stage| {
                    if intermediate.contains(&stage.name) {
                        on_stage(tools, stage, *v_index);
                        if !tools.held.is_empty()
                            && let Some(u) = stage.value_of("u")
                        {
                            stages_seen.push((stage.time, u.to_vec(), stage.value_of("v").map(<[f64]>::to_vec)));
                        }
                    }
                });
                let report = match result {
                    Ok(report) => report,
                    Err(e) => {
                        if let Some(saved) = saved {
                            states.clone_from_slice(&saved);
                        }
                        // A law whose derivative is 0/0 is so at any Δt: no cut helps.
                        if let crate::runtime::time::stepper::StepError::NonFiniteTangent { .. } = e {
                            outcome.stopped = Some(CaseError::Failed { t, cause: e.to_string() });
                            break 'steps;
                        }
                        if level < max_cuts {
                            level += 1;
                            streak = 0;
                            outcome.cuts += 1;
                            tracing::warn!(t, dt = h / 2.0, "step failed ({e}); retrying with Δt halved");
                            continue;
                        }
                        outcome.stopped = Some(CaseError::Stopped {
                            t,
                            cuts: level,
                            dt: h,
                            cause: e.to_string(),
                            history: history(&e),
                        });
                        break 'steps;
                    }
                };
                outcome.step_seconds.push(clock.elapsed().as_secs_f64());
                done += units;
                accepted += 1;
                let t_end = if done == full { t0 + (k + 1) as f64 * dt } else { t + h };
                // A checkpoint after the last step would resume nothing.
                let periodic = control.every > 0 && (k + 1).is_multiple_of(control.every) && k + 1 < steps;
                let interrupted = crate::interrupt::requested();
                // With periodic checkpoints an interrupt keeps the last one, which resumes bit
                // for bit; without, it writes one of its own (which resumes to round-off).
                let on_interrupt = interrupted && control.every == 0;
                let mut record = (done == full && (periodic || on_interrupt)).then(Vec::new);
                if let Some(load) = &tools.varying_load {
                    energy.step_work(tools, load.as_ref(), &before, &states[0], t + 0.5 * h);
                }
                if !tools.held.is_empty() {
                    // Over each sub-interval between the step's stages.
                    let v = v_index.map(|i| states[i].clone());
                    let mut points = vec![(t, before.clone(), v_before.clone())];
                    points.append(&mut stages_seen);
                    points.push((t + h, states[0].clone(), v));
                    for w in points.windows(2) {
                        let ((t0, u0, v0), (t1, u1, v1)) = (&w[0], &w[1]);
                        let vs = v0.as_deref().zip(v1.as_deref());
                        energy.held_work(tools, u0, u1, vs, t1 - t0, 0.5 * (t0 + t1));
                    }
                }
                if tools.probe.as_ref().is_some_and(|p| p.time_dependent()) {
                    energy.obstacle_work(tools, &before, &states[0], t, h);
                }
                if let Some(work) = &tools.contact_work {
                    energy.law_work += work.value(tools.asm, &[&states[0], &before], t + 0.5 * h);
                }
                // Checked before the observer sees the step: the outputs end at the last good one.
                if let Some(grown) =
                    energy.check(tools, states, *v_index, &before, h, t_end, guard.energy_tolerance, *law)
                {
                    outcome.stopped = Some(match grown.cause {
                        Cause::Negative(potential) => CaseError::NotCoercive {
                            t: t_end,
                            potential,
                            scale: grown.scale,
                            tolerance: guard.energy_tolerance,
                            params: params.clone(),
                        },
                        Cause::LawWork { work, outside } => {
                            CaseError::LawWork { t: t_end, work, outside, params: params.clone() }
                        }
                        Cause::Growth => CaseError::BlowUp {
                            t: t_end,
                            energy: grown.energy,
                            bound: grown.bound,
                            scale: grown.scale,
                            tolerance: guard.energy_tolerance,
                            law: law.map_or_else(
                                || " (the scheme claims no energy law)".to_string(),
                                |l| format!(" beyond what a {} scheme allows", l.name()),
                            ),
                            params: params.clone(),
                        },
                    });
                    break 'steps;
                }
                outcome.energy_growth = energy.growth;
                let step = Step { k: accepted, t: t_end, dt: h, states, before: &before, report: &report };
                on_step(tools, &step, record.as_mut())?;
                streak += 1;
                if level > 0 && streak >= 2 && done.is_multiple_of(2 * units) {
                    level -= 1;
                    streak = 0;
                }
                if let Some(record) = record {
                    let driver = crate::checkpoint::DriverState {
                        steps_done: k + 1,
                        accepted,
                        level,
                        streak,
                        cuts: outcome.cuts,
                        energy_initial: energy.initial,
                        energy_work: energy.work,
                        energy_varying_work: energy.varying_work,
                        energy_law_work: energy.law_work,
                        energy_u0: energy.u0.clone(),
                        energy_kinetic: energy.kinetic,
                        energy_growth: energy.growth,
                        energy_lowest: energy.lowest,
                        energy_allowance: energy.allowance,
                        energy_switches: energy.switches.clone(),
                        states: states.to_vec(),
                        periodic: !interrupted,
                    };
                    if let Err(e) = control.write(driver, record) {
                        // The outputs up to here are still written.
                        outcome.stopped = Some(e);
                        break 'steps;
                    }
                    if !interrupted {
                        stepper.forget();
                    }
                }
                if crash_at == Some(accepted) {
                    std::process::abort();
                }
                // An interrupt lets the nominal step finish, so that its checkpoint is on the
                // nominal time levels.
                if interrupted && done == full {
                    outcome.stopped = Some(CaseError::Interrupted { t: t_end });
                    break 'steps;
                }
            }
        }
        bar.finish();
        Ok(outcome)
    }
}

/// What a case does with each accepted step; when a checkpoint is due, it also writes its
/// record of the run so far into the buffer.
pub type OnStep<'a> = dyn FnMut(&Tools, &Step, Option<&mut Vec<u8>>) -> Result<(), CaseError> + 'a;

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

/// The residual history of a failed Newton, for the stop message.
fn history(e: &crate::runtime::time::stepper::StepError) -> String {
    use crate::runtime::nonlinear::newton::NewtonError;
    use crate::runtime::time::stepper::StepError;
    let StepError::Newton { source, .. } = e else { return String::new() };
    let report = match source {
        NewtonError::IterationLimit { report, .. } | NewtonError::NonFinite { report } => report,
        NewtonError::Linear { report, .. } => report,
    };
    let mut text = format!("residual {:.3e}", report.initial_residual);
    for it in &report.history {
        text.push_str(&format!(" → {:.3e} ({} active)", it.residual, it.active));
    }
    text
}

/// The energy guard: the growth of E_aug = ½uᵀKu + ½vᵀMv + the contact law's
/// `contact_energy(u)` beyond E_aug(0) + the work of the loads, over the problem's energy scale
/// (the largest of |E_aug(0)|, the work's magnitude so far, and the kinetic energy reached).
pub(crate) struct EnergyWatch {
    pub(crate) initial: f64,
    pub(crate) u0: Vec<f64>,
    /// The largest magnitude of the work of the loads so far.
    pub(crate) work: f64,
    /// The work summed step by step (midpoint rule): a load that changes with time, the held
    /// dofs' reactions, a moving obstacle's.
    pub(crate) varying_work: f64,
    /// The contact law's `contact_work` so far: energy the law itself gives or takes.
    pub(crate) law_work: f64,
    /// The largest kinetic energy so far.
    pub(crate) kinetic: f64,
    /// The largest growth over the scale so far (the summary's `energy_growth`).
    pub(crate) growth: f64,
    /// The lowest E_aug − W so far (a dissipative scheme's bound: what it lost stays lost).
    pub(crate) lowest: f64,
    /// A conserving scheme's allowance so far: on each step whose active set changed, the
    /// larger of `contact_jump` before and after it.
    pub(crate) allowance: f64,
    /// The active set after the previous step (a conserving scheme's).
    pub(crate) switches: Vec<bool>,
}

/// An energy above what the guard allows.
struct Grown {
    /// E_aug and E_aug(0) + W.
    energy: f64,
    bound: f64,
    scale: f64,
    cause: Cause,
}

/// What the guard saw.
enum Cause {
    /// E_aug beyond its bound.
    Growth,
    /// ½uᵀKu + the contact energy negative beyond the tolerance.
    Negative(f64),
    /// The law's own work beyond the energy from outside.
    LawWork { work: f64, outside: f64 },
}

impl EnergyWatch {
    fn new(tools: &Tools, states: &[Vec<f64>], v_index: Option<usize>, t: f64) -> Self {
        let u = &states[0];
        let v = v_index.map(|i| states[i].as_slice());
        let kinetic = tools.kinetic(v);
        let initial = tools.elastic(u) + kinetic + Self::contact(tools, u, t);
        EnergyWatch {
            initial,
            u0: u.clone(),
            work: 0.0,
            varying_work: 0.0,
            law_work: 0.0,
            kinetic,
            growth: 0.0,
            lowest: initial,
            allowance: 0.0,
            switches: tools.contact_switches(u, t),
        }
    }

    /// The contact law's energy (0 for a law without `contact_energy`).
    fn contact(tools: &Tools, u: &[f64], t: f64) -> f64 {
        Self::value(&tools.contact_energy, tools, u, t)
    }

    /// A functional of u alone at `u` (0 without it).
    fn value(f: &Option<Box<dyn BoundFunctional + '_>>, tools: &Tools, u: &[f64], t: f64) -> f64 {
        f.as_ref().filter(|f| f.fields() == 1).map_or(0.0, |f| f.value(tools.asm, &[u], t))
    }

    /// Adds the work of a time-dependent load over one step: L(t_mid)·(u − u_before).
    fn step_work(&mut self, tools: &Tools, load: &dyn BoundForm, before: &[f64], u: &[f64], t_mid: f64) {
        let mut l = vec![0.0; u.len()];
        load.residual(tools.asm, &[], t_mid, &mut l);
        self.varying_work += l.iter().zip(u.iter().zip(before)).map(|(l, (a, b))| l * (a - b)).sum::<f64>();
    }

    /// Adds the work of the held dofs' reactions over one step: the reaction at the step's
    /// midpoint, K u_mid − F + M (v' − v)/Δt at the held dofs (exact for Crank–Nicolson; without
    /// a velocity state, its quasi-static part), times their motion.
    fn held_work(&mut self, tools: &Tools, before: &[f64], u: &[f64], v: Option<(&[f64], &[f64])>, h: f64, t_mid: f64) {
        let mid: Vec<f64> = before.iter().zip(u).map(|(a, b)| 0.5 * (a + b)).collect();
        let mut reaction = vec![0.0; u.len()];
        tools.stiffness.mul_vec(&mid, &mut reaction);
        if let Some((v0, v1)) = v {
            let dv: Vec<f64> = v1.iter().zip(v0).map(|(a, b)| (a - b) / h).collect();
            let mut inertia = vec![0.0; u.len()];
            tools.scheme_mass.mul_vec(&dv, &mut inertia);
            reaction.iter_mut().zip(&inertia).for_each(|(r, m)| *r += m);
        }
        let load = match &tools.varying_load {
            Some(form) => {
                let mut l = vec![0.0; u.len()];
                form.residual(tools.asm, &[], t_mid, &mut l);
                l
            }
            None => tools.load.clone(),
        };
        self.varying_work += tools.held.iter().map(|&i| (reaction[i] - load[i]) * (u[i] - before[i])).sum::<f64>();
    }

    /// Adds the work of an obstacle that moves (a gap that changes with time) over one step:
    /// the change of the contact energy with time alone, at the step's mid-displacement.
    fn obstacle_work(&mut self, tools: &Tools, before: &[f64], u: &[f64], t: f64, h: f64) {
        let mid: Vec<f64> = before.iter().zip(u).map(|(a, b)| 0.5 * (a + b)).collect();
        self.varying_work +=
            Self::value(&tools.contact_energy, tools, &mid, t + h) - Self::value(&tools.contact_energy, tools, &mid, t);
    }

    /// After each accepted step: the energy, and whether it grew beyond what `law` allows by
    /// more than `tolerance` × the scale. Without a law, E_aug − W may not exceed its initial
    /// value. A conserving scheme's E_aug may also jump on the steps where points enter or leave
    /// contact, by at most the energy of their contact stress (docs/mathematics.md §5:
    /// (1/2γ)(pⁿ)² or (1/2γ)(pⁿ⁺¹)²), which the law gives as `contact_jump`: on each such step
    /// the larger of its values before and after is added to what is allowed. A dissipative scheme's
    /// E_aug − W may not exceed the lowest value it reached. The kinetic energy of this step
    /// joins the scale only once the step passes (a blow-up's own motion does not widen its
    /// bound).
    #[allow(clippy::too_many_arguments)]
    fn check(
        &mut self,
        tools: &Tools,
        states: &[Vec<f64>],
        v_index: Option<usize>,
        before: &[f64],
        h: f64,
        t: f64,
        tolerance: f64,
        law: Option<EnergyLaw>,
    ) -> Option<Grown> {
        let u = &states[0];
        let fd: Vec<f64>;
        let v = match v_index {
            Some(i) => states[i].as_slice(),
            None => {
                fd = u.iter().zip(before).map(|(a, b)| (a - b) / h).collect();
                &fd
            }
        };
        let kinetic = tools.kinetic(Some(v));
        let potential = tools.elastic(u) + Self::contact(tools, u, t);
        let energy = potential + kinetic;
        // A conserving scheme: the allowance grows on the steps where the active set changes.
        let (switches, allowance) = match law {
            Some(EnergyLaw::Conserving) => {
                let switches = tools.contact_switches(u, t);
                let jump = if switches != self.switches {
                    let value = |x: &[f64], at: f64| Self::value(&tools.contact_jump, tools, x, at);
                    value(u, t).max(value(before, t - h))
                } else {
                    0.0
                };
                (switches, self.allowance + jump)
            }
            _ => (Vec::new(), 0.0),
        };
        // The work summed step by step (a varying load's, the held dofs', a moving obstacle's),
        // a constant load's from u(0), and the law's own.
        let constant: f64 = match tools.varying_load {
            Some(_) => 0.0,
            None => tools.load.iter().zip(u.iter().zip(&self.u0)).map(|(l, (a, b))| l * (a - b)).sum(),
        };
        let external = self.varying_work + constant;
        self.work = self.work.max(external.abs());
        let scale = self.initial.abs().max(self.work).max(self.kinetic).max(f64::MIN_POSITIVE);
        let work = external + self.law_work;
        let bound = match law {
            Some(EnergyLaw::Conserving) => self.initial + work + allowance,
            Some(EnergyLaw::Dissipative) => self.lowest + work,
            None => self.initial + work,
        };
        // The law's own work (Nitsche θ ≠ 1) is part of the balance, but it may not drive the
        // motion: beyond the energy that came from outside (initially and by the loads), the
        // balance would hold while the motion grows without bound.
        let outside = self.initial.abs().max(self.work).max(f64::MIN_POSITIVE);
        if tolerance > 0.0 && self.law_work.abs() > outside {
            return Some(Grown { energy, bound, scale, cause: Cause::LawWork { work: self.law_work, outside } });
        }
        let growth = (energy - bound) / scale;
        // NaN compares false: a non-finite energy is a growth beyond any tolerance.
        self.growth = if growth.is_finite() { self.growth.max(growth) } else { f64::INFINITY };
        if tolerance > 0.0 && (growth > tolerance || growth.is_nan()) {
            return Some(Grown { energy, bound, scale, cause: Cause::Growth });
        }
        // The potential energy of a coercive law is not negative: where it is, E_aug may be kept
        // while the motion grows without bound (Nitsche θ = 1 with γ0 too small).
        if tolerance > 0.0 && potential < -tolerance * scale {
            return Some(Grown { energy, bound, scale, cause: Cause::Negative(potential) });
        }
        // With the guard off, the default tolerance still decides what joins the scale, so that
        // the summary's `energy_growth` measures the same thing.
        let admitted = if tolerance > 0.0 { tolerance } else { ENERGY_TOLERANCE };
        if growth <= admitted {
            self.kinetic = self.kinetic.max(kinetic);
        }
        self.switches = switches;
        self.allowance = allowance;
        self.lowest = self.lowest.min(energy - work);
        None
    }
}

/// VTU snapshots every `every` steps into `dir`/vtu, and the PVD collection of them.
pub struct Snapshots {
    dir: Option<PathBuf>,
    every: usize,
    name: String,
    written: Vec<(f64, String)>,
}

impl Snapshots {
    /// Writes nothing unless `out` is given and `every` > 0.
    pub fn new(out: Option<&PathBuf>, every: usize, name: &str) -> Snapshots {
        Snapshots { dir: out.filter(|_| every > 0).cloned(), every, name: name.to_string(), written: Vec::new() }
    }

    /// The displacement and velocity at step `k`, and the cell-mean von Mises stress when the
    /// files in use provide it.
    pub fn write(&mut self, tools: &Tools, k: usize, t: f64, u: &[f64], v: &[f64]) -> Result<(), CaseError> {
        let Some(dir) = &self.dir else { return Ok(()) };
        if !k.is_multiple_of(self.every) {
            return Ok(());
        }
        let mesh = tools.asm.mesh();
        let file = format!("{}_{k:06}.vtu", self.name);
        let vm = match (&tools.von_mises, &tools.cell_measure) {
            (Some(vm), Some(measure)) => {
                let size = measure.cell_values(tools.asm, &[], 0.0);
                vm.cell_values(tools.asm, &[u], 0.0).iter().zip(&size).map(|(v, a)| v / a).collect()
            }
            _ => vec![f64::NAN; mesh.num_cells()],
        };
        let d = mesh.dim();
        let point = [
            crate::vtu::Field { name: "displacement", components: d, values: u },
            crate::vtu::Field { name: "velocity", components: d, values: v },
        ];
        let cell = [crate::vtu::Field { name: "von_mises", components: 1, values: &vm }];
        let path = dir.join("vtu").join(&file);
        crate::vtu::write(&path, mesh, &point, &cell)
            .map_err(|source| CaseError::Write { path: path.display().to_string(), source })?;
        self.written.push((t, format!("vtu/{file}")));
        Ok(())
    }

    /// The snapshots written so far: (time, file), for a checkpoint.
    pub fn written(&self) -> &[(f64, String)] {
        &self.written
    }

    /// Adds snapshots an earlier part of the run wrote.
    pub fn extend_written(&mut self, written: Vec<(f64, String)>) {
        self.written.extend(written);
    }

    /// Writes the collection `dir`/NAME.pvd (if any snapshot was written).
    pub fn finish(self) -> Result<(), CaseError> {
        let (Some(dir), false) = (&self.dir, self.written.is_empty()) else { return Ok(()) };
        let path = dir.join(format!("{}.pvd", self.name));
        crate::vtu::write_collection(&path, &self.written)
            .map_err(|source| CaseError::Write { path: path.display().to_string(), source })
    }
}
