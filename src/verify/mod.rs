//! `signorini verify`: the claims the mathematics makes, measured (docs/mathematics.md §5, §7).
//! (a) every scheme's time order on the oscillator and on the bar before impact, and its ρ∞;
//! (b) space orders of P1 and P2 in 1D, 2D and 3D on manufactured solutions; (c) the discrete
//! energy laws, with contact and without; (d) the disc's convergence under Δt and h refinement;
//! (e) the limits the library's problems expect (`expect` lines: rigid bodies, friction bounds);
//! (f) the frictional laws' tangents in separation, stick and slip.
//! Written as DIR/verify.md with figures in DIR/verify/ (`signorini report` includes it).

pub mod convergence;
pub mod energy;
pub mod limits;
mod oscillator;
pub mod scheme;
pub mod space;
pub mod tangents;
pub mod time;

use std::fmt::Write;
use std::path::Path;

use serde::Serialize;

/// The ωΔt up to which the scheme claims to be stable: its `claim cfl` (an explicit scheme);
/// none for a scheme that claims no limit.
pub fn claimed_cfl(methods: &crate::driver::Methods) -> Result<Option<f64>, crate::error::CaseError> {
    let in_use = crate::driver::FilesInUse::resolve(methods, &[])?;
    Ok(in_use.scheme_claims()?.into_iter().find(|(c, _)| c == "cfl").map(|(_, v)| v))
}

pub use oscillator::{oscillator_energies, oscillator_error, spectral_radius, with_oscillator, with_oscillator_scheme};

use crate::error::CaseError;
use crate::plot::Curve;

/// Everything `signorini verify` measures.
#[derive(Clone, Debug, Serialize)]
pub struct Verification {
    pub time: Vec<time::TimeRow>,
    pub space: Vec<space::SpaceRow>,
    pub energy: Vec<energy::EnergyRow>,
    pub dissipation: Vec<energy::DissipationRow>,
    pub disc: convergence::DiscConvergence,
    pub limits: Vec<limits::LimitRow>,
    pub regimes: Vec<tangents::RegimeRow>,
}

/// Runs every measurement.
pub fn run(progress: &mut dyn FnMut(&str)) -> Result<Verification, CaseError> {
    Ok(Verification {
        time: time::orders(progress)?,
        space: space::orders(progress)?,
        energy: energy::contact_laws(progress)?,
        dissipation: energy::dissipation(progress)?,
        disc: convergence::disc(progress),
        limits: limits::expectations(progress)?,
        regimes: tangents::regimes(progress)?,
    })
}

/// (log₁₀ x, log₁₀ y), for log-log figures.
fn log10(points: impl IntoIterator<Item = (f64, f64)>) -> Vec<(f64, f64)> {
    points.into_iter().filter(|(x, y)| *x > 0.0 && *y > 0.0).map(|(x, y)| (x.log10(), y.log10())).collect()
}

fn plot_error(path: &Path) -> impl Fn(String) -> CaseError + '_ {
    move |e| CaseError::Write { path: path.display().to_string(), source: std::io::Error::other(e) }
}

impl Verification {
    /// Writes `dir/verify.md`, `dir/verify.json` and the figures in `dir/verify/`.
    pub fn write(&self, dir: &Path) -> Result<(), CaseError> {
        self.figures(&dir.join("verify"))?;
        let json = dir.join("verify.json");
        crate::output::write_json(&json, self)
            .map_err(|source| CaseError::Write { path: json.display().to_string(), source })?;
        let md = dir.join("verify.md");
        crate::output::write_atomic(&md, format!("# signorini verify\n\n{}", self.markdown()).as_bytes())
            .map_err(|source| CaseError::Write { path: md.display().to_string(), source })
    }

