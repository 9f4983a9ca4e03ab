//! `verify --scheme` on schemes a user writes (issue 14): a generalized-α file is measured at
//! order 2 with a spectral radius tending to its ρ∞, and its claims hold; a backward Euler that
//! claims order 2 is measured at order 1 and the claim is contradicted; a damped Newmark has
//! order 2 on the damped oscillator, and one with an explicit damping term order 1 there
//! (though 2 without damping).

use signorini::driver::Methods;
use signorini::verify::scheme;

fn write(name: &str, text: &str) -> String {
    let dir = std::env::temp_dir().join(format!("signorini-verify-scheme-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path.display().to_string()
}

/// Chung and Hulbert's generalized-α, written from the paper by a user (not the library's file).
const GENERALIZED_ALPHA: &str = "
scheme my_genalpha(r = 0.6 in [0, 1]) {
  uses mass, stiffness, contact, load
  state u, v, a
  claim order = 2
  claim rho_inf = r
  let am = (2*r - 1)/(r + 1)
  let af = r/(r + 1)
  let g = 1/2 - am + af
  let b = (1 - am + af)^2/4
  initial a: mass(a) + stiffness(u) + contact(u) == load(t)
  unknown u'
  relate u' = u + dt*v + dt^2*((1/2 - b)*a + b*a')
  relate v' = v + dt*((1 - g)*a + g*a')
  residual mass((1 - am)*a' + am*a) + stiffness((1 - af)*u' + af*u) + contact((1 - af)*u' + af*u)
    == load(t + (1 - af)*dt)
}
";

const BACKWARD_EULER: &str = "
scheme euler {
  uses mass, stiffness, contact, load
  state u, v
  claim order = 2
  unknown u'
  new a
  relate u' = u + dt*v'
  relate v' = v + dt*a
  residual mass(a) + stiffness(u') + contact(u') == load(t + dt)
}
";

#[test]
fn a_users_generalized_alpha_has_order_two_and_its_rho_infinity() {
    let path = write("my_genalpha.wf", GENERALIZED_ALPHA);
    for r in [0.6, 0.3] {
        let methods = Methods { scheme: path.clone(), ..Methods::default() }.set("r", r);
        let v = scheme::run(&methods, &mut |_| {}).unwrap();
        assert!((v.oscillator_order - 2.0).abs() < 0.05, "order {}", v.oscillator_order);
        // Round-off of the step at ωΔt = 1e12 leaves about 1e-6.
        assert!((v.rho_infinity - r).abs() < 1e-4, "ρ∞ {} for r = {r}", v.rho_infinity);
        // The spectral radius falls from 1 at small ωΔt to ρ∞ at large.
        let (first, last) = (v.spectrum.first().unwrap(), v.spectrum.last().unwrap());
        assert!((first.rho - 1.0).abs() < 1e-3 && (last.rho - r).abs() < 1e-3, "{first:?} … {last:?}");
        assert!(v.spectrum.windows(2).all(|w| w[1].rho <= w[0].rho + 1e-9), "ρ(ωΔt) is not monotone");
        // Second order: the period error falls 100-fold per decade of ωΔt at small steps.
        let e = |k: usize| v.spectrum[k].period_error.unwrap();
        assert!((e(0) / e(8) - 1e-2).abs() < 2e-3, "period error {} → {}", e(0), e(8));
        // order, ρ∞, and the stability at every ωΔt that a claimed ρ∞ implies.
        assert_eq!(v.verdicts.len(), 3);
        assert!(v.stability_limit.is_none(), "{:?}", v.stability_limit);
        assert!(v.holds(), "{:?}", v.verdicts);
        assert!(v.bar_orders.iter().all(|b| (b.order - 2.0).abs() < 0.2), "{:?}", v.bar_orders);
    }
}

#[test]
fn a_first_order_scheme_that_claims_two_is_contradicted() {
    let path = write("euler.wf", BACKWARD_EULER);
    let v = scheme::run(&Methods { scheme: path, ..Methods::default() }, &mut |_| {}).unwrap();
    assert!((v.oscillator_order - 1.0).abs() < 0.1, "order {}", v.oscillator_order);
    assert!(!v.holds());
    let order = &v.verdicts[0];
    assert!(order.claim == "order" && !order.holds && (order.measured - 1.0).abs() < 0.1, "{order:?}");
    // L-stable: the spectral radius tends to 0.
    assert!(v.rho_infinity < 1e-6, "ρ∞ {}", v.rho_infinity);
}

/// Newmark (trapezoidal) with a damping slot applied at `LEVEL`.
const DAMPED_NEWMARK: &str = "
scheme NAME {
  uses mass, damping, stiffness, contact, load
  state u, v, a
  claim order = 2
  initial a: mass(a) + damping(v) + stiffness(u) + contact(u) == load(t)
  unknown u'
  relate u' = u + dt*v + dt^2/4*(a + a')
  relate v' = v + dt/2*(a + a')
  residual mass(a') + damping(LEVEL) + stiffness(u') + contact(u') == load(t + dt)
}
";

