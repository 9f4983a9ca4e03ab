//! The compiled schemes on a single oscillator (ü + u = 0 as a one-dof finite-element system:
//! one P1 element, E = 1, ρ = 3, so M = ρh/3 = 1, K = E/h = 1): second order, spectral radius
//! at ωΔt → ∞, exact energy conservation of midpoint and Crank–Nicolson. A scheme written only
//! for these tests runs with nothing but its file.

use nalgebra::DMatrix;
use signorini::forms::nitsche;
use signorini::forms::schemes::{hht, hht_imex, hht_unweighted, hybrid, midpoint, newmark, trbdf2};
use signorini::runtime::assembly::{Assembler, Quadrature};
use signorini::runtime::kernel::Coef;
use signorini::runtime::linalg::Structure;
use signorini::runtime::mesh::structured;
use signorini::runtime::newton::NewtonOptions;
use signorini::runtime::problem::Constraints;
use signorini::runtime::scheme::{Bound, BoundForm, Stepper, TimeScheme};

signorini::forms!("tests/wf/newmark_general.wf");

fn stepper<'a, S: TimeScheme>(scheme: S, asm: &'a Assembler<'a>) -> Stepper<'a, S> {
    let p = nitsche::Params::default().with("rho", 3.0).unwrap();
    let c =
        nitsche::Coefficients { f: Coef::constant(vec![0.0]), g: Coef::scalar(0.0), nc: Coef::constant(vec![-1.0]) };
    let q = Quadrature::default();
    let none: &[signorini::runtime::mesh::Facet] = &[];
    let b = |k| -> Box<dyn BoundForm> { k };
    let forms: Vec<(&'static str, Box<dyn BoundForm>)> = vec![
        ("mass", b(Box::new(Bound { kernel: nitsche::Mass::new(&p, &c), quadrature: q, regions: vec![] }))),
        ("stiffness", b(Box::new(Bound { kernel: nitsche::Stiffness::new(&p, &c), quadrature: q, regions: vec![] }))),
        ("load", b(Box::new(Bound { kernel: nitsche::Load::new(&p, &c), quadrature: q, regions: vec![] }))),
        // No contact facets: a free oscillator.
        (
            "contact",
            b(Box::new(Bound {
                kernel: nitsche::Contact::new(&p, &c),
                quadrature: q,
                regions: vec![("Gamma_C".into(), none)],
            })),
        ),
        (
            "hybrid_contact",
            b(Box::new(Bound {
                kernel: hybrid::HybridContact::new(
                    &hybrid::Params::default(),
                    &hybrid::Coefficients {
                        f: Coef::constant(vec![0.0]),
                        g: Coef::scalar(0.0),
                        nc: Coef::constant(vec![-1.0]),
                    },
                ),
                quadrature: q,
                regions: vec![("Gamma_C".into(), none)],
            })),
        ),
    ];
    let mut constraints = Constraints::none(asm.size());
    constraints.fix(1);
    Stepper::new(scheme, asm, forms, constraints, Structure::General, NewtonOptions::default()).unwrap()
}

fn with_mesh<R>(f: impl FnOnce(&Assembler) -> R) -> R {
    let mesh = structured::interval(1, 0.0, 1.0);
    let asm = Assembler::new(&mesh);
    f(&asm)
}

/// Integrates from u = 1, v = 0 to t = T; returns |u(T) − cos T|.
fn error<S: TimeScheme>(scheme: S, dt: f64, t_end: f64) -> f64 {
    with_mesh(|asm| {
        let mut st = stepper(scheme, asm);
        let mut states: Vec<Vec<f64>> = S::DESC.states.iter().map(|_| vec![0.0; 2]).collect();
        states[0][0] = 1.0;
        st.initialize(&mut states, 0.0).unwrap();
        let steps = (t_end / dt).round() as usize;
        for k in 0..steps {
            st.step(&mut states, k as f64 * dt, dt).unwrap();
        }
        (states[0][0] - t_end.cos()).abs()
    })
}

