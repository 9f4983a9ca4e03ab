//! `signorini verify --scheme NAME|FILE.wf [--param ...]`: one scheme, measured where the
//! mathematics gives exact answers, in seconds. The oscillator ü + ω²u = 0 (ω = 1) gives the
//! observed order against cos t, the one-step map's spectral radius and relative period error
//! over ωΔt ∈ [1e-2, 1e6] (beside the library's Newmark, HHT and generalized-α), and the energy
//! ½(u² + v²) step by step; the bar before impact gives the order on a system with every mode of
//! the mesh excited and its energy balance; the bar's and the disc's summaries put the scheme
//! beside the library's. What the file claims (`claim order = 2`, `claim rho_inf = ...`) is
//! checked against the measurements: a contradiction fails the command.

use std::fmt::Write;
use std::path::Path;

use serde::Serialize;

use super::oscillator::{
    damped_oscillator_error, estimate_ratio, oscillator_energies, oscillator_error, spectral_radius, step_map,
};
use super::time::{BAR_STEPS, BarOrder, OSCILLATOR_STEPS, bar_orders, last_order};
use crate::cases::{bar, disc};
use crate::compiler::scheme::EnergyLaw;
use crate::driver::{FilesInUse, Methods};
use crate::error::CaseError;
use crate::plot::Curve;
use crate::problem::run::Options;

/// ζ of the damped oscillator ü + 2ζu̇ + u = 0.
const ZETA: f64 = 0.1;
/// ωΔt of the spectrum: 10^(-2 + k/8), k = 0..=64 (1e-2 to 1e6).
fn omega_dts() -> Vec<f64> {
    (0..=64).map(|k| 10f64.powf(-2.0 + k as f64 / 8.0)).collect()
}
/// A measured order agrees with a claimed one within this.
const ORDER_TOLERANCE: f64 = 0.25;
/// A measured ρ∞ agrees with a claimed one within this.
const RHO_TOLERANCE: f64 = 1e-3;
/// A one-step map with ρ above 1 + this is unstable (ρ of a double root on the unit circle
/// measures 1 + ~1e-11 by the squarings of `spectral_radius`).
const RHO_UNSTABLE: f64 = 1e-8;
/// A measured stability limit agrees with a claimed `cfl` within this fraction.
const CFL_TOLERANCE: f64 = 1e-3;
/// The steps at which the `estimate` is set against one step's true local error.
const ESTIMATE_STEPS: [f64; 3] = [0.1, 0.01, 0.001];
/// An estimate within this factor of the true local error at the smallest of them steers an
/// adaptive run to within its cube root of the tolerance.
const ESTIMATE_FACTOR: f64 = 2.0;
/// An energy law holds on the oscillator to this fraction of E₀ (round-off over 1000 steps).
const ENERGY_LAW_TOLERANCE: f64 = 1e-10;

/// The one-step map at one ωΔt.
#[derive(Clone, Debug, Serialize)]
pub struct SpectrumPoint {
    pub omega_dt: f64,
    pub rho: f64,
    /// T̄/T − 1 of the principal roots ρ e^{±iΩΔt}; absent where the roots are real.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub period_error: Option<f64>,
}

/// A claim of the file and what was measured.
#[derive(Clone, Debug, Serialize)]
pub struct Verdict {
    pub claim: String,
    pub claimed: f64,
    pub measured: f64,
    pub holds: bool,
}

/// One row of the bar's or the disc's comparison.
#[derive(Clone, Debug, Serialize)]
pub struct CaseRow {
    pub scheme: String,
    pub values: Vec<(String, f64)>,
}

