//! The critical step of an explicit scheme (one that claims `cfl`, the largest stable ω Δt):
//! Δt_c = cfl / ω_max, with ω_max² the largest eigenvalue of M⁻¹(K + J_C), where J_C is the
//! contact law's tangent with the body pushed into the obstacle (every contact point active, so
//! that the contact's stiffness counts as it will once the body touches). ω_max is estimated at
//! the start of the run by power iteration with the Rayleigh quotient, which approaches it from
//! below: the estimated Δt_c is at most a little above the true one, and the energy guard
//! stops a run that is unstable all the same. A nonlinear stiffness changes its tangent with
//! the state: [`Tracker`] estimates Δt_c again along the run, from the current tangent.

use super::Operators;
use crate::error::CaseError;
use crate::runtime::fem::kernel::Coef;
use crate::runtime::linalg::{Factorization, Matrix, Structure};
use crate::runtime::nonlinear::statics::Constraints;

/// The estimate, for the refusal's message and the summary.
#[derive(Clone, Copy, Debug)]
pub struct StableStep {
    pub cfl: f64,
    pub omega_max: f64,
    /// cfl / ω_max.
    pub dt: f64,
    /// Contact points active in the pushed state, of all.
    pub active: usize,
    pub points: usize,
}

/// Power iterations at most, and the relative change of the Rayleigh quotient that ends them.
const ITERATIONS: usize = 1000;
const CONVERGED: f64 = 1e-10;

/// Estimates Δt_c for a scheme claiming `cfl`, with the scheme's mass and the problem's
/// obstacle (`g`, `nc` of `coefs`).
pub fn estimate(
    ops: &Operators,
    coefs: &dyn Fn(&str) -> Option<Coef>,
    constraints: &Constraints,
    cfl: f64,
) -> Result<StableStep, CaseError> {
    let (contact, active, points) = contact_stiffness(ops, coefs);
    let mut a = ops.stiffness.clone();
    if let Some(c) = &contact {
        a.add_scaled(1.0, c);
    }
    let mut mass = scheme_mass(ops)?;
    let mut x = scattered(ops.asm.size());
    let lambda = largest(ops, &a, &mut mass, &constraints.fixed, &mut x, ITERATIONS, CONVERGED)?;
    let omega_max = lambda.max(0.0).sqrt();
    Ok(StableStep { cfl, omega_max, dt: cfl / omega_max, active, points })
}

/// The contact law's tangent with the body pushed into the obstacle, and the contact points
/// active there, of all.
fn contact_stiffness(ops: &Operators, coefs: &dyn Fn(&str) -> Option<Coef>) -> (Option<Matrix>, usize, usize) {
    let asm = ops.asm;
    let Some(probe) = &ops.probe else { return (None, 0, 0) };
    let pushed = pushed_into_obstacle(ops, coefs);
    let mut contact = asm.zero_matrix();
    // Pushed from where it was: a frictional law sticks there, its stiffest state.
    let args = crate::runtime::fem::bound::with_previous(probe.previous(), &[&pushed], &pushed);
    probe.tangent(asm, &args, 0, 0.0, &mut contact);
    let mut switches = Vec::new();
    probe.switches(asm, &args, 0, 0.0, &mut switches);
    let active = switches.iter().filter(|s| **s).count();
    (Some(contact), active, switches.len())
}

fn scheme_mass(ops: &Operators) -> Result<Factorization, CaseError> {
    let mut mass = Factorization::new(Structure::SymmetricPositiveDefinite);
    mass.factor(ops.scheme_mass()).map_err(|e| CaseError::Option(format!("the scheme's mass: {e}")))?;
    Ok(mass)
}

