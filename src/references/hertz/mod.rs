//! Hertz's contact of an elastic cylinder (2D, plane strain, per unit length) or ball (3D) of
//! radius R pressed onto a rigid frictionless plane by a force F: the half-width (radius) a of
//! the contact zone, the peak pressure p₀ and the profile p₀ √(1 − r²/a²), against a run's
//! contact pressure (the contact law's `contact_pressure` integrand, sampled on the contact
//! boundary). A problem names it as `reference hertz(radius = R, force = F, copies = k)`, where
//! k copies of the model make the body (a half cylinder, a quarter ball), and the first contact
//! point is the origin (`forms/problems/hertz_cylinder.wf`, `hertz_ball.wf`).

pub mod closed_form;
pub mod impact;
pub mod profile;

use std::cell::RefCell;
use std::path::Path;

use super::{At, BoundReference, Reference, RunFacts};

/// `reference hertz(...)`.
pub struct Hertz;

#[derive(Clone, Copy)]
enum Functional {
    Size,
    PeakPressure,
    MeasuredSize,
    MeasuredPeakPressure,
    PressureError,
    ContactCellSize,
}

const FUNCTIONALS: &[(&str, &str, Functional)] = &[
    ("hertz_size", "Hertz's half-width (2D) or contact radius (3D) a under the force F", Functional::Size),
    ("hertz_peak_pressure", "Hertz's peak pressure p₀ under F", Functional::PeakPressure),
    (
        "contact_size",
        "the measured a, from the measure of the contact zone (where the pressure is positive) projected onto the plane, for the whole body",
        Functional::MeasuredSize,
    ),
    (
        "contact_peak_pressure",
        "the measured p₀: Σ w p_h / Σ w √(1 − r²/a²) over the samples within a/4 of the first contact point",
        Functional::MeasuredPeakPressure,
    ),
    (
        "pressure_error",
        "‖p_h − p‖ / ‖p‖ in L² on the contact boundary projected onto the plane",
        Functional::PressureError,
    ),
    ("contact_cell_size", "the smallest diameter of the cells with a facet on Γ_C", Functional::ContactCellSize),
];

const ARGS: &[(&str, &str)] = &[
    ("radius", "R, the body's radius"),
    ("force", "F, the load on the whole body (per unit length in 2D)"),
    ("copies", "how many copies of the model make the body (2: a half cylinder, 4: a quarter ball; default 1)"),
    (
        "modulus",
        "E*, the contact modulus (default E/(1 − ν²), the run's material on the rigid plane; two bodies: 1/E* = (1 − ν₁²)/E₁ + (1 − ν₂²)/E₂, with 1/R = 1/R₁ + 1/R₂ for `radius`)",
    ),
];

impl Reference for Hertz {
    fn name(&self) -> &'static str {
        "hertz"
    }

    fn doc(&self) -> &'static str {
        "Hertz's contact of a cylinder (2D) or ball (3D) of radius R on the rigid plane under a force F: a, p₀ and the pressure profile"
    }

    fn dims(&self) -> &'static [usize] {
        &[2, 3]
    }

    fn args(&self) -> Vec<(&'static str, &'static str)> {
        ARGS.to_vec()
    }

    fn functionals(&self) -> Vec<(&'static str, &'static str)> {
        FUNCTIONALS.iter().map(|(name, doc, _)| (*name, *doc)).collect()
    }

    fn bind(&self, run: &RunFacts) -> Result<Box<dyn BoundReference>, String> {
        let (radius, force) = (run.positive("radius", None)?, run.positive("force", None)?);
        let copies = run.positive("copies", Some(1.0))?;
        let modulus = match run.args.iter().any(|(n, _)| n == "modulus") {
            true => run.positive("modulus", None)?,
            false => closed_form::Material::of(run)?.contact_modulus(),
        };
        let dim = run.mesh.dim();
        let (a, p0) = closed_form::static_contact(dim, radius, modulus, force);
        let cell_size =
            run.contact.iter().map(|f| run.mesh.cell_diameter(f.cell as usize)).fold(f64::INFINITY, f64::min);
        Ok(Box::new(BoundHertz { dim, copies, a, p0, cell_size, samples: Sampler::default() }))
    }
}

/// Hertz's figures for one run.
struct BoundHertz {
    dim: usize,
    copies: f64,
    a: f64,
    p0: f64,
    cell_size: f64,
    samples: Sampler,
}

/// The contact pressure's samples of the last state asked for: a row asks for several figures
/// of one state.
#[derive(Default)]
pub(super) struct Sampler {
    last: RefCell<Option<Sampled>>,
}

/// (A state's time bits, its displacement's address), its samples.
type Sampled = ((u64, usize), Vec<profile::Sample>);

impl Sampler {
    /// `f` of the samples of the state `at` (none if the contact law has no `contact_pressure`).
    pub(super) fn with<R>(&self, at: &At, f: impl FnOnce(&[profile::Sample]) -> R) -> Option<R> {
        let pressure = at.pressure?;
        let key = (at.t.to_bits(), at.u.as_ptr() as usize);
        let mut last = self.last.borrow_mut();
        if last.as_ref().is_none_or(|(k, _)| *k != key) {
            *last = Some((key, profile::sample(at.asm, pressure, at.u)));
        }
        last.as_ref().map(|(_, s)| f(s))
    }
}

impl BoundReference for BoundHertz {
    fn value(&self, which: usize, at: &At) -> f64 {
        let zone = |s: &[profile::Sample]| profile::zone(self.dim, self.copies, s, self.a).ok();
        match FUNCTIONALS.get(which).map(|f| f.2) {
            Some(Functional::Size) => Some(self.a),
            Some(Functional::PeakPressure) => Some(self.p0),
            Some(Functional::MeasuredSize) => self.samples.with(at, |s| zone(s).map(|z| z.size)).flatten(),
            Some(Functional::MeasuredPeakPressure) => {
                self.samples.with(at, |s| zone(s).map(|z| z.peak_pressure)).flatten()
            }
            Some(Functional::PressureError) => self
                .samples
                .with(at, |s| profile::l2_error(s, |r| closed_form::pressure(self.a, self.p0, r)))
                .filter(|e| e.is_finite()),
            Some(Functional::ContactCellSize) => Some(self.cell_size),
            None => None,
        }
        .unwrap_or(f64::NAN)
    }

    /// `profile.png`: the measured pressure (ring averages) against Hertz's.
    fn write(&self, dir: &Path, at: &At) -> std::io::Result<()> {
        use crate::plot::Curve;
        let (a, p0) = (self.a, self.p0);
        let Some(measured) = self.samples.with(at, |s| profile::binned(s, 1.5 * a, 60)) else { return Ok(()) };
        let hertz: Vec<(f64, f64)> =
            (0..=200).map(|i| 1.5 * a * i as f64 / 200.0).map(|r| (r, closed_form::pressure(a, p0, r))).collect();
        let axis = if self.dim == 2 {
            "x (distance from the first contact point)"
        } else {
            "r (distance from the first contact point)"
        };
        crate::plot::panels(
            &dir.join("profile.png"),
            axis,
            &[(
                "contact pressure",
                "p",
                vec![
                    Curve { label: "computed (ring averages)", points: measured, dashed: false },
                    Curve { label: "Hertz p0 √(1 − r²/a²)", points: hertz, dashed: true },
                ],
            )],
        )
        .map_err(std::io::Error::other)
    }
}
