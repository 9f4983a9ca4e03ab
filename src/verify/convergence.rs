//! Convergence of the bouncing disc toward a fine reference, through the first impact
//! (t ≤ 12; first contact at √40 ≈ 6.32): under Δt refinement on the built-in h = 1 mesh, for
//! every scheme, and under h refinement at fixed Δt with the default scheme. Contact makes the
//! solution non-smooth in time, so the observed orders are measurements, not the schemes'
//! smooth-problem orders.

use serde::Serialize;

use crate::cases::disc;
use crate::driver::Methods;
use crate::error::CaseError;
use crate::problem::run::Options;

const T_END: f64 = 12.0;
/// Δt refinement: the steps, and the reference's.
pub const DT_STEPS: [f64; 3] = [0.04, 0.02, 0.01];
const DT_REFERENCE: f64 = 0.0025;
/// h refinement (built-in curved P2 meshes) at this Δt, and the reference's h.
pub const H_STEPS: [f64; 3] = [4.0, 2.0, 1.0];
const H_REFERENCE: f64 = 0.5;
const H_DT: f64 = 0.01;

/// Errors of one run against the reference, sampled at the run's own times.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Errors {
    /// Δt or h.
    pub step: f64,
    /// max_t |ū_y − ū_y,ref| / max_t |ū_y,ref| (centre of mass).
    pub uy_mean: f64,
    /// ‖f_y − f_y,ref‖ / ‖f_y,ref‖ over the sampled times (the contact force, with its
    /// oscillations).
    pub fy_contact: f64,
    /// max_t |v̄_y − v̄_y,ref| / max |v̄_y,ref|: the centre of mass's velocity, which the
    /// contact impulse changes.
    pub vy_mean: f64,
}

fn errors(step: f64, run: &[disc::Row], reference: &[disc::Row]) -> Errors {
    // The reference at the run's times (its step divides the run's).
    let stride = ((run[1].t - run[0].t) / (reference[1].t - reference[0].t)).round() as usize;
    let pairs: Vec<(&disc::Row, &disc::Row)> = run.iter().zip(reference.iter().step_by(stride.max(1))).collect();
    let max_ref = pairs.iter().map(|(_, r)| r.u_vertical_mean.abs()).fold(0.0, f64::max);
    let uy = pairs.iter().map(|(a, r)| (a.u_vertical_mean - r.u_vertical_mean).abs()).fold(0.0, f64::max) / max_ref;
    let num: f64 = pairs.iter().map(|(a, r)| (a.f_vertical_contact - r.f_vertical_contact).powi(2)).sum();
    let den: f64 = pairs.iter().map(|(_, r)| r.f_vertical_contact.powi(2)).sum();
    let max_v = pairs.iter().map(|(_, r)| r.v_vertical_mean.abs()).fold(0.0, f64::max);
    let vy = pairs.iter().map(|(a, r)| (a.v_vertical_mean - r.v_vertical_mean).abs()).fold(0.0, f64::max) / max_v;
    Errors { step, uy_mean: uy, fy_contact: (num / den).sqrt(), vy_mean: vy }
}

/// One refinement study.
#[derive(Clone, Debug, Serialize)]
pub struct Study {
    pub scheme: String,
    /// The errors per run (empty when a run failed; `failure` says why).
    pub errors: Vec<Errors>,
    pub uy_order: f64,
    pub fy_order: f64,
    pub vy_order: f64,
    pub failure: Option<String>,
}

fn study(scheme: &str, runs: impl Fn(f64) -> Options, steps: &[f64], reference: f64) -> Study {
    let go = || -> Result<Vec<Errors>, CaseError> {
        let reference = disc::run(&runs(reference))?.series;
        steps.iter().map(|&s| Ok(errors(s, &disc::run(&runs(s))?.series, &reference))).collect()
    };
    match go() {
        Ok(errors) => {
            let order = |f: fn(&Errors) -> f64| {
                super::time::last_order(&errors.iter().map(|e| (e.step, f(e))).collect::<Vec<_>>())
            };
            Study {
                scheme: scheme.into(),
                uy_order: order(|e| e.uy_mean),
                fy_order: order(|e| e.fy_contact),
                vy_order: order(|e| e.vy_mean),
                errors,
                failure: None,
            }
        }
        // A scheme that cannot take the coarsest step (explicit contact) is a result.
        Err(e) => Study {
            scheme: scheme.into(),
            errors: Vec::new(),
            uy_order: f64::NAN,
            fy_order: f64::NAN,
            vy_order: f64::NAN,
            failure: Some(e.to_string()),
        },
    }
}

/// Both studies: Δt for every scheme, h for the default one.
#[derive(Clone, Debug, Serialize)]
pub struct DiscConvergence {
    pub dt: Vec<Study>,
    pub h: Study,
}

pub fn disc(progress: &mut dyn FnMut(&str)) -> DiscConvergence {
    let dt = crate::driver::all_schemes()
        .into_iter()
        .map(|scheme| {
            progress(&format!("disc Δt convergence {scheme}"));
            let methods = Methods { scheme: scheme.into(), ..Methods::default() };
            let runs = |dt| Options { methods: methods.clone(), dt: Some(dt), t_end: Some(T_END), ..disc::options() };
            study(scheme, runs, &DT_STEPS, DT_REFERENCE)
        })
        .collect();
    progress("disc h convergence");
    let methods = Methods::default();
    let runs =
        |h| Options { methods: methods.clone().set("h", h), dt: Some(H_DT), t_end: Some(T_END), ..disc::options() };
    let h = study(&methods.scheme, runs, &H_STEPS, H_REFERENCE);
    DiscConvergence { dt, h }
}
