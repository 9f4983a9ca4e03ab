//! The compiled contact tangents against central finite differences of the compiled residuals
//! (Nitsche θ ∈ {1, 0, −1} and penalty, 1D P1 and 2D curved P2), at states where some contact
//! quadrature points are active and some are not; and the 1D contact residual against the
//! closed-form kernel of spec §3.4, which pins down the sign conventions of the .wf files.

use signorini::runtime::fem::element::ElementKind;
use signorini::runtime::fem::kernel::{Coef, FacetTabulation, FormKernel, OnFacet, facet_matrix, facet_vector};

signorini::forms!("forms/contact_nitsche.wf");
signorini::forms!("forms/contact_penalty.wf");
signorini::forms!("forms/contact_nitsche_traction.wf");
signorini::forms!("tests/problems/power_law_penalty.wf");

/// Gap to the plane {x_d = 0} with the obstacle below: g = x_d, n_c = −e_d.
fn gap(d: usize) -> Coef {
    Coef::function(1, move |x, _, out| out[0] = x[d - 1])
}

fn down(d: usize) -> Coef {
    Coef::constant((0..d).map(|k| if k == d - 1 { -1.0 } else { 0.0 }).collect::<Vec<_>>())
}

fn nitsche(theta: f64, gamma0: f64, e: f64, nu: f64, d: usize) -> contact_nitsche::Contact {
    let p = contact_nitsche::Params::default()
        .with("theta", theta)
        .and_then(|p| p.with("gamma0", gamma0))
        .and_then(|p| p.with("E", e))
        .and_then(|p| p.with("nu", nu))
        .unwrap();
    let c = contact_nitsche::Coefficients { f: Coef::constant(vec![0.0; d]), g: gap(d), nc: down(d) };
    c.check(d).unwrap();
    contact_nitsche::Contact::new(&p, &c)
}

/// GetFEM's variant: the θ term with the full traction σ(u)n·σ(v)n.
fn traction(theta: f64, d: usize) -> contact_nitsche_traction::Contact {
    let p = contact_nitsche_traction::Params::default().with("theta", theta).and_then(|p| p.with("nu", 0.3)).unwrap();
    let c = contact_nitsche_traction::Coefficients { f: Coef::constant(vec![0.0; d]), g: gap(d), nc: down(d) };
    contact_nitsche_traction::Contact::new(&p, &c)
}

fn penalty(gamma0: f64, d: usize) -> contact_penalty::Contact {
    let p = contact_penalty::Params::default().with("gamma0", gamma0).unwrap();
    let c = contact_penalty::Coefficients { f: Coef::constant(vec![0.0; d]), g: gap(d), nc: down(d) };
    contact_penalty::Contact::new(&p, &c)
}

/// Max-norm relative difference between the tangent and central differences of the residual.
fn fd_error<const D: usize, const N: usize, K: FormKernel<D, N>>(
    k: &K,
    tab: &FacetTabulation<D, N>,
    x: &[[f64; D]; N],
    u: &[[f64; D]; N],
) -> f64 {
    let h = signorini::runtime::fem::geometry::diameter(x, D + 1);
    let jac = facet_matrix(k, tab, OnFacet { region: 0, facet: 0, h }, x, &[u], 0, 0.0);
    let scale = jac.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut worst = 0.0f64;
    for col in 0..N * D {
        let eps = 1e-7;
        let (mut up, mut um) = (*u, *u);
        up[col / D][col % D] += eps;
        um[col / D][col % D] -= eps;
        let rp = facet_vector(k, tab, OnFacet { region: 0, facet: 0, h }, x, &[&up], 0.0);
        let rm = facet_vector(k, tab, OnFacet { region: 0, facet: 0, h }, x, &[&um], 0.0);
        for row in 0..N * D {
            let fd = (rp[row / D][row % D] - rm[row / D][row % D]) / (2.0 * eps);
            worst = worst.max((fd - jac[row][col]).abs() / scale);
        }
    }
    worst
}

