//! `signorini verify`: the claims the mathematics makes, measured. For every scheme of the
//! library: its observed time order on the oscillator ü + u = 0 and its spectral radius at
//! ωΔt → ∞; and the discrete energy laws with contact (Crank–Nicolson and midpoint conserve
//! E_aug on every step whose active set does not change) on the bar and the disc.

use std::fmt::Write;

use serde::Serialize;

use crate::cases::{CaseError, bar, disc};
use crate::driver::{Active, Setup};
use crate::runtime::assembly::{Assembler, Quadrature};
use crate::runtime::kernel::Coef;
use crate::runtime::library::Binding;
use crate::runtime::linalg::Structure;
use crate::runtime::mesh::structured;
use crate::runtime::newton::NewtonOptions;
use crate::runtime::problem::Constraints;
use crate::runtime::scheme::{Stepper, TimeScheme};

/// Runs `f` with a stepper of `setup`'s scheme on the oscillator: one P1 element, E = 1,
/// ρ = 3, so M = ρh/3 = 1 and K = E/h = 1 on the free dof; no contact facets.
pub fn with_oscillator<R>(setup: &Setup, f: impl FnOnce(&mut Stepper) -> R) -> Result<R, CaseError> {
    with_oscillator_scheme(setup, None, f)
}

/// As [`with_oscillator`], stepping `scheme` (e.g. one compiled by a crate's own `forms!`)
/// instead of `setup`'s when given; the forms still come from `setup`.
pub fn with_oscillator_scheme<R>(
    setup: &Setup,
    scheme: Option<Box<dyn TimeScheme>>,
    f: impl FnOnce(&mut Stepper) -> R,
) -> Result<R, CaseError> {
    let mesh = structured::interval(1, 0.0, 1.0);
    let asm = Assembler::new(&mesh);
    let active = Active::resolve(&setup.clone().set("elasticity.rho", 3.0), &[])?;
    let coefs = |name: &str| match name {
        "f" => Some(Coef::constant(vec![0.0])),
        "g" => Some(Coef::scalar(0.0)),
        "nc" => Some(Coef::constant(vec![-1.0])),
        _ => None,
    };
    let binding = Binding { quadrature: Quadrature::default(), regions: vec![("Gamma_C".into(), &[])], dim: 1 };
    let mut inst = active.forms.instantiate(&coefs, &binding)?;
    let forms = active.scheme_forms(&mut inst)?;
    let mut constraints = Constraints::none(asm.size());
    constraints.fix(1);
    let scheme = match scheme {
        Some(s) => s,
        None => active.time_scheme()?,
    };
    let mut stepper = Stepper::new(scheme, &asm, forms, constraints, Structure::General, NewtonOptions::default())?;
    Ok(f(&mut stepper))
}

/// |u(T) − cos T| from u = 1, v = 0.
pub fn oscillator_error(setup: &Setup, dt: f64, t_end: f64) -> Result<f64, CaseError> {
    with_oscillator(setup, |st| -> Result<f64, CaseError> {
        let mut states: Vec<Vec<f64>> = st.desc().states.iter().map(|_| vec![0.0; 2]).collect();
        states[0][0] = 1.0;
        st.initialize(&mut states, 0.0)?;
        let steps = (t_end / dt).round() as usize;
        for k in 0..steps {
            st.step(&mut states, k as f64 * dt, dt)?;
        }
        Ok((states[0][0] - t_end.cos()).abs())
    })?
}

/// Spectral radius of the one-step map of the oscillator's states at step `dt` (ω = 1).
pub fn spectral_radius(setup: &Setup, dt: f64) -> Result<f64, CaseError> {
    with_oscillator(setup, |st| -> Result<f64, CaseError> {
        let m = st.desc().states.len();
        let mut a = vec![vec![0.0; m]; m];
        for j in 0..m {
            let mut states: Vec<Vec<f64>> = (0..m).map(|_| vec![0.0; 2]).collect();
            states[j][0] = 1.0;
            st.step(&mut states, 0.0, dt)?;
            for i in 0..m {
                a[i][j] = states[i][0];
            }
        }
        Ok(spectral_radius_of(&a))
    })?
}

