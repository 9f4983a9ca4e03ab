//! The talk's conclusions in numbers: the bar and the disc for every scheme of the library, with
//! the consistent and the redistributed mass, over a ladder of Δt. Per run: the change of E_aug,
//! the spurious oscillation of the contact pressure, Newton's iterations; per scheme and mass:
//! the largest Δt of the ladder at which the run still converges. A failure is a result.

use std::fmt::Write;
use std::path::Path;

use serde::Serialize;

use crate::cases::bar;
use crate::cases::disc;
use crate::driver::Methods;
use crate::error::CaseError;
use crate::numbers::readable;
use crate::plot::Curve;
use crate::problem::run::Options;
use crate::report::table::{Failures, Table};
use crate::simulation::MassChoice;

const BAR_STEPS: [f64; 7] = [0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.5];
const DISC_STEPS: [f64; 7] = [0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0];
const MASSES: [MassChoice; 2] = [MassChoice::Consistent, MassChoice::Redistributed];
/// A run whose |E_aug(T) − E_aug(0)| exceeds this fraction of its energy scale has not converged
/// to anything physical (explicit contact blows up slowly rather than failing Newton).
const BOUNDED: f64 = 0.5;
/// The bar's first contact phase is t ∈ [1, 2] (its exact solution): its pressure is looked at
/// over this window around it.
const BAR_PHASE: (f64, f64) = (0.5, 2.5);

/// One run of the sweep.
#[derive(Clone, Debug, Serialize)]
pub struct Point {
    pub case: &'static str,
    pub scheme: String,
    pub mass: &'static str,
    pub dt: f64,
    /// The measures, or why the run failed.
    pub outcome: Result<Measures, String>,
}

#[derive(Clone, Debug, Serialize)]
pub struct Measures {
    /// (E_aug(T) − E_aug(0)) / E_aug(0) on the bar; over the largest kinetic energy on the disc,
    /// which starts at rest with E_aug(0) = 0.
    pub energy_change: f64,
    /// Total variation of the contact pressure over the first contact phase over that of a
    /// clean pulse (bar: the exact solution's, 1; disc: 2 max f_y, one rise and one fall).
    /// 1 = no spurious oscillation.
    pub oscillation: f64,
    /// The same from the pressure at t^{n+1/2}, where midpoint and hybrid impose contact (bar).
    pub oscillation_half: f64,
    /// Mean and largest Newton iterations per step.
    pub newton_mean: f64,
    pub newton_max: usize,
    pub max_penetration: f64,
    /// What the run was: the mesh, the end time, the contact law and its params.
    #[serde(skip)]
    pub setting: String,
}

impl Point {
    pub fn converged(&self) -> bool {
        self.outcome.as_ref().is_ok_and(|m| m.energy_change.abs() < BOUNDED)
    }
}

/// The sweep's runs: coarse steps lose accuracy on purpose, and the energy guard stops a run
/// only where the sweep would not count it as converging.
fn sweep_setup(scheme: &str) -> Methods {
    let mut methods = Methods { scheme: scheme.into(), ..Methods::default() };
    methods.guard.energy_tolerance = BOUNDED;
    methods
}

fn bar_point(scheme: &str, mass: MassChoice, dt: f64) -> Result<Measures, CaseError> {
    let methods = sweep_setup(scheme);
    let r = bar::run(&Options { methods, mass, dt: Some(dt), ..bar::options() })?;
    let s = &r.summary;
    let variation = |f: fn(&bar::Row) -> f64| -> f64 {
        let phase: Vec<f64> =
            r.series.iter().filter(|row| (BAR_PHASE.0..=BAR_PHASE.1).contains(&row.t)).map(f).collect();
        phase.windows(2).map(|w| (w[1] - w[0]).abs()).sum()
    };
    Ok(Measures {
        energy_change: s.energy_aug_drift_final,
        oscillation: variation(|row| row.lambda),
        oscillation_half: variation(|row| row.lambda_half),
        newton_mean: s.newton_total as f64 / s.steps.max(1) as f64,
        newton_max: s.newton_max,
        max_penetration: s.max_penetration,
        setting: format!("N = {} elements, T = {}, {}", s.elements, s.t_end, super::law(&s.contact, &s.params)),
    })
}