const DAMPING_FORM: &str = "param c = 0.05 in [0, inf)\nform damping(w; v) = int(Omega) c * dot(w, v)\n";

#[test]
fn damping_applied_explicitly_costs_an_order_on_the_damped_oscillator() {
    let forms = write("damping.wf", DAMPING_FORM);
    let run = |name: &str, level: &str| {
        let path = write(&format!("{name}.wf"), &DAMPED_NEWMARK.replace("NAME", name).replace("LEVEL", level));
        let methods = Methods { scheme: path, forms: vec![forms.clone().into()], ..Methods::default() };
        scheme::run(&methods, &mut |_| {}).unwrap()
    };
    let implicit = run("newmark_damped", "v'");
    let d = implicit.damped_order.expect("the damping slot is applied");
    assert!(
        (d - 2.0).abs() < 0.1 && (implicit.oscillator_order - 2.0).abs() < 0.1,
        "{d} {}",
        implicit.oscillator_order
    );
    assert!(implicit.holds(), "{:?}", implicit.verdicts);
    let explicit = run("newmark_explicit_damping", "v");
    let d = explicit.damped_order.unwrap();
    assert!((d - 1.0).abs() < 0.15, "explicit damping: order {d}");
    assert!((explicit.oscillator_order - 2.0).abs() < 0.1);
    let damped = explicit.verdicts.iter().find(|v| v.claim == "order (damped)").unwrap();
    assert!(!damped.holds && !explicit.holds(), "{:?}", explicit.verdicts);
}

/// Newmark with γ = 0.6 that claims to dissipate: its energy identity proves the claim where
/// β = γ/2 and refutes it at β = 1/4 (an acceleration square of negative coefficient), and the
/// oscillator's sampling agrees both times.
const DISSIPATIVE_NEWMARK: &str = "
scheme newmark_damped(beta = 0.3 in (0, 1/2], gam = 0.6 in [1/2, 1]) {
  uses mass, stiffness, contact, load
  state u, v, a
  claim energy = dissipative
  initial a: mass(a) + stiffness(u) + contact(u) == load(t)
  unknown u'
  relate u' = u + dt*v + dt^2/2*((1 - 2*beta)*a + 2*beta*a')
  relate v' = v + dt*((1 - gam)*a + gam*a')
  residual mass(a') + stiffness(u') + contact(u') == load(t + dt)
}
";

#[test]
fn the_energy_law_proved_and_the_energy_law_sampled_agree() {
    let path = write("newmark_damped.wf", DISSIPATIVE_NEWMARK);
    let methods = Methods { scheme: path, ..Methods::default() };
    let v = scheme::run(&methods, &mut |_| {}).unwrap();
    assert_eq!(v.energy_proof.as_deref(), Some("proved"));
    assert!(v.holds(), "{:?}", v.verdicts);
    let v = scheme::run(&methods.set("beta", 0.25), &mut |_| {}).unwrap();
    let proof = v.energy_proof.clone().unwrap();
    assert!(proof.starts_with("refuted") && proof.contains("‖a' - a‖²_M"), "{proof}");
    assert!(!v.holds(), "the oscillator gains energy at ωΔt = 10: {:?}", v.verdicts);
}
