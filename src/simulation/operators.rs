//! What a run measures with, bound on its mesh: the material's mass, the mass the scheme steps
//! with, the stiffness and the load; the contact form (its residual is the contact force, its
//! switches the active set) and the contact law's functionals (energy, jump, work, pressure);
//! the energies ½uᵀKu (or the material's `strain_energy(u)` for a stiffness nonlinear in u) and
//! ½vᵀMv, each computed once per step; and the binding of all of it, with the scheme's forms,
//! from the files in use.

use std::sync::Arc;

use super::{MassChoice, Problem, stability};
use crate::driver::FilesInUse;
use crate::error::CaseError;
use crate::runtime::fem::assembly::Assembler;
use crate::runtime::fem::bound::{BoundForm, BoundFunctional, MatrixForm, with_previous};
use crate::runtime::fem::mesh::{Facet, Mesh};
use crate::runtime::library::Binding;
use crate::runtime::linalg::Matrix;
use crate::runtime::linalg::lower_half::{HalfPattern, LowerHalf};

/// A run's operators bound on its mesh, which the observers, the energy guard and the stability
/// estimate measure with: the matrices (mass, the scheme's mass, stiffness), the load, the
/// contact form and the contact law's functionals, and the energies they give.
pub struct Operators<'m> {
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
    /// The energy a frictional law takes over a step (its dissipation, ≥ 0 where the friction
    /// opposes the slip), a functional of the step's end and start displacements.
    pub friction_work: Option<Box<dyn BoundFunctional + 'm>>,
    pub contact_pressure: Option<Box<dyn BoundFunctional + 'm>>,
    pub contact_trial: Option<Box<dyn BoundFunctional + 'm>>,
    pub von_mises: Option<Box<dyn BoundFunctional + 'm>>,
    pub cell_measure: Option<Box<dyn BoundFunctional + 'm>>,
    /// The consistent mass, the mass the scheme steps with when it is another (redistributed or
    /// lumped: [`Operators::scheme_mass`]), the stiffness and the load vector at t = 0.
    pub mass: Matrix,
    pub other_mass: Option<Matrix>,
    /// The stiffness's tangent at u = 0 (K itself for a linear material).
    pub stiffness: Matrix,
    /// A stiffness nonlinear in u (a finite-strain material): its form and stored energy.
    pub nonlinear: Option<NonlinearStiffness<'m>>,
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
    last_switches: std::sync::Mutex<Option<KeptSwitches>>,
}

/// A stiffness nonlinear in u: the form, whose residual S(u) is the internal force, and the
/// material's `strain_energy(u)`, whose derivative it is.
pub struct NonlinearStiffness<'m> {
    pub form: Box<dyn BoundForm + 'm>,
    pub energy: Box<dyn BoundFunctional + 'm>,
}

/// Switches kept for the u, the previous level (empty when the law does not read it) and the
/// time (its bits) they were computed at.
type KeptSwitches = (Vec<f64>, Vec<f64>, u64, Vec<bool>);

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
    /// The last u and value of a nonlinear material's stored energy (the step's end is read by
    /// the stepper's check, the guard and the observers).
    last_stored: std::sync::Mutex<Option<(Vec<f64>, f64)>>,
}

impl Energies {
    /// Without lower halves: the full products.
    pub fn full() -> Energies {
        Energies {
            stiffness: None,
            mass: None,
            work: Default::default(),
            last: Default::default(),
            last_stored: Default::default(),
        }
    }

    /// With the stepper's lower-half pattern when it has one (the same pattern); without a
    /// stiffness matrix when the stiffness is nonlinear (its energy is a functional).
    pub fn new(
        asm: &Assembler,
        half: Option<&Arc<HalfPattern>>,
        stiffness: Option<&Matrix>,
        mass: &Matrix,
    ) -> Energies {
        let half = half.cloned().unwrap_or_else(|| Arc::new(HalfPattern::new(asm.pattern())));
        let lower = |a: &Matrix| a.is_symmetric_everywhere(1e-12).then(|| LowerHalf::new(a, &half));
        Energies {
            stiffness: stiffness.and_then(lower),
            mass: lower(mass),
            work: Default::default(),
            last: Default::default(),
            last_stored: Default::default(),
        }
    }

