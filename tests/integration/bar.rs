//! The compressed bar (spec §6.1, §7): initial energy, Nitsche against penalty, convergence,
//! HHT dissipation, the hybrid scheme's energy decay, and the exact energy identities of
//! Crank–Nicolson and midpoint with contact.

use signorini::cases::bar;
use signorini::problem::run::Options;

fn run(f: impl FnOnce(&mut Options)) -> bar::Run {
    let mut o = bar::options();
    f(&mut o);
    bar::run(&o).unwrap()
}

#[test]
fn initial_energy_is_one_eighth() {
    let r = run(|o| o.t_end = Some(0.1));
    assert!((r.summary.energy_initial - 0.125).abs() < 1e-14, "{}", r.summary.energy_initial);
}

#[test]
fn nitsche_penetrates_less_than_penalty() {
    let nitsche = run(|_| {}).summary.max_penetration;
    let penalty = run(|o| o.methods.contact = "penalty".into()).summary.max_penetration;
    assert!(nitsche < 0.9 * penalty, "Nitsche {nitsche} vs penalty {penalty}");
}

#[test]
fn displacement_error_decreases_under_refinement() {
    let coarse = run(|_| {}).summary.err_linf_l2_u;
    let fine = run(|o| {
        o.methods = o.methods.clone().set("ne", 100.0);
        o.dt = Some(0.002);
    })
    .summary
    .err_linf_l2_u;
    assert!(fine < coarse, "{coarse} → {fine}");
}

#[test]
fn hht_dissipation_grows_with_alpha() {
    let e: Vec<f64> = [0.0, 0.05, 1.0 / 3.0]
        .iter()
        .map(|&a| {
            run(|o| {
                o.methods.scheme = "hht".into();
                o.methods = o.methods.clone().set("alpha", a);
            })
            .summary
            .energy_aug_final
        })
        .collect();
    assert!(e[0] > e[1] && e[1] > e[2], "{e:?}");
}

#[test]
fn hybrid_never_increases_the_augmented_energy() {
    for dt in [0.01, 0.05, 0.1] {
        let r = run(|o| {
            o.methods.scheme = "hybrid".into();
            o.dt = Some(dt);
        });
        let e0 = r.summary.energy_aug_initial;
        for w in r.series.windows(2) {
            assert!(
                w[1].energy_aug <= w[0].energy_aug + 1e-11 * e0,
                "dt = {dt}, t = {}: {} → {}",
                w[1].t,
                w[0].energy_aug,
                w[1].energy_aug
            );
        }
    }
}

/// Spec §4.2–4.3 with θ = 1 and one contact point: E_Θ increments equal D (weight 1).
#[test]
fn crank_nicolson_and_midpoint_energy_increments_match_the_formulas() {
    let gamma = 5.0 * 20.0;
    let neg = |p: f64| p.min(0.0);
    let cn = |p0: f64, p1: f64| (neg(p1).powi(2) - neg(p0).powi(2) - (neg(p0) + neg(p1)) * (p1 - p0)) / (2.0 * gamma);
    let mid = |p0: f64, p1: f64| {
        (neg(p1).powi(2) - neg(p0).powi(2)) / (2.0 * gamma) - neg(0.5 * (p0 + p1)) * (p1 - p0) / gamma
    };
    for (scheme, formula) in [("newmark", &cn as &dyn Fn(f64, f64) -> f64), ("midpoint", &mid)] {
        let r = run(|o| o.methods.scheme = scheme.into());
        let e0 = r.summary.energy_aug_initial;
        let (mut gains, mut losses) = (0, 0);
        for w in r.series.windows(2) {
            let d = formula(w[0].p1, w[1].p1);
            let de = w[1].energy_aug - w[0].energy_aug;
            assert!((de - d).abs() < 1e-11 * e0, "{scheme:?} t = {}: ΔE_Θ {de:e} vs D {d:e}", w[1].t);
            if d > 1e-14 * e0 {
                gains += 1;
            }
            if d < -1e-14 * e0 {
                losses += 1;
            }
        }
        assert!(gains > 0 && losses > 0, "{scheme:?}: {gains} gains, {losses} losses");
    }
}

