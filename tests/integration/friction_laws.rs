//! The library's frictional laws at the kernel level, on a curved P2 triangle whose edge lies
//! on the ground: their tangents against central differences of their residuals in each regime
//! (separation, stick, slip; Nitsche θ = 1, 0, −1, Tresca, penalty), Coulomb's bound reached in
//! slip and not in stick, and the frictionless limit: with F = 0 each Coulomb law's residual
//! and tangent are its frictionless law's, bit for bit.

use signorini::forms::{
    contact_nitsche_coulomb as coulomb, contact_nitsche_traction as traction, contact_nitsche_tresca as tresca,
    contact_penalty as penalty, contact_penalty_coulomb as penalty_coulomb,
};
use signorini::runtime::fem::element::ElementKind;
use signorini::runtime::fem::kernel::{Coef, FacetTabulation, FormKernel, OnFacet, facet_matrix, facet_vector};

use crate::tangents::Rng;

type Nodes = [[f64; 2]; 6];

/// Gap to the ground y = 0 below the body: g = y, n_c = −e_y.
fn gap() -> Coef {
    Coef::function(1, |x, _, out| out[0] = x[1])
}

fn down() -> Coef {
    Coef::constant(vec![0.0, -1.0])
}

fn f() -> Coef {
    Coef::constant(vec![0.0, 0.0])
}

/// A curved P2 triangle whose edge (0, 1) lies along the ground, bulging below it.
fn cell() -> Nodes {
    let (a, b, c) = ([0.0, 0.02], [1.0, 0.06], [0.35, 0.85]);
    let mid = |p: [f64; 2], q: [f64; 2]| [0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1])];
    [a, b, c, [0.5, 0.0], mid(b, c), mid(c, a)]
}

/// The regimes a state is built for.
#[derive(Clone, Copy, Debug)]
enum Regime {
    /// Lifted off the ground: no contact, no friction.
    Separation,
    /// Pressed in, with a slip from the previous level far below Coulomb's bound.
    Stick,
    /// Pressed in, slid along x by far more than the bound allows.
    Slip,
}

/// (u, previous) for `regime`: pressed in by `depth` (shifted by a little noise).
fn state(rng: &mut Rng, regime: Regime) -> (Nodes, Nodes) {
    let x = cell();
    let (lift, slide) = match regime {
        Regime::Separation => (0.5, 0.3),
        Regime::Stick => (-0.01, 1e-7),
        Regime::Slip => (-0.01, 0.3),
    };
    let u: Nodes = std::array::from_fn(|j| [0.001 * rng.next(), lift - 0.002 * x[j][0] + 0.0005 * rng.next()]);
    let previous: Nodes = std::array::from_fn(|j| [u[j][0] - slide * (1.0 + 0.1 * rng.next()), u[j][1]]);
    (u, previous)
}

fn tab() -> FacetTabulation<2, 6> {
    FacetTabulation::<2, 6>::new(ElementKind::TriangleP2, 8).unwrap()
}

fn h() -> f64 {
    signorini::runtime::fem::geometry::diameter(&cell(), 3)
}

fn residual<K: FormKernel<2, 6>>(k: &K, fields: &[&Nodes]) -> Nodes {
    facet_vector(k, &tab(), OnFacet { region: 0, facet: 0, h: h() }, &cell(), fields, 0.0)
}

fn jacobian<K: FormKernel<2, 6>>(k: &K, fields: &[&Nodes]) -> Vec<Vec<f64>> {
    jacobian_wrt(k, fields, 0)
}

fn jacobian_wrt<K: FormKernel<2, 6>>(k: &K, fields: &[&Nodes], wrt: usize) -> Vec<Vec<f64>> {
    facet_matrix(k, &tab(), OnFacet { region: 0, facet: 0, h: h() }, &cell(), fields, wrt, 0.0)
}