#[derive(Clone, Debug, Serialize)]
pub struct SchemeVerification {
    pub scheme: String,
    /// The scheme's params with their values.
    pub params: Vec<(String, f64)>,
    pub claims: Vec<(String, f64)>,
    /// (Δt, |u(10) − cos 10|).
    pub oscillator: Vec<(f64, f64)>,
    pub oscillator_order: f64,
    /// (Δt, |u(10) − u_exact(10)|) on ü + 2ζu̇ + u = 0 (ζ = 0.1), for a scheme that applies the
    /// damping slot of forms/library.toml; empty otherwise.
    pub damped_oscillator: Vec<(f64, f64)>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub damped_order: Option<f64>,
    /// (Δt, the `estimate` over one step's true local error in u) on the oscillator from the
    /// exact states; empty for a scheme that declares no estimate.
    pub estimate: Vec<(f64, f64)>,
    pub bar_orders: Vec<BarOrder>,
    pub rho_infinity: f64,
    pub spectrum: Vec<SpectrumPoint>,
    pub references: Vec<(String, Vec<SpectrumPoint>)>,
    /// The oscillator at ωΔt = 0.1 over 1000 steps: max |E_{n+1} − E_n| / E_0 and (E_N − E_0)/E_0.
    pub energy_step_max: Option<f64>,
    pub energy_drift: Option<f64>,
    /// The bar before impact (t ≤ 0.8, at its file's Δt): max_n |E_n − E_0| / E_0, and that Δt.
    pub bar_energy_drift: f64,
    pub bar_energy_dt: f64,
    pub bar: Vec<CaseRow>,
    pub disc: Vec<CaseRow>,
    /// What the bar and disc rows ran: the mesh, Δt and T.
    pub bar_setting: String,
    pub disc_setting: String,
    /// The smallest ωΔt with ρ > 1 (none: stable over [1e-2, 1e6]).
    pub stability_limit: Option<f64>,
    /// The energy law the file claims.
    pub energy_law: Option<String>,
    /// What the scheme's derived energy identity proves of that law at these params.
    pub energy_proof: Option<String>,
    pub verdicts: Vec<Verdict>,
}

impl SchemeVerification {
    pub fn holds(&self) -> bool {
        self.verdicts.iter().all(|v| v.holds)
    }
}

