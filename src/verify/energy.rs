//! Discrete energy laws (docs/mathematics.md §5). With contact: Crank–Nicolson and midpoint
//! keep E_aug on every step whose active set (contact status at the quadrature points) is
//! unchanged, on the bar and the disc; the jumps on the other steps are reported. Without
//! contact: every scheme's energy decays per step like the square of its spectral radius, so
//! it is conserved by Crank–Nicolson and midpoint (ρ = 1) and dissipated by HHT, TR-BDF2 and
//! generalized-α (ρ < 1).

use serde::Serialize;

use super::oscillator::{oscillator_energies, spectral_radius};
use crate::cases::{bar, disc};
use crate::driver::Methods;
use crate::error::CaseError;
use crate::problem::run::Options;

/// How E_aug behaves on one run: on steps whose active set is unchanged, and on the others.
#[derive(Clone, Debug, Serialize)]
pub struct EnergyRow {
    pub case: &'static str,
    pub scheme: String,
    pub contact: String,
    /// Steps whose active set did not change, and the largest |ΔE_aug| over them, relative to
    /// the energy scale.
    pub kept_steps: usize,
    pub kept_largest: f64,
    /// Steps whose active set changed, and their total ΔE_aug (relative).
    pub changed_steps: usize,
    pub changed_total: f64,
    /// Steps on which points only entered contact, and the extreme ΔE_aug over them (the
    /// largest for Crank–Nicolson, whose jumps there are ≤ 0; the smallest for midpoint, ≥ 0).
    pub entering_steps: usize,
    pub entering_range: (f64, f64),
    /// Steps on which points only left contact, and the range of ΔE_aug over them.
    pub releasing_steps: usize,
    pub releasing_range: (f64, f64),
    /// What the run was: the mesh, Δt and T.
    #[serde(skip)]
    pub setting: String,
}

fn energy_row(case: &'static str, scheme: &str, contact: &str, rows: &[(Vec<bool>, f64, f64)]) -> EnergyRow {
    let scale = rows.iter().map(|r| r.2.abs()).fold(0.0f64, f64::max).max(1e-300);
    let (mut kept, mut largest, mut changed, mut total) = (0, 0.0f64, 0, 0.0);
    let empty = (f64::INFINITY, f64::NEG_INFINITY);
    let (mut entering, mut entering_range, mut releasing, mut releasing_range) = (0, empty, 0, empty);
    let widen = |r: &mut (f64, f64), x: f64| *r = (r.0.min(x), r.1.max(x));
    for w in rows.windows(2) {
        let delta = (w[1].1 - w[0].1) / scale;
        if w[0].0 == w[1].0 {
            kept += 1;
            largest = largest.max(delta.abs());
        } else {
            changed += 1;
            total += delta;
            let pairs = || w[0].0.iter().zip(&w[1].0);
            let enters = pairs().any(|(a, b)| !a && *b);
            let leaves = pairs().any(|(a, b)| *a && !b);
            if enters && !leaves {
                entering += 1;
                widen(&mut entering_range, delta);
            } else if leaves && !enters {
                releasing += 1;
                widen(&mut releasing_range, delta);
            }
        }
    }
    EnergyRow {
        case,
        scheme: scheme.into(),
        contact: contact.into(),
        kept_steps: kept,
        kept_largest: largest,
        changed_steps: changed,
        changed_total: total,
        entering_steps: entering,
        entering_range,
        releasing_steps: releasing,
        releasing_range,
        setting: String::new(),
    }
}

/// The library's schemes whose file claims `energy = conserving`.
pub fn conserving_schemes() -> Result<Vec<&'static str>, CaseError> {
    let mut out = Vec::new();
    for scheme in crate::driver::all_schemes() {
        let in_use = crate::driver::FilesInUse::resolve(&Methods { scheme: scheme.into(), ..Methods::default() }, &[])?;
        if in_use.scheme_energy_law()? == Some(crate::compiler::scheme::EnergyLaw::Conserving) {
            out.push(scheme);
        }
    }
    Ok(out)
}

