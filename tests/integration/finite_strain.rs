//! Finite strain: materials whose stiffness is nonlinear in u (docs/mathematics.md §8). A block
//! pulled to a homogeneous stretch has the material's closed-form stress to round-off; a free
//! body spun through whole turns keeps its exact angular and linear momenta under the
//! midpoint rule, and stays strain-free to round-off of its kinetic energy.

use signorini::driver::Setting;
use signorini::problem::run::{Options, run};

fn setting(name: &str, value: f64) -> Setting {
    Setting { name: name.into(), value, origin: "test".into() }
}

/// Lamé's constants of E = 100, ν = 0.3 (the stretched block's).
fn lame() -> (f64, f64) {
    let (e, nu) = (100.0, 0.3);
    (e / (2.0 * (1.0 + nu)), e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)))
}

/// The first Piola–Kirchhoff stress's diagonal and the stored energy of F = diag(λ₁, λ₂) (plane
/// strain): neo-Hookean and Saint Venant–Kirchhoff.
fn closed_form(material: &str, l1: f64, l2: f64) -> (f64, f64, f64) {
    let (mu, lambda) = lame();
    match material {
        "neo_hookean" => {
            let lj = (l1 * l2).ln();
            let p = |l: f64| mu * (l - 1.0 / l) + lambda * lj / l;
            let w = mu / 2.0 * (l1 * l1 + l2 * l2 - 2.0) - mu * lj + lambda / 2.0 * lj * lj;
            (p(l1), p(l2), w)
        }
        "saint_venant_kirchhoff" => {
            let (e1, e2) = ((l1 * l1 - 1.0) / 2.0, (l2 * l2 - 1.0) / 2.0);
            let s = |e: f64| lambda * (e1 + e2) + 2.0 * mu * e;
            let w = lambda / 2.0 * (e1 + e2).powi(2) + mu * (e1 * e1 + e2 * e2);
            (l1 * s(e1), l2 * s(e2), w)
        }
        _ => unreachable!(),
    }
}

#[test]
fn a_block_stretched_homogeneously_has_the_closed_form_stress_to_round_off() {
    for material in ["neo_hookean", "saint_venant_kirchhoff"] {
        for (stretch, cells) in [(2.0, 2.0), (0.7, 3.0), (1.0 + 1e-3, 2.0)] {
            let mut o = Options::new("stretched_block");
            o.methods.material = material.into();
            o.chosen.material = true;
            o.methods.params.extend([setting("stretch", stretch), setting("cells", cells)]);
            let r = run(&o).unwrap();
            let key = |k: &str| r.summary.number(k).unwrap();
            let l2 = key("lateral_stretch");
            let (p11, p22, w) = closed_form(material, stretch, l2);
            // The stresses are sums of terms of size E that cancel at small strain: round-off
            // and Newton's tolerance are relative to |P₁₁| + E.
            let scale = p11.abs() + 100.0;
            // The lateral faces are free: P₂₂ = 0 fixes λ₂.
            assert!(p22.abs() < 1e-11 * scale, "{material} λ₁ = {stretch}: P₂₂ = {p22:e} at λ₂ = {l2}");
            let pulled = key("pulled");
            assert!((pulled - p11).abs() < 1e-11 * scale, "{material} λ₁ = {stretch}: force {pulled} vs P₁₁ {p11}");
            let stored = key("stored");
            // W is P's integral: its error is the stress's times the strain.
            let strain = (stretch - 1.0f64).abs().max((l2 - 1.0).abs());
            assert!((stored - w).abs() < 1e-11 * scale * strain, "{material}: W {stored} vs {w}");
            assert!(key("iterations") <= 12.0);
        }
    }
}

/// The turning disc (ω = 1, R = 1, ρ = 1) through three turns at h = 0.5, Δt = 0.02, with a
/// material, a scheme and E.
fn turning(material: &str, scheme: &str, young: f64) -> signorini::problem::run::Run {
    let mut o = Options::new("turning_disc");
    o.methods.material = material.into();
    o.chosen.material = true;
    o.methods.scheme = scheme.into();
    o.chosen.scheme = true;
    o.dt = Some(0.02);
    o.methods.params.extend([setting("h", 0.5), setting("young", young), setting("turns", 3.0)]);
    run(&o).unwrap()
}