/// Measures the scheme of `methods` (its `scheme` and `params`).
pub fn run(methods: &Methods, progress: &mut dyn FnMut(&str)) -> Result<SchemeVerification, CaseError> {
    let in_use = FilesInUse::resolve(methods, &[])?;
    let scheme = in_use.scheme_name().to_string();
    let params: Vec<(String, f64)> = in_use
        .scheme
        .params()
        .iter()
        .zip(in_use.forms.params.scheme_values(in_use.scheme.params()))
        .map(|(p, v)| (p.name.to_string(), v))
        .collect();
    let claims = in_use.scheme_claims()?;
    progress(&format!("{scheme}: oscillator"));
    let oscillator: Vec<(f64, f64)> = OSCILLATOR_STEPS
        .iter()
        .chain(&[0.005])
        .map(|&dt| Ok((dt, oscillator_error(methods, dt, 10.0)?)))
        .collect::<Result<_, CaseError>>()?;
    let oscillator_order = last_order(&oscillator);
    let settings = &crate::settings::get().verify;
    let damping = settings.damping_slot.as_str();
    let damped_oscillator: Vec<(f64, f64)> = if in_use.scheme.desc().uses.iter().any(|s| s.name == damping) {
        progress(&format!("{scheme}: damped oscillator"));
        OSCILLATOR_STEPS
            .iter()
            .chain(&[0.005])
            .map(|&dt| Ok((dt, damped_oscillator_error(methods, damping, ZETA, dt, 10.0)?)))
            .collect::<Result<_, CaseError>>()?
    } else {
        Vec::new()
    };
    let damped_order = (!damped_oscillator.is_empty()).then(|| last_order(&damped_oscillator));
    let estimate: Vec<(f64, f64)> = ESTIMATE_STEPS
        .iter()
        .filter_map(|&dt| estimate_ratio(methods, dt).map(|r| r.map(|r| (dt, r))).transpose())
        .collect::<Result<_, CaseError>>()?;
    let rho_infinity = spectral_radius(methods, 1e12)?;
    progress(&format!("{scheme}: spectrum"));
    let own = spectrum(methods)?;
    let others: Vec<&String> = settings.references.iter().filter(|r| **r != scheme).collect();
    let references = others
        .iter()
        .map(|r| Ok((r.to_string(), spectrum(&reference(methods, r))?)))
        .collect::<Result<_, CaseError>>()?;
    let (energy_step_max, energy_drift) = match oscillator_energies(methods, 0.1, 1000) {
        Ok(e) => {
            let step = e.windows(2).map(|w| (w[1] - w[0]).abs()).fold(0.0, f64::max) / e[0];
            (Some(step), Some((e[e.len() - 1] - e[0]) / e[0]))
        }
        // A scheme without a velocity state has no ½v² to measure.
        Err(_) => (None, None),
    };
    progress(&format!("{scheme}: bar before impact"));
    let bar_orders = bar_orders(methods)?;
    let before = bar::run(&Options { methods: methods.clone(), t_end: Some(0.8), ..bar::options() })?;
    let e0 = before.series[0].energy;
    let bar_energy_drift = before.series.iter().map(|r| (r.energy - e0).abs()).fold(0.0, f64::max) / e0;
    let bar_energy_dt = before.summary.dt;
    let (mut bar_setting, mut disc_setting) = (String::new(), String::new());
    progress(&format!("{scheme}: bar and disc beside the library"));
    let mut bar_rows = Vec::new();
    let mut disc_rows = Vec::new();
    let names = std::iter::once(None).chain(others.iter().map(|r| Some(r.as_str())));
    for name in names {
        let s = match name {
            None => methods.clone(),
            Some(r) => reference(methods, r),
        };
        let label = name.map_or(scheme.clone(), |r| r.to_string());
        let b = bar::run(&Options { methods: s.clone(), ..bar::options() })?.summary;
        bar_setting = format!("N = {}, Δt = {}, T = {}", b.elements, b.dt, b.t_end);
        bar_rows.push(CaseRow {
            scheme: label.clone(),
            values: vec![
                ("err_u".into(), b.err_linf_l2_u),
                ("err_λ".into(), b.err_l2_lambda.unwrap_or(f64::NAN)),
                ("E_aug drift".into(), b.energy_aug_drift_final),
                ("penetration".into(), b.max_penetration),
                ("Newton".into(), b.newton_total as f64),
            ],
        });
        let d = disc::run(&Options { methods: s.set_default("h", 2.0), ..disc::options() })?.summary;
        disc_setting = format!("{}, Δt = {}, T = {}", d.mesh, d.dt, d.t_end);
        disc_rows.push(CaseRow {
            scheme: label,
            values: vec![
                ("first contact".into(), d.first_contact.unwrap_or(f64::NAN)),
                ("min ȳ".into(), d.min_u_vertical_mean),
                ("penetration".into(), d.max_penetration),
                ("E_aug(T)".into(), d.energy_aug_final),
                ("Newton".into(), d.newton_total as f64),
            ],
        });
    }
    let stability_limit = stability_limit(methods)?;
    let law = in_use.scheme_energy_law()?;
    let energy_law = match law {
        Some(law) => Some((law, energy_law_defect(methods, law)?)),
        None => None,
    };
    let mut verdicts = verdicts(&claims, oscillator_order, damped_order, rho_infinity, stability_limit, energy_law)?;
    if let Some(&(_, ratio)) = estimate.last() {
        let holds = (1.0 / ESTIMATE_FACTOR..=ESTIMATE_FACTOR).contains(&ratio);
        verdicts.push(Verdict { claim: "estimate / local error".into(), claimed: 1.0, measured: ratio, holds });
    }
    Ok(SchemeVerification {
        scheme,
        params,
        claims,
        oscillator,
        oscillator_order,
        damped_oscillator,
        damped_order,
        estimate,
        bar_orders,
        rho_infinity,
        spectrum: own,
        references,
        energy_step_max,
        energy_drift,
        bar_energy_drift,
        bar_energy_dt,
        bar: bar_rows,
        disc: disc_rows,
        bar_setting,
        disc_setting,
        stability_limit,
        energy_law: law.map(|l| l.name().to_string()),
        energy_proof: in_use.scheme_energy_proof()?,
        verdicts,
    })
}