/// The energy laws of the schemes that claim `energy = conserving` with each contact law of
/// forms/library.toml's `verify.contacts`, on the bar and the disc (coarse built-in mesh, T = 16).
pub fn contact_laws(progress: &mut dyn FnMut(&str)) -> Result<Vec<EnergyRow>, CaseError> {
    let mut out = Vec::new();
    let v = &crate::settings::get().verify;
    let cases = &crate::settings::get().cases;
    for scheme in conserving_schemes()? {
        for contact in &v.contacts {
            progress(&format!("energy law {scheme} {contact}"));
            let methods = Methods { scheme: scheme.into(), contact: contact.clone(), ..Methods::default() };
            let b = bar::run(&Options { methods: methods.clone(), ..bar::options() })?;
            // The bar's one contact point: its status is the sign of λ.
            let rows: Vec<_> = b.series.iter().map(|r| (vec![r.lambda < 0.0], r.energy_aug, r.energy)).collect();
            let setting = format!("N = {}, Δt = {}, T = {}", b.summary.elements, b.summary.dt, b.summary.t_end);
            out.push(EnergyRow { setting, ..energy_row(&cases.bar, scheme, contact, &rows) });
            let d =
                disc::run(&Options { methods: methods.set_default("h", 2.0), t_end: Some(16.0), ..disc::options() })?;
            let rows: Vec<_> = d.series.iter().map(|r| (r.switches.clone(), r.energy_aug, r.energy)).collect();
            let setting = format!("{}, Δt = {}, T = {}", d.summary.mesh, d.summary.dt, d.summary.t_end);
            out.push(EnergyRow { setting, ..energy_row(&cases.disc, scheme, contact, &rows) });
        }
    }
    Ok(out)
}

/// ωΔt of the dissipation measurements, and the number of steps of each.
pub const DISSIPATION_STEPS: [f64; 3] = [0.1, 1.0, 10.0];
const DISSIPATION_COUNT: usize = 2000;

/// One scheme's energy decay on the contact-free oscillator at one ωΔt.
#[derive(Clone, Debug, Serialize)]
pub struct DissipationRow {
    pub scheme: String,
    pub omega_dt: f64,
    /// Spectral radius ρ of the one-step map.
    pub rho: f64,
    /// (E_N/E_0)^(1/2N) over N = 2000 steps (fewer if E falls below 1e-200 E_0): ρ for a map
    /// whose energy decays like ρ^2n.
    pub measured_rate: f64,
    /// The largest one-step increase of E, relative to E_0 (> 0: E is not monotone).
    pub largest_increase: f64,
    /// E_N/E_0.
    pub final_ratio: f64,
}

/// Energy decay of every scheme without contact, against its spectral radius.
pub fn dissipation(progress: &mut dyn FnMut(&str)) -> Result<Vec<DissipationRow>, CaseError> {
    let mut out = Vec::new();
    for scheme in crate::driver::all_schemes() {
        progress(&format!("dissipation {scheme}"));
        let methods = Methods { scheme: scheme.into(), ..Methods::default() };
        // An explicit scheme, only where it is stable.
        let cfl = super::claimed_cfl(&methods)?.unwrap_or(f64::INFINITY);
        for omega_dt in DISSIPATION_STEPS.into_iter().filter(|x| *x <= cfl) {
            let e = oscillator_energies(&methods, omega_dt, DISSIPATION_COUNT)?;
            // Strongly damped schemes reach underflow long before N steps: measure up to 1e-200.
            let n = e.iter().rposition(|&x| x > 1e-200 * e[0]).unwrap_or(0).max(1);
            let (e0, en) = (e[0], e[n]);
            out.push(DissipationRow {
                scheme: scheme.into(),
                omega_dt,
                rho: spectral_radius(&methods, omega_dt)?,
                measured_rate: (en / e0).powf(0.5 / n as f64),
                largest_increase: e.windows(2).map(|w| (w[1] - w[0]) / e0).fold(f64::NEG_INFINITY, f64::max),
                final_ratio: e[DISSIPATION_COUNT] / e0,
            });
        }
    }
    Ok(out)
}
