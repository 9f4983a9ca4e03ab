//! The derivation's exact identities for the library's schemes, at symbolic params.

use super::*;
use crate::scheme::rational::Rat;

fn derived(name: &str) -> (SchemeIr, Ansatz) {
    let (_, ir) = super::super::library_schemes().into_iter().find(|(n, _)| n == name).expect("a library scheme");
    let a = derive(&ir).unwrap_or_else(|e| panic!("{name}: {e:?}"));
    (ir, a)
}

/// The value of unknown `k`, solved.
fn value(a: &Ansatz, k: usize) -> RatFn {
    a.solved[k].as_ref().filter(|u| u.is_known()).map(|u| u.c0.clone()).expect("solved")
}

/// `form` equals Σ coef · l⊗l over `parts`, exactly, with no unknown left.
fn assert_form(form: &Form, parts: &[(RatFn, Lin)], what: &str) {
    let unknowns = form.entries[0].c.len();
    let mut want = Form::zero(form.n, unknowns);
    for (c, l) in parts {
        want.add_product(&Unk::constant(c.clone(), unknowns), l, l).unwrap();
    }
    for (got, want) in form.entries.iter().zip(&want.entries) {
        assert!(got.is_known(), "{what}: an unknown is left");
        assert!(got.c0.sub(&want.c0).unwrap().is_zero(), "{what}: not the expected form");
    }
}

/// Newmark at symbolic β, γ: the multipliers (1 − γ, γ) of the residuals at t and t + dt on
/// Δu, the kept energy's ½dt²(β − γ/2)‖a‖²_M, and D = (γ − ½)‖Δu‖²_K +
/// (γ − ½)(β − γ/2)dt²‖Δa‖²_M (Krenk's form of the Newmark energy balance), exactly.
#[test]
fn newmark_s_identity_is_krenk_s() {
    let (ir, a) = derived("newmark");
    let (beta, gam, dt) = (RatFn::var(0), RatFn::var(1), RatFn::var(super::super::poly::DT));
    let half = RatFn::constant(Rat::new(1, 2).unwrap());
    let value = |k: usize| value(&a, k);
    let start = a.residuals.iter().position(|r| r.stage.is_none()).expect("the residual at t");
    let end = a.residuals.iter().position(|r| r.stage == Some(0)).expect("the residual at t + dt");
    assert!(value(a.residuals[start].nu[0]).sub(&RatFn::one().sub(&gam).unwrap()).unwrap().is_zero());
    assert!(value(a.residuals[end].nu[0]).sub(&gam).unwrap().is_zero());
    let q_a = gam.mul(&half).unwrap();
    let q_a = beta.sub(&q_a).unwrap();
    assert!(value(a.q_a.unwrap()).sub(&q_a).unwrap().is_zero());
    let n = a.window.free.len();
    let acceleration = ir.initial.as_ref().unwrap().state;
    let end_of = |i: usize| end_level(&ir, &a.window, i);
    let du = sub(&end_of(0), &unit(n, 0)).unwrap();
    let da = sub(&end_of(acceleration), &unit(n, acceleration)).unwrap();
    let g = gam.sub(&half).unwrap();
    assert_form(&a.d_k, &[(g.clone(), du)], "D on K");
    let m = g.mul(&q_a).unwrap().mul(&dt.powi(2).unwrap()).unwrap();
    assert_form(&a.d_m, &[(m, da)], "D on M");
}

/// The midpoint rule tests its one residual with Δu whole, keeps E, and dissipates nothing:
/// D ≡ 0. So does the hybrid scheme's part (its contact is the law's), and energy–momentum,
/// whose discrete-gradient stiffness is a force whose work it reports.
#[test]
fn the_midpoint_schemes_dissipate_nothing() {
    for name in ["midpoint", "hybrid", "energy_momentum"] {
        let (_, a) = derived(name);
        let [r] = a.residuals.as_slice() else { panic!("{name}: one residual") };
        let nu = a.solved[r.nu[0]].as_ref().expect("solved");
        assert_eq!(nu.c0.as_constant(), Some(Rat::ONE), "{name}: w = Δu");
        for form in [&a.d_m, &a.d_k] {
            assert!(form.entries.iter().all(Unk::is_zero), "{name}: D ≢ 0");
        }
    }
}

fn r(n: i128, d: i128) -> RatFn {
    RatFn::constant(Rat::new(n, d).unwrap())
}