#[test]
fn the_midpoint_rule_keeps_a_turning_body_s_momenta() {
    let r = turning("neo_hookean", "midpoint", 1e4);
    let key = |k: &str| r.summary.number(k).unwrap();
    // Three whole turns: the point that started at (1, 0) went round.
    let turned = r.column("turned").unwrap();
    let laps = turned.windows(2).filter(|w| w[0] > 3.0 && w[1] < -3.0).count();
    assert_eq!(laps, 3, "the disc turned {laps} times");
    // ∫ρ (x + u) × v and ∫ρ v, exact for frame-indifferent W (docs/mathematics.md §8), to
    // Newton's tolerance.
    assert!(key("angular_drift") < 1e-10, "angular momentum drifted by {:e}", key("angular_drift"));
    assert!(key("momentum_max") < 1e-12 * key("angular_initial"), "linear momentum {:e}", key("momentum_max"));
    // Strain-free turning: the disc keeps its size (the linear material's grows without bound).
    assert!((key("radius_max") - 1.0).abs() < 1e-3, "radius {}", key("radius_max"));
    let linear = turning("elasticity", "midpoint", 1e4);
    assert!(linear.summary.number("radius_max").unwrap() > 10.0, "a linear material turned strain-free");
}

#[test]
fn the_energy_momentum_scheme_keeps_the_energy_and_strains_only_centrifugally() {
    let mut stored = Vec::new();
    for young in [1e4, 1e8] {
        let r = turning("saint_venant_kirchhoff", "energy_momentum", young);
        let key = |k: &str| r.summary.number(k).unwrap();
        // W(u') − W(u) is the discrete gradient's work exactly: E is kept to Newton's tolerance.
        assert!(key("energy_drift") < 1e-9, "E = {young}: energy drifted by {:e}", key("energy_drift"));
        assert!(key("angular_drift") < 1e-9, "E = {young}: angular momentum drifted by {:e}", key("angular_drift"));
        stored.push(key("stored_max") / (key("kinetic_initial") * key("strain_scale")));
    }
    // The stored energy is the centrifugal stretch's, of order ρω²R²/E of the kinetic energy,
    // with the same constant for a body 10⁴ times stiffer: none of it is the rotation's.
    assert!(stored.iter().all(|s| *s > 0.1 && *s < 2.0), "W_max / (K ρω²R²/E) = {stored:?}");
    assert!((stored[0] / stored[1] - 1.0).abs() < 0.05, "{stored:?}");
}

#[test]
fn a_step_that_turns_a_cell_inside_out_is_cut_and_the_cut_steps_go_through() {
    let file = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/problems/crushed_block.wf");
    let r = run(&Options::new(file.to_str().unwrap())).unwrap();
    assert!(r.summary.number("step_cuts").unwrap() > 0.0, "no step was cut");
    assert_eq!(r.summary.number("final_width"), Some(0.5));
    // Every row written is a state with J > 0: its strain energy is finite.
    assert!(r.column("stored").unwrap().iter().all(|w| w.is_finite() && *w >= 0.0));
}

/// Hertz's cylinder (level 1) with a load `ratio` = a/R, linear or neo-Hookean: the peak
/// contact pressure.
fn hertz_peak(material: &str, ratio: f64) -> f64 {
    let mut o = Options::new("hertz_cylinder");
    o.methods.material = material.into();
    o.chosen.material = true;
    o.methods.params.extend([setting("level", 1.0), setting("ratio", ratio)]);
    run(&o).unwrap().summary.number("peak_pressure").unwrap()
}

#[test]
fn at_small_loads_the_neo_hookean_contact_approaches_the_linear_one_at_first_order() {
    // The strains scale with a/R: the finite-strain terms change the stress by a relative
    // O(a/R), so the relative difference of the peak pressures halves with the load's a/R.
    let gaps: Vec<f64> = [0.1, 0.05, 0.025]
        .iter()
        .map(|&r| {
            let linear = hertz_peak("elasticity", r);
            (hertz_peak("neo_hookean", r) - linear).abs() / linear
        })
        .collect();
    for w in gaps.windows(2) {
        let order = (w[0] / w[1]).log2();
        assert!((0.8..1.3).contains(&order), "relative differences {gaps:?}: order {order}");
    }
    assert!(gaps[2] < 3e-3, "{gaps:?}");
}

/// The pressed block's run with a material, a contact law and params.
fn pressed(material: &str, contact: &str, params: &[(&str, f64)]) -> signorini::problem::run::Run {
    let mut o = Options::new("pressed_block");
    o.methods.material = material.into();
    o.chosen.material = true;
    o.methods.contact = contact.into();
    o.chosen.contact = true;
    o.methods.params.extend(params.iter().map(|(k, v)| setting(k, *v)));
    run(&o).unwrap()
}

#[test]
fn nitsche_on_the_deformed_configuration_is_consistent_at_finite_strain() {
    for material in ["neo_hookean", "saint_venant_kirchhoff"] {
        for theta in [1.0, 0.0, -1.0] {
            for (press, cells) in [(0.3, 2.0), (0.05, 3.0)] {
                let r = pressed(material, "nitsche_deformed", &[("press", press), ("cells", cells), ("theta", theta)]);
                let key = |k: &str| r.summary.number(k).unwrap();
                let (l1, l2) = (key("lateral_stretch"), 1.0 - press);
                let (p11, p22, _) = closed_form(material, l1, l2);
                let scale = p22.abs() + 100.0;
                let what = format!("{material}, θ = {theta}, press {press}");
                // The sides are free and the bottom slides: P₁₁ = 0 fixes λ₁.
                assert!(p11.abs() < 1e-11 * scale, "{what}: P₁₁ = {p11:e} at λ₁ = {l1}");
                // The plane pushes with the material's traction, as the top is pushed.
                for k in ["top_force", "contact_force"] {
                    assert!((key(k) + p22).abs() < 1e-11 * scale, "{what}: {k} {} vs −P₂₂ {}", key(k), -p22);
                }
                assert!(key("iterations") <= 12.0);
            }
        }
    }
}

