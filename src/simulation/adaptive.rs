//! Adaptive time steps: each step's local error is the scheme's own `estimate` (a combination
//! of the step's levels its file declares), measured against the tolerance in the largest
//! displacement's units; a PI controller (Gustafsson 1991) chooses the next step from it, a step
//! whose error exceeds the tolerance is taken again smaller, and a step across which the contact
//! set becomes empty or non-empty (a first contact, a release) is bisected until it is no longer
//! than the event tolerance, so that the run lands on the event. docs/mathematics.md §5 (adaptive steps).

use super::energy_guard::EnergyWatch;
pub use super::step_control::{Adaptive, AdaptiveState, Controller, Steps};
use super::{Cursor, Outcome, Simulation, Start, Taken, Walk, Watch};
use crate::checkpoint::Control;
use crate::error::CaseError;
use crate::runtime::linalg::ranks;
use crate::runtime::time::stepper::StepError;

/// The run's interval.
#[derive(Clone, Copy)]
pub struct Interval {
    pub t0: f64,
    pub t_end: f64,
    /// The first step tried.
    pub dt: f64,
}

impl Simulation<'_> {
    /// Runs from `span.t0` to `span.t_end` with steps the scheme's estimate chooses (see the
    /// module's doc), showing every accepted step to `watch` as [`Simulation::run`] does: the
    /// energy guard, observers and checkpoints see accepted steps only.
    pub fn run_adaptive(
        &mut self,
        span: Interval,
        adaptive: Adaptive,
        progress: bool,
        control: &mut Control,
        watch: Watch,
    ) -> Result<Outcome, CaseError> {
        if !self.stepper.estimate_steps() {
            return Err(CaseError::Option(format!(
                "--adaptive: scheme `{}` declares no `estimate` (its local error as a combination of its levels, e.g. `estimate dt^2*(beta - 1/6)*(a' - a)` for Newmark); the library's {} declare one",
                self.stepper.desc().name,
                crate::driver::estimating_schemes().join(", ")
            )));
        }
        // An explicit scheme's step is also bounded by its critical step.
        let dt_max = self.stable.map_or(adaptive.dt_max, |s| adaptive.dt_max.min(s.dt));
        if dt_max < adaptive.dt_min {
            return Err(CaseError::Option(format!(
                "--adaptive: scheme `{}` is stable up to Δt_c = {dt_max:.4e}, below --dt-min {}",
                self.stepper.desc().name,
                adaptive.dt_min
            )));
        }
        let adaptive = Adaptive { dt_max, ..adaptive };
        let k = self.order + 1.0;
        let floor = self.ops.asm.mesh().smallest_cell();
        let intermediate = self.intermediate_stages();
        let mut outcome = Outcome::new(0);
        let mut bar = crate::progress::Progress::new(PROGRESS_TICKS, progress);
        let mut energy = EnergyWatch::new(&self.ops, &self.states, self.v_index, span.t0);
        let mut at = Cursor::default();
        let mut state = AdaptiveState {
            t: span.t0,
            controller: Controller::new(span.dt.clamp(adaptive.dt_min, adaptive.dt_max)),
            steps: Steps::default(),
            bracket: None,
        };
        let crash_at = super::crash_after_step();
        if let Some((saved, _)) = &control.resume {
            (at, energy) = self.resume(saved, &mut outcome)?;
            state = saved.adaptive.clone().ok_or_else(|| {
                CaseError::Option("the checkpoint is of a run with fixed steps: resume it without --adaptive".into())
            })?;
        }
        // The previous level, as the step that ended here saw its end (a law's `prev`).
        let previous = self.stepper.previous().map(<[f64]>::to_vec);
        let mut touching = self.touching(&self.states[0], state.t, previous.as_deref())?;
        let length = span.t_end - span.t0;
        while span.t_end - state.t > 1e-12 * length {
            bar.tick(((state.t - span.t0) / length * PROGRESS_TICKS as f64) as usize);
            let t = state.t;
            let h = next_step(&state, &adaptive, span.t_end);
            let (result, start, seen, clock) = self.attempt(watch.stage, &intermediate, t, h, 1);
            let report = match result {
                Ok(report) => report,
                Err(e) => {
                    if let StepError::NonFiniteTangent { .. } = e {
                        outcome.stopped = Some(CaseError::Failed { t, cause: e.to_string() });
                        break;
                    }
                    state.steps.failed += 1;
                    state.controller.h = h * AFTER_FAILURE;
                    state.controller.rejected = true;
                    tracing::warn!(t, dt = state.controller.h, "step failed ({e}); retrying with a smaller Δt");
                    if let Some(stop) = too_small(t, state.controller.h, &adaptive, || format!("Newton failed: {e}")) {
                        outcome.stopped = Some(stop);
                        break;
                    }
                    continue;
                }
            };
            let err = self.local_error(&start, adaptive.tolerance, floor)?;
            let after = self.touching(&self.states[0], t + h, Some(&start.before))?;
            let event = after.any != touching.any;
            let changed = after.switches != touching.switches;
            // A step across an event is bisected down to the event tolerance; one across which
            // the contact set changes is accepted at that size whatever its estimate, which
            // assumes a smooth solution.
            let landing = adaptive.event.max(adaptive.dt_min);
            let verdict = if event && h > landing {
                Verdict::Event
            } else if err > 1.0 && !(changed && h <= landing) {
                Verdict::Error
            } else {
                Verdict::Accept
            };
            if verdict != Verdict::Accept {
                if let Some(saved) = &start.saved {
                    self.states.clone_from_slice(saved);
                }
                match verdict {
                    Verdict::Event => {
                        state.steps.rejected_event += 1;
                        state.bracket = Some(t + h);
                        state.controller.h = (0.5 * h).max(adaptive.dt_min);
                    }
                    _ => {
                        state.steps.rejected_error += 1;
                        state.controller.rejected(h, err, k);
                    }
                }
                let cause = || format!("the local error estimate is {} × the tolerance", crate::numbers::readable(err));
                if let Some(stop) = too_small(t, state.controller.h, &adaptive, cause) {
                    outcome.stopped = Some(stop);
                    break;
                }
                continue;
            }
            outcome.step_seconds.push(clock.elapsed().as_secs_f64());
            at.accepted += 1;
            let t_end = if span.t_end - (t + h) <= 1e-12 * length { span.t_end } else { t + h };
            let index = at.accepted - 1;
            let taken = Taken { k: index, whole: true, t, h, t_end, start, seen, report: &report };
            // The state after this step, which its checkpoint (if one is due) keeps.
            let mut next = state.clone();
            next.t = t_end;
            next.steps.accepted(h);
            if event {
                next.steps.events += 1;
                next.bracket = None;
                next.controller.restart();
            }
            next.controller.accepted(h, err, k);
            if next.bracket.is_some_and(|b| b <= t_end) {
                next.bracket = None;
            }
            let walk = (&mut at, &mut energy, &mut outcome, &mut *control, crash_at);
            let stop = self.accept_adaptive(walk, &next, taken, watch.step)?;
            state = next;
            touching = after;
            if let Some(stop) = stop {
                outcome.stopped = Some(stop);
                break;
            }
        }
        bar.finish();
        outcome.adaptive = Some(state.steps);
        Ok(outcome)
    }

    /// The accepted step through [`Simulation::accept`], `next` the run's state after it (for
    /// the checkpoint it may write).
    fn accept_adaptive(
        &mut self,
        (at, energy, outcome, control, crash_at): Walked,
        next: &AdaptiveState,
        taken: Taken,
        on_step: &mut super::OnStep,
    ) -> Result<Option<CaseError>, CaseError> {
        let mut walk = Walk { at, energy, outcome, control, crash_at, adaptive: Some(next.clone()) };
        self.accept(&mut walk, usize::MAX, taken, on_step)
    }

    /// The step's local error in tolerances: the estimate's root mean square over tolerance ×
    /// the displacement scale (the larger root mean square of u at the step's ends, and at least
    /// the smallest cell's size), the largest over the processes.
    fn local_error(&self, start: &Start, tolerance: f64, floor: f64) -> Result<f64, CaseError> {
        let e = self.stepper.estimate().unwrap_or(&[]);
        let rms = |x: &[f64]| (x.iter().map(|v| v * v).sum::<f64>() / x.len().max(1) as f64).sqrt();
        let scale = rms(&start.before).max(rms(&self.states[0])).max(floor);
        let err = rms(e) / (tolerance * scale);
        let err = if err.is_finite() { err } else { f64::INFINITY };
        ranks::max(err).map_err(|e| CaseError::Option(format!("MPI: {e}")))
    }

    /// The contact set at u (at time t, `previous` the level before): its switches, and whether
    /// any point is in contact on any process.
    fn touching(&self, u: &[f64], t: f64, previous: Option<&[f64]>) -> Result<Touching, CaseError> {
        let switches = self.ops.contact_switches(u, previous.unwrap_or(u), t);
        let any = ranks::any(switches.iter().any(|&s| s)).map_err(|e| CaseError::Option(format!("MPI: {e}")))?;
        Ok(Touching { switches, any })
    }
}

