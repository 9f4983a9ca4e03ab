//! The energy guard: after every step, what the steps made of E_aug = W(u) + ½vᵀMv + the
//! contact law's energy (W the stored energy, ½uᵀKu for a linear material) beyond the work done
//! on the body (the loads', the held dofs' reactions', a moving obstacle's, the contact law's
//! own, less what its friction took), less the allowance the scheme's energy law gives; where
//! the scheme's energy identity measures the step ([`super::ledger`]), its kept energy and the
//! loads' work with its weights. A growth beyond the tolerance, a negative potential energy, or
//! a law's own work beyond the energy from outside stops the run (docs/mathematics.md §5).

use std::borrow::Cow;

use super::Operators;
use super::ledger::Exact;
use crate::compiler::scheme::EnergyLaw;
use crate::error::CaseError;
use crate::guard::ENERGY_TOLERANCE;
use crate::runtime::fem::bound::{BoundForm, BoundFunctional};

/// The step the guard checks: the states at its end, the displacement at its start, its size
/// and its end time.
pub(super) struct Ended<'s> {
    pub(super) states: &'s [Vec<f64>],
    /// The velocity state, if the scheme has one (else the step's difference quotient serves).
    pub(super) v_index: Option<usize>,
    pub(super) before: &'s [f64],
    pub(super) h: f64,
    pub(super) t: f64,
}

impl Ended<'_> {
    fn velocity(&self) -> Cow<'_, [f64]> {
        match self.v_index {
            Some(i) => Cow::Borrowed(self.states[i].as_slice()),
            None => Cow::Owned(self.states[0].iter().zip(self.before).map(|(a, b)| (a - b) / self.h).collect()),
        }
    }
}

/// The energy guard: what the steps made of E_aug = W(u) + ½vᵀMv + the contact law's
/// `contact_energy(u)` beyond what the work of the loads brought (and the law's own work), over
/// the problem's energy scale (the largest of |E_aug(0)|, the work's magnitude so far, and the
/// kinetic energy reached). A step measured by the scheme's energy identity ([`Exact`]) counts
/// the change of its kept energy Ẽ_aug against the loads' work with the scheme's weights.
pub(super) struct EnergyWatch {
    pub(super) initial: f64,
    pub(super) u0: Vec<f64>,
    /// The largest magnitude of the work of the loads so far.
    pub(super) work: f64,
    /// The work summed step by step (midpoint rule): a load that changes with time, the held
    /// dofs' reactions, a moving obstacle's.
    pub(super) varying_work: f64,
    /// The contact law's `contact_work` so far: energy the law itself gives or takes.
    pub(super) law_work: f64,
    /// The law's `friction_work` so far: the energy its friction has taken.
    pub(super) dissipated: f64,
    /// The largest kinetic energy so far.
    pub(super) kinetic: f64,
    /// The largest growth over the scale so far (the summary's `energy_growth`).
    pub(super) growth: f64,
    /// The energy the steps made so far, net of the allowances (the sum of [`Made`]).
    pub(super) made: f64,
    /// The least `made` so far (a dissipative scheme's bound: what it lost stays lost).
    pub(super) lowest: f64,
    /// E_aug and the work of the loads (E_aug's measure) at the end of the step before.
    pub(super) last: f64,
    pub(super) external: f64,
    /// The active set after the previous step (a conserving scheme's).
    pub(super) switches: Vec<bool>,
}

/// An energy above what the guard allows.
pub(super) struct Grown {
    /// E_aug and what the guard allows it.
    pub(super) energy: f64,
    pub(super) bound: f64,
    pub(super) scale: f64,
    pub(super) cause: Cause,
}

/// What the guard saw.
pub(super) enum Cause {
    /// E_aug beyond its bound.
    Growth,
    /// W(u) + the contact energy negative beyond the tolerance.
    Negative(f64),
    /// The law's own work beyond the energy from outside.
    LawWork { work: f64, outside: f64 },
}

impl Grown {
    /// The error that stops a run whose energy the guard refused at `t`.
    pub(super) fn stop(
        self,
        t: f64,
        tolerance: f64,
        params: &str,
        law: Option<EnergyLaw>,
        by_identity: bool,
    ) -> CaseError {
        let params = params.to_string();
        match self.cause {
            Cause::Negative(potential) => CaseError::NotCoercive { t, potential, scale: self.scale, tolerance, params },
            Cause::LawWork { work, outside } => CaseError::LawWork { t, work, outside, params },
            Cause::Growth => CaseError::BlowUp {
                t,
                energy: self.energy,
                bound: self.bound,
                scale: self.scale,
                tolerance,
                law: law.map_or_else(
                    || " (the scheme claims no energy law)".to_string(),
                    |l| format!(" beyond what a {} scheme allows", l.name()),
                ) + if by_identity {
                    ", measured by its energy identity (`signorini emit SCHEME.wf --stage energy`: its kept energy Ẽ and the loads' work with its weights)"
                } else {
                    ""
                },
                params,
            },
        }
    }
}