#[test]
fn a_traction_of_small_strain_misses_the_finite_strain_equilibrium() {
    // The exact equilibrium: λ₁ where P₁₁(λ₁, 0.7) = 0, by bisection (P₁₁ grows with λ₁).
    let (mut lo, mut hi) = (0.5, 2.0);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if closed_form("neo_hookean", mid, 0.7).0 > 0.0 { hi = mid } else { lo = mid }
    }
    let (_, p22, _) = closed_form("neo_hookean", lo, 0.7);
    // Hooke's σ_N on the reference configuration: the plane does not push with the material's
    // traction, and the equilibrium found is another (6.6 % off at λ₂ = 0.7).
    let r = pressed("neo_hookean", "nitsche", &[("press", 0.3)]);
    let force = r.summary.number("contact_force").unwrap();
    assert!((force + p22).abs() > 0.05 * p22.abs(), "{force} vs −P₂₂ {}", -p22);
    let r = pressed("neo_hookean", "nitsche_deformed", &[("press", 0.3)]);
    let force = r.summary.number("contact_force").unwrap();
    assert!((force + p22).abs() < 1e-11 * (p22.abs() + 100.0), "{force} vs −P₂₂ {}", -p22);
}

/// The bar of `bar.wf` (E = ρ = 1, ν = 0, h = 1/20, released from u₀ = (1 − x)/2, so F = 1/2)
/// of neo-Hookean material under central differences with steps of `dt`.
fn central_bar(dt: f64) -> Result<signorini::problem::run::Run, signorini::error::CaseError> {
    let mut o = Options::new("bar");
    o.methods.material = "neo_hookean".into();
    o.chosen.material = true;
    o.methods.scheme = "central".into();
    o.chosen.scheme = true;
    o.dt = Some(dt);
    o.t_end = Some(3.0);
    run(&o)
}

#[test]
fn central_differences_follow_the_critical_step_of_the_current_tangent() {
    use signorini::error::CaseError;
    // At F = 1/2 the 1D neo-Hookean modulus ∂P/∂F = μ(1 + F⁻²) is 5/2 of E = 2μ: the bulk's
    // ω_max = 2√3 c/h grows by √(5/2), and the contact's stiffness (in the estimate too) only
    // raises it. Δt = 0.02 is below Δt_c at rest but above it at the start.
    let bulk = 2.0 / (2.0 * 3f64.sqrt() * 2.5f64.sqrt() / 0.05);
    match central_bar(0.02) {
        Err(CaseError::Stiffened { t, stable, initial, .. }) => {
            assert_eq!(t, 0.0);
            assert!(stable < 0.02 && 0.02 < initial, "Δt_c {stable} now, {initial} at rest");
            assert!(stable <= bulk && stable > 0.95 * bulk, "Δt_c {stable} against the bulk's {bulk}");
        }
        other => panic!("expected a refusal at the start, got {:?}", other.map(|r| r.summary.number("stable_dt"))),
    }
    // Below it, the run goes through and reports the smallest Δt_c it met.
    let r = central_bar(0.005).unwrap();
    let least = r.summary.number("stable_dt_least").unwrap();
    let rest = r.summary.number("stable_dt").unwrap();
    assert!(least < bulk && least > 0.005, "least Δt_c {least}, at rest {rest}");
}

#[test]
fn nitsche_at_finite_strain_with_theta_below_one_is_solved_as_the_nonsymmetric_system_it_is() {
    // Its tangent is nonsymmetric only in contact, where the material is finite only near its
    // rest: the stepper's probe must find both at once (a rigid translation into the obstacle),
    // or Cholesky, reading half the matrix, meets the first contact as a singular matrix.
    for theta in [0.0, -1.0] {
        let mut o = Options::new("disc");
        o.methods.material = "neo_hookean".into();
        o.chosen.material = true;
        o.methods.contact = "nitsche_deformed".into();
        o.chosen.contact = true;
        o.methods.params.push(setting("theta", theta));
        o.t_start = Some(6.2);
        o.t_end = Some(6.6);
        let r = run(&o).unwrap_or_else(|e| panic!("θ = {theta}: {e}"));
        assert!(r.summary.number("first_contact").is_some_and(|t| t < 6.6), "θ = {theta}: no contact");
    }
}