    /// xᵀAx for A the stiffness (`which` 0) or the mass (1): the last value again for the
    /// same x, else from A's lower half when there is one, else from `a`.
    pub fn quad(&self, which: usize, a: &Matrix, x: &[f64]) -> f64 {
        let mut last = self.last.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((kept, value)) = &last[which]
            && kept.as_slice() == x
        {
            return *value;
        }
        let half = if which == 0 { &self.stiffness } else { &self.mass };
        let value = match half {
            None => Operators::quad(a, x, x),
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

impl Operators<'_> {
    /// xᵀ A y ([`Matrix::quad`]).
    pub fn quad(a: &Matrix, x: &[f64], y: &[f64]) -> f64 {
        a.quad(x, y)
    }

    /// The mass the scheme steps with: the material's, or the one that replaces it.
    pub fn scheme_mass(&self) -> &Matrix {
        self.other_mass.as_ref().unwrap_or(&self.mass)
    }

    /// ½vᵀMv with the scheme's mass (0 without a velocity).
    pub fn kinetic(&self, v: Option<&[f64]>) -> f64 {
        v.map_or(0.0, |v| 0.5 * self.energies.quad(1, self.scheme_mass(), v))
    }

    /// E = W(u) + ½vᵀMv − Fᵀu, W the stored energy ([`Operators::elastic`]).
    pub fn energy(&self, u: &[f64], v: Option<&[f64]>) -> f64 {
        self.energy_with_kinetic(u, self.kinetic(v))
    }

    /// E = W(u) + `kinetic` − Fᵀu, with ½vᵀMv already computed.
    pub fn energy_with_kinetic(&self, u: &[f64], kinetic: f64) -> f64 {
        self.elastic(u) + kinetic - self.load.iter().zip(u).map(|(l, x)| l * x).sum::<f64>()
    }

    /// The stored energy W(u): ½uᵀKu, or a nonlinear material's `strain_energy(u)`.
    pub fn elastic(&self, u: &[f64]) -> f64 {
        let Some(m) = &self.nonlinear else { return 0.5 * self.energies.quad(0, &self.stiffness, u) };
        let mut last = self.energies.last_stored.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((kept, value)) = &*last
            && kept.as_slice() == u
        {
            return *value;
        }
        let value = m.energy.value(self.asm, &[u], 0.0);
        *last = Some((u.to_vec(), value));
        value
    }

    /// The internal force S(u): K u, or a nonlinear material's residual.
    pub fn internal_force(&self, u: &[f64]) -> Vec<f64> {
        let mut f = vec![0.0; u.len()];
        match &self.nonlinear {
            Some(m) => m.form.residual(self.asm, &[u], 0.0, &mut f),
            None => self.stiffness.mul_vec(u, &mut f),
        }
        f
    }

    /// The resultant of the contact term on the body along each axis (zeros without a
    /// `contact` slot), at u with `previous` the level before it (what a law's `prev` reads).
    pub fn contact_force(&self, u: &[f64], previous: &[f64], t: f64) -> Vec<f64> {
        let mut c = vec![0.0; u.len()];
        if let Some(probe) = &self.probe {
            probe.residual(self.asm, &with_previous(probe.previous(), &[u], previous), t, &mut c);
        }
        resultant(&c, self.asm.mesh().dim())
    }

    /// The contact slot's switch at each of its quadrature points (none without the slot), at
    /// u with `previous` the level before it.
    ///
    /// The energy guard and the observers ask for the same step's: the last answer is kept and
    /// reused for the same u, previous level and t.
    pub fn contact_switches(&self, u: &[f64], previous: &[f64], t: f64) -> Vec<bool> {
        let mut last = self.last_switches.lock().unwrap_or_else(|e| e.into_inner());
        let reads = self.probe.as_ref().is_some_and(|p| p.previous());
        if let Some((kept, kept_previous, at, switches)) = &*last
            && *at == t.to_bits()
            && kept.as_slice() == u
            && (!reads || kept_previous.as_slice() == previous)
        {
            return switches.clone();
        }
        let mut switches = Vec::new();
        if let Some(probe) = &self.probe {
            probe.switches(self.asm, &with_previous(reads, &[u], previous), 0, t, &mut switches);
        }
        let kept_previous = if reads { previous.to_vec() } else { Vec::new() };
        *last = Some((u.to_vec(), kept_previous, t.to_bits(), switches.clone()));
        switches
    }

    /// The mass-weighted mean along `axis` (of the displacement: the centre of mass's).
    pub fn axis_mean(&self, axis: usize, nodes: Option<&[bool]>) -> AxisMean {
        let d = self.asm.mesh().dim();
        // Bodies share no mass entry: M e over one body's nodes is its own mass.
        let on = |i: usize| i % d == axis && nodes.is_none_or(|n| n[i / d]);
        let e: Vec<f64> = (0..self.mass.size()).map(|i| if on(i) { 1.0 } else { 0.0 }).collect();
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

/// What a run binds before it steps: the operators, the scheme's forms, and whether the scheme
/// has inertia.
pub(super) struct Parts<'m> {
    pub(super) ops: Operators<'m>,
    pub(super) forms: Vec<(String, Box<dyn BoundForm + 'm>)>,
    pub(super) inertia: bool,
}

impl<'m> Parts<'m> {
    pub(super) fn build(asm: &'m Assembler<'m>, problem: Problem<'_>, in_use: &FilesInUse) -> Result<Self, CaseError> {
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
        let binding = Binding {
            bodies: &mesh.bodies,
            pairs: problem.pairs.iter().map(|p| p.on(mesh)).collect(),
            ..Binding::new(problem.quadrature, regions, mesh.dim())
        };
        let mut inst = in_use.forms.instantiate(problem.coefs, &binding)?;
        let mut forms: Vec<(String, Box<dyn BoundForm + 'm>)> =
            in_use.scheme_forms(&mut inst)?.into_iter().map(|(slot, f)| (slot.to_string(), f)).collect();
        let missing = |what: &str| {
            CaseError::Option(format!("the case needs `{what}`, which the form files in use do not provide"))
        };
        let slot = |forms: &[(String, Box<dyn BoundForm + 'm>)], name: &str| {
            forms.iter().position(|(s, _)| s == name).ok_or_else(|| missing(name))
        };
        let zero = vec![0.0; n];
        let mut mass = asm.zero_matrix();
        // A scheme without inertia (quasi-static: equilibrium at every step) does not apply the
        // mass; the material's still weighs the means and the figures.
        let inertia = forms.iter().any(|(s, _)| s == "mass");
        match forms.iter().find(|(s, _)| s == "mass") {
            Some((_, f)) => f.tangent(asm, &[&zero], 0, 0.0, &mut mass),
            None => {
                let material = in_use.forms.instantiate(problem.coefs, &binding)?.take_form("mass");
                material.ok_or_else(|| missing("mass"))?.tangent(asm, &[&zero], 0, 0.0, &mut mass);
            }
        }
        // A scheme that applies another slot in its place (an energy–momentum stress) still
        // measures with the material's.
        let material_stiffness;
        let stiffness_form = match forms.iter().find(|(s, _)| s == "stiffness") {
            Some((_, f)) => f,
            None => {
                material_stiffness = in_use.forms.instantiate(problem.coefs, &binding)?.take_form("stiffness");
                material_stiffness.as_ref().ok_or_else(|| missing("stiffness"))?
            }
        };
        let nonlinear = match stiffness_form.linear() {
            true => None,
            false => Some(nonlinear_stiffness(in_use, problem.coefs, &binding, &mut inst)?),
        };
        let mut stiffness = asm.zero_matrix();
        stiffness_form.tangent(asm, &[&zero], 0, 0.0, &mut stiffness);
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
        if let Some(matrix) = &scheme_mass {
            let i = slot(&forms, "mass")?;
            forms[i] = ("mass".into(), Box::new(MatrixForm { name: "mass".into(), matrix: matrix.clone() }));
        }
        let mut ops = Operators {
            asm,
            contact_facets,
            probe: in_use.forms.instantiate(problem.coefs, &binding)?.take_form("contact"),
            contact_energy: inst.take_functional("contact_energy"),
            contact_jump: inst.take_functional("contact_jump"),
            contact_work: inst.take_functional("contact_work").filter(|f| f.fields() == 2),
            friction_work: inst.take_functional("friction_work").filter(|f| f.fields() == 2),
            contact_pressure: inst.take_functional("contact_pressure"),
            contact_trial: inst.take_functional("contact_trial"),
            von_mises: inst.take_functional("von_mises"),
            cell_measure: inst.take_functional("measure"),
            // The full products until a stepper gives its lower-half pattern.
            energies: Energies::full(),
            last_switches: Default::default(),
            mass,
            other_mass: scheme_mass,
            stiffness,
            nonlinear,
            load,
            varying_load: in_use
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
        // and strained every way, where any other law's work is not zero. Pairs that start
        // apart do no work in that probe whatever their law: their work is kept.
        if let Some(work) = &ops.contact_work
            && problem.pairs.is_empty()
        {
            let pushed = stability::pushed_into_obstacle(&ops, problem.coefs);
            let size = pushed.iter().fold(0.0f64, |m, x| m.max(x.abs())).max(1.0);
            let strained: Vec<f64> =
                pushed.iter().zip(stability::scattered(n)).map(|(p, r)| p + 1e-3 * size * r).collect();
            if work.value(asm, &[&strained, &vec![0.0; n]], 0.0) == 0.0 {
                ops.contact_work = None;
            }
        }
        Ok(Parts { ops, forms, inertia })
    }
}

/// The stiffness slot again, for the internal force, and the `strain_energy` its files provide
/// (the energy columns and the guard read it: ½uᵀKu would be the energy of the tangent at rest).
fn nonlinear_stiffness<'m>(
    in_use: &FilesInUse,
    coefs: &dyn Fn(&str) -> Option<crate::runtime::fem::kernel::Coef>,
    binding: &Binding<'m>,
    inst: &mut crate::driver::Instance<'m>,
) -> Result<NonlinearStiffness<'m>, CaseError> {
    let form = in_use.forms.instantiate(coefs, binding)?.take_form("stiffness");
    let energy = inst.take_functional("strain_energy").filter(|f| f.fields() == 1);
    match (form, energy) {
        (Some(form), Some(energy)) => Ok(NonlinearStiffness { form, energy }),
        _ => Err(CaseError::Incomplete(
            "the `stiffness` slot is nonlinear in u (a finite-strain material), and no file provides its stored energy: add `functional strain_energy(u) = int(Omega) W` to the material's file (the energy columns and the energy guard read it; ½uᵀKu is the energy of a linear material only)"
                .into(),
        )),
    }
}

impl<'m> Operators<'m> {
    /// The operators of a problem solved without a stepper (one equilibrium, `run static`).
    pub fn bind(asm: &'m Assembler<'m>, problem: Problem<'_>, in_use: &FilesInUse) -> Result<Self, CaseError> {
        Ok(Parts::build(asm, problem, in_use)?.ops)
    }
}