/// The spectral radius lim ‖Aᵏ‖^(1/k), by 40 normalized squarings (k = 2⁴⁰): exact to
/// ~1e-10 even for the double and triple roots at infinite step (generalized-α, TR-BDF2), where
/// eigenvalue iterations converge slowly.
fn spectral_radius_of(a: &[Vec<f64>]) -> f64 {
    let n = a.len();
    let mut b = a.to_vec();
    let mut log_scale = 0.0;
    for _ in 0..40 {
        let mut c = vec![vec![0.0; n]; n];
        for i in 0..n {
            for j in 0..n {
                c[i][j] = (0..n).map(|k| b[i][k] * b[k][j]).sum();
            }
        }
        let s = c.iter().flatten().fold(0.0f64, |x, v| x.max(v.abs()));
        if s == 0.0 || !s.is_finite() {
            return if s == 0.0 { 0.0 } else { f64::INFINITY };
        }
        c.iter_mut().flatten().for_each(|v| *v /= s);
        b = c;
        // After m squarings A^(2^m) = b · exp(log_scale).
        log_scale = 2.0 * log_scale + s.ln();
    }
    (log_scale / 2f64.powi(40)).exp()
}

/// One scheme's measured properties.
#[derive(Clone, Debug, Serialize)]
pub struct SchemeRow {
    pub scheme: String,
    /// log2 of the error ratio between Δt = 0.02 and 0.01 on the oscillator, T = 10.
    pub order: f64,
    /// Spectral radius at ωΔt = 1e12.
    pub rho_infinity: f64,
}

/// Order and ρ∞ of every scheme of the library, with its default params.
pub fn schemes() -> Result<Vec<SchemeRow>, CaseError> {
    crate::driver::all_schemes()
        .into_iter()
        .map(|scheme| {
            let setup = Setup { scheme: scheme.into(), ..Setup::default() };
            let order = (oscillator_error(&setup, 0.02, 10.0)? / oscillator_error(&setup, 0.01, 10.0)?).log2();
            Ok(SchemeRow { scheme: scheme.into(), order, rho_infinity: spectral_radius(&setup, 1e12)? })
        })
        .collect()
}

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
}

fn energy_row(case: &'static str, scheme: &str, contact: &str, rows: &[(Vec<bool>, f64, f64)]) -> EnergyRow {
    let scale = rows.iter().map(|r| r.2.abs()).fold(0.0f64, f64::max).max(1e-300);
    let (mut kept, mut largest, mut changed, mut total) = (0, 0.0f64, 0, 0.0);
    for w in rows.windows(2) {
        let delta = (w[1].1 - w[0].1) / scale;
        if w[0].0 == w[1].0 {
            kept += 1;
            largest = largest.max(delta.abs());
        } else {
            changed += 1;
            total += delta;
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
    }
}

/// The energy laws of Crank–Nicolson and midpoint (Nitsche θ = 1 and penalty) on the bar and
/// the disc (coarse built-in mesh, T = 16).
pub fn energy_laws() -> Result<Vec<EnergyRow>, CaseError> {
    let mut out = Vec::new();
    let v = &crate::settings::get().verify;
    for scheme in &v.energy_conserving {
        for contact in &v.contacts {
            let setup = Setup { scheme: scheme.clone(), contact: contact.clone(), ..Setup::default() };
            let b = bar::run(&bar::Options { setup: setup.clone(), ..bar::Options::default() })?;
            // The bar's one contact point: its status is the sign of λ.
            let rows: Vec<_> = b.series.iter().map(|r| (vec![r.lambda < 0.0], r.energy_aug, r.energy)).collect();
            out.push(energy_row("bar", scheme, contact, &rows));
            let d = disc::run(&disc::Options { setup, h: 2.0, t_end: 16.0, ..disc::Options::default() })?;
            let rows: Vec<_> = d.series.iter().map(|r| (r.switches.clone(), r.energy_aug, r.energy)).collect();
            out.push(energy_row("disc", scheme, contact, &rows));
        }
    }
    Ok(out)
}

/// The verification as Markdown.
pub fn markdown(schemes: &[SchemeRow], energies: &[EnergyRow]) -> String {
    let mut md = String::from(
        "### Time order and spectral radius\n\nOscillator ü + u = 0 (one P1 element), T = 10: observed order log₂(err(0.02)/err(0.01)); spectral radius of the one-step map at ωΔt = 10¹².\n\n| scheme | order | ρ∞ |\n|---|---|---|\n",
    );
    for r in schemes {
        let _ = writeln!(md, "| {} | {:.3} | {:.6} |", r.scheme, r.order, r.rho_infinity);
    }
    md.push_str("\n### Energy laws with contact\n\nCrank–Nicolson (Newmark β = ¼) and midpoint conserve E_aug on every step whose active set (contact status at the quadrature points) does not change; the other steps carry the jumps D of docs/mathematics.md §5. Relative to the largest |E| of the run.\n\n| case | scheme | contact | steps, active set kept | max \\|ΔE_aug\\| there | steps, active set changed | total ΔE_aug there |\n|---|---|---|---|---|---|---|\n");
    for r in energies {
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {:.1e} | {} | {:.2e} |",
            r.case, r.scheme, r.contact, r.kept_steps, r.kept_largest, r.changed_steps, r.changed_total
        );
    }
    md
}