    /// The figures, in `dir`.
    pub fn figures(&self, dir: &Path) -> Result<(), CaseError> {
        let path = dir.join("time_orders.png");
        let osc: Vec<Curve> = self
            .time
            .iter()
            .map(|r| Curve { label: &r.scheme, points: log10(r.oscillator.clone()), dashed: false })
            .collect();
        let labels: Vec<String> =
            self.time.iter().flat_map(|r| r.bar.iter().map(move |b| format!("{} ({})", r.scheme, b.contact))).collect();
        let bar: Vec<Curve> = self
            .time
            .iter()
            .flat_map(|r| r.bar.iter().enumerate())
            .zip(&labels)
            .map(|((k, b), label)| Curve { label, points: log10(b.differences.clone()), dashed: k > 0 })
            .collect();
        crate::plot::panels(
            &path,
            "log₁₀ Δt",
            &[
                ("oscillator: |u(10) − cos 10|", "log₁₀ error", osc),
                ("bar before impact: max |u_c,Δt − u_c,Δt/2| (dashed: second contact law)", "log₁₀ difference", bar),
            ],
        )
        .map_err(plot_error(&path))?;
        let path = dir.join("space_orders.png");
        let labels: Vec<String> = self.space.iter().map(|r| format!("{} P{}", r.case, r.degree)).collect();
        let curve = |k: usize, f: fn(&(f64, f64, f64)) -> f64| -> Vec<Curve> {
            self.space
                .iter()
                .zip(&labels)
                .map(|(r, l)| Curve {
                    label: l,
                    points: log10(r.errors.iter().map(|e| (e.0, f(e)))),
                    dashed: r.degree as usize != k,
                })
                .collect()
        };
        crate::plot::panels(
            &path,
            "log₁₀ h",
            &[
                ("manufactured solutions: L2 error (dashed: P1)", "log₁₀ L2 error", curve(2, |e| e.1)),
                ("manufactured solutions: H1 error (dashed: P1)", "log₁₀ H1 error", curve(2, |e| e.2)),
            ],
        )
        .map_err(plot_error(&path))?;
        let path = dir.join("disc_convergence.png");
        let dt: Vec<Curve> = self
            .disc
            .dt
            .iter()
            .map(|s| Curve {
                label: &s.scheme,
                points: log10(s.errors.iter().map(|e| (e.step, e.uy_mean))),
                dashed: false,
            })
            .collect();
        let h = vec![
            Curve {
                label: "ū_y",
                points: log10(self.disc.h.errors.iter().map(|e| (e.step, e.uy_mean))),
                dashed: false,
            },
            Curve {
                label: "v̄_y",
                points: log10(self.disc.h.errors.iter().map(|e| (e.step, e.vy_mean))),
                dashed: false,
            },
            Curve {
                label: "f_y",
                points: log10(self.disc.h.errors.iter().map(|e| (e.step, e.fy_contact))),
                dashed: false,
            },
        ];
        crate::plot::panels(
            &path,
            "log₁₀ Δt (top), log₁₀ h (bottom)",
            &[
                ("disc, Δt refinement: error of ū_y against Δt = 0.0025", "log₁₀ error", dt),
                ("disc, h refinement (default scheme): errors against h = 0.5", "log₁₀ error", h),
            ],
        )
        .map_err(plot_error(&path))
    }