fn tangent<const D: usize, const N: usize, K: FormKernel<D, N>>(
    k: &K,
    tab: &FacetTabulation<D, N>,
    x: &[[f64; D]; N],
    u: &[[f64; D]; N],
) -> Vec<Vec<f64>> {
    let h = signorini::runtime::fem::geometry::diameter(x, D + 1);
    facet_matrix(k, tab, OnFacet { region: 0, facet: 0, h }, x, &[u], 0, 0.0)
}

/// Deterministic pseudo-random numbers in [−1, 1] (xorshift), so failures reproduce.
pub(crate) struct Rng(pub(crate) u64);
impl Rng {
    pub(crate) fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }
}

/// A curved P2 triangle whose edge (0,1) lies along the ground y ≈ 0, bulging below it.
fn cell_2d() -> [[f64; 2]; 6] {
    let (a, b, c) = ([0.0, 0.02], [1.0, 0.06], [0.35, 0.85]);
    let mid = |p: [f64; 2], q: [f64; 2]| [0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1])];
    [a, b, c, [0.5, 0.0], mid(b, c), mid(c, a)]
}

/// A state whose normal displacement goes from penetrating to separated along the facet.
fn state_2d(rng: &mut Rng, shift: f64) -> [[f64; 2]; 6] {
    let x = cell_2d();
    std::array::from_fn(|j| [0.02 * rng.next(), 0.3 * (x[j][0] - 0.5) + 0.01 * rng.next() + shift])
}

fn check_2d<K: FormKernel<2, 6>>(k: &K, what: &str) {
    let tab = FacetTabulation::<2, 6>::new(ElementKind::TriangleP2, 7).unwrap();
    let x = cell_2d();
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    for trial in 0..5 {
        let u = state_2d(&mut rng, 0.0);
        let err = fd_error(k, &tab, &x, &u);
        assert!(err < 1e-6, "{what}, trial {trial}: tangent differs from finite differences by {err:e}");
        // Mixed active set: the tangent differs from both the all-active state (pushed into
        // the obstacle) and the all-inactive one (lifted off it).
        let mixed = tangent(k, &tab, &x, &u);
        let all_in = tangent(k, &tab, &x, &u.map(|n| [n[0], n[1] - 10.0]));
        let all_out = tangent(k, &tab, &x, &u.map(|n| [n[0], n[1] + 10.0]));
        let differ = |a: &[Vec<f64>], b: &[Vec<f64>]| {
            a.iter().flatten().zip(b.iter().flatten()).any(|(p, q)| (p - q).abs() > 1e-8)
        };
        assert!(
            differ(&mixed, &all_in) && differ(&mixed, &all_out),
            "{what}, trial {trial}: the active set is not mixed"
        );
    }
}

#[test]
fn nitsche_tangent_matches_finite_differences_in_2d() {
    for theta in [1.0, 0.0, -1.0] {
        check_2d(&nitsche(theta, 5.0, 1.0, 0.3, 2), &format!("Nitsche θ = {theta}"));
        check_2d(&traction(theta, 2), &format!("Nitsche (full traction) θ = {theta}"));
    }
}

#[test]
fn penalty_tangent_matches_finite_differences_in_2d() {
    check_2d(&penalty(5.0, 2), "penalty");
}

/// A real power in a law (ε [u_N − g]_+^(3/2)): its derivative (3/2) ε [u_N − g]_+^(1/2) in
/// the compiled tangent, and in 1D against the closed form.
#[test]
fn a_real_power_differentiates_as_p_times_the_power_below() {
    let p = power_law_penalty::Params::default().with("gamma0", 5.0).unwrap();
    for d in [1, 2] {
        let c = power_law_penalty::Coefficients { f: Coef::constant(vec![0.0; d]), g: gap(d), nc: down(d) };
        let k = power_law_penalty::Contact::new(&p, &c);
        if d == 2 {
            check_2d(&k, "power-law penalty");
            continue;
        }
        check_1d(&k, "power-law penalty");
        // The bar element [0, h] pushed in by δ at x = 0: the tangent's (0, 0) entry is
        // (3/2) (γ0/h) δ^(1/2) (n = −1 twice).
        let tab = FacetTabulation::<1, 2>::new(ElementKind::IntervalP1, 1).unwrap();
        let (h, delta) = (0.25, 0.04);
        let x = [[0.0], [h]];
        let jac = facet_matrix(&k, &tab, OnFacet { region: 0, facet: 0, h }, &x, &[&[[-delta], [0.0]]], 0, 0.0);
        let exact = 1.5 * 5.0 / h * delta.sqrt();
        assert!((jac[0][0] - exact).abs() < 1e-12 * exact, "{} against {exact}", jac[0][0]);
    }
}