/// Spec §7 check 10: with HHT or TR-BDF2, mass redistribution calms the contact stress: its
/// standard deviation over τ ∈ (1.2, 1.8) drops by at least 2×.
#[test]
fn mass_redistribution_calms_the_contact_stress() {
    use signorini::simulation::MassChoice;
    let std = |r: &bar::Run| {
        let lam: Vec<f64> = r.series.iter().filter(|row| row.t > 1.2 && row.t < 1.8).map(|row| row.lambda).collect();
        let mean = lam.iter().sum::<f64>() / lam.len() as f64;
        (lam.iter().map(|l| (l - mean).powi(2)).sum::<f64>() / lam.len() as f64).sqrt()
    };
    for scheme in ["hht", "trbdf2"] {
        let consistent = run(|o| o.methods.scheme = scheme.into());
        let redistributed = run(|o| {
            o.methods.scheme = scheme.into();
            o.mass = MassChoice::Redistributed;
        });
        let (a, b) = (std(&consistent), std(&redistributed));
        assert!(b <= a / 2.0, "{scheme:?}: std of λ {a} → {b}");
        assert!(
            redistributed.summary.max_penetration < 1e-12,
            "{scheme:?}: penetration {}",
            redistributed.summary.max_penetration
        );
    }
}

/// Spec §6.1 [P]: with redistributed mass, midpoint and hybrid impose contact at t^{n+½}, so
/// the contact stress at integer steps oscillates with period 2 while at half steps it is as
/// accurate as the other schemes' (err_λ of HHT and TR-BDF2 with redistribution ≈ 0.37).
#[test]
fn midpoint_schemes_measure_contact_at_half_steps() {
    use signorini::simulation::MassChoice;
    for scheme in ["midpoint", "hybrid"] {
        let s = run(|o| {
            o.methods.scheme = scheme.into();
            o.mass = MassChoice::Redistributed;
        })
        .summary;
        let half = s.err_l2_lambda_half.expect("contact on [0, 12]");
        assert!(half < 0.45, "{scheme:?}: err_λ at half steps {half}");
    }
    let midpoint = run(|o| {
        o.methods.scheme = "midpoint".into();
        o.mass = MassChoice::Redistributed;
    })
    .summary;
    let (full, half) = (midpoint.err_l2_lambda.unwrap(), midpoint.err_l2_lambda_half.unwrap());
    assert!(full > 4.0 * half, "{midpoint:?}");
}

/// In 1D σ(u)n = σ_N(u) n, so GetFEM's full-traction Nitsche law is the normal one, and GetFEM's
/// cell size is the length: the same series, step for step, for every θ.
#[test]
fn full_traction_nitsche_is_the_normal_law_in_1d() {
    for theta in [1.0, 0.0, -1.0] {
        let normal = run(|o| o.methods = o.methods.clone().set("theta", theta));
        let traction = run(|o| {
            o.methods = signorini::driver::Methods { contact: "nitsche-traction".into(), ..o.methods.clone() }
                .set("theta", theta);
            o.cell_size = signorini::runtime::fem::mesh::CellSize::GetFem;
        });
        for (a, b) in normal.series.iter().zip(&traction.series) {
            assert!((a.u_c - b.u_c).abs() <= 1e-14, "θ = {theta}, t = {}: {} vs {}", a.t, a.u_c, b.u_c);
        }
    }
}