    /// The tables, as Markdown (figures linked from `verify/`).
    pub fn markdown(&self) -> String {
        let mut md = String::new();
        let laws: Vec<&str> =
            self.time.first().map_or(Vec::new(), |r| r.bar.iter().map(|b| b.contact.as_str()).collect());
        md.push_str("### (a) Time order and spectral radius\n\nOscillator ü + u = 0 (one P1 element, T = 10): error |u(10) − cos 10| at Δt = 0.04, 0.02, 0.01. Bar before impact (N = 20, t ≤ 0.8, every mode excited), per contact law: d(Δt) = max |u_c,Δt − u_c,Δt/2| at Δt = 0.004 … 0.0005. Penalty's contact term vanishes before impact; Nitsche's θ term −θ/γ σ_n(u)σ_n(v) does not, so a scheme that treats the contact slot unlike the stiffness (explicitly, or without HHT's weighting) loses order there. Orders from the two smallest steps. ρ∞: spectral radius of the one-step map at ωΔt = 10¹².\n\n| scheme | oscillator error (Δt = 0.01) | order |");
        for law in &laws {
            let _ = write!(md, " bar, {law}: d(0.001) | order |");
        }
        md.push_str(" ρ∞ |\n|---|---|---|");
        md.push_str(&"---|---|".repeat(laws.len()));
        md.push_str("---|\n");
        for r in &self.time {
            let last = |p: &[(f64, f64)]| p.last().map_or(f64::NAN, |x| x.1);
            let _ = write!(md, "| {} | {:.2e} | {:.3} |", r.scheme, last(&r.oscillator), r.oscillator_order);
            for b in &r.bar {
                let _ = write!(md, " {:.2e} | {:.3} |", last(&b.differences), b.order);
            }
            let _ = writeln!(
                md,
                " {:.6}{} |",
                r.rho_infinity,
                r.cfl.map_or(String::new(), |c| format!(" (at ωΔt = cfl = {c})"))
            );
        }
        md.push_str("\n![time orders](verify/time_orders.png)\n\n");
        md.push_str("### (b) Space order\n\nLinear elasticity with a manufactured solution (u₁ = Πₖ sin πxₖ), the exact solution imposed on the boundary, through the library's compiled elasticity forms. Expected: L2 order p + 1, H1 order p.\n\n| mesh family | P | h (finest) | L2 error | L2 order | H1 error | H1 order |\n|---|---|---|---|---|---|---|\n");
        for r in &self.space {
            let (h, l2, h1) = r.errors.last().copied().unwrap_or((f64::NAN, f64::NAN, f64::NAN));
            let _ = writeln!(
                md,
                "| {} | {} | {h} | {l2:.2e} | {:.3} | {h1:.2e} | {:.3} |",
                r.case, r.degree, r.l2_order, r.h1_order
            );
        }
        md.push_str("\n![space orders](verify/space_orders.png)\n\n");
        // What each case ran, from its first row.
        let mut settings: Vec<String> = Vec::new();
        for r in &self.energy {
            let text = format!("{}: {}", r.case, r.setting);
            if !settings.iter().any(|s| s.starts_with(&format!("{}:", r.case))) {
                settings.push(text);
            }
        }
        let _ = write!(
            md,
            "### (c) Energy laws\n\nWith contact: Crank–Nicolson (Newmark β = ¼) and midpoint conserve E_aug on every step whose active set (contact status at the quadrature points) does not change; the other steps carry the jumps D of docs/mathematics.md §5. Relative to the largest |E| of the run. {}.\n\nOf the changed steps, those on which points only enter contact and those on which they only leave it (Crank–Nicolson: ΔE_aug ≤ 0 entering, ≥ 0 leaving; midpoint: the reverse), with the range of ΔE_aug over them.\n\n| case | scheme | contact | steps, active set kept | max \\|ΔE_aug\\| there | steps, active set changed | total ΔE_aug there | entering: steps, ΔE_aug range | leaving: steps, ΔE_aug range |\n|---|---|---|---|---|---|---|---|---|\n",
            settings.join("; ")
        );
        let range =
            |n: usize, r: (f64, f64)| if n == 0 { "0".to_string() } else { format!("{n}: [{:.1e}, {:.1e}]", r.0, r.1) };
        for r in &self.energy {
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | {:.1e} | {} | {:.2e} | {} | {} |",
                r.case,
                r.scheme,
                r.contact,
                r.kept_steps,
                r.kept_largest,
                r.changed_steps,
                r.changed_total,
                range(r.entering_steps, r.entering_range),
                range(r.releasing_steps, r.releasing_range)
            );
        }
        md.push_str("\nWithout contact (oscillator, 2000 steps): the energy decays per step like ρ², ρ the spectral radius of the one-step map at that ωΔt; `rate` = (E_N/E_0)^(1/2N). `max step increase`: the largest E_{n+1} − E_n over E_0. TR-BDF2's E decreases at every step; HHT's and generalized-α's E oscillates while it decays (their monotone energy is an algorithmic one, not E).\n\n| scheme | ωΔt | ρ | rate | E_N/E_0 | max step increase |\n|---|---|---|---|---|---|\n");
        for r in &self.dissipation {
            let _ = writeln!(
                md,
                "| {} | {} | {:.8} | {:.8} | {:.3e} | {:.1e} |",
                r.scheme, r.omega_dt, r.rho, r.measured_rate, r.final_ratio, r.largest_increase
            );
        }
        md.push_str("\n### (d) Convergence of the disc\n\nThrough the first impact (T = 12). Errors against a fine reference, at the run's own times: `ū_y` = max_t |ū_y − ū_y,ref| / max |ū_y,ref| (the centre of mass); `v̄_y` = the same for the centre of mass's velocity, which the contact impulse changes; `f_y` = the relative ℓ² error of the contact force itself, whose high-frequency oscillations (the stiff contact mode, ωΔt ≫ 1) no step here resolves. Δt refinement on the built-in h = 1 mesh, each scheme against itself at Δt = 0.0025:\n\n| scheme | ū_y at Δt = 0.04, 0.02, 0.01 | order | v̄_y | order | f_y | order |\n|---|---|---|---|---|---|---|\n");
        let list = |s: &convergence::Study, f: fn(&convergence::Errors) -> f64| {
            s.errors.iter().map(|e| format!("{:.2e}", f(e))).collect::<Vec<_>>().join(", ")
        };
        let row = |s: &convergence::Study| match &s.failure {
            // The cause in a sentence: a multi-line message would break the table's row.
            Some(f) => {
                format!("| {} | failed: {} | | | | | |", s.scheme, crate::report::table::cause(f).replace('|', "/"))
            }
            None => format!(
                "| {} | {} | {:.2} | {} | {:.2} | {} | {:.2} |",
                s.scheme,
                list(s, |e| e.uy_mean),
                s.uy_order,
                list(s, |e| e.vy_mean),
                s.vy_order,
                list(s, |e| e.fy_contact),
                s.fy_order
            ),
        };
        for s in &self.disc.dt {
            let _ = writeln!(md, "{}", row(s));
        }
        let _ = writeln!(
            md,
            "\nh refinement (Δt = 0.01) on the built-in meshes h = 4, 2, 1 against h = 0.5:\n\n| scheme | ū_y at h = 4, 2, 1 | order | v̄_y | order | f_y | order |\n|---|---|---|---|---|---|---|\n{}\n\n![disc convergence](verify/disc_convergence.png)\n",
            row(&self.disc.h)
        );
        md.push_str(&limits::markdown(&self.limits));
        md.push_str(&tangents::markdown(&self.regimes));
        md
    }
}

