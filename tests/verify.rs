//! `signorini verify`'s measurements as CI checks: every scheme of the library is second order
//! on the oscillator with ρ∞ ≤ 1; Crank–Nicolson and midpoint conserve the augmented energy
//! on every step whose active set is unchanged, on the bar and the disc, with Nitsche θ = 1
//! and penalty (docs/mathematics.md §5).

use signorini::verify;

#[test]
fn every_scheme_is_second_order_and_stable_at_infinity() {
    let rows = verify::schemes().unwrap();
    assert_eq!(rows.len(), signorini::driver::all_schemes().len());
    for r in &rows {
        assert!((r.order - 2.0).abs() < 0.05, "{}: order {}", r.scheme, r.order);
        assert!(r.rho_infinity <= 1.0 + 1e-9, "{}: ρ∞ = {}", r.scheme, r.rho_infinity);
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
    let rows = verify::energy_laws().unwrap();
    assert_eq!(rows.len(), 8);
    for r in &rows {
        // Newton stops at a relative residual of 1e-10: the disc's steps keep E_aug to ~3e-11
        // of its energy scale, the bar's to ~4e-14.
        assert!(r.kept_largest < 1e-9, "{r:?}");
        assert!(r.kept_steps > 500 && r.changed_steps > 5, "{r:?}");
    }
}