/// 1D bar element [0, h] with contact at x = 0 (facet 0).
fn check_1d<K: FormKernel<1, 2>>(k: &K, what: &str) {
    let tab = FacetTabulation::<1, 2>::new(ElementKind::IntervalP1, 1).unwrap();
    let x = [[0.0], [0.05]];
    let mut rng = Rng(12345);
    let (mut active, mut inactive) = (0, 0);
    for trial in 0..40 {
        let u = [[0.1 * rng.next()], [0.1 * rng.next()]];
        let err = fd_error(k, &tab, &x, &u);
        assert!(err < 1e-6, "{what}, trial {trial}: tangent differs from finite differences by {err:e}");
        let j = tangent(k, &tab, &x, &u);
        let j_far = tangent(k, &tab, &x, &[[10.0], [10.0]]);
        if j.iter().flatten().zip(j_far.iter().flatten()).any(|(p, q)| (p - q).abs() > 1e-8) {
            active += 1;
        } else {
            inactive += 1;
        }
    }
    assert!(active > 5 && inactive > 5, "{what}: {active} active and {inactive} inactive states");
}

#[test]
fn contact_tangents_match_finite_differences_in_1d() {
    for theta in [1.0, 0.0, -1.0] {
        check_1d(&nitsche(theta, 5.0, 1.0, 0.0, 1), &format!("Nitsche θ = {theta}"));
    }
    check_1d(&penalty(5.0, 1), "penalty");
}

/// Spec §3.4: with s = (E/h)(−1, 1) and e0 = (1, 0),
/// C(u) = −θ/γ (s·u) s + 1/γ [(s + γ e0)·u]_− (θ s + γ e0); penalty: C(u) = ε min(u0, 0) e0.
#[test]
fn one_dimensional_contact_residual_is_the_spec_kernel() {
    let (e, h, gamma0) = (1.3, 0.05, 5.0);
    let gamma = gamma0 / h;
    let tab = FacetTabulation::<1, 2>::new(ElementKind::IntervalP1, 1).unwrap();
    let x = [[0.0], [h]];
    let mut rng = Rng(777);
    for theta in [1.0, 0.0, -1.0] {
        let k = nitsche(theta, gamma0, e, 0.0, 1);
        for _ in 0..20 {
            let u = [[0.05 * rng.next()], [0.05 * rng.next()]];
            let s = [-e / h, e / h];
            let su = s[0] * u[0][0] + s[1] * u[1][0];
            let p1 = su + gamma * u[0][0];
            let neg = p1.min(0.0);
            let expect = [
                -theta / gamma * su * s[0] + neg / gamma * (theta * s[0] + gamma),
                -theta / gamma * su * s[1] + neg / gamma * theta * s[1],
            ];
            let got = facet_vector(&k, &tab, OnFacet { region: 0, facet: 0, h }, &x, &[&u], 0.0);
            for i in 0..2 {
                assert!(
                    (got[i][0] - expect[i]).abs() < 1e-12 * (1.0 + expect[i].abs()),
                    "θ = {theta}: {got:?} vs {expect:?}"
                );
            }
        }
    }
    let k = penalty(gamma0, 1);
    for _ in 0..20 {
        let u = [[0.05 * rng.next()], [0.05 * rng.next()]];
        let got = facet_vector(&k, &tab, OnFacet { region: 0, facet: 0, h }, &x, &[&u], 0.0);
        let expect = gamma * u[0][0].min(0.0);
        assert!((got[0][0] - expect).abs() < 1e-12 && got[1][0] == 0.0, "penalty: {got:?} vs {expect}");
    }
}

