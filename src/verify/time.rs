//! Time orders: every scheme of the library on the oscillator ü + u = 0 (error against cos t)
//! and on the bar before its first impact (t ≤ 0.8: a linear system with every mode of the mesh
//! excited), where the order comes from successive differences ‖u_Δt − u_Δt/2‖ since the
//! semi-discrete solution has no closed form. The bar runs with each contact law of
//! verify's list (forms/library.toml): penalty's contact term is zero before impact; Nitsche's θ
//! term −θ/γ σ_n(u)σ_n(v) acts on the free
//! boundary too: a scheme that treats the contact slot differently from the stiffness (explicit,
//! or unweighted) shows it here. Plus the spectral radius of the one-step map at ωΔt → ∞.

use serde::Serialize;

use super::oscillator::{oscillator_error, spectral_radius};
use crate::cases::bar;
use crate::driver::Methods;
use crate::error::CaseError;
use crate::problem::run::Options;

/// The oscillator's steps (T = 10).
pub const OSCILLATOR_STEPS: [f64; 3] = [0.04, 0.02, 0.01];
/// The bar's steps (T = 0.8, N = 20: ω_max Δt ≤ 0.28).
pub const BAR_STEPS: [f64; 4] = [0.004, 0.002, 0.001, 0.0005];
const BAR_END: f64 = 0.8;

/// One scheme's measured time behaviour.
#[derive(Clone, Debug, Serialize)]
pub struct TimeRow {
    pub scheme: String,
    /// (Δt, |u(10) − cos 10|) on the oscillator.
    pub oscillator: Vec<(f64, f64)>,
    /// log₂ of the ratio of the last two errors.
    pub oscillator_order: f64,
    /// The bar before impact, per contact law of verify's list (forms/library.toml).
    pub bar: Vec<BarOrder>,
    /// Spectral radius at ωΔt = 1e12, or at its `cfl` for an explicit scheme (unstable beyond).
    pub rho_infinity: f64,
    /// The stability limit the scheme claims (an explicit one).
    pub cfl: Option<f64>,
}

/// The bar before impact with one contact law.
#[derive(Clone, Debug, Serialize)]
pub struct BarOrder {
    pub contact: String,
    /// (Δt, max over t ≤ 0.8 of |u_c,Δt − u_c,Δt/2|) at the contact point.
    pub differences: Vec<(f64, f64)>,
    pub order: f64,
}

/// The rate between the last two (step, error) pairs, each step half the last.
pub fn last_order(points: &[(f64, f64)]) -> f64 {
    match points {
        [.., (h0, e0), (h1, e1)] => (e0 / e1).ln() / (h0 / h1).ln(),
        _ => f64::NAN,
    }
}

/// max |a(t) − b(t)| over a's times, b on a grid twice as fine.
fn coarse_difference(a: &[bar::Row], b: &[bar::Row]) -> f64 {
    a.iter().zip(b.iter().step_by(2)).map(|(x, y)| (x.u_c - y.u_c).abs()).fold(0.0, f64::max)
}

/// The bar before impact: successive differences of the contact point's displacement.
fn bar_differences(methods: &Methods) -> Result<Vec<(f64, f64)>, CaseError> {
    let runs: Vec<Vec<bar::Row>> = BAR_STEPS
        .iter()
        .map(|&dt| {
            let opts = Options { methods: methods.clone(), dt: Some(dt), t_end: Some(BAR_END), ..bar::options() };
            Ok(bar::run(&opts)?.series)
        })
        .collect::<Result<_, CaseError>>()?;
    Ok(runs.windows(2).zip(BAR_STEPS).map(|(w, dt)| (dt, coarse_difference(&w[0], &w[1]))).collect())
}

/// The bar's order before impact with each contact law of verify's list (forms/library.toml).
pub fn bar_orders(methods: &Methods) -> Result<Vec<BarOrder>, CaseError> {
    crate::settings::get()
        .verify
        .contacts
        .iter()
        .map(|contact| {
            let differences = bar_differences(&Methods { contact: contact.clone(), ..methods.clone() })?;
            Ok(BarOrder { contact: contact.clone(), order: last_order(&differences), differences })
        })
        .collect()
}

/// Orders and ρ∞ of every scheme of the library, with its default params.
pub fn orders(progress: &mut dyn FnMut(&str)) -> Result<Vec<TimeRow>, CaseError> {
    crate::driver::all_schemes()
        .into_iter()
        .map(|scheme| {
            progress(&format!("time order {scheme}"));
            let methods = Methods { scheme: scheme.into(), ..Methods::default() };
            let oscillator: Vec<(f64, f64)> = OSCILLATOR_STEPS
                .iter()
                .map(|&dt| Ok((dt, oscillator_error(&methods, dt, 10.0)?)))
                .collect::<Result<_, CaseError>>()?;
            let bar = bar_orders(&methods)?;
            let cfl = super::claimed_cfl(&methods)?;
            Ok(TimeRow {
                scheme: scheme.into(),
                oscillator_order: last_order(&oscillator),
                oscillator,
                bar,
                rho_infinity: spectral_radius(&methods, cfl.unwrap_or(1e12))?,
                cfl,
            })
        })
        .collect()
}
