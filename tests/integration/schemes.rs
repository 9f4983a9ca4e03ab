//! Every scheme of the library on a single oscillator (ü + u = 0 as a one-dof finite-element
//! system: one P1 element, E = 1, ρ = 3, so M = ρh/3 = 1, K = E/h = 1), held to what its file
//! claims: its order, its spectral radius at ωΔt → ∞, its energy law. The schemes come from the
//! library's registry and their claims from their files; a scheme written only for these tests
//! runs by path (interpreted) and compiled, with nothing but its file.

use signorini::compiler::scheme::EnergyLaw;
use signorini::driver::{self, FilesInUse, Methods};
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

/// What the scheme's file claims (`claim order = 2`, `claim rho_inf = ...`) at `methods`'
/// params.
fn claim(methods: &Methods, what: &str) -> Option<f64> {
    let files = FilesInUse::resolve(methods, &[]).unwrap();
    files.scheme_claims().unwrap().into_iter().find(|(c, _)| c == what).map(|(_, v)| v)
}

/// The energy law the scheme's file claims, if it does.
fn energy_law(methods: &Methods) -> Option<EnergyLaw> {
    FilesInUse::resolve(methods, &[]).unwrap().scheme_energy_law().unwrap()
}

#[test]
fn every_scheme_has_the_order_its_file_claims() {
    let mut checked = Vec::new();
    for name in every_scheme() {
        let s = methods(&name);
        let Some(order) = claim(&s, "order") else { continue };
        let r = error(&s, 0.02, 10.0) / error(&s, 0.01, 10.0);
        let expected = 2f64.powf(order);
        assert!((r - expected).abs() < 0.15, "{name}: error ratio {r}, its file claims order {order}");
        checked.push(name);
    }
    // The test scheme claims first order (γ ≠ 1/2); most of the library claims second.
    assert!(checked.contains(&TEST_SCHEME.to_string()), "{checked:?}");
    assert!(checked.len() > driver::all_schemes().len() / 2, "{checked:?}");
}

#[test]
fn every_scheme_has_the_spectral_radius_at_infinite_step_its_file_claims() {
    let mut checked = Vec::new();
    for name in every_scheme() {
        let s = methods(&name);
        let Some(expected) = claim(&s, "rho_inf") else { continue };
        // Far out: generalized-α approaches its limit like 1/(ωΔt) (round-off of the one-step
        // map there is ~1e-8).
        let r = spectral_radius(&s, 1e12);
        assert!((r - expected).abs() < 1e-6, "{name}: ρ∞ = {r}, its file claims {expected}");
        checked.push(name);
    }
    assert!(checked.len() >= 4, "{checked:?}");
    // At α = 1/3 the two principal roots meet at infinity (a double root): the radius approaches
    // the limit like (ωΔt)^(-1/2).
    let third = methods("hht").set("alpha", 1.0 / 3.0);
    let (r, claimed) = (spectral_radius(&third, 1e12), claim(&third, "rho_inf").unwrap());
    assert!((r - claimed).abs() < 1e-6, "HHT α = 1/3: ρ∞ = {r}, its file claims {claimed}");
}

/// A scheme that claims to conserve energy keeps ½Mv² + ½Ku² exactly (to round-off) on a linear
/// problem; one that claims to dissipate it never gains any.
#[test]
fn every_scheme_keeps_the_energy_law_its_file_claims() {
    let energies = |name: &str| {
        with_stepper(&methods(name), None, |st| {
            let mut states: Vec<Vec<f64>> = st.desc().states.iter().map(|_| vec![0.0; 2]).collect();
            states[0][0] = 1.0;
            st.initialize(&mut states, 0.0).unwrap();
            let energy = |s: &[Vec<f64>]| 0.5 * s[1][0] * s[1][0] + 0.5 * s[0][0] * s[0][0];
            let mut series = vec![energy(&states)];
            for k in 0..2000 {
                st.step(&mut states, k as f64 * 0.37, 0.37).unwrap();
                series.push(energy(&states));
            }
            series
        })
    };
    let mut checked = Vec::new();
    for name in every_scheme() {
        let Some(law) = energy_law(&methods(&name)) else { continue };
        let e = energies(&name);
        let e0 = e[0];
        match law {
            EnergyLaw::Conserving => {
                let drift = e.iter().fold(0.0f64, |m, x| m.max((x - e0).abs() / e0));
                assert!(drift < 1e-12, "{name}: drift {drift}");
            }
            EnergyLaw::Dissipative => {
                let gain = e.windows(2).fold(0.0f64, |m, w| m.max((w[1] - w[0]) / e0));
                assert!(gain < 1e-12, "{name}: a step gains {gain}");
            }
        }
        checked.push(name);
    }
    assert!(checked.len() >= 2, "{checked:?}");
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
