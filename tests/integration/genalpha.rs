//! Generalized-α (Chung–Hulbert), `forms/schemes/genalpha.wf`: its high-frequency spectral
//! radius is the param ρ∞; with ρ∞ = 1 it is Newmark (trapezoidal) on the bar, step for step;
//! and the file run by path from outside the repository gives the compiled scheme's series
//! and those of an independent implementation written here with dense matrices.

use nalgebra::{DMatrix, DVector};
use signorini::cases::bar;
use signorini::driver::Methods;
use signorini::forms::{contact_nitsche, contact_penalty, elasticity};
use signorini::problem::run::Options;
use signorini::runtime::fem::assembly::{Assembler, Quadrature};
use signorini::runtime::fem::bound::{Bound, BoundForm};
use signorini::runtime::fem::kernel::Coef;
use signorini::runtime::fem::mesh::structured;

fn run(methods: Methods, steps: usize) -> bar::Run {
    let opts = Options { methods, t_end: Some(steps as f64 * 0.01), ..bar::options() };
    bar::run(&opts).unwrap()
}

fn genalpha(rho: f64) -> Methods {
    Methods { scheme: "genalpha".into(), ..Methods::default() }.set("genalpha.rho", rho)
}

/// One-step map of the free oscillator ü + u = 0 (one P1 element, E = 1, ρ = 3) at ωΔt = 1e12
/// (with ρ∞ = 0 the three roots meet at 0 and approach it like (ωΔt)^(-2/3): evaluate far out).
fn spectral_radius(rho: f64) -> f64 {
    // The one-step map on `signorini verify`'s oscillator; its eigenvalues by nalgebra (an
    // independent method from verify's repeated squaring).
    let a = signorini::verify::with_oscillator(&genalpha(rho), |st| {
        let mut a = DMatrix::<f64>::zeros(3, 3);
        for j in 0..3 {
            let mut states: Vec<Vec<f64>> = (0..3).map(|_| vec![0.0; 2]).collect();
            states[j][0] = 1.0;
            st.step(&mut states, 0.0, 1e12).unwrap();
            for i in 0..3 {
                a[(i, j)] = states[i][0];
            }
        }
        a
    })
    .unwrap();
    a.complex_eigenvalues().iter().map(|z| z.norm()).fold(0.0, f64::max)
}

#[test]
fn spectral_radius_at_infinite_step_is_rho_infinity() {
    for rho in [0.0, 0.3, 0.5, 0.8, 1.0] {
        let r = spectral_radius(rho);
        assert!((r - rho).abs() < 1e-6, "ρ∞ = {rho}: measured {r}");
    }
}

/// With ρ∞ = 1 (αm = αf = ½, γ = ½, β = ¼) each step solves the average of Newmark's equations
/// at tⁿ and tⁿ⁺¹; with the consistent initial acceleration the one at tⁿ holds already, so the
/// steps are Newmark's, contact included.
#[test]
fn rho_one_is_newmark_on_the_bar() {
    for contact in ["nitsche", "penalty"] {
        let a = run(Methods { contact: contact.into(), ..genalpha(1.0) }, 1200);
        let b = run(Methods { scheme: "newmark".into(), contact: contact.into(), ..Methods::default() }, 1200);
        let scale = b.series.iter().map(|r| r.u_c.abs()).fold(0.0, f64::max);
        for (x, y) in a.series.iter().zip(&b.series) {
            assert!((x.u_c - y.u_c).abs() < 1e-10 * scale, "{contact} t = {}: {} vs {}", x.t, x.u_c, y.u_c);
            assert!((x.energy_aug - y.energy_aug).abs() < 1e-10, "{contact} t = {}", x.t);
        }
    }
}