/// Max-norm difference between the tangent and central differences of the residual in u (the
/// previous level held), relative to the tangent's largest entry, or absolute where that is
/// below 1 (Tresca's slip along a fixed direction has a zero tangent: its stress is s).
fn fd_error<K: FormKernel<2, 6>>(k: &K, u: &Nodes, previous: &Nodes) -> f64 {
    let jac = jacobian(k, &[u, previous]);
    let scale = jac.iter().flatten().fold(1.0f64, |m, v| m.max(v.abs()));
    let mut worst = 0.0f64;
    for col in 0..12 {
        let eps = 1e-8;
        let (mut up, mut um) = (*u, *u);
        up[col / 2][col % 2] += eps;
        um[col / 2][col % 2] -= eps;
        let (rp, rm) = (residual(k, &[&up, previous]), residual(k, &[&um, previous]));
        for row in 0..12 {
            let fd = (rp[row / 2][row % 2] - rm[row / 2][row % 2]) / (2.0 * eps);
            worst = worst.max((fd - jac[row][col]).abs() / scale);
        }
    }
    worst
}

fn nitsche_coulomb(theta: f64, friction: f64) -> coulomb::Contact {
    let p = coulomb::Params::default()
        .with("theta", theta)
        .and_then(|p| p.with("F", friction))
        .and_then(|p| p.with("gamma0", 50.0))
        .unwrap();
    coulomb::Contact::new(&p, &coulomb::Coefficients { f: f(), g: gap(), nc: down() })
}

fn nitsche_tresca(theta: f64) -> tresca::Contact {
    let p = tresca::Params::default()
        .with("theta", theta)
        .and_then(|p| p.with("s", 0.05))
        .and_then(|p| p.with("gamma0", 50.0))
        .unwrap();
    tresca::Contact::new(&p, &tresca::Coefficients { f: f(), g: gap(), nc: down() })
}

fn penalty_coulomb_law(friction: f64) -> penalty_coulomb::Contact {
    let p = penalty_coulomb::Params::default().with("F", friction).and_then(|p| p.with("gamma0", 50.0)).unwrap();
    penalty_coulomb::Contact::new(&p, &penalty_coulomb::Coefficients { f: f(), g: gap(), nc: down() })
}

const REGIMES: [Regime; 3] = [Regime::Separation, Regime::Stick, Regime::Slip];

#[test]
fn frictional_tangents_match_finite_differences_in_every_regime() {
    let mut rng = Rng(0x2545_f491_4f6c_dd1d);
    for regime in REGIMES {
        for trial in 0..3 {
            let (u, previous) = state(&mut rng, regime);
            let check = |what: &str, err: f64| {
                assert!(err < 1e-6, "{what}, {regime:?}, trial {trial}: tangent off finite differences by {err:e}")
            };
            for theta in [1.0, 0.0, -1.0] {
                check(&format!("Nitsche–Coulomb θ = {theta}"), fd_error(&nitsche_coulomb(theta, 0.3), &u, &previous));
                check(&format!("Nitsche–Tresca θ = {theta}"), fd_error(&nitsche_tresca(theta), &u, &previous));
            }
            check("penalty–Coulomb", fd_error(&penalty_coulomb_law(0.3), &u, &previous));
        }
    }
}

/// The penalty law's tangential and normal resultants (Σ over the nodes of the residual's x
/// and y components: ∫ t_x and ∫ ε[u_N − g]_+ n_c,y).
fn resultants(u: &Nodes, previous: &Nodes) -> (f64, f64) {
    let r = residual(&penalty_coulomb_law(0.3), &[u, previous]);
    (r.iter().map(|n| n[0]).sum(), r.iter().map(|n| n[1]).sum())
}

#[test]
fn coulombs_bound_is_reached_in_slip_and_not_in_stick() {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    for trial in 0..3 {
        // Slid along −x everywhere: t = F ε [u_N − g]_+ (1, 0) at every point, so the
        // tangential resultant is F times the normal one.
        let (u, previous) = state(&mut rng, Regime::Slip);
        let (tangential, normal) = resultants(&u, &previous);
        assert!(normal.abs() > 0.0, "trial {trial}: in contact");
        assert!(
            (tangential.abs() - 0.3 * normal.abs()).abs() <= 1e-13 * normal.abs(),
            "trial {trial}: slip: |T| = {tangential}, F |N| = {}",
            0.3 * normal.abs()
        );
        let (u, previous) = state(&mut rng, Regime::Stick);
        let (tangential, normal) = resultants(&u, &previous);
        assert!(tangential.abs() < 0.01 * 0.3 * normal.abs(), "trial {trial}: stick: |T| = {tangential}, N = {normal}");
        let (u, previous) = state(&mut rng, Regime::Separation);
        assert_eq!(resultants(&u, &previous), (0.0, 0.0), "trial {trial}: separated");
    }
}

