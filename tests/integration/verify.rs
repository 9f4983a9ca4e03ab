//! `signorini verify`'s measurements as CI checks (docs/mathematics.md §5): every scheme of the
//! library is second order on the oscillator and on the bar before impact, with ρ∞ ≤ 1;
//! Crank–Nicolson and midpoint conserve the augmented energy on every step whose active set is
//! unchanged, on the bar and the disc, with Nitsche θ = 1 and penalty; without contact every
//! scheme's energy decays per step like the square of its spectral radius; the library's problems
//! meet their `expect` lines; the frictional laws' tangents match finite differences in each regime.

use signorini::verify;

#[test]
fn every_scheme_is_second_order_and_stable_at_infinity() {
    let rows = verify::time::orders(&mut |_| {}).unwrap();
    assert_eq!(rows.len(), signorini::driver::all_schemes().len());
    for r in &rows {
        assert!((r.oscillator_order - 2.0).abs() < 0.05, "{}: oscillator order {}", r.scheme, r.oscillator_order);
        // The bar's free end starts with a stress jump: every mode of the mesh is excited, and
        // the finest pair of steps is in the asymptotic range (ω_max Δt ≤ 0.07).
        for b in &r.bar {
            // Nitsche's θ term acts before impact: the schemes that apply the contact slot
            // unlike the stiffness (explicitly; without HHT's weighting) lose order there.
            let inconsistent = b.contact == "nitsche" && matches!(r.scheme.as_str(), "hht_imex" | "hht_unweighted");
            if inconsistent {
                assert!(
                    b.order > 0.9 && b.order < 1.8,
                    "{} with {}: bar order {} ({b:?})",
                    r.scheme,
                    b.contact,
                    b.order
                );
            } else {
                assert!((b.order - 2.0).abs() < 0.1, "{} with {}: bar order {} ({b:?})", r.scheme, b.contact, b.order);
            }
        }
        assert_eq!(r.bar.len(), signorini::settings::get().verify.contacts.len());
        // An explicit scheme: ρ at its limit ωΔt = cfl, a double root on the unit circle (the
        // squarings measure it 1 + ~1e-9).
        let tolerance = if r.cfl.is_some() { 1e-8 } else { 1e-9 };
        assert!(r.rho_infinity <= 1.0 + tolerance, "{}: ρ∞ = {}", r.scheme, r.rho_infinity);
    }
    // The radius by repeated squaring against the closed forms (the one-step map at
    // ωΔt = 1e12 mixes entries of very different sizes: round-off of ~1e-8 in it).
    let get = |name: &str| rows.iter().find(|r| r.scheme == name).unwrap().rho_infinity;
    assert!((get("hht") - 0.95 / 1.05).abs() < 1e-6, "{}", get("hht") - 0.95 / 1.05);
    assert!((get("genalpha") - 0.8).abs() < 1e-6, "{}", get("genalpha") - 0.8);
    assert!(get("trbdf2") < 1e-6);
}

#[test]
fn crank_nicolson_and_midpoint_conserve_energy_while_the_active_set_is_kept() {
    let rows = verify::energy::contact_laws(&mut |_| {}).unwrap();
    // Bar and disc for every energy-conserving scheme × contact law of forms/library.toml.
    let v = &signorini::settings::get().verify;
    // The schemes that claim it: Crank–Nicolson (newmark), midpoint, and energy–momentum
    // (the midpoint rule for the linear material these runs bind).
    let conserving = verify::energy::conserving_schemes().unwrap();
    assert_eq!(conserving, ["energy_momentum", "midpoint", "newmark"]);
    assert_eq!(rows.len(), 2 * conserving.len() * v.contacts.len());
    for r in &rows {
        // Newton stops at a relative residual of 1e-10: the disc's steps keep E_aug to ~3e-11
        // of its energy scale, the bar's to ~4e-14.
        assert!(r.kept_largest < 1e-9, "{r:?}");
        assert!(r.kept_steps > 500 && r.changed_steps > 5, "{r:?}");
        // The jumps' signs (docs/mathematics.md §5): Crank–Nicolson loses energy when points
        // enter contact and gains it when they leave; midpoint the reverse.
        let sign = if r.scheme == "newmark" { 1.0 } else { -1.0 };
        assert!(r.entering_steps > 0 && r.releasing_steps > 0, "{r:?}");
        let (entering, releasing) = if sign > 0.0 {
            (r.entering_range.1, -r.releasing_range.0)
        } else {
            (-r.entering_range.0, r.releasing_range.1)
        };
        assert!(entering <= 1e-9 && releasing <= 1e-9, "{r:?}");
    }
}