/// One step's work besides the loads': the contact law's own (`contact_work`) and what its
/// friction took (`friction_work`).
#[derive(Clone, Copy, Default)]
pub(super) struct StepWork {
    pub(super) law: f64,
    pub(super) friction: f64,
}

impl EnergyWatch {
    pub(super) fn new(ops: &Operators, states: &[Vec<f64>], v_index: Option<usize>, t: f64) -> Self {
        let u = &states[0];
        let v = v_index.map(|i| states[i].as_slice());
        let kinetic = ops.kinetic(v);
        let initial = ops.elastic(u) + kinetic + Self::contact(ops, u, t);
        EnergyWatch {
            initial,
            u0: u.clone(),
            work: 0.0,
            varying_work: 0.0,
            law_work: 0.0,
            dissipated: 0.0,
            kinetic,
            growth: 0.0,
            made: 0.0,
            lowest: 0.0,
            last: initial,
            external: 0.0,
            // The first level's previous level is itself (as the stepper's is).
            switches: ops.contact_switches(u, u, t),
        }
    }

    /// The contact law's energy (0 for a law without `contact_energy`).
    fn contact(ops: &Operators, u: &[f64], t: f64) -> f64 {
        Self::value(&ops.contact_energy, ops, u, t)
    }

    /// A functional of u alone at `u` (0 without it).
    fn value(f: &Option<Box<dyn BoundFunctional + '_>>, ops: &Operators, u: &[f64], t: f64) -> f64 {
        f.as_ref().filter(|f| f.fields() == 1).map_or(0.0, |f| f.value(ops.asm, &[u], t))
    }

    /// Adds the work of a time-dependent load over one step: L(t_mid)·(u − u_before).
    pub(super) fn step_work(&mut self, ops: &Operators, load: &dyn BoundForm, before: &[f64], u: &[f64], t_mid: f64) {
        let mut l = vec![0.0; u.len()];
        load.residual(ops.asm, &[], t_mid, &mut l);
        self.varying_work += l.iter().zip(u.iter().zip(before)).map(|(l, (a, b))| l * (a - b)).sum::<f64>();
    }

    /// Adds the work of the held dofs' reactions over one step: the reaction at the step's
    /// midpoint, S(u_mid) − F + M (v' − v)/Δt at the held dofs (S the internal force, K u for a linear material) (exact for Crank–Nicolson; without
    /// a velocity state, its quasi-static part), times their motion.
    pub(super) fn held_work(
        &mut self,
        ops: &Operators,
        before: &[f64],
        u: &[f64],
        v: Option<(&[f64], &[f64])>,
        h: f64,
        t_mid: f64,
    ) {
        let mid: Vec<f64> = before.iter().zip(u).map(|(a, b)| 0.5 * (a + b)).collect();
        let mut reaction = ops.internal_force(&mid);
        if let Some((v0, v1)) = v {
            let dv: Vec<f64> = v1.iter().zip(v0).map(|(a, b)| (a - b) / h).collect();
            let mut inertia = vec![0.0; u.len()];
            ops.scheme_mass().mul_vec(&dv, &mut inertia);
            reaction.iter_mut().zip(&inertia).for_each(|(r, m)| *r += m);
        }
        let load = match &ops.varying_load {
            Some(form) => {
                let mut l = vec![0.0; u.len()];
                form.residual(ops.asm, &[], t_mid, &mut l);
                l
            }
            None => ops.load.clone(),
        };
        self.varying_work += ops.held.iter().map(|&i| (reaction[i] - load[i]) * (u[i] - before[i])).sum::<f64>();
    }

    /// Adds the work of an obstacle that moves (a gap that changes with time) over one step:
    /// the change of the contact energy with time alone, at the step's mid-displacement.
    pub(super) fn obstacle_work(&mut self, ops: &Operators, before: &[f64], u: &[f64], t: f64, h: f64) {
        let mid: Vec<f64> = before.iter().zip(u).map(|(a, b)| 0.5 * (a + b)).collect();
        self.varying_work +=
            Self::value(&ops.contact_energy, ops, &mid, t + h) - Self::value(&ops.contact_energy, ops, &mid, t);
    }