/// Spectral radius of the one-step map of (u, v[, a]) at step dt (ω = 1).
fn spectral_radius<S: TimeScheme>(scheme: S, dt: f64) -> f64 {
    with_mesh(|asm| {
        let mut st = stepper(scheme, asm);
        let m = S::DESC.states.len();
        let mut a = DMatrix::<f64>::zeros(m, m);
        for j in 0..m {
            let mut states: Vec<Vec<f64>> = (0..m).map(|_| vec![0.0; 2]).collect();
            states[j][0] = 1.0;
            st.step(&mut states, 0.0, dt).unwrap();
            for i in 0..m {
                a[(i, j)] = states[i][0];
            }
        }
        a.complex_eigenvalues().iter().map(|z| z.norm()).fold(0.0, f64::max)
    })
}

macro_rules! for_each_scheme {
    ($f:ident) => {
        vec![
            ("newmark", $f(newmark::Newmark::default())),
            ("hht", $f(hht::Hht::default())),
            ("hht_imex", $f(hht_imex::HhtImex::default())),
            ("hht_unweighted", $f(hht_unweighted::HhtUnweighted::default())),
            ("midpoint", $f(midpoint::Midpoint::default())),
            ("trbdf2", $f(trbdf2::Trbdf2::default())),
            ("hybrid", $f(hybrid::Hybrid::default())),
            ("newmark_general (test file)", $f(newmark_general::NewmarkGeneral::default())),
        ]
    };
}

#[test]
fn every_scheme_is_second_order() {
    fn ratio<S: TimeScheme + Clone>(s: S) -> f64 {
        error(s.clone(), 0.02, 10.0) / error(s, 0.01, 10.0)
    }
    for (name, r) in for_each_scheme!(ratio) {
        if name.starts_with("newmark_general") {
            // γ = 0.6 ≠ 1/2: first order, by design of the test scheme.
            assert!((r - 2.0).abs() < 0.15, "{name}: error ratio {r}");
        } else {
            assert!((r - 4.0).abs() < 0.15, "{name}: error ratio {r}");
        }
    }
}

#[test]
fn spectral_radius_at_infinite_step() {
    fn rho<S: TimeScheme>(s: S) -> f64 {
        spectral_radius(s, 1e6)
    }
    let alpha: f64 = 0.05;
    let hht_limit = (1.0 - alpha) / (1.0 + alpha);
    for (name, r) in for_each_scheme!(rho) {
        let expected = match name {
            "newmark" | "midpoint" | "hybrid" => 1.0,
            "hht" | "hht_imex" | "hht_unweighted" => hht_limit,
            "trbdf2" => 0.0,
            _ => continue,
        };
        let tol = if name == "trbdf2" { 1e-5 } else { 1e-6 };
        assert!((r - expected).abs() < tol, "{name}: ρ∞ = {r}, expected {expected}");
    }
    // At α = 1/3 the two principal roots meet at infinity (a double root), so the radius at
    // finite ωΔt approaches the limit like (ωΔt)^(-1/2): evaluate further out.
    let third = spectral_radius(hht::Hht::default().with("alpha", 1.0 / 3.0).unwrap(), 1e12);
    assert!((third - 0.5).abs() < 1e-6, "HHT α = 1/3: ρ∞ = {third}");
}

/// Midpoint and Crank–Nicolson conserve ½Mv² + ½Ku² exactly (to round-off) for linear problems.
#[test]
fn midpoint_and_crank_nicolson_conserve_energy() {
    fn drift<S: TimeScheme>(scheme: S) -> f64 {
        with_mesh(|asm| {
            let mut st = stepper(scheme, asm);
            let mut states: Vec<Vec<f64>> = S::DESC.states.iter().map(|_| vec![0.0; 2]).collect();
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
    }
    assert!(drift(newmark::Newmark::default()) < 1e-12);
    assert!(drift(midpoint::Midpoint::default()) < 1e-12);
    assert!(drift(hybrid::Hybrid::default()) < 1e-12);
}