#[test]
fn without_friction_the_coulomb_laws_are_the_frictionless_ones_bit_for_bit() {
    let mut rng = Rng(0x6a09_e667_f3bc_c909);
    let frictionless_penalty = penalty::Contact::new(
        &penalty::Params::default().with("gamma0", 50.0).unwrap(),
        &penalty::Coefficients { f: f(), g: gap(), nc: down() },
    );
    for regime in REGIMES {
        let (u, previous) = state(&mut rng, regime);
        let both = [&u, &previous];
        assert_eq!(residual(&penalty_coulomb_law(0.0), &both), residual(&frictionless_penalty, &[&u]), "{regime:?}");
        assert_eq!(jacobian(&penalty_coulomb_law(0.0), &both), jacobian(&frictionless_penalty, &[&u]), "{regime:?}");
        for theta in [1.0, 0.0, -1.0] {
            let p = traction::Params::default().with("theta", theta).and_then(|p| p.with("gamma0", 50.0)).unwrap();
            let frictionless = traction::Contact::new(&p, &traction::Coefficients { f: f(), g: gap(), nc: down() });
            let law = nitsche_coulomb(theta, 0.0);
            assert_eq!(residual(&law, &both), residual(&frictionless, &[&u]), "θ = {theta}, {regime:?}");
            assert_eq!(jacobian(&law, &both), jacobian(&frictionless, &[&u]), "θ = {theta}, {regime:?}");
        }
        // The hybrid scheme's term, from u0 = previous to u1 = u, by each argument.
        let coefs = || (f(), gap(), down());
        let (f0, g0, n0) = coefs();
        let p = penalty_coulomb::Params::default().with("F", 0.0).and_then(|p| p.with("gamma0", 50.0)).unwrap();
        let law = penalty_coulomb::HybridContact::new(&p, &penalty_coulomb::Coefficients { f: f0, g: g0, nc: n0 });
        let (f0, g0, n0) = coefs();
        let p = penalty::Params::default().with("gamma0", 50.0).unwrap();
        let frictionless = penalty::HybridContact::new(&p, &penalty::Coefficients { f: f0, g: g0, nc: n0 });
        let steps = [&previous, &u];
        assert_eq!(residual(&law, &steps), residual(&frictionless, &steps), "penalty hybrid, {regime:?}");
        for wrt in 0..2 {
            let (a, b) = (jacobian_wrt(&law, &steps, wrt), jacobian_wrt(&frictionless, &steps, wrt));
            assert_eq!(a, b, "penalty hybrid by u{wrt}, {regime:?}");
        }
        for theta in [1.0, 0.0, -1.0] {
            let (f0, g0, n0) = coefs();
            let p = coulomb::Params::default()
                .with("theta", theta)
                .and_then(|p| p.with("F", 0.0))
                .and_then(|p| p.with("gamma0", 50.0))
                .unwrap();
            let law = coulomb::HybridContact::new(&p, &coulomb::Coefficients { f: f0, g: g0, nc: n0 });
            let (f0, g0, n0) = coefs();
            let p = traction::Params::default().with("theta", theta).and_then(|p| p.with("gamma0", 50.0)).unwrap();
            let frictionless = traction::HybridContact::new(&p, &traction::Coefficients { f: f0, g: g0, nc: n0 });
            assert_eq!(residual(&law, &steps), residual(&frictionless, &steps), "θ = {theta} hybrid, {regime:?}");
            for wrt in 0..2 {
                let (a, b) = (jacobian_wrt(&law, &steps, wrt), jacobian_wrt(&frictionless, &steps, wrt));
                assert_eq!(a, b, "θ = {theta} hybrid by u{wrt}, {regime:?}");
            }
        }
    }
}