/// What the file claims against what was measured. An order claim holds for the oscillator
/// and, when measured, the damped one; `cfl` is the stability limit in ωΔt; a claimed ρ∞
/// implies stability at every ωΔt; an energy law is measured on the oscillator.
fn verdicts(
    claims: &[(String, f64)],
    oscillator_order: f64,
    damped_order: Option<f64>,
    rho_infinity: f64,
    stability_limit: Option<f64>,
    energy_law: Option<(EnergyLaw, f64)>,
) -> Result<Vec<Verdict>, CaseError> {
    let mut verdicts = Vec::new();
    let limit = stability_limit.unwrap_or(f64::INFINITY);
    for (claim, claimed) in claims {
        let claimed = *claimed;
        let measured: Vec<(String, f64, f64, bool)> = match claim.as_str() {
            "order" => std::iter::once(("order".to_string(), oscillator_order))
                .chain(damped_order.map(|o| ("order (damped)".to_string(), o)))
                .map(|(c, m)| (c, claimed, m, (m - claimed).abs() <= ORDER_TOLERANCE))
                .collect(),
            "rho_inf" => vec![
                (claim.clone(), claimed, rho_infinity, (rho_infinity - claimed).abs() <= RHO_TOLERANCE),
                ("stability limit (ωΔt)".into(), f64::INFINITY, limit, stability_limit.is_none()),
            ],
            "cfl" => vec![(claim.clone(), claimed, limit, (limit - claimed).abs() <= CFL_TOLERANCE * claimed)],
            other => return Err(CaseError::Option(format!("verify cannot measure the claim `{other}` yet"))),
        };
        for (name, claimed, measured, holds) in measured {
            verdicts.push(Verdict { claim: name, claimed, measured, holds });
        }
    }
    if let Some((law, defect)) = energy_law {
        verdicts.push(Verdict {
            claim: format!("energy = {}", law.name()),
            claimed: 0.0,
            measured: defect,
            holds: defect <= ENERGY_LAW_TOLERANCE,
        });
    }
    Ok(verdicts)
}

/// A measured value for the tables: four decimals, or four digits in exponent form when it is
/// small or large.
fn figure(x: f64) -> String {
    if x != 0.0 && x.is_finite() && !(1e-3..1e4).contains(&x.abs()) { format!("{x:.4e}") } else { format!("{x:.4}") }
}