fn disc_point(scheme: &str, mass: MassChoice, dt: f64) -> Result<Measures, CaseError> {
    let methods = sweep_setup(scheme);
    let r = disc::run(&Options { methods, mass, dt: Some(dt), ..disc::options() })?;
    let s = &r.summary;
    // The first contact phase: from the first step with an active point to the next without.
    let start = r.series.iter().position(|row| row.active_points > 0);
    let phase: Vec<f64> = start.map_or(Vec::new(), |k| {
        r.series[k.saturating_sub(1)..]
            .iter()
            .enumerate()
            .take_while(|(i, row)| *i < 2 || row.active_points > 0)
            .map(|(_, row)| row.f_vertical_contact)
            .collect()
    });
    let peak = phase.iter().fold(0.0f64, |m, f| m.max(f.abs()));
    let tv: f64 = phase.windows(2).map(|w| (w[1] - w[0]).abs()).sum();
    Ok(Measures {
        // E_aug(0) = 0 (at rest, u = 0): relative to the kinetic energy at impact.
        energy_change: (s.energy_aug_final - s.energy_aug_initial) / s.kinetic_energy_max,
        oscillation: if peak > 0.0 { tv / (2.0 * peak) } else { f64::NAN },
        oscillation_half: f64::NAN,
        newton_mean: s.newton_total as f64 / s.steps.max(1) as f64,
        newton_max: s.newton_max,
        max_penetration: s.max_penetration,
        setting: format!("{}, T = {}, {}", s.mesh, s.t_end, super::law(&s.contact, &s.params)),
    })
}

/// Every run of the sweeps.
#[derive(Serialize)]
pub struct Sweeps {
    pub points: Vec<Point>,
}

pub type Measure = fn(&str, MassChoice, f64) -> Result<Measures, CaseError>;

/// One sweep: the case, its Δt ladder, its measurement.
pub struct Case {
    pub name: &'static str,
    pub steps: &'static [f64],
    pub measure: Measure,
}

/// The bar's and the disc's sweeps (their problems: forms/library.toml's `cases`).
pub fn cases() -> [Case; 2] {
    let names = &crate::settings::get().cases;
    [
        Case { name: &names.bar, steps: &BAR_STEPS, measure: bar_point },
        Case { name: &names.disc, steps: &DISC_STEPS, measure: disc_point },
    ]
}

/// Runs `cases` for every scheme and both masses.
pub fn run(progress: &mut dyn FnMut(&str), cases: &[Case]) -> Sweeps {
    let mut points = Vec::new();
    for &Case { name: case, steps, measure } in cases {
        for scheme in crate::driver::all_schemes() {
            for mass in MASSES {
                progress(&format!("{case} Δt sweep {scheme} {}", mass.name()));
                for &dt in steps {
                    let outcome = measure(scheme, mass, dt).map_err(|e| e.to_string());
                    points.push(Point { case, scheme: scheme.into(), mass: mass.name(), dt, outcome });
                }
            }
        }
    }
    Sweeps { points }
}

impl Sweeps {
    /// The runs of one case, scheme and mass, in Δt order.
    pub fn series(&self, case: &str, scheme: &str, mass: &str) -> Vec<&Point> {
        self.points.iter().filter(|p| p.case == case && p.scheme == scheme && p.mass == mass).collect()
    }

    /// The largest Δt at which the run and every run with a smaller Δt converged.
    pub fn largest_converging(&self, case: &str, scheme: &str, mass: &str) -> Option<f64> {
        self.series(case, scheme, mass).into_iter().take_while(|p| p.converged()).last().map(|p| p.dt)
    }

