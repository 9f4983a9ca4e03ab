//! The energy ledger of a run: each step's balance from the scheme's derived energy identity
//! (docs/mathematics.md §5), Ẽ' − Ẽ = W − D, evaluated with the run's own matrices and bound
//! slots at the step's free variables (the states at its start and its stages' unknowns). The
//! energy guard measures with it what a step made: the change of Ẽ_aug = Ẽ + the contact law's
//! energy (+ ½uᵀKu where the identity applies K as an opaque slot) less the work of the loads
//! with the scheme's own weights, so that neither the difference between Ẽ and E (the central
//! scheme's ¼·½Δt²‖a‖²_M) nor a quadrature of the loads' work counts as growth.

use crate::compiler::scheme::energy::evaluate::{self, Balance, Plan};
use crate::compiler::scheme::energy::window::Free;
use crate::driver::SchemeIdentity;
use std::sync::Mutex;

use crate::runtime::time::stepper::Stepper;

use super::Operators;

/// A step's energies by the identity: its kept energies and the potential energies the guard
/// adds to them, at the step's start and end, the loads' work and the dissipation.
#[derive(Clone, Copy, Debug)]
pub(super) struct Exact {
    pub(super) balance: Balance,
    pub(super) potential_before: f64,
    pub(super) potential_after: f64,
}

impl Exact {
    /// Ẽ_aug at the step's start and end.
    pub(super) fn before(&self) -> f64 {
        self.balance.kept_before + self.potential_before
    }

    pub(super) fn after(&self) -> f64 {
        self.balance.kept_after + self.potential_after
    }
}

/// The scheme's identity, for a run it measures.
pub(super) struct Ledger {
    scheme: SchemeIdentity,
    /// The loads applied last, and the last slot applied to fields ([`Kept`]).
    kept: Mutex<Kept>,
    /// The last step's size, and Ẽ and the potential energies at its end: the next step's start
    /// at the same size (Ẽ reads dt).
    end: Mutex<Option<(f64, f64, f64)>>,
    /// The identity's coefficients at the params and the last step's size.
    plan: Mutex<Option<(f64, Plan)>>,
}

/// The loads applied last (slots of no field), by slot and time (none: the same at any time):
/// a step reads a load where the step before read it, or at every step alike; and the last
/// slot applied to fields, with its time and fields.
#[derive(Default)]
struct Kept {
    loads: Vec<(String, Option<u64>, Vec<f64>)>,
    fields: Option<SlotValue>,
}

/// A slot applied to fields: its name, its time's bits, the fields and its value.
type SlotValue = (String, u64, Vec<Vec<f64>>, Vec<f64>);

impl Ledger {
    /// The ledger of a run with this identity, where the identity and the law's energy make the
    /// whole balance of each step: a linear material (K is the stiffness), no held dofs that move
    /// (their reactions' work is no slot's), no obstacle that moves, no law that reads the level
    /// before, one process holding the whole mesh; and an identity over the step's own levels
    /// that keeps K's energy there. Where it keeps K's energy with the step before's too (HHT's
    /// ½‖u − u⁻‖²_K, generalized-α's weighted levels), the contact slot has no such term and
    /// Φ(u) is not its counterpart: what the steps make would oscillate with the contact force.
    /// None otherwise: the guard then measures E_aug against the work as before.
    pub(super) fn new(scheme: Option<SchemeIdentity>, ops: &Operators, stepper: &Stepper) -> Option<Ledger> {
        let scheme = scheme?;
        let own_levels = scheme.identity.free().iter().all(|f| matches!(f, Free::State(_) | Free::Unknown(_)))
            && scheme.identity.weight.is_none()
            && scheme.identity.step_before.is_none();
        let applies = own_levels
            && ops.nonlinear.is_none()
            && ops.held.is_empty()
            && !ops.probe.as_ref().is_some_and(|p| p.time_dependent())
            && !stepper.reads_previous()
            && ops.asm.pattern().ownership().is_none();
        applies.then_some(Ledger { scheme, kept: Mutex::default(), end: Mutex::default(), plan: Mutex::default() })
    }