/// The largest eigenvalue of M⁻¹A on the free dofs by power iteration from `x` (left at the
/// last iterate): the Rayleigh quotient, after `iterations` at most or once it changes by less
/// than `converged` relatively.
fn largest(
    ops: &Operators,
    a: &Matrix,
    mass: &mut Factorization,
    fixed: &[bool],
    x: &mut [f64],
    iterations: usize,
    converged: f64,
) -> Result<f64, CaseError> {
    let n = x.len();
    let free = |x: &mut [f64]| x.iter_mut().zip(fixed).filter(|(_, f)| **f).for_each(|(x, _)| *x = 0.0);
    free(x);
    let (mut ax, mut lambda) = (vec![0.0; n], 0.0f64);
    for _ in 0..iterations {
        a.mul_vec(x, &mut ax);
        let xmx = ops.scheme_mass().quad(x, x);
        let rayleigh = x.iter().zip(&ax).map(|(p, q)| p * q).sum::<f64>() / xmx;
        let done = (rayleigh - lambda).abs() <= converged * rayleigh.abs();
        lambda = rayleigh;
        if done {
            break;
        }
        free(&mut ax);
        mass.solve_in_place(&mut ax).map_err(|e| CaseError::Option(format!("the scheme's mass: {e}")))?;
        free(&mut ax);
        let norm = ax.iter().map(|v| v * v).sum::<f64>().sqrt();
        if !(norm > 0.0 && norm.is_finite()) {
            break;
        }
        x.iter_mut().zip(&ax).for_each(|(x, y)| *x = y / norm);
    }
    Ok(lambda)
}

/// Steps between two estimates of Δt_c along a run whose stiffness is nonlinear, by the margin
/// Δt/Δt_c of the last one: every step near the limit, rarely far below it. Then the power
/// iterations each may take, warm-started from the last dominant vector (which a state that
/// changes little leaves nearly dominant), and their relative convergence.
const RECHECK_STEPS: [(f64, usize); 3] = [(0.5, 10), (0.8, 3), (f64::INFINITY, 1)];
const RECHECK_ITERATIONS: usize = 100;
const RECHECK_CONVERGED: f64 = 1e-6;

/// Δt_c followed along a run whose stiffness is nonlinear (a finite-strain material): ω_max of
/// M⁻¹(K_T(u) + the contact stiffness), K_T(u) the material's tangent at the current state (a
/// compressed neo-Hookean body stiffens), the contact's as at the start (pushed in).
pub struct Tracker {
    cfl: f64,
    contact: Option<Matrix>,
    mass: Factorization,
    fixed: Vec<bool>,
    vector: Vec<f64>,
    /// Steps until the next estimate.
    due: usize,
    /// The smallest Δt_c met, and the time it was met at.
    pub least: Option<(f64, f64)>,
}

impl Tracker {
    /// A tracker for a scheme claiming `cfl`, if the stiffness is nonlinear (otherwise the
    /// estimate at the start holds for the whole run).
    pub fn new(
        ops: &Operators,
        coefs: &dyn Fn(&str) -> Option<Coef>,
        constraints: &Constraints,
        cfl: f64,
    ) -> Result<Option<Tracker>, CaseError> {
        if ops.nonlinear.is_none() {
            return Ok(None);
        }
        let (contact, ..) = contact_stiffness(ops, coefs);
        let mass = scheme_mass(ops)?;
        let (fixed, vector) = (constraints.fixed.clone(), scattered(ops.asm.size()));
        Ok(Some(Tracker { cfl, contact, mass, fixed, vector, due: 0, least: None }))
    }

    /// Whether an estimate is due after one more step.
    pub fn due(&mut self) -> bool {
        self.due = self.due.saturating_sub(1);
        self.due == 0
    }

    /// Δt_c at the displacement `u` and time `t` for steps of `dt` (the smallest so far is
    /// kept, and the next estimate is due by the margin).
    pub fn at(&mut self, ops: &Operators, u: &[f64], t: f64, dt: f64) -> Result<StableStep, CaseError> {
        let nonlinear = ops.nonlinear.as_ref().expect("a tracker follows a nonlinear stiffness");
        let mut a = ops.asm.zero_matrix();
        nonlinear.form.tangent(ops.asm, &[u], 0, t, &mut a);
        if let Some(c) = &self.contact {
            a.add_scaled(1.0, c);
        }
        let lambda =
            largest(ops, &a, &mut self.mass, &self.fixed, &mut self.vector, RECHECK_ITERATIONS, RECHECK_CONVERGED)?;
        let omega_max = lambda.max(0.0).sqrt();
        let stable = self.cfl / omega_max;
        if self.least.is_none_or(|(least, _)| stable < least) {
            self.least = Some((stable, t));
        }
        self.due = RECHECK_STEPS.iter().find(|(margin, _)| dt / stable < *margin).map_or(1, |(_, steps)| *steps);
        Ok(StableStep { cfl: self.cfl, omega_max, dt: stable, active: 0, points: 0 })
    }
}