    /// The sweeps' tables; a failed run's full message goes to `failures`.
    pub fn markdown(&self, failures: &Failures) -> String {
        let mut cases: Vec<&str> = self.points.iter().map(|p| p.case).collect();
        cases.dedup();
        // What each case ran, from its first run that has measures.
        let settings: Vec<String> = cases
            .iter()
            .filter_map(|&case| {
                let m = self.points.iter().filter(|p| p.case == case).find_map(|p| p.outcome.as_ref().ok())?;
                Some(format!("{case}: {}", m.setting))
            })
            .collect();
        let mut md = format!(
            "Every scheme, consistent and redistributed mass (docs/mathematics.md §5). {}. `ΔE_aug` = (E_aug(T) − E_aug(0)) over the energy scale: E_aug(0) on the bar, the largest kinetic energy on the disc (which starts at rest, E_aug(0) = 0). `osc` = total variation of the contact pressure over the first contact phase divided by a clean pulse's (bar: λ over t ∈ [{}, {}] against the exact 1; disc: f_y from first contact to release against 2 max f_y): 1 = no spurious oscillation. `osc½`: the same on the bar from λ at t^{{n+½}}, computed from (uⁿ + uⁿ⁺¹)/2, where midpoint and hybrid impose contact. A run converges when Newton converges at every step and |ΔE_aug| < {BOUNDED}.\n\n### Largest converging Δt\n\n",
            settings.join("; "),
            BAR_PHASE.0,
            BAR_PHASE.1
        );
        let columns: Vec<(&str, &str)> =
            cases.iter().flat_map(|&c| MASSES.iter().map(move |&m| (c, m.name()))).collect();
        let mut header = vec!["scheme".to_string()];
        header.extend(columns.iter().map(|(case, mass)| format!("{case}, {mass}")));
        let mut largest = Table::new(&header);
        for scheme in crate::driver::all_schemes() {
            let mut row = vec![scheme.to_string()];
            row.extend(
                columns.iter().map(|(case, mass)| {
                    self.largest_converging(case, scheme, mass).map_or("none".to_string(), readable)
                }),
            );
            largest.row_vec(row);
        }
        md.push_str(&largest.markdown());
        for case in cases {
            let _ = write!(md, "\n### {case}\n\n![{case} Δt sweep]({case}_dt_sweep.png)\n\n");
            let mut table = Table::new(&[
                "scheme",
                "mass",
                "Δt",
                "ΔE_aug",
                "osc",
                "osc½",
                "max penetration",
                "Newton iterations per step (mean/max)",
            ]);
            for p in self.points.iter().filter(|p| p.case == case) {
                let (scheme, mass, dt) = (p.scheme.clone(), p.mass.to_string(), readable(p.dt));
                match &p.outcome {
                    Ok(m) => table.row([
                        scheme,
                        mass,
                        dt,
                        format!("{:+.2e}", m.energy_change),
                        format!("{:.2}", m.oscillation),
                        if m.oscillation_half.is_nan() { "—".into() } else { format!("{:.2}", m.oscillation_half) },
                        format!("{:.2e}", m.max_penetration),
                        format!("{:.2}/{}", m.newton_mean, m.newton_max),
                    ]),
                    Err(e) => {
                        let name = format!("{case}_{}_{}_dt{}", p.scheme, p.mass, readable(p.dt));
                        let cell = failures.cell(&name, e);
                        table.row([scheme, mass, dt, cell, String::new(), String::new(), String::new(), String::new()])
                    }
                }
            }
            md.push_str(&table.markdown());
        }
        md
    }

    /// `dir/bar_dt_sweep.png` and `dir/disc_dt_sweep.png`: |ΔE_aug|, the oscillation and Newton
    /// iterations against Δt (solid: consistent mass; dashed: redistributed).
    pub fn figures(&self, dir: &Path) -> Result<(), CaseError> {
        let mut cases: Vec<&str> = self.points.iter().map(|p| p.case).collect();
        cases.dedup();
        for case in cases {
            let path = dir.join(format!("{case}_dt_sweep.png"));
            let labels: Vec<(String, &str, &str)> = MASSES
                .iter()
                .flat_map(|&m| {
                    crate::driver::all_schemes().into_iter().map(move |s| {
                        let tag = if m == MassChoice::Redistributed { " (redistributed)" } else { "" };
                        (format!("{s}{tag}"), s, m.name())
                    })
                })
                .collect();
            let curves = |f: fn(&Measures) -> f64| -> Vec<Curve> {
                labels
                    .iter()
                    .map(|(label, scheme, mass)| Curve {
                        label,
                        points: self
                            .series(case, scheme, mass)
                            .into_iter()
                            .filter_map(|p| p.outcome.as_ref().ok().map(|m| (p.dt.log10(), f(m))))
                            .filter(|(_, y)| y.is_finite())
                            .collect(),
                        dashed: *mass == "redistributed",
                    })
                    .collect()
            };
            crate::plot::panels(
                &path,
                "log₁₀ Δt",
                &[
                    (
                        format!("{case}: log₁₀ |ΔE_aug| over T").as_str(),
                        "log₁₀ |ΔE_aug|",
                        curves(|m| m.energy_change.abs().max(1e-16).log10()),
                    ),
                    (format!("{case}: pressure oscillation (1 = none)").as_str(), "osc", curves(|m| m.oscillation)),
                    (format!("{case}: Newton iterations per step").as_str(), "mean", curves(|m| m.newton_mean)),
                ],
            )
            .map_err(|e| CaseError::Write { path: path.display().to_string(), source: std::io::Error::other(e) })?;
        }
        Ok(())
    }
}