/// Central differences (Newmark at β = 0, γ = ½): multipliers (½, ½), the kept energy
/// E − dt²/8 ‖a‖²_M (q_a = −¼), and no dissipation.
#[test]
fn central_differences_keep_e_less_an_eighth_of_dt2_a_m_a() {
    let (_, a) = derived("central");
    for t in &a.residuals {
        assert_eq!(value(&a, t.nu[0]).as_constant(), Rat::new(1, 2).ok());
    }
    assert_eq!(value(&a, a.q_a.expect("a corrected energy")).as_constant(), Rat::new(-1, 4).ok());
    assert!(a.d_m.entries.iter().chain(&a.d_k.entries).all(Unk::is_zero));
}

/// TR-BDF2 keeps E itself, for every gs: the residuals at t and at the trapezoidal stage
/// tested with w₁ = [(3 − 2gs)/2 δ₁ + (1 − gs) δ₂]/(2 − gs)², the BDF2 stage's with
/// w₂ = [(1 − gs)² δ₁ + (gs² − 2gs + 2) δ₂]/(2 − gs)² (δ₁ = u_m − u, δ₂ = u' − u_m), and
/// D = ‖(1 − gs)δ₁ − gs δ₂‖²_K/(2(2 − gs)²) + (gs(1 − gs)dt)²/(8(2 − gs)⁴) ‖a + a_m − 2a'‖²_M.
#[test]
fn trbdf2_keeps_e_with_a_dissipation_of_both_stages() {
    let (ir, a) = derived("trbdf2");
    assert!(a.q_a.is_none(), "the kept energy is E");
    let gs = RatFn::var(0);
    let one = RatFn::one();
    let two_minus = r(2, 1).sub(&gs).unwrap();
    let sq = two_minus.powi(2).unwrap();
    let one_minus = one.sub(&gs).unwrap();
    let w1 = [r(3, 2).sub(&gs).unwrap().div(&sq).unwrap(), one_minus.div(&sq).unwrap()];
    let w2 = [
        one_minus.powi(2).unwrap().div(&sq).unwrap(),
        gs.powi(2).unwrap().sub(&gs.mul(&r(2, 1)).unwrap()).unwrap().add(&r(2, 1)).unwrap().div(&sq).unwrap(),
    ];
    for t in &a.residuals {
        let want = if t.stage == Some(1) { &w2 } else { &w1 };
        for (j, w) in want.iter().enumerate() {
            assert!(value(&a, t.nu[j]).sub(w).unwrap().is_zero(), "stage {:?}, increment {j}", t.stage);
        }
    }
    let n = a.window.free.len();
    let (d1, d2) = (&a.increments[0], &a.increments[1]);
    let combination = |x: &RatFn, l: &Lin, y: &RatFn, m: &Lin| -> Lin {
        Lin(l.0.iter().zip(&m.0).map(|(p, q)| p.mul(x).unwrap().add(&q.mul(y).unwrap()).unwrap()).collect())
    };
    let k_row = combination(&one_minus, d1, &gs.neg().unwrap(), d2);
    let k_coef = one.div(&sq.mul(&r(2, 1)).unwrap()).unwrap();
    assert_form(&a.d_k, &[(k_coef, k_row)], "D on K");
    // a + a_m − 2a': the start's acceleration, the trapezoidal stage's, the end's.
    let acceleration = ir.initial.as_ref().unwrap().state;
    let a_m = ir.stages[0].quantities.iter().position(|q| q == "am").expect("am");
    let mut row = unit(n, acceleration);
    row = combination(&one, &row, &one, &a.window.levels[0][a_m]);
    row = combination(&one, &row, &r(-2, 1), &end_level(&ir, &a.window, acceleration));
    let dt = RatFn::var(super::super::poly::DT);
    let m_coef = gs.mul(&one_minus).unwrap().mul(&dt).unwrap().powi(2).unwrap();
    let m_coef = m_coef.div(&sq.powi(2).unwrap().mul(&r(8, 1)).unwrap()).unwrap();
    assert_form(&a.d_m, &[(m_coef, row)], "D on M");
}

/// HHT-α keeps E + ½dt²(α²/4)‖a‖²_M + ½α(½ − α)‖u − u⁻‖²_K, with the previous step's
/// displacement u⁻, and dissipates D = α³dt²/4 ‖Δa‖²_M + ½α(½ − α)‖(u' − u) − (u − u⁻)‖²_K,
/// exactly at symbolic α; so do its variants, which differ in the contact's levels only.
#[test]
fn hht_keeps_its_modified_energy() {
    for name in ["hht", "hht_imex", "hht_unweighted"] {
        hht_s_identity(name);
    }
}