    /// The balance of the step of size `h` from `t` that started at `start`, solved `unknowns`
    /// (one per stage) and ended at `end` (the states).
    pub(super) fn balance(
        &self,
        run: (&Operators, &Stepper),
        start: &[Vec<f64>],
        unknowns: &[Vec<f64>],
        end: &[Vec<f64>],
        t: f64,
        h: f64,
    ) -> Option<Exact> {
        let (ops, stepper) = run;
        let x: Option<Vec<&[f64]>> = self
            .scheme
            .identity
            .free()
            .iter()
            .map(|f| match *f {
                Free::State(i) => start.get(i).map(Vec::as_slice),
                Free::Unknown(k) => unknowns.get(k).map(Vec::as_slice),
                Free::Previous(_) | Free::PreviousUnknown(_) => None,
            })
            .collect();
        let x = x?;
        let SchemeIdentity { ir, identity, params } = &self.scheme;
        let applied = Applied { ops, stepper, kept: &self.kept };
        // ½uᵀKu where the identity keeps no elastic energy of its own (K an opaque slot, whose
        // work is then in W), and the law's energy.
        let potential = |u: &[f64], at: f64| {
            let elastic = if identity.elastic { 0.0 } else { ops.elastic(u) };
            elastic
                + ops.contact_energy.as_ref().filter(|f| f.fields() == 1).map_or(0.0, |f| f.value(ops.asm, &[u], at))
        };
        // Ẽ and the potential at the step's start are where the step before ended, at the same
        // size (Ẽ reads dt); Ẽ at its end, of the states the run holds (the observers read the
        // same energies of them).
        let mut last = self.end.lock().unwrap_or_else(|e| e.into_inner());
        let known = last.take().filter(|(size, _, _)| *size == h);
        let kept_before = match known {
            Some((_, kept, _)) => kept,
            None => identity.kept_at(ir, &applied, params, h, start)?,
        };
        let kept_after = identity.kept_at(ir, &applied, params, h, end)?;
        let mut plan = self.plan.lock().unwrap_or_else(|e| e.into_inner());
        if plan.as_ref().is_none_or(|(size, _)| *size != h) {
            *plan = Some((h, identity.plan(ir, params, h)));
        }
        let ends: Vec<&[f64]> = end.iter().map(Vec::as_slice).collect();
        let (work, loads, dissipation) = plan.as_ref().map(|(_, p)| p.step(&applied, t, &x, Some(&ends)))?;
        let balance = Balance { kept_before, kept_after, work, loads, dissipation };
        let potential_before = known.map_or_else(|| potential(&start[0], t), |(_, _, p)| p);
        let potential_after = potential(&end[0], t + h);
        *last = Some((h, kept_after, potential_after));
        Some(Exact { balance, potential_before, potential_after })
    }
}

/// The run's matrices (its stiffness and the mass it steps with, through their lower halves)
/// and its stepper's bound slots.
struct Applied<'a, 'm> {
    ops: &'a Operators<'m>,
    stepper: &'a Stepper<'m>,
    kept: &'a Mutex<Kept>,
}

impl Applied<'_, '_> {
    fn product(a: &crate::runtime::linalg::Matrix, x: &[f64]) -> Vec<f64> {
        let mut y = vec![0.0; x.len()];
        a.mul_vec(x, &mut y);
        y
    }
}

impl evaluate::Operators for Applied<'_, '_> {
    fn mass(&self, x: &[f64]) -> Vec<f64> {
        Self::product(self.ops.scheme_mass(), x)
    }

    fn stiffness(&self, x: &[f64]) -> Vec<f64> {
        Self::product(&self.ops.stiffness, x)
    }

    fn mass_quad(&self, x: &[f64]) -> f64 {
        self.ops.energies.quad(1, self.ops.scheme_mass(), x)
    }

    fn stiffness_quad(&self, x: &[f64]) -> f64 {
        self.ops.energies.quad(0, &self.ops.stiffness, x)
    }

    fn apply(&self, slot: &str, args: &[Vec<f64>], t: f64) -> Vec<f64> {
        let fields: Vec<&[f64]> = args.iter().map(Vec::as_slice).collect();
        let mut out = vec![0.0; self.ops.asm.size()];
        self.stepper.apply_into(slot, &fields, t, &mut out);
        out
    }

    fn apply_dots(&self, slot: &str, args: &[&[f64]], t: f64, with: &[&[f64]]) -> Vec<f64> {
        let dots = |f: &[f64]| with.iter().map(|w| w.iter().zip(f).map(|(a, b)| a * b).sum()).collect();
        let mut kept = self.kept.lock().unwrap_or_else(|e| e.into_inner());
        if !args.is_empty() {
            // A slot read at a step's end is read again at the next one's start, at the same
            // states (the run's) and time.
            let same = |(s, at, fields, _): &SlotValue| {
                s == slot && *at == t.to_bits() && fields.iter().map(Vec::as_slice).eq(args.iter().copied())
            };
            if let Some((.., value)) = kept.fields.as_ref().filter(|k| same(k)) {
                return dots(value);
            }
            // Every slot the scheme applies is bound (the stepper checked it when it was built).
            let mut value = vec![0.0; self.ops.asm.size()];
            self.stepper.apply_into(slot, args, t, &mut value);
            let out = dots(&value);
            kept.fields = Some((slot.to_string(), t.to_bits(), args.iter().map(|a| a.to_vec()).collect(), value));
            return out;
        }
        let time = self.stepper.time_dependent(slot).unwrap_or(true).then_some(t.to_bits());
        let loads = &mut kept.loads;
        if let Some((_, _, value)) = loads.iter().find(|(s, at, _)| s == slot && *at == time) {
            return dots(value);
        }
        let mut value = vec![0.0; self.ops.asm.size()];
        self.stepper.apply_into(slot, &[], t, &mut value);
        let out = dots(&value);
        // A load that changes with time is read at the step's levels: two times of each slot.
        if loads.iter().filter(|(s, _, _)| s == slot).count() >= 2
            && let Some(oldest) = loads.iter().position(|(s, _, _)| s == slot)
        {
            loads.remove(oldest);
        }
        loads.push((slot.to_string(), time, value));
        out
    }
}