/// Newton's stopping scale is the residual's own, not the inertial right-hand side's (∝ 1/Δt²):
/// from Δt = 1 down to 1e-7 every step iterates, and the error against the exact solution on
/// [0, 0.01] falls like Δt² onto the space error (the Δt = 1e-7 run's).
#[test]
fn time_steps_from_one_to_1e_minus_7_converge_onto_the_space_error() {
    for dt in [1.0, 0.1] {
        let r = run(|o| {
            o.dt = Some(dt);
            o.t_end = Some(dt);
        });
        assert!(r.series[1..].iter().all(|row| row.newton >= 1), "Δt = {dt}: a step without a Newton iteration");
        assert!(r.series.iter().all(|row| row.u_c.is_finite()), "Δt = {dt}");
    }
    let steps = [1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7];
    let errors: Vec<f64> = steps
        .iter()
        .map(|&dt| {
            let r = run(|o| {
                o.dt = Some(dt);
                o.t_end = Some(0.01);
            });
            assert!(r.series[1..].iter().all(|row| row.newton >= 1), "Δt = {dt}: a step without a Newton iteration");
            r.summary.err_linf_l2_u
        })
        .collect();
    let space = errors[errors.len() - 1];
    let time: Vec<f64> = errors.iter().map(|e| e - space).collect();
    // Second order: each tenth of Δt divides the time error by ~100, until round-off (1e-12).
    for k in 0..steps.len() - 1 {
        if time[k] > 1e-11 {
            assert!(time[k + 1] < time[k] / 50.0, "Δt {} → {}: time errors {time:?}", steps[k], steps[k + 1]);
        } else {
            assert!(time[k + 1].abs() < 1e-11, "Δt {}: {time:?}", steps[k + 1]);
        }
    }
    assert!(time[0] > 1e-7, "the largest step has a visible time error: {time:?}");
}