/// Chung–Hulbert on the bar, written out: M, K and the contact form assembled from the
/// compiled form files, the step solved by Newton with dense LU. Returns u(0, tⁿ).
fn independent(contact: &dyn BoundForm, asm: &Assembler, rho: f64, steps: usize, dt: f64) -> Vec<f64> {
    let n = asm.size();
    let p = elasticity::Params::default();
    let c = elasticity::Coefficients { f: Coef::constant(vec![0.0]) };
    let q = Quadrature::default();
    let dense = |form: &dyn BoundForm| {
        let mut m = asm.zero_matrix();
        form.tangent(asm, &[&vec![0.0; n]], 0, 0.0, &mut m);
        DMatrix::from_fn(n, n, |i, j| m.get(i, j))
    };
    let mass = dense(&Bound { kernel: elasticity::Mass::new(&p, &c), quadrature: q, regions: vec![], cells: None });
    let stiff =
        dense(&Bound { kernel: elasticity::Stiffness::new(&p, &c), quadrature: q, regions: vec![], cells: None });
    let fixed = n - 1; // u(1) = 0
    let c_res = |u: &DVector<f64>| {
        let mut r = vec![0.0; n];
        contact.residual(asm, &[u.as_slice()], 0.0, &mut r);
        DVector::from_vec(r)
    };
    let c_tan = |u: &DVector<f64>| {
        let mut m = asm.zero_matrix();
        contact.tangent(asm, &[u.as_slice()], 0, 0.0, &mut m);
        DMatrix::from_fn(n, n, |i, j| m.get(i, j))
    };
    let pin = |m: &mut DMatrix<f64>, r: &mut DVector<f64>| {
        m.row_mut(fixed).fill(0.0);
        m.column_mut(fixed).fill(0.0);
        m[(fixed, fixed)] = 1.0;
        r[fixed] = 0.0;
    };
    let (am, af) = ((2.0 * rho - 1.0) / (rho + 1.0), rho / (rho + 1.0));
    let gam = 0.5 - am + af;
    let beta = 0.25 * (1.0 - am + af).powi(2);
    let mut u = DVector::from_fn(n, |i, _| 0.5 * (1.0 - i as f64 / (n - 1) as f64));
    let mut v = DVector::zeros(n);
    // M a⁰ = −K u⁰ − C(u⁰).
    let (mut m0, mut r0) = (mass.clone(), -(&stiff * &u + c_res(&u)));
    pin(&mut m0, &mut r0);
    let mut a = m0.lu().solve(&r0).unwrap();
    let mut out = vec![u[0]];
    for _ in 0..steps {
        let pred = &u + dt * &v + dt * dt / 2.0 * (1.0 - 2.0 * beta) * &a;
        let mut w = u.clone();
        for _ in 0..50 {
            let a1 = (&w - &pred) / (beta * dt * dt);
            let mut r = (1.0 - am) * &mass * &a1
                + am * &mass * &a
                + (1.0 - af) * (&stiff * &w + c_res(&w))
                + af * (&stiff * &u + c_res(&u));
            let mut j = (1.0 - am) / (beta * dt * dt) * &mass + (1.0 - af) * (&stiff + c_tan(&w));
            pin(&mut j, &mut r);
            let delta = j.lu().solve(&r).unwrap();
            w -= &delta;
            if delta.amax() <= 1e-14 * w.amax().max(1e-300) {
                break;
            }
        }
        let a1 = (&w - &pred) / (beta * dt * dt);
        v = &v + dt * ((1.0 - gam) * &a + gam * &a1);
        a = a1;
        u = w;
        out.push(u[0]);
    }
    out
}

/// The scheme file copied outside the repository and run by path (interpreted) gives the
/// compiled scheme's series, and the independent implementation's, for penalty and Nitsche
/// θ = ±1 with ρ∞ = 0.8.
#[test]
fn by_path_compiled_and_independent_agree() {
    let dir = std::env::temp_dir().join(format!("signorini-genalpha-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("my_genalpha.wf");
    std::fs::copy(concat!(env!("CARGO_MANIFEST_DIR"), "/forms/schemes/genalpha.wf"), &file).unwrap();
    let steps = 300; // through the first impact and release (t ∈ [1, 2])
    let mesh = structured::interval(20, 0.0, 1.0);
    let asm = Assembler::new(&mesh);
    let facets = asm.region("left").unwrap();
    let g = || Coef::function(1, |x, _, out| out[0] = x[0]);
    for (law, theta) in [("penalty", f64::NAN), ("nitsche", 1.0), ("nitsche", -1.0)] {
        let mut methods = Methods { contact: law.into(), ..genalpha(0.8) };
        if !theta.is_nan() {
            methods = methods.set("theta", theta);
        }
        let compiled = run(methods.clone(), steps);
        let by_path = run(Methods { scheme: file.display().to_string(), ..methods }, steps);
        assert_eq!(by_path.summary.interpreted, vec![file.display().to_string()]);
        let q = Quadrature::default();
        let regions = vec![("Gamma_C".to_string(), facets)];
        let contact: Box<dyn BoundForm> = if law == "penalty" {
            let c =
                contact_penalty::Coefficients { f: Coef::constant(vec![0.0]), g: g(), nc: Coef::constant(vec![-1.0]) };
            Box::new(Bound {
                kernel: contact_penalty::Contact::new(&Default::default(), &c),
                quadrature: q,
                regions,
                cells: None,
            })
        } else {
            let p = contact_nitsche::Params::default().with("theta", theta).unwrap();
            let c =
                contact_nitsche::Coefficients { f: Coef::constant(vec![0.0]), g: g(), nc: Coef::constant(vec![-1.0]) };
            Box::new(Bound { kernel: contact_nitsche::Contact::new(&p, &c), quadrature: q, regions, cells: None })
        };
        let reference = independent(contact.as_ref(), &asm, 0.8, steps, 0.01);
        let scale = reference.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let (mut contact_steps, mut largest) = (0, 0.0f64);
        for (k, ((a, b), r)) in compiled.series.iter().zip(&by_path.series).zip(&reference).enumerate() {
            assert_eq!(a.u_c, b.u_c, "{law} θ = {theta}, step {k}: compiled vs by path");
            assert!((a.u_c - r).abs() < 1e-10 * scale, "{law} θ = {theta}, step {k}: {} vs independent {r}", a.u_c);
            largest = largest.max((a.u_c - r).abs() / scale);
            contact_steps += usize::from(a.lambda < 0.0);
        }
        eprintln!("{law} θ = {theta}: largest relative difference to the independent implementation {largest:e}");
        assert!(contact_steps > 10, "{law}: the run must include contact ({contact_steps} steps)");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