/// What an accepted step moves on (as [`Walk`] without the adaptive state).
type Walked<'w> = (&'w mut Cursor, &'w mut EnergyWatch, &'w mut Outcome, &'w mut Control, Option<usize>);

/// A step that fails in Newton is taken again this much smaller.
const AFTER_FAILURE: f64 = 0.25;

/// How many ticks the progress bar shows over the run's interval.
const PROGRESS_TICKS: usize = 1000;

#[derive(Clone, Copy, PartialEq, Eq)]
enum Verdict {
    Accept,
    Error,
    Event,
}

/// The contact set at the end of a step.
struct Touching {
    switches: Vec<bool>,
    any: bool,
}

/// Why the run stops at t, when the step the controller asks for, h, is below the minimum.
fn too_small(t: f64, h: f64, adaptive: &Adaptive, cause: impl FnOnce() -> String) -> Option<CaseError> {
    (h < adaptive.dt_min).then(|| CaseError::StepTooSmall { t, dt: h, dt_min: adaptive.dt_min, cause: cause() })
}

/// The next step to try: the controller's, within the bounds, not beyond a pending event's
/// bracket, and landing on the end (stretched to it rather than leaving a sliver).
fn next_step(state: &AdaptiveState, adaptive: &Adaptive, t_end: f64) -> f64 {
    let t = state.t;
    let mut h = state.controller.h.clamp(adaptive.dt_min, adaptive.dt_max);
    if let Some(b) = state.bracket {
        h = h.min(b - t);
    }
    let left = t_end - t;
    if h >= left || left - h < 0.01 * h { left } else { h }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_last_step_lands_on_the_end() {
        let adaptive = Adaptive { tolerance: 1e-3, dt_min: 1e-9, dt_max: 1.0, event: 1e-3 };
        let state = |t: f64, h: f64| AdaptiveState {
            t,
            controller: Controller::new(h),
            steps: Steps::default(),
            bracket: None,
        };
        assert_eq!(next_step(&state(0.95, 0.1), &adaptive, 1.0), 1.0 - 0.95);
        assert_eq!(next_step(&state(0.0, 0.5), &adaptive, 1.0), 0.5);
        assert_eq!(next_step(&state(0.0, 0.999), &adaptive, 1.0), 1.0);
        let bracketed = AdaptiveState { bracket: Some(0.2), ..state(0.1, 0.5) };
        assert!((next_step(&bracketed, &adaptive, 1.0) - 0.1).abs() < 1e-15);
    }
}