/// Values in [−½, ½) from a fixed pseudo-random sequence (xorshift): every mode present, the
/// same on every run.
pub(crate) fn scattered(n: usize) -> Vec<f64> {
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    (0..n)
        .map(|_| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        })
        .collect()
}

/// The body translated along the contact normal at the first contact node far enough that every
/// contact node is past the obstacle by a thousandth of the body's size: a rigid motion, so
/// the elastic stress stays zero and a law that compares the stress with the gap (Nitsche's)
/// sees every point in contact.
pub(crate) fn pushed_into_obstacle(ops: &Operators, coefs: &dyn Fn(&str) -> Option<Coef>) -> Vec<f64> {
    let mesh = ops.asm.mesh();
    let d = mesh.dim();
    let n = ops.asm.size();
    let at = |coef: &Option<Coef>, x: &[f64], components: usize| -> Vec<f64> {
        match coef {
            Some(Coef::Constant(v)) => v.clone(),
            Some(Coef::Function { components, f, .. }) => {
                let mut out = vec![0.0; *components];
                f(x, 0.0, &mut out);
                out
            }
            None => vec![0.0; components],
        }
    };
    let (g, nc) = (coefs("g"), coefs("nc"));
    let Some(&first) = ops.contact_nodes.first() else { return vec![0.0; n] };
    let x0 = &mesh.coords[d * first as usize..d * (first as usize + 1)];
    let direction = at(&nc, x0, d);
    let size = (0..d)
        .map(|k| {
            let c = mesh.coords.iter().skip(k).step_by(d);
            c.clone().fold(f64::NEG_INFINITY, |a, &b| a.max(b)) - c.fold(f64::INFINITY, |a, &b| a.min(b))
        })
        .fold(0.0, f64::max);
    // The translation s along `direction` puts node x past the obstacle when
    // s (direction · nc(x)) − g(x) > 0.
    let mut s = 0.0f64;
    for &node in &ops.contact_nodes {
        let x = &mesh.coords[d * node as usize..d * (node as usize + 1)];
        let normal = at(&nc, x, d);
        let along: f64 = direction.iter().zip(&normal).map(|(a, b)| a * b).sum();
        if along > 1e-3 {
            s = s.max((at(&g, x, 1)[0] + 1e-3 * size) / along);
        }
    }
    (0..n).map(|i| s * direction.get(i % d).copied().unwrap_or(0.0)).collect()
}

/// The checks of an explicit scheme's step against its critical step, at the start and along
/// the run.
impl super::Simulation<'_> {
    /// Why the run stops after this step, if the next would step beyond the critical step of
    /// the current tangent (a nonlinear stiffness, when [`stability::Tracker::due`]).
    pub(super) fn check_current_tangent(&mut self, dt: f64, t: f64) -> Result<Option<CaseError>, CaseError> {
        let (Some(tracker), Some(initial)) = (&mut self.tracker, self.stable) else { return Ok(None) };
        let now = tracker.at(&self.ops, &self.states[0], t, dt)?;
        if dt <= now.dt || self.guard.allow_unstable_dt {
            return Ok(None);
        }
        Ok(Some(CaseError::Stiffened {
            t,
            dt,
            scheme: self.stepper.desc().name.to_string(),
            stable: now.dt,
            cfl: now.cfl,
            omega_max: now.omega_max,
            initial: initial.dt,
        }))
    }

    /// Refuses a Δt beyond an explicit scheme's critical step, unless the guard allows it.
    pub(super) fn check_stable(&self, dt: f64) -> Result<(), CaseError> {
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
                mass: self.ops.mass_choice.name().to_string(),
            });
        }
        Ok(())
    }
}
