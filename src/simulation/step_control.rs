//! The step controller of an adaptive run: what it is asked for, Gustafsson's PI controller on
//! the steps' local errors, and the counts the summary gives; the state a checkpoint keeps.

use serde::{Deserialize, Serialize};

/// The controller's safety factor on the step its error model predicts.
const SAFETY: f64 = 0.9;
/// The most a step may shrink and grow by, against the one before.
const SHRINK: f64 = 0.2;
const GROW: f64 = 5.0;
/// Growth by less than this factor keeps the step (Hairer and Wanner's Radau5 does so too).
const KEEP: f64 = 1.05;
/// The PI controller's exponents times the local error's order k (Hairer and Wanner, vol. II,
/// §IV.2: kI = 0.3/k, kP = 0.4/k).
const INTEGRAL: f64 = 0.3;
const PROPORTIONAL: f64 = 0.4;

/// What an adaptive run is asked for.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Adaptive {
    /// The local error allowed in a step, relative to the displacement scale.
    pub tolerance: f64,
    pub dt_min: f64,
    pub dt_max: f64,
    /// A step across which the contact set becomes empty or non-empty is no longer than this.
    pub event: f64,
}

/// The step controller's state, which a checkpoint keeps: the next step, the last accepted
/// step's error and whether the last attempt was rejected (then the step may not grow).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Controller {
    pub h: f64,
    pub error: f64,
    pub rejected: bool,
}

impl Controller {
    pub fn new(h: f64) -> Self {
        Controller { h, error: 1.0, rejected: false }
    }

    /// After an accepted step of `h` with error `err` (in tolerances) of local order `k`: the
    /// PI step h·0.9·err^(−kI)·(err_prev/err)^(kP), within [0.2 h, 5 h] (no growth right after
    /// a rejection).
    pub fn accepted(&mut self, h: f64, err: f64, k: f64) {
        let err = err.max(1e-10);
        let factor = SAFETY * err.powf(-INTEGRAL / k) * (self.error / err).powf(PROPORTIONAL / k);
        let grow = if self.rejected { 1.0 } else { GROW };
        let factor = factor.clamp(SHRINK, grow);
        // A step kept as it is keeps its factorization: small growth is not worth a new one.
        self.h = if (1.0..=KEEP).contains(&factor) { h } else { h * factor };
        self.error = err.max(1e-4);
        self.rejected = false;
    }

    /// After a rejected step of `h` with error `err` > 1: the step its error model predicts,
    /// h·0.9·err^(−1/k), at least 0.2 h.
    pub fn rejected(&mut self, h: f64, err: f64, k: f64) {
        self.h = h * (SAFETY * err.powf(-1.0 / k)).clamp(SHRINK, SAFETY);
        self.rejected = true;
    }

    /// After an event is landed on: the error memory starts afresh (the solution's smoothness
    /// changed there).
    pub fn restart(&mut self) {
        self.error = 1.0;
        self.rejected = false;
    }
}

/// An adaptive run's steps, for the summary.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Steps {
    pub accepted: usize,
    /// Taken again smaller: for their error, for an event, or after a failed Newton.
    pub rejected_error: usize,
    pub rejected_event: usize,
    pub failed: usize,
    /// First contacts and releases landed on.
    pub events: usize,
    pub dt_min: f64,
    pub dt_max: f64,
}

impl Steps {
    pub fn accepted(&mut self, h: f64) {
        if self.accepted == 0 {
            (self.dt_min, self.dt_max) = (h, h);
        }
        self.accepted += 1;
        self.dt_min = self.dt_min.min(h);
        self.dt_max = self.dt_max.max(h);
    }

    pub fn rejected(&self) -> usize {
        self.rejected_error + self.rejected_event + self.failed
    }
}

/// Where an adaptive run is, which a checkpoint keeps: the time, the controller and the counts.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AdaptiveState {
    pub t: f64,
    pub controller: Controller,
    pub steps: Steps,
    /// The end of the interval a pending event was found in.
    pub bracket: Option<f64>,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On an error that scales as h^k the PI controller settles where 0.9·err^(−0.3/k) = 1,
    /// whatever the step it started from.
    #[test]
    fn the_controller_steers_to_the_tolerance() {
        let k = 3.0;
        let c = 1e3; // err = c·h^k
        let mut ctl = Controller::new(1e-3);
        let mut h = ctl.h;
        for _ in 0..60 {
            let err = c * h.powf(k);
            if err > 1.0 {
                ctl.rejected(h, err, k);
            } else {
                ctl.accepted(h, err, k);
            }
            h = ctl.h;
        }
        // Within the band where a step is kept rather than grown: the factor 0.9·err^(−0.3/k)
        // goes as h^(−0.3), so it is below KEEP down to target·KEEP^(−1/0.3).
        let target = (SAFETY.powf(k / INTEGRAL) / c).powf(1.0 / k);
        let lowest = target * KEEP.powf(-1.0 / INTEGRAL);
        assert!(h <= target * (1.0 + 1e-9) && h >= lowest * (1.0 - 1e-9), "h = {h}, in [{lowest}, {target}]");
    }

    #[test]
    fn a_rejection_shrinks_by_the_error_model_and_forbids_growth() {
        let mut ctl = Controller::new(1.0);
        ctl.rejected(1.0, 8.0, 3.0);
        assert!((ctl.h - 0.45).abs() < 1e-12);
        ctl.accepted(0.45, 1e-6, 3.0);
        assert_eq!(ctl.h, 0.45);
        ctl.accepted(0.45, 1e-6, 3.0);
        assert_eq!(ctl.h, 0.45 * GROW);
        let mut steady = Controller { h: 1.0, error: 0.3, rejected: false };
        steady.accepted(1.0, 0.3, 3.0);
        assert_eq!(steady.h, 1.0, "a growth below {KEEP} keeps the step");
    }
}
