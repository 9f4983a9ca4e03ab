//! Section 2 of the report: the bouncing disc, energies and Newton iterations per scheme.

use std::fmt::Write;
use std::path::Path;

use super::table::{Failures, Table};
use super::{Laws, past_the_guard, write_error};
use crate::cases::disc;
use crate::driver::Methods;
use crate::error::CaseError;
use crate::numbers::readable;
use crate::plot::Curve;
use crate::problem::run::Options;

pub(super) fn section(out: &Path, progress: &mut dyn FnMut(&str)) -> Result<String, CaseError> {
    let mut md = String::new();
    let cases = &crate::settings::get().cases;
    let mut table = Table::new(&[
        "scheme",
        "first contact",
        "max penetration",
        "E_aug(T)",
        "Newton iterations (total)",
        "Newton iterations (max per step)",
        "ms per step",
    ]);
    let failures = Failures::new(out);
    let mut laws = Laws::default();
    let mut disc_run: Option<disc::Summary> = None;
    let mut disc_energies = Vec::new();
    let mut disc_newton = Vec::new();
    let mut stopped: Vec<String> = Vec::new();
    for scheme in crate::driver::all_schemes() {
        progress(&format!("disc {scheme}"));
        let dir = out.join(&cases.disc).join(scheme);
        let methods = Methods { scheme: scheme.into(), ..Methods::default() };
        // A scheme that fails here (explicit contact is unstable at this step) is a result.
        let run = past_the_guard(methods, |methods| {
            disc::run(&Options { methods, out: Some(dir.clone()), ..disc::options() })
        });
        let (r, guard) = match run {
            Ok(r) => r,
            Err(e) => {
                let cell = failures.cell(&format!("disc_{scheme}"), &e.to_string());
                table.row([
                    scheme.to_string(),
                    cell,
                    String::new(),
                    String::new(),
                    String::new(),
                    String::new(),
                    String::new(),
                ]);
                continue;
            }
        };
        let s = &r.summary;
        table.row([
            format!("{scheme}{}", if guard.is_some() { " (†)" } else { "" }),
            s.first_contact.map_or("—".into(), |t| format!("{t:.2}")),
            format!("{:.2e}", s.max_penetration),
            readable(s.energy_aug_final),
            s.newton_total.to_string(),
            s.newton_max.to_string(),
            format!("{:.2}", 1e3 * s.seconds_per_step),
        ]);
        laws.add(&s.contact, &s.params);
        disc_run.get_or_insert_with(|| s.clone());
        // A run whose energy grows is in the table, not on the energy's scale of the others.
        if let Some(g) = guard {
            stopped.push(format!("{scheme} ({g})"));
        } else {
            disc_energies
                .push((scheme.to_string(), r.series.iter().map(|row| (row.t, row.energy_aug)).collect::<Vec<_>>()));
        }
        disc_newton
            .push((scheme.to_string(), r.series.iter().map(|row| (row.t, row.newton as f64)).collect::<Vec<_>>()));
    }
    let (mesh, dt, t_end) =
        disc_run.as_ref().map_or((String::new(), f64::NAN, f64::NAN), |s| (s.mesh.clone(), s.dt, s.t_end));
    let _ = write!(
        md,
        "## 2. Bouncing disc (docs/mathematics.md §6)\n\nMesh: {mesh}; {}; Δt = {}, T = {}.\n\n",
        laws.text(),
        readable(dt),
        readable(t_end)
    );
    md.push_str(&table.markdown());
    if !stopped.is_empty() {
        let _ = write!(
            md,
            "\n† The energy guard stopped these runs, whose energy grows; they ran on without it and their energy is left out of the figure: {}.\n",
            stopped.join("; ")
        );
    }
    crate::plot::panels(
        &out.join("disc_energies.png"),
        "t",
        &[
            (
                "E_Θ per scheme",
                "E_Θ",
                disc_energies.iter().map(|(l, p)| Curve { label: l, points: p.clone(), dashed: false }).collect(),
            ),
            (
                "Newton iterations per step",
                "iterations",
                disc_newton.iter().map(|(l, p)| Curve { label: l, points: p.clone(), dashed: false }).collect(),
            ),
        ],
    )
    .map_err(write_error(out))?;
    let _ = write!(
        md,
        "\n![disc energies and Newton iterations](disc_energies.png)\n\nPer scheme: `{p}/<scheme>/{p}.png` (energies, displacements, contact force, Newton).\n\n",
        p = cases.disc
    );
    Ok(md)
}