#[cfg(test)]
mod estimates {
    use crate::driver::Methods;

    /// Each library scheme's `estimate` is its local error in u to leading order on the
    /// oscillator: the ratio tends to 1 as O(Δt). A scheme that carries no acceleration between
    /// steps (midpoint, the hybrid scheme, energy–momentum) has nothing to compare and declares
    /// none.
    #[test]
    fn every_library_estimate_is_the_local_error() {
        for scheme in crate::driver::all_schemes() {
            let m = Methods { scheme: scheme.to_string(), ..Default::default() };
            let ratios: Vec<Option<f64>> =
                [1e-2, 1e-3].iter().map(|&h| super::oscillator::estimate_ratio(&m, h).unwrap()).collect();
            match ratios[..] {
                [Some(r2), Some(r3)] => {
                    assert!((r3 - 1.0).abs() < 2e-3, "{scheme}: {ratios:?}");
                    assert!((r3 - 1.0).abs() < 0.2 * (r2 - 1.0).abs(), "{scheme}: not O(Δt): {ratios:?}");
                }
                // Without an estimate: a scheme whose step carries no acceleration (u and v only).
                _ => {
                    let states = crate::driver::FilesInUse::resolve(&m, &[]).unwrap().scheme.desc().states.len();
                    assert_eq!(states, 2, "{scheme} carries an acceleration but declares no estimate");
                }
            }
        }
    }
}