/// A form of two time levels: the tangent with respect to either level matches finite
/// differences with respect to that level only.
#[test]
fn hybrid_contact_tangents_match_finite_differences_for_each_time_level() {
    let p = contact_nitsche::Params::default().with("gamma0", 5.0).and_then(|p| p.with("nu", 0.3)).unwrap();
    let c = contact_nitsche::Coefficients { f: Coef::constant(vec![0.0; 2]), g: gap(2), nc: down(2) };
    let k = contact_nitsche::HybridContact::new(&p, &c);
    assert_eq!(*contact_nitsche::HybridContact::META.fields, ["u0", "u1"]);
    const { assert!(!contact_nitsche::HybridContact::META.linear) };
    let tab = FacetTabulation::<2, 6>::new(ElementKind::TriangleP2, 7).unwrap();
    let x = cell_2d();
    let h = signorini::runtime::fem::geometry::diameter(&x, 3);
    let mut rng = Rng(4242);
    for trial in 0..5 {
        let u0 = state_2d(&mut rng, 0.0);
        let u1 = state_2d(&mut rng, 0.02);
        for wrt in 0..2 {
            let jac = facet_matrix(&k, &tab, OnFacet { region: 0, facet: 0, h }, &x, &[&u0, &u1], wrt, 0.0);
            let scale = jac.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
            assert!(scale > 0.0);
            for col in 0..12 {
                let eps = 1e-7;
                let mut plus = [u0, u1];
                let mut minus = [u0, u1];
                plus[wrt][col / 2][col % 2] += eps;
                minus[wrt][col / 2][col % 2] -= eps;
                let rp = facet_vector(&k, &tab, OnFacet { region: 0, facet: 0, h }, &x, &[&plus[0], &plus[1]], 0.0);
                let rm = facet_vector(&k, &tab, OnFacet { region: 0, facet: 0, h }, &x, &[&minus[0], &minus[1]], 0.0);
                for row in 0..12 {
                    let fd = (rp[row / 2][row % 2] - rm[row / 2][row % 2]) / (2.0 * eps);
                    let err = (fd - jac[row][col]).abs() / scale;
                    assert!(err < 1e-6, "trial {trial}, d/du{wrt}, entry ({row}, {col}): {err:e}");
                }
            }
        }
    }
}

/// Nitsche and penalty tangents depend on the state only through the active set: states with
/// the same switches have the same tangent, and the switches of a mixed state are mixed.
#[test]
fn equal_switches_mean_equal_tangents() {
    use signorini::runtime::fem::kernel::FacetCtx;
    const { assert!(contact_nitsche::Contact::META.piecewise && contact_penalty::Contact::META.piecewise) };
    let tab = FacetTabulation::<2, 6>::new(ElementKind::TriangleP2, 7).unwrap();
    let x = cell_2d();
    let h = signorini::runtime::fem::geometry::diameter(&x, 3);
    let k = nitsche(-1.0, 5.0, 1.0, 0.3, 2);
    let switches = |u: &[[f64; 2]; 6]| {
        let (ftab, normal) = &tab.facets[0];
        let mut s = Vec::new();
        k.facet_switches(0, &FacetCtx { tab: ftab, ref_normal: normal, coords: &x, h, t: 0.0 }, &[u], 0, &mut s);
        s
    };
    let mut rng = Rng(99);
    let mut pairs = 0;
    let states: Vec<[[f64; 2]; 6]> = (0..60)
        .map(|_| {
            let shift = 0.02 * rng.next();
            state_2d(&mut rng, shift)
        })
        .collect();
    for a in &states {
        let sa = switches(a);
        assert_eq!(sa.len(), tab.facets[0].0.len());
        for b in &states {
            if switches(b) == sa {
                pairs += 1;
                assert_eq!(tangent(&k, &tab, &x, a), tangent(&k, &tab, &x, b));
            }
        }
    }
    assert!(pairs > states.len(), "no two distinct states shared an active set");
    let s = switches(&states[0]);
    assert!(s.iter().any(|b| *b) && s.iter().any(|b| !*b), "{s:?}");
}
