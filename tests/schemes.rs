//! Every scheme of the library on a single oscillator (ü + u = 0 as a one-dof finite-element
//! system: one P1 element, E = 1, ρ = 3, so M = ρh/3 = 1, K = E/h = 1): second order, spectral
//! radius at ωΔt → ∞, exact energy conservation of midpoint and Crank–Nicolson. The schemes
//! come from the library's registry; a scheme written only for these tests runs by path
//! (interpreted) and compiled, with nothing but its file.

use signorini::driver::{self, Methods};
use signorini::runtime::time::scheme::TimeScheme;
use signorini::runtime::time::stepper::Stepper;

signorini::forms!("tests/wf/newmark_general.wf");

const TEST_SCHEME: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/wf/newmark_general.wf");

/// Runs `f` on a stepper of the oscillator (`signorini verify`'s), with `scheme` instead of
/// `methods`'s when given.
fn with_stepper<R>(methods: &Methods, scheme: Option<Box<dyn TimeScheme>>, f: impl FnOnce(&mut Stepper) -> R) -> R {
    signorini::verify::with_oscillator_scheme(methods, scheme, f).unwrap()
}

fn methods(scheme: &str) -> Methods {
    Methods { scheme: scheme.into(), ..Methods::default() }
}

/// |u(T) − cos T| from u = 1, v = 0 (`signorini verify`'s oscillator).
fn error(methods: &Methods, dt: f64, t_end: f64) -> f64 {
    signorini::verify::oscillator_error(methods, dt, t_end).unwrap()
}

/// Spectral radius of the one-step map at step dt (ω = 1).
fn spectral_radius(methods: &Methods, dt: f64) -> f64 {
    signorini::verify::spectral_radius(methods, dt).unwrap()
}

/// Every scheme of the library, and the test-only scheme by path.
fn every_scheme() -> Vec<String> {
    let mut all: Vec<String> = driver::all_schemes().iter().map(|s| s.to_string()).collect();
    all.push(TEST_SCHEME.to_string());
    all
}

#[test]
fn every_scheme_is_second_order() {
    for name in every_scheme() {
        let s = methods(&name);
        let r = error(&s, 0.02, 10.0) / error(&s, 0.01, 10.0);
        if name == TEST_SCHEME {
            // γ = 0.6 ≠ 1/2: first order, by design of the test scheme.
            assert!((r - 2.0).abs() < 0.15, "{name}: error ratio {r}");
        } else {
            assert!((r - 4.0).abs() < 0.15, "{name}: error ratio {r}");
        }
    }
}

#[test]
fn spectral_radius_at_infinite_step() {
    let alpha: f64 = 0.05;
    let hht_limit = (1.0 - alpha) / (1.0 + alpha);
    let mut checked = 0;
    for name in every_scheme() {
        let expected = match name.as_str() {
            "newmark" | "midpoint" | "hybrid" => 1.0,
            "hht" | "hht_imex" | "hht_unweighted" => hht_limit,
            "trbdf2" => 0.0,
            _ => continue,
        };
        let r = spectral_radius(&methods(&name), 1e6);
        let tol = if name == "trbdf2" { 1e-5 } else { 1e-6 };
        assert!((r - expected).abs() < tol, "{name}: ρ∞ = {r}, expected {expected}");
        checked += 1;
    }
    assert_eq!(checked, 7);
    // At α = 1/3 the two principal roots meet at infinity (a double root), so the radius at
    // finite ωΔt approaches the limit like (ωΔt)^(-1/2): evaluate further out.
    let third = spectral_radius(&methods("hht").set("alpha", 1.0 / 3.0), 1e12);
    assert!((third - 0.5).abs() < 1e-6, "HHT α = 1/3: ρ∞ = {third}");
}

/// Midpoint and Crank–Nicolson conserve ½Mv² + ½Ku² exactly (to round-off) for linear problems.
#[test]
fn midpoint_and_crank_nicolson_conserve_energy() {
    let drift = |name: &str| {
        with_stepper(&methods(name), None, |st| {
            let mut states: Vec<Vec<f64>> = st.desc().states.iter().map(|_| vec![0.0; 2]).collect();
            states[0][0] = 1.0;
            st.initialize(&mut states, 0.0).unwrap();
            let energy = |s: &[Vec<f64>]| 0.5 * s[1][0] * s[1][0] + 0.5 * s[0][0] * s[0][0];
            let e0 = energy(&states);
            let mut worst = 0.0f64;
            for k in 0..2000 {
                st.step(&mut states, k as f64 * 0.37, 0.37).unwrap();
                worst = worst.max((energy(&states) - e0).abs() / e0);
            }
            worst
        })
    };
    for name in ["newmark", "midpoint", "hybrid"] {
        assert!(drift(name) < 1e-12, "{name}");
    }
}

/// The test scheme run by path (interpreted: coefficients from the expression DAG) and compiled
/// by `forms!` take the same steps to round-off, with non-default params.
#[test]
fn interpreted_and_compiled_schemes_agree() {
    let run = |compiled: bool| {
        let s = methods(TEST_SCHEME).set("beta", 0.35).set("gam", 0.7);
        let scheme: Option<Box<dyn TimeScheme>> = compiled.then(|| {
            let c = newmark_general::NewmarkGeneral::default();
            Box::new(c.with("beta", 0.35).unwrap().with("gam", 0.7).unwrap()) as Box<dyn TimeScheme>
        });
        with_stepper(&s, scheme, |st| {
            let mut states: Vec<Vec<f64>> = st.desc().states.iter().map(|_| vec![0.0; 2]).collect();
            states[0][0] = 1.0;
            st.initialize(&mut states, 0.0).unwrap();
            let mut series = Vec::new();
            for k in 0..100 {
                st.step(&mut states, k as f64 * 0.1, 0.1).unwrap();
                series.push(states[0][0]);
            }
            series
        })
    };
    let (a, b) = (run(false), run(true));
    for (k, (x, y)) in a.iter().zip(&b).enumerate() {
        assert!((x - y).abs() <= 1e-14 * x.abs().max(1e-3), "step {k}: {x} vs {y}");
    }
}