/// Nitsche θ = −1 with γ0 = 1e-6: the law's own work ((1 − θ)/γ ∫ [P]_- Δσ_N, which E_Θ does
/// not keep) drives the motion, and the energy explodes (to 1e140 by t = 12). The energy guard
/// stops the run once that work exceeds the energy that came from outside, with the cause,
/// writes the series up to the last good step and a summary that says why.
#[test]
fn an_unstable_run_stops_with_its_cause_and_its_results_so_far() {
    let dir = std::env::temp_dir().join(format!("signorini-blowup-{}", std::process::id()));
    let mut o = Options { out: Some(dir.clone()), ..bar::options() };
    o.methods = o.methods.clone().set("theta", -1.0).set("gamma0", 1e-6);
    let err = bar::run(&o).err().expect("the run must stop");
    let text = err.to_string();
    assert!(text.contains("drives the motion") && text.contains("gamma0 = 0.000001"), "{text}");
    let csv = std::fs::read_to_string(dir.join("series.csv")).unwrap();
    let last_t: f64 = csv.lines().last().unwrap().split(',').next().unwrap().parse().unwrap();
    assert!(last_t > 0.0 && last_t < 1.0, "stopped at {last_t}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    assert!(summary["stopped"].as_str().unwrap().contains("drives the motion"), "{summary}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A Newton allowed one iteration cannot follow the active set's change at first contact at
/// any Δt: the step is retried at Δt/2 ... Δt/64, then the run stops saying where, with the
/// residual history, after writing the series up to the last good step.
#[test]
fn a_step_that_fails_at_every_cut_stops_the_run_with_its_history() {
    let dir = std::env::temp_dir().join(format!("signorini-cuts-{}", std::process::id()));
    let mut o = Options { t_end: Some(2.0), out: Some(dir.clone()), ..bar::options() };
    o.newton.max_iterations = 1;
    let text = bar::run(&o).err().expect("no step converges in one iteration at contact").to_string();
    assert!(text.contains("after 6 step cuts") && text.contains("Newton: residual"), "{text}");
    let csv = std::fs::read_to_string(dir.join("series.csv")).unwrap();
    let times: Vec<f64> = csv.lines().skip(1).map(|l| l.split(',').next().unwrap().parse().unwrap()).collect();
    // Up to just before the impact at t = 1, the cut steps included.
    assert!(times.last().is_some_and(|t| *t > 0.99 && *t < 1.0), "{:?}", &times[times.len() - 3..]);
    assert!(times.windows(2).any(|w| w[1] - w[0] < 0.5 * (times[1] - times[0])), "no cut step in the series");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// ω_max of M⁻¹(K + J_C) on the bar (N = 20, E = ρ = 1, Nitsche θ = 1, γ = γ0/h = 100), the end
/// x = 0 in contact and x = 1 held, computed densely: P1 stiffness (1/h)[1 −1; −1 1] per
/// element, the lumped mass h/2 per element end or the consistent (h/6)[2 1; 1 2], and the
/// active contact term (1/γ)(b − γ∇u_N)(b − γ∇u_N)ᵀ − (1/γ) b bᵀ with b = ∇σ_N.
fn dense_omega_max(lumped: bool) -> f64 {
    use nalgebra::{DMatrix, SymmetricEigen};
    let (n, h, gamma) = (20, 1.0 / 20.0, 100.0);
    let (mut k, mut m) = (DMatrix::<f64>::zeros(n + 1, n + 1), DMatrix::<f64>::zeros(n + 1, n + 1));
    for e in 0..n {
        for (a, b, kv, mc, ml) in
            [(0, 0, 1.0, 2.0, 3.0), (0, 1, -1.0, 1.0, 0.0), (1, 0, -1.0, 1.0, 0.0), (1, 1, 1.0, 2.0, 3.0)]
        {
            k[(e + a, e + b)] += kv / h;
            m[(e + a, e + b)] += if lumped { ml * h / 6.0 } else { mc * h / 6.0 };
        }
    }
    let mut sigma = nalgebra::DVector::<f64>::zeros(n + 1);
    sigma[0] = -1.0 / h;
    sigma[1] = 1.0 / h;
    let mut un = nalgebra::DVector::<f64>::zeros(n + 1);
    un[0] = -1.0;
    let p = &sigma - gamma * &un;
    let a = k + (&p * p.transpose() - &sigma * sigma.transpose()) / gamma;
    // The held end's dof removed; M = L Lᵀ, and L⁻¹ A L⁻ᵀ is symmetric with M⁻¹A's eigenvalues.
    let (a, m) = (a.view((0, 0), (n, n)).into_owned(), m.view((0, 0), (n, n)).into_owned());
    let l = m.cholesky().expect("the mass is positive definite").l();
    let li = l.try_inverse().expect("invertible");
    let s = &li * a * li.transpose();
    SymmetricEigen::new(0.5 * (&s + s.transpose())).eigenvalues.max().sqrt()
}

/// Central differences (forms/schemes/central.wf, `claim cfl = 2`): the run's power-iteration
/// estimate of ω_max matches the dense eigenvalue, with either mass; below Δt_c the energy
/// guard stays quiet with either mass, as for the implicit Crank–Nicolson; above it the run is
/// refused before it steps.
#[test]
fn central_differences_know_their_critical_step() {
    use signorini::error::CaseError;
    use signorini::simulation::MassChoice;
    for (mass, lumped) in [(MassChoice::Consistent, false), (MassChoice::Lumped, true)] {
        let central = |dt: f64| {
            let mut o = Options { mass, dt: Some(dt), ..bar::options() };
            o.methods.scheme = "central".into();
            bar::run(&o)
        };
        let r = central(0.02).unwrap();
        let stable = r.summary.stable_dt.expect("an explicit scheme reports Δt_c");
        let omega = dense_omega_max(lumped);
        assert!((2.0 / stable - omega).abs() < 1e-8 * omega, "{mass:?}: ω_max {} against {omega}", 2.0 / stable);
        assert!(r.summary.energy_growth < 0.05, "{mass:?}: {}", r.summary.energy_growth);
        assert!(r.summary.energy_aug_drift_max < 0.04, "{mass:?}: {}", r.summary.energy_aug_drift_max);
        match central(1.01 * stable) {
            Err(CaseError::UnstableStep { stable: s, .. }) => assert_eq!(s, stable),
            other => panic!("{mass:?}: above Δt_c: {:?}", other.map(|r| r.summary.energy_growth)),
        }
    }
}