/// The smallest ωΔt at which the oscillator's one-step map has ρ > 1 (to [`RHO_UNSTABLE`]),
/// scanned over [`omega_dts`] and bisected; none when it is stable over the whole range.
fn stability_limit(methods: &Methods) -> Result<Option<f64>, CaseError> {
    let unstable = |x: f64| -> Result<bool, CaseError> { Ok(spectral_radius(methods, x)? > 1.0 + RHO_UNSTABLE) };
    let grid = omega_dts();
    let mut first = None;
    for (k, &x) in grid.iter().enumerate() {
        if unstable(x)? {
            first = Some(k);
            break;
        }
    }
    let Some(k) = first else { return Ok(None) };
    if k == 0 {
        return Ok(Some(grid[0]));
    }
    let (mut lo, mut hi) = (grid[k - 1], grid[k]);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if unstable(mid)? {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Ok(Some(lo))
}

/// How far the oscillator's energy ½(u² + v²) departs from the claimed law, over 1000 steps at
/// ωΔt = 0.1, 1 and 10, relative to E₀: max |Eₙ − E₀| for a conserving scheme, the largest
/// step increase max (Eₙ₊₁ − Eₙ) for a dissipative one. (With contact, the runs' energy guard
/// applies the same law.)
fn energy_law_defect(methods: &Methods, law: EnergyLaw) -> Result<f64, CaseError> {
    let mut defect = 0.0f64;
    for dt in [0.1, 1.0, 10.0] {
        let e = oscillator_energies(methods, dt, 1000)?;
        let d = match law {
            EnergyLaw::Conserving => e.iter().map(|x| (x - e[0]).abs()).fold(0.0, f64::max),
            EnergyLaw::Dissipative => e.windows(2).map(|w| w[1] - w[0]).fold(0.0, f64::max),
        };
        defect = defect.max(d / e[0]);
    }
    Ok(defect)
}

/// The methods with a reference scheme instead: the settings that apply to it (the form files'
/// params, and scheme params of the same name) are kept.
fn reference(methods: &Methods, scheme: &str) -> Methods {
    let params = methods
        .params
        .iter()
        .filter(|p| {
            let probe = Methods { scheme: scheme.into(), params: vec![(*p).clone()], ..methods.clone() };
            FilesInUse::resolve(&probe, &[]).is_ok()
        })
        .cloned()
        .collect();
    Methods { scheme: scheme.into(), params, ..methods.clone() }
}

/// The oscillator's one-step map over [`omega_dts`]: its spectral radius and the relative
/// period error of its principal roots.
fn spectrum(methods: &Methods) -> Result<Vec<SpectrumPoint>, CaseError> {
    omega_dts()
        .into_iter()
        .map(|dt| {
            let a = step_map(methods, dt)?;
            let m = a.len();
            let matrix = nalgebra::DMatrix::from_fn(m, m, |i, j| a[i][j]);
            let roots = matrix.complex_eigenvalues();
            let rho = roots.iter().map(|z| z.norm()).fold(0.0, f64::max);
            // The principal pair: the complex root of largest modulus in the upper half plane.
            let principal = roots
                .iter()
                .filter(|z| z.im > 1e-12 * z.norm().max(1e-300))
                .max_by(|x, y| x.norm().total_cmp(&y.norm()));
            let period_error = principal.map(|z| dt / z.im.atan2(z.re) - 1.0);
            Ok(SpectrumPoint { omega_dt: dt, rho, period_error })
        })
        .collect()
}

impl SchemeVerification {
    /// Writes DIR/verify_NAME.md, .json and .png.
    pub fn write(&self, dir: &Path) -> Result<(), CaseError> {
        let stem = format!("verify_{}", self.scheme);
        let png = dir.join(format!("{stem}.png"));
        let labels: Vec<&str> =
            std::iter::once(self.scheme.as_str()).chain(self.references.iter().map(|(n, _)| n.as_str())).collect();
        let series: Vec<&[SpectrumPoint]> =
            std::iter::once(&self.spectrum[..]).chain(self.references.iter().map(|(_, s)| &s[..])).collect();
        // The scheme solid, the library's dashed.
        let curves = |f: &dyn Fn(&SpectrumPoint) -> Option<f64>| -> Vec<Curve> {
            labels
                .iter()
                .zip(&series)
                .enumerate()
                .map(|(i, (label, s))| Curve {
                    label,
                    points: s.iter().filter_map(|p| f(p).map(|y| (p.omega_dt.log10(), y))).collect(),
                    dashed: i > 0,
                })
                .collect()
        };
        // log10 ρ, floored: a growth beyond 1 (an explicit scheme past its limit) shows at its
        // size, and 0 is the stability line.
        let rho = curves(&|p| Some(p.rho.max(1e-3).log10()));
        let period = curves(&|p| p.period_error.filter(|e| *e > 0.0).map(f64::log10));
        crate::plot::panels(
            &png,
            "log10 ωΔt",
            &[
                ("spectral radius of the one-step map (ρ ≤ 1: stable)", "log10 ρ", rho),
                ("relative period error", "log10 (T̄/T − 1)", period),
            ],
        )
        .map_err(super::plot_error(&png))?;
        let json = dir.join(format!("{stem}.json"));
        crate::output::write_json(&json, self)
            .map_err(|source| CaseError::Write { path: json.display().to_string(), source })?;
        let md = dir.join(format!("{stem}.md"));
        crate::output::write_atomic(&md, self.markdown().as_bytes())
            .map_err(|source| CaseError::Write { path: md.display().to_string(), source })
    }

    pub fn markdown(&self) -> String {
        let mut s = String::new();
        let params: Vec<String> = self.params.iter().map(|(n, v)| format!("{n} = {v}")).collect();
        let _ = writeln!(
            s,
            "# verify --scheme {}\n\nParams: {}.\n",
            self.scheme,
            if params.is_empty() { "none".into() } else { params.join(", ") }
        );
        if self.verdicts.is_empty() {
            let _ = writeln!(
                s,
                "The file claims nothing (`claim order = 2`, `claim rho_inf = ...`, `claim cfl = ...`, `claim energy = ...` would be checked).\n"
            );
        } else {
            let _ = writeln!(s, "| claim | claimed | measured | |\n|---|---|---|---|");
            for v in &self.verdicts {
                let _ = writeln!(
                    s,
                    "| {} | {} | {} | {} |",
                    v.claim,
                    v.claimed,
                    figure(v.measured),
                    if v.holds { "holds" } else { "**contradicted**" }
                );
            }
            s.push('\n');
        }
        if let (Some(law), Some(proof)) = (&self.energy_law, &self.energy_proof) {
            let _ = writeln!(
                s,
                "The claim `energy = {law}` by the scheme's energy identity (`signorini emit --stage energy`) at these params: {proof}.\n"
            );
        }
        let _ = writeln!(s, "## Oscillator ü + u = 0\n\n| Δt | \\|u(10) − cos 10\\| |\n|---|---|");
        for (dt, e) in &self.oscillator {
            let _ = writeln!(s, "| {dt} | {e:.3e} |");
        }
        let _ = writeln!(
            s,
            "\nObserved order {:.2}; spectral radius at ωΔt = 1e12: {}; {}.",
            self.oscillator_order,
            figure(self.rho_infinity),
            match self.stability_limit {
                Some(x) => format!("stable (ρ ≤ 1) up to ωΔt = {x:.6}, unstable beyond"),
                None => "stable (ρ ≤ 1) over ωΔt ∈ [1e-2, 1e6]".into(),
            }
        );
        match self.damped_order {
            Some(order) => {
                let _ = writeln!(
                    s,
                    "\nDamped oscillator ü + 2ζu̇ + u = 0 (ζ = {ZETA}, the damping slot bound to 2ζM):\n\n| Δt | error at t = 10 |\n|---|---|"
                );
                for (dt, e) in &self.damped_oscillator {
                    let _ = writeln!(s, "| {dt} | {e:.3e} |");
                }
                let _ = writeln!(s, "\nObserved order {order:.2}.");
            }
            None => {
                let _ = writeln!(s, "The scheme applies no damping slot: the damped oscillator is not measured.");
            }
        }
        match self.estimate.is_empty() {
            false => {
                let _ = writeln!(
                    s,
                    "\nThe `estimate` over the true local error of u after one step from the exact states at t = 1/2 (1 where it is asymptotically exact):\n\n| Δt | ratio |\n|---|---|"
                );
                for (dt, r) in &self.estimate {
                    let _ = writeln!(s, "| {dt} | {r:.6} |");
                }
                s.push('\n');
            }
            true => {
                let _ = writeln!(s, "The scheme declares no `estimate`: it cannot run with adaptive steps.");
            }
        }
        match (self.energy_step_max, self.energy_drift) {
            (Some(step), Some(drift)) => {
                let _ = writeln!(
                    s,
                    "Energy ½(u² + v²) at ωΔt = 0.1 over 1000 steps: largest change in one step {step:.3e} E₀, drift {drift:.3e} E₀."
                );
            }
            _ => {
                let _ = writeln!(s, "No velocity state: the oscillator's energy is not measured.");
            }
        }
        let others: Vec<&str> = self.references.iter().map(|(n, _)| n.as_str()).collect();
        let _ = writeln!(
            s,
            "\nSpectral radius and period error over ωΔt ∈ [1e-2, 1e6], beside {}: verify_{}.png.\n",
            others.join(", "),
            self.scheme
        );
        let _ = writeln!(
            s,
            "## Bar before impact (t ≤ 0.8)\n\n| contact law | order (successive differences) |\n|---|---|"
        );
        for b in &self.bar_orders {
            let _ = writeln!(s, "| {} | {:.2} |", b.contact, b.order);
        }
        let _ = writeln!(
            s,
            "\nEnergy: max |E_n − E_0| / E_0 = {:.3e} at Δt = {} (steps {:?} for the orders).\n",
            self.bar_energy_drift, self.bar_energy_dt, BAR_STEPS
        );
        let titles = [format!("Bar ({})", self.bar_setting), format!("Disc ({})", self.disc_setting)];
        for (title, rows) in titles.iter().zip([&self.bar, &self.disc]) {
            let _ = writeln!(s, "## {title}\n");
            if let Some(first) = rows.first() {
                let heads: Vec<&str> = first.values.iter().map(|(n, _)| n.as_str()).collect();
                let _ = writeln!(s, "| scheme | {} |\n|---|{}", heads.join(" | "), "---|".repeat(heads.len()));
                for r in rows.iter() {
                    let vals: Vec<String> = r.values.iter().map(|(_, v)| format!("{v:.4e}")).collect();
                    let _ = writeln!(s, "| {} | {} |", r.scheme, vals.join(" | "));
                }
            }
            s.push('\n');
        }
        s
    }
}