    /// After each accepted step: the energy, and whether what the steps made of it so far
    /// exceeds what `law` allows by more than `tolerance` × the scale.
    ///
    /// A step makes the change of E_aug less the work of the loads and the law's own work (plus
    /// what friction took, under an energy law: that energy left for good). Measured by the
    /// scheme's identity (`exact`), the change is that of Ẽ_aug and the loads' work is the
    /// identity's. Without a law, the steps may make nothing; a dissipative scheme may not
    /// make again what it lost (the bound is the least reached). A conserving scheme may also
    /// make energy on the steps where points enter or leave contact, by at most the energy of
    /// their contact stress (docs/mathematics.md §5: (1/2γ)(pⁿ)² or (1/2γ)(pⁿ⁺¹)²), which the
    /// law gives as `contact_jump`: by the identity, what the step made up to that bound; else
    /// the bound itself. The kinetic energy of this step joins the scale only once the step
    /// passes (a blow-up's own motion does not widen its bound).
    pub(super) fn check(
        &mut self,
        ops: &Operators,
        step: &Ended,
        tolerance: f64,
        law: Option<EnergyLaw>,
        taken: (StepWork, Option<Exact>),
    ) -> Option<Grown> {
        let (own, exact) = taken;
        let u = &step.states[0];
        let kinetic = ops.kinetic(Some(&step.velocity()));
        let potential = ops.elastic(u) + Self::contact(ops, u, step.t);
        let energy = potential + kinetic;
        let external = self.external_work(ops, u);
        let friction = if law.is_some() { own.friction } else { 0.0 };
        let made = match &exact {
            Some(e) => e.after() - e.before() - e.balance.loads,
            None => energy - self.last - (external - self.external),
        } - own.law
            + friction;
        let (switches, jump) = self.jump(ops, step, law);
        let allowed = match (jump, &exact) {
            (None, _) => 0.0,
            (Some(jump), Some(_)) => made.clamp(0.0, jump),
            (Some(jump), None) => jump,
        };
        let total = self.made + made - allowed;
        self.work = self.work.max(external.abs());
        let scale = self.initial.abs().max(self.work).max(self.kinetic).max(f64::MIN_POSITIVE);
        let excess = match law {
            Some(EnergyLaw::Dissipative) => total - self.lowest,
            _ => total,
        };
        let bound = energy - excess;
        // The law's own work (Nitsche θ ≠ 1) is part of the balance, but it may not drive the
        // motion: beyond the energy that came from outside (initially and by the loads), the
        // balance would hold while the motion grows without bound.
        let outside = self.initial.abs().max(self.work).max(f64::MIN_POSITIVE);
        if tolerance > 0.0 && self.law_work.abs() > outside {
            return Some(Grown { energy, bound, scale, cause: Cause::LawWork { work: self.law_work, outside } });
        }
        let growth = excess / scale;
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
        self.made = total;
        self.lowest = self.lowest.min(total);
        self.last = energy;
        self.external = external;
        None
    }

    /// A conserving scheme's bound on what a step may make where the active set changes (see
    /// [`EnergyWatch::check`]; none on other steps and under other laws), and the contact
    /// switches at the step's end.
    fn jump(&self, ops: &Operators, step: &Ended, law: Option<EnergyLaw>) -> (Vec<bool>, Option<f64>) {
        let (u, before, t, h) = (&step.states[0], step.before, step.t, step.h);
        if law != Some(EnergyLaw::Conserving) {
            return (Vec::new(), None);
        }
        let switches = ops.contact_switches(u, before, t);
        let jump = (switches != self.switches).then(|| {
            let value = |x: &[f64], at: f64| Self::value(&ops.contact_jump, ops, x, at);
            value(u, t).max(value(before, t - h))
        });
        (switches, jump)
    }

    /// The work of the loads from the start to `u`: summed step by step (a varying load's, the
    /// held dofs', a moving obstacle's), a constant load's from u(0).
    fn external_work(&self, ops: &Operators, u: &[f64]) -> f64 {
        let constant: f64 = match ops.varying_load {
            Some(_) => 0.0,
            None => ops.load.iter().zip(u.iter().zip(&self.u0)).map(|(l, (a, b))| l * (a - b)).sum(),
        };
        self.varying_work + constant
    }
}
