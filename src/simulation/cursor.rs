//! Where a fixed-step run is, and its step cuts: after a failed Newton the step is taken again
//! with Δt halved, and Δt doubles back once the run is on the nominal time levels again.

use super::Outcome;
use super::energy_guard::EnergyWatch;
use crate::error::CaseError;
use crate::runtime::time::stepper::StepError;

/// Where a run is: the nominal steps done before it (from a checkpoint), the steps accepted,
/// how many times Δt is halved now, and the steps accepted since it last changed.
#[derive(Clone, Copy, Default)]
pub(super) struct Cursor {
    pub(super) first: usize,
    pub(super) accepted: usize,
    pub(super) level: usize,
    pub(super) streak: usize,
}

impl Cursor {
    /// After a failed step: None to retry it with Δt halved, or why the run stops (a law whose
    /// derivative is 0/0 is so at any Δt: no cut helps; nor one beyond `max_cuts`).
    pub(super) fn cut(
        &mut self,
        e: StepError,
        t: f64,
        h: f64,
        max_cuts: usize,
        outcome: &mut Outcome,
    ) -> Option<CaseError> {
        if let StepError::NonFiniteTangent { .. } = e {
            return Some(CaseError::Failed { t, cause: e.to_string() });
        }
        if self.level < max_cuts {
            self.level += 1;
            self.streak = 0;
            outcome.cuts += 1;
            tracing::warn!(t, dt = h / 2.0, "step failed ({e}); retrying with Δt halved");
            return None;
        }
        Some(CaseError::Stopped { t, cuts: self.level, dt: h, cause: e.to_string(), history: history(&e) })
    }

    /// After an accepted step of `units`: Δt doubles back after two accepted steps that end on
    /// a multiple of the doubled size, so that the run returns to the nominal time levels.
    pub(super) fn accept(&mut self, done: u64, units: u64) {
        self.streak += 1;
        if self.level > 0 && self.streak >= 2 && done.is_multiple_of(2 * units) {
            self.level -= 1;
            self.streak = 0;
        }
    }

    /// The driver's part of a checkpoint after `steps_done` nominal steps.
    pub(super) fn driver_state(
        &self,
        steps_done: usize,
        cuts: usize,
        energy: &EnergyWatch,
        states: &[Vec<f64>],
        previous: Option<&[f64]>,
        periodic: bool,
    ) -> crate::checkpoint::DriverState {
        crate::checkpoint::DriverState {
            steps_done,
            accepted: self.accepted,
            level: self.level,
            streak: self.streak,
            cuts,
            energy_initial: energy.initial,
            energy_work: energy.work,
            energy_varying_work: energy.varying_work,
            energy_law_work: energy.law_work,
            energy_dissipated: energy.dissipated,
            energy_u0: energy.u0.clone(),
            energy_kinetic: energy.kinetic,
            energy_growth: energy.growth,
            energy_made: energy.made,
            energy_lowest: energy.lowest,
            energy_last: energy.last,
            energy_external: energy.external,
            energy_switches: energy.switches.clone(),
            states: states.iter().map(Vec::as_slice).chain(previous).map(<[f64]>::to_vec).collect(),
            periodic,
            adaptive: None,
        }
    }
}

/// Newton's iterations of the last attempt, as a line of the stop's message (none when the step
/// failed otherwise: an inverted cell).
fn history(e: &crate::runtime::time::stepper::StepError) -> String {
    use crate::runtime::time::stepper::StepError;
    let StepError::Newton { source, .. } = e else { return String::new() };
    format!("  Newton: {}\n", source.report().describe())
}