/// Generalized-α over two steps, its levels weighted by α_m = (2ρ − 1)/(ρ + 1) as its
/// residual weighs its inertia: it keeps Ê + ½dt²(1 − ρ)²/(4(1 + ρ)²)‖â‖²_M +
/// ½(1 − ρ)²/(2(1 + ρ)²)‖u − u⁻‖²_K and dissipates D = 3(1 − ρ)³/(4(1 + ρ)³)‖Δu − δu‖²_K +
/// dt²(1 − ρ)³/(4(1 + ρ)³)‖Δâ‖²_M, exactly at symbolic ρ: the α-method's balance with the
/// weighted sequences (Δu = u' − u, δu = u − u⁻, Δâ = (1 − α_m)(a' − a) + α_m(a − a⁻)).
#[test]
fn generalized_alpha_keeps_its_weighted_energy() {
    let (ir, a) = derived("genalpha");
    let (rho, one) = (RatFn::var(0), RatFn::one());
    let (p, m) = (one.add(&rho).unwrap(), one.sub(&rho).unwrap());
    let am = r(2, 1).mul(&rho).unwrap().sub(&one).unwrap().div(&p).unwrap();
    assert!(a.weight.as_ref().expect("weighted levels").sub(&am).unwrap().is_zero());
    let ratio2 = m.div(&p).unwrap().powi(2).unwrap();
    assert!(value(&a, a.q_a.unwrap()).sub(&ratio2.div(&r(4, 1)).unwrap()).unwrap().is_zero());
    assert!(value(&a, a.q_delta.unwrap()).sub(&ratio2.div(&r(2, 1)).unwrap()).unwrap().is_zero());
    let w = &a.window;
    let n = w.free.len();
    let acc = ir.initial.as_ref().unwrap().state;
    let before = |i: usize| unit(n, i);
    let (u0, u1, u2) = (before(0), w.start[0].clone(), end_level(&ir, w, 0));
    let (a0, a1, a2) = (before(acc), w.start[acc].clone(), end_level(&ir, w, acc));
    let second = sub(&sub(&u2, &u1).unwrap(), &sub(&u1, &u0).unwrap()).unwrap();
    let ratio3 = m.div(&p).unwrap().powi(3).unwrap();
    assert_form(&a.d_k, &[(ratio3.mul(&r(3, 4)).unwrap(), second)], "D on K");
    let weighted = |x: &Lin, y: &Lin| -> Lin {
        Lin(x
            .0
            .iter()
            .zip(&y.0)
            .map(|(x, y)| x.mul(&one.sub(&am).unwrap()).unwrap().add(&y.mul(&am).unwrap()).unwrap())
            .collect())
    };
    let da_hat = sub(&weighted(&a2, &a1), &weighted(&a1, &a0)).unwrap();
    let dt2 = RatFn::var(super::super::poly::DT).powi(2).unwrap();
    assert_form(&a.d_m, &[(ratio3.mul(&dt2).unwrap().div(&r(4, 1)).unwrap(), da_hat)], "D on M");
}

/// HHT's identity for `name` (its variants differ in the contact's levels only).
fn hht_s_identity(name: &str) {
    let (ir, a) = derived(name);
    let alpha = RatFn::var(0);
    let q_a = alpha.powi(2).unwrap().mul(&r(1, 4)).unwrap();
    let q_delta = alpha.mul(&r(1, 2).sub(&alpha).unwrap()).unwrap();
    assert!(value(&a, a.q_a.expect("q_a")).sub(&q_a).unwrap().is_zero());
    assert!(value(&a, a.q_delta.expect("q_δ")).sub(&q_delta).unwrap().is_zero());
    let n = a.window.free.len();
    let previous = a.window.free.iter().position(|f| *f == super::super::window::Free::Previous(0)).unwrap();
    let acceleration = ir.initial.as_ref().unwrap().state;
    let da = sub(&end_level(&ir, &a.window, acceleration), &unit(n, acceleration)).unwrap();
    let now = sub(&end_level(&ir, &a.window, 0), &unit(n, 0)).unwrap();
    let then = sub(&unit(n, 0), &unit(n, previous)).unwrap();
    let dt = RatFn::var(super::super::poly::DT);
    let m = alpha.powi(3).unwrap().mul(&dt.powi(2).unwrap()).unwrap().mul(&r(1, 4)).unwrap();
    assert_form(&a.d_m, &[(m, da)], "D on M");
    assert_form(&a.d_k, &[(q_delta.mul(&r(1, 2)).unwrap(), sub(&now, &then).unwrap())], "D on K");
}
