//! Section 1 of the report: the compressed bar, Nitsche against penalty with the talk's
//! schemes and masses, against the exact solution.

use std::fmt::Write;
use std::path::Path;

use super::table::Table;
use super::{Laws, optional, past_the_guard, write_error};
use crate::cases::bar;
use crate::driver::Methods;
use crate::error::CaseError;
use crate::numbers::readable;
use crate::plot::Curve;
use crate::problem::run::Options;
use crate::simulation::MassChoice;

pub(super) fn section(out: &Path, progress: &mut dyn FnMut(&str)) -> Result<String, CaseError> {
    let mut md = String::new();
    // The talk's comparisons (forms/library.toml).
    let runs: Vec<(&str, &str, MassChoice)> = crate::settings::get()
        .report
        .bar
        .iter()
        .flat_map(|b| b.runs.iter())
        .map(|(s, c, m)| {
            let mass =
                <MassChoice as clap::ValueEnum>::from_str(m, true).expect("checked by tests/integration/settings.rs");
            (s.as_str(), c.as_str(), mass)
        })
        .collect();
    let mut table = Table::new(&[
        "run",
        "err_u",
        "err_λ",
        "err_λ½",
        "E_Θ(0)",
        "E_Θ(T)",
        "max penetration",
        "Newton iterations (total/max per step)",
    ]);
    let mut energies: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
    let mut figures = String::new();
    let mut laws = Laws::default();
    let mut stopped = Vec::new();
    let mut bar_run: Option<bar::Summary> = None;
    let default_contact = &crate::settings::get().defaults.contact;
    let cases = &crate::settings::get().cases;
    for &(scheme, contact, mass) in &runs {
        let label = format!("{scheme}-{contact}-{}", mass.name());
        let dir = out.join(&cases.bar).join(&label);
        progress(&format!("bar {label}"));
        let methods = Methods { scheme: scheme.into(), contact: contact.into(), ..Methods::default() };
        let (r, guard) = past_the_guard(methods, |methods| {
            bar::run(&Options { methods, mass, out: Some(dir.clone()), ..bar::options() })
        })?;
        let s = &r.summary;
        table.row([
            format!("{scheme} {contact} {}{}", mass.name(), if guard.is_some() { " (†)" } else { "" }),
            format!("{:.4}", s.err_linf_l2_u),
            optional(s.err_l2_lambda, 4),
            optional(s.err_l2_lambda_half, 4),
            readable(s.energy_aug_initial),
            readable(s.energy_aug_final),
            format!("{:.2e}", s.max_penetration),
            format!("{}/{}", s.newton_total, s.newton_max),
        ]);
        if let Some(g) = guard {
            stopped.push(format!("{label} ({g})"));
        }
        let _ = writeln!(figures, "**{label}**\n\n![{label}]({p}/{label}/{p}.png)\n", p = cases.bar);
        laws.add(&s.contact, &s.params);
        // Energies that stay bounded (a run whose energy grows has its own row).
        let bounded = r.summary.energy_aug_drift_max < 1.0;
        if mass == MassChoice::Consistent && contact == default_contact && bounded {
            energies.push((scheme.to_string(), r.series.iter().map(|row| (row.t, row.energy_aug)).collect()));
        }
        bar_run.get_or_insert_with(|| r.summary.clone());
    }
    let (elements, dt, t_end) = bar_run.as_ref().map_or((0, f64::NAN, f64::NAN), |s| (s.elements, s.dt, s.t_end));
    let _ = write!(
        md,
        "## 1. Compressed bar (docs/mathematics.md §6)\n\nN = {elements} elements, Δt = {}, T = {}; {}. `err_u` = max‖u_h − I_h u‖/max‖I_h u‖ (mass norm), `err_λ` = relative ℓ² error of the contact stress at tⁿ, `err_λ½` the same at t^{{n+½}} from (uⁿ + uⁿ⁺¹)/2 (where midpoint and hybrid impose contact).\n\n",
        readable(dt),
        readable(t_end),
        laws.text()
    );
    md.push_str(&table.markdown());
    let curves: Vec<Curve> =
        energies.iter().map(|(name, pts)| Curve { label: name, points: pts.clone(), dashed: false }).collect();
    let title = format!("E_Θ of every scheme ({})", laws.of(default_contact));
    crate::plot::panels(&out.join("bar_energies.png"), "t", &[(title.as_str(), "E_Θ", curves)])
        .map_err(write_error(out))?;
    if !stopped.is_empty() {
        let _ = write!(
            md,
            "\n† The energy guard (docs/language.md) stopped these runs, whose energy grows; they are shown without the guard: {}.\n",
            stopped.join("; ")
        );
    }
    md.push_str("\n### Energy of every scheme\n\n![energies](bar_energies.png)\n\n");
    md.push_str("### Contact displacement and stress against the exact solution\n\n");
    md.push_str(&figures);

    Ok(md)
}