#[test]
fn without_contact_energy_decays_like_the_spectral_radius_squared() {
    let rows = verify::energy::dissipation(&mut |_| {}).unwrap();
    // Every scheme at every ωΔt, an explicit one (central differences, cfl = 2) only where it
    // is stable.
    let expected: usize = signorini::driver::all_schemes()
        .into_iter()
        .map(|scheme| {
            let methods = signorini::driver::Methods { scheme: scheme.into(), ..Default::default() };
            let cfl = verify::claimed_cfl(&methods).unwrap().unwrap_or(f64::INFINITY);
            verify::energy::DISSIPATION_STEPS.iter().filter(|x| **x <= cfl).count()
        })
        .sum();
    assert_eq!(rows.len(), expected);
    for r in &rows {
        let methods = signorini::driver::Methods { scheme: r.scheme.clone(), ..Default::default() };
        if verify::claimed_cfl(&methods).unwrap().is_some() {
            // Central differences keep a modified energy, ½v² + ½(1 − (ωΔt)²/4)u²: the
            // physical one oscillates about it by a fraction of order (ωΔt)², without drift.
            assert!((r.final_ratio - 1.0).abs() <= r.omega_dt * r.omega_dt, "{r:?}");
            assert!(r.rho <= 1.0 + 1e-12, "{r:?}");
            continue;
        }
        if r.rho > 1.0 - 1e-12 {
            // Conserving (Crank–Nicolson, midpoint, hybrid without contact): to round-off.
            assert!((r.final_ratio - 1.0).abs() < 1e-10, "{r:?}");
        } else {
            // Dissipating: E never grows, and its mean decay rate is ρ (transients of the
            // non-normal one-step map account for the tolerance).
            assert!(r.final_ratio < 1.0, "{r:?}");
            assert!((r.measured_rate - r.rho).abs() < 1e-3 * r.rho.max(1e-3), "{r:?}");
        }
        assert!(r.rho <= 1.0 + 1e-12, "{r:?}");
    }
}

/// `verify`'s (e): the library's problems that state `expect` lines (found in the library:
/// the friction problems today) meet them at their defaults, and each row is the run's own
/// key against a finite expected value.
#[test]
fn the_library_problems_meet_what_they_expect() {
    let rows = verify::limits::expectations(&mut |_| {}).unwrap();
    let problems: std::collections::BTreeSet<&str> = rows.iter().map(|r| r.problem.as_str()).collect();
    for p in ["rolling_disc", "shear_block", "sliding_block"] {
        assert!(problems.contains(p), "{p} states expectations: {problems:?}");
    }
    for r in &rows {
        let x = &r.expectation;
        assert!(x.expected.is_some_and(f64::is_finite) && x.value.is_some(), "{}: {x:?}", r.problem);
        assert!(x.met, "{} ({} {}): {x:?}", r.problem, r.scheme, r.contact);
    }
    assert!(
        verify::limits::markdown(&rows).contains("| rolling_disc | hht | contact_nitsche_coulomb | rolling_time |")
    );
}

/// verify (f): every frictional law of the library, in separation, stick and slip (each shown to
/// be the regime intended by the law's own functionals), has a tangent equal to central
/// differences of its residual; a Coulomb law's active set decides its tangent out of contact
/// (no friction radius) and not in stick or slip, a Tresca law's nowhere (its radius is s).
/// The Coulomb laws are those that are not Tresca's (`penalty_deformed` is one).
#[test]
fn every_frictional_law_s_tangent_matches_finite_differences_in_every_regime() {
    let rows = verify::tangents::regimes(&mut |_| {}).unwrap();
    let laws = signorini::driver::frictional_contact_names();
    assert_eq!(rows.len(), 3 * laws.len(), "three regimes per law");
    for r in &rows {
        assert!(r.present, "{} {}: not in its regime: {r:?}", r.contact, r.regime);
        assert!(r.error <= verify::tangents::TOLERANCE, "{} {}: tangent off by {:e}", r.contact, r.regime, r.error);
        let coulomb = !r.contact.ends_with("tresca");
        assert_eq!(
            r.decided,
            coulomb && r.regime == "separation",
            "{} {}: set decides: {}",
            r.contact,
            r.regime,
            r.decided
        );
    }
    for law in ["nitsche_coulomb", "nitsche_tresca", "penalty_coulomb"] {
        assert!(rows.iter().any(|r| r.contact == law), "{law} is checked");
    }
    assert!(verify::tangents::markdown(&rows).contains("| penalty_coulomb | slip |"));
}
