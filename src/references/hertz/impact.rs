//! Hertz's quasi-static impact of an elastic ball of radius R on a rigid frictionless plane at
//! speed v: F = k δ^{3/2}, k = (4/3) E* √R, the ball's mass m = ρ (4/3) π R³. A problem names it
//! as `reference hertz_impact(radius = R, speed = v, copies = k, t_hit = t₀)`, where k copies of
//! the model make the ball and t₀ is the time of first contact (`forms/problems/hertz_impact.wf`).

use super::closed_form::{Impact, Material};
use super::{Sampler, profile};
use crate::references::{At, BoundReference, Reference, RunFacts};

/// `reference hertz_impact(...)`.
pub struct HertzImpact;

#[derive(Clone, Copy)]
enum Functional {
    Duration,
    PeakForce,
    Radius,
    IndentationRatio,
    WaveTimeRatio,
    Force,
    MeasuredRadius,
}

const FUNCTIONALS: &[(&str, &str, Functional)] = &[
    ("hertz_contact_duration", "Hertz's contact time 2 δ_max/v ∫₀¹ (1 − x^{5/2})^{−1/2} dx", Functional::Duration),
    ("hertz_peak_force", "Hertz's peak force k δ_max^{3/2}", Functional::PeakForce),
    ("hertz_contact_radius", "Hertz's contact radius at the peak, √(R δ_max)", Functional::Radius),
    ("indentation_ratio", "δ_max / R: the theory wants it small (≤ 2 %, say)", Functional::IndentationRatio),
    (
        "wave_time_ratio",
        "Hertz's contact time over R / c_p: the theory wants it large (≥ 10, say)",
        Functional::WaveTimeRatio,
    ),
    ("hertz_force", "Hertz's force at the row's time (m δ'' = −k δ^{3/2} from t_hit, by RK4)", Functional::Force),
    (
        "contact_radius",
        "the measured contact radius, from the measure of the zone where the pressure is positive, for the whole ball",
        Functional::MeasuredRadius,
    ),
];

const ARGS: &[(&str, &str)] = &[
    ("radius", "R, the ball's radius"),
    ("speed", "v, the impact speed"),
    ("copies", "how many copies of the model make the ball (4: a quarter ball; default 1)"),
    ("t_hit", "the time of first contact (default 0)"),
];

impl Reference for HertzImpact {
    fn name(&self) -> &'static str {
        "hertz_impact"
    }

    fn doc(&self) -> &'static str {
        "Hertz's quasi-static impact of a ball of radius R on the rigid plane at speed v: contact time, peak force, contact radius"
    }

    fn dims(&self) -> &'static [usize] {
        &[3]
    }

    fn args(&self) -> Vec<(&'static str, &'static str)> {
        ARGS.to_vec()
    }

    fn functionals(&self) -> Vec<(&'static str, &'static str)> {
        FUNCTIONALS.iter().map(|(name, doc, _)| (*name, *doc)).collect()
    }

    fn bind(&self, run: &RunFacts) -> Result<Box<dyn BoundReference>, String> {
        let (radius, speed) = (run.positive("radius", None)?, run.positive("speed", None)?);
        let copies = run.positive("copies", Some(1.0))?;
        let t_hit = run.arg_or("t_hit", 0.0);
        let material = Material::of(run)?;
        let hertz = Impact::new(radius, &material, speed);
        // The history at a twentieth of a thousandth of the contact time: far finer than a step.
        let history = Impact::force_history(radius, &material, speed, hertz.contact_duration / 20_000.0);
        Ok(Box::new(BoundImpact {
            hertz,
            radius,
            wave_speed: material.wave_speed(),
            copies,
            t_hit,
            history,
            samples: Sampler::default(),
        }))
    }
}

struct BoundImpact {
    hertz: Impact,
    radius: f64,
    wave_speed: f64,
    copies: f64,
    t_hit: f64,
    /// Hertz's force from first contact: (time, force), at a fixed step.
    history: Vec<(f64, f64)>,
    samples: Sampler,
}

impl BoundImpact {
    /// Hertz's force at time `t` (linear between the history's points; zero outside contact).
    fn force(&self, t: f64) -> f64 {
        let s = t - self.t_hit;
        let i = self.history.partition_point(|(time, _)| *time <= s);
        if s < 0.0 || i == 0 || i >= self.history.len() {
            return 0.0;
        }
        let ((t0, f0), (t1, f1)) = (self.history[i - 1], self.history[i]);
        f0 + (f1 - f0) * (s - t0) / (t1 - t0)
    }
}

impl BoundReference for BoundImpact {
    fn value(&self, which: usize, at: &At) -> f64 {
        let h = &self.hertz;
        match FUNCTIONALS.get(which).map(|f| f.2) {
            Some(Functional::Duration) => h.contact_duration,
            Some(Functional::PeakForce) => h.peak_force,
            Some(Functional::Radius) => h.contact_radius,
            Some(Functional::IndentationRatio) => h.max_indentation / self.radius,
            Some(Functional::WaveTimeRatio) => h.contact_duration * self.wave_speed / self.radius,
            Some(Functional::Force) => self.force(at.t),
            Some(Functional::MeasuredRadius) => self
                .samples
                .with(at, |s| profile::zone(3, self.copies, s, h.contact_radius).ok().map(|z| z.size))
                .flatten()
                .unwrap_or(f64::NAN),
            None => f64::NAN,
        }
    }
}
