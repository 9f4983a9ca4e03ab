//! Contact measured on the deformed configuration (`forms/contact_penalty_deformed.wf`): the
//! compiled tangent against central differences of the compiled residual against a curved
//! obstacle (a disc the body lies outside of), where the gap and the normal are read at the
//! displaced point and their derivatives there (the obstacle's curvature) enter the tangent:
//! in separation and contact at once, and with friction in stick and in slip; and against a
//! plane, where g(x + u) = g − u·nc, the residual of the law of small strain.

use signorini::runtime::fem::element::ElementKind;
use signorini::runtime::fem::kernel::{Coef, FacetTabulation, FormKernel, OnFacet, facet_matrix, facet_vector};

use crate::tangents::Rng;

signorini::forms!("forms/contact_penalty_deformed.wf");
signorini::forms!("forms/contact_penalty_coulomb.wf");

/// A rigid disc of radius `r` about `c`, the body outside: g = |y − c| − r, nc = (c − y)/|y − c|,
/// with their first and second derivatives (the curvature (I − n̂n̂ᵀ)/|y − c|).
fn disc(c: [f64; 2], r: f64) -> (Coef, Coef) {
    // n̂ = (y − c)/ρ, ∂_k n̂_i = (δ_ik − n̂_i n̂_k)/ρ.
    let unit = move |y: &[f64]| {
        let d = [y[0] - c[0], y[1] - c[1]];
        let rho = d[0].hypot(d[1]);
        ([d[0] / rho, d[1] / rho], rho)
    };
    let dn = |n: [f64; 2], rho: f64, i: usize, k: usize| (f64::from(i == k) - n[i] * n[k]) / rho;
    let g = Coef::function(1, move |y, _, out| out[0] = unit(y).1 - r).with_derivatives(move |y, _, order, out| {
        let (n, rho) = unit(y);
        for k in 0..2 {
            if order == 1 {
                out[k] = n[k];
            } else {
                for l in 0..2 {
                    out[k * 2 + l] = dn(n, rho, k, l);
                }
            }
        }
    });
    let nc = Coef::function(2, move |y, _, out| {
        let (n, _) = unit(y);
        out[0] = -n[0];
        out[1] = -n[1];
    })
    .with_derivatives(move |y, _, order, out| {
        let (n, rho) = unit(y);
        for i in 0..2 {
            for k in 0..2 {
                if order == 1 {
                    out[i * 2 + k] = -dn(n, rho, i, k);
                } else {
                    // ∂_l ∂_k n̂_i = −(∂_l n̂_i n̂_k + n̂_i ∂_l n̂_k)/ρ − (δ_ik − n̂_i n̂_k) n̂_l/ρ².
                    for l in 0..2 {
                        let second =
                            -(dn(n, rho, i, l) * n[k] + n[i] * dn(n, rho, k, l)) / rho - dn(n, rho, i, k) * n[l] / rho;
                        out[(i * 2 + k) * 2 + l] = -second;
                    }
                }
            }
        }
    });
    (g, nc)
}

fn law(f: f64, g: Coef, nc: Coef) -> contact_penalty_deformed::Contact {
    let p = contact_penalty_deformed::Params::default().with("gamma0", 5.0).and_then(|p| p.with("F", f)).unwrap();
    contact_penalty_deformed::Contact::new(&p, &contact_penalty_deformed::Coefficients { g, nc })
}

/// A curved P2 triangle whose facet 0 runs along y ≈ 0 from x = 0 to x = 1.
fn cell() -> [[f64; 2]; 6] {
    let (a, b, c) = ([0.0, 0.02], [1.0, 0.06], [0.35, 0.85]);
    let mid = |p: [f64; 2], q: [f64; 2]| [0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1])];
    [a, b, c, [0.5, 0.0], mid(b, c), mid(c, a)]
}

const H: f64 = 1.0;

/// The tangent with respect to u and its largest difference from central differences of the
/// residual, relative to the tangent's largest entry; fields [u, w] (w the previous level).
fn fd_error<K: FormKernel<2, 6>>(k: &K, u: &[[f64; 2]; 6], w: &[[f64; 2]; 6]) -> (Vec<Vec<f64>>, f64) {
    let tab = FacetTabulation::<2, 6>::new(ElementKind::TriangleP2, 8).unwrap();
    let (x, at) = (cell(), OnFacet { region: 0, facet: 0, h: H });
    let jac = facet_matrix(k, &tab, at, &x, &[u, w], 0, 0.0);
    let scale = jac.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut worst = 0.0f64;
    for col in 0..12 {
        let eps = 1e-7;
        let (mut up, mut um) = (*u, *u);
        up[col / 2][col % 2] += eps;
        um[col / 2][col % 2] -= eps;
        let rp = facet_vector(k, &tab, at, &x, &[&up, w], 0.0);
        let rm = facet_vector(k, &tab, at, &x, &[&um, w], 0.0);
        for row in 0..12 {
            let fd = (rp[row / 2][row % 2] - rm[row / 2][row % 2]) / (2.0 * eps);
            worst = worst.max((fd - jac[row][col]).abs() / scale);
        }
    }
    (jac, worst)
}

/// The disc below the facet, its top at y = −0.02 under x = 0.5: a state that pushes the
/// middle of the facet into it and keeps its ends off, displaced sideways by `slide` too.
fn state(rng: &mut Rng, slide: f64) -> [[f64; 2]; 6] {
    let x = cell();
    std::array::from_fn(|j| [slide + 0.01 * rng.next(), 0.15 * (x[j][0] - 0.5) - 0.05 + 0.005 * rng.next()])
}

/// The contact switches at the facet's quadrature points: (active, inactive).
fn switches<K: FormKernel<2, 6>>(k: &K, u: &[[f64; 2]; 6]) -> (usize, usize) {
    use signorini::runtime::fem::kernel::FacetCtx;
    let tab = FacetTabulation::<2, 6>::new(ElementKind::TriangleP2, 8).unwrap();
    let (ftab, normal) = &tab.facets[0];
    let x = cell();
    let ctx = FacetCtx { tab: ftab, ref_normal: normal, coords: &x, h: H, t: 0.0 };
    let mut out = Vec::new();
    k.facet_switches(0, &ctx, &[u, u], 0, &mut out);
    let on = out.iter().filter(|s| **s).count();
    (on, out.len() - on)
}

#[test]
fn the_tangent_on_a_curved_obstacle_matches_finite_differences_in_contact_and_separation() {
    let (g, nc) = disc([0.5, -1.02], 1.0);
    let k = law(0.0, g, nc);
    let mut rng = Rng(0x2545_f491_4f6c_dd1d);
    for trial in 0..5 {
        // Slid far along the obstacle: the contact is where the body is, not where it was.
        let u = state(&mut rng, 0.05 * trial as f64);
        let (_, err) = fd_error(&k, &u, &u);
        assert!(err < 1e-6, "trial {trial}: tangent differs from finite differences by {err:e}");
        // Contact and separation at once.
        let (on, off) = switches(&k, &u);
        assert!(on > 0 && off > 0, "trial {trial}: the active set is not mixed ({on} on, {off} off)");
    }
}

#[test]
fn the_frictional_tangent_matches_finite_differences_in_stick_and_slip() {
    let (g, nc) = disc([0.5, -1.02], 1.0);
    let k = law(0.3, g, nc);
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    // Pushed into the obstacle all along: stick for a small slip since the previous level,
    // slip for a large one (the trial stress outside Coulomb's ball).
    let x = cell();
    for (slip, what) in [(1e-5, "stick"), (0.05, "slip")] {
        let u: [[f64; 2]; 6] = std::array::from_fn(|j| [0.1 + 0.01 * rng.next(), -0.03 + 0.002 * x[j][0]]);
        let w = u.map(|n| [n[0] - slip, n[1]]);
        let (_, err) = fd_error(&k, &u, &w);
        assert!(err < 1e-6, "{what}: tangent differs from finite differences by {err:e}");
    }
}

#[test]
fn against_a_plane_it_is_the_law_of_small_strain() {
    // g = x_1 + 0.1 and nc = −e_1 as functions of the point; the reference law reads them at x.
    let g = Coef::function(1, |y, _, out| out[0] = y[1] + 0.1).with_derivatives(|_, _, order, out| {
        out.fill(0.0);
        if order == 1 {
            out[1] = 1.0;
        }
    });
    let nc = Coef::constant(vec![0.0, -1.0]);
    let deformed = law(0.3, g.clone(), nc.clone());
    let p = contact_penalty_coulomb::Params::default().with("gamma0", 5.0).and_then(|p| p.with("F", 0.3)).unwrap();
    let small = contact_penalty_coulomb::Contact::new(
        &p,
        &contact_penalty_coulomb::Coefficients { f: Coef::constant(vec![0.0, 0.0]), g, nc },
    );
    let tab = FacetTabulation::<2, 6>::new(ElementKind::TriangleP2, 8).unwrap();
    let (x, at) = (cell(), OnFacet { region: 0, facet: 0, h: H });
    let mut rng = Rng(0x1234_5678_9abc_def1);
    for _ in 0..5 {
        let u: [[f64; 2]; 6] = std::array::from_fn(|j| [0.02 * rng.next(), -0.1 + 0.2 * (x[j][0] - 0.5)]);
        let w = u.map(|n| [n[0] - 0.01, n[1]]);
        let a = facet_vector(&deformed, &tab, at, &x, &[&u, &w], 0.0);
        let b = facet_vector(&small, &tab, at, &x, &[&u, &w], 0.0);
        let scale = b.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
        let diff = a.iter().flatten().zip(b.iter().flatten()).fold(0.0f64, |m, (p, q)| m.max((p - q).abs()));
        assert!(scale > 0.0 && diff <= 1e-14 * scale, "differ by {diff:e} of {scale:e}");
    }
}

// Nitsche's method on the deformed configuration (`forms/contact_nitsche_deformed.wf`), its
// traction the material's first Piola–Kirchhoff stress: compiled with the neo-Hookean material
// bound to its `import material = elasticity`, and with that default.
signorini::forms!(mod nitsche_neo_hookean = "forms/contact_nitsche_deformed.wf", material = "forms/neo_hookean.wf");
signorini::forms!("forms/contact_nitsche_deformed.wf");
signorini::forms!("forms/contact_nitsche.wf");

fn nitsche_neo_hookean(theta: f64, g: Coef, nc: Coef) -> nitsche_neo_hookean::Contact {
    let p = nitsche_neo_hookean::Params::default();
    let p = p.with("gamma0", 50.0).and_then(|p| p.with("theta", theta)).and_then(|p| p.with("E", 10.0)).unwrap();
    let p = p.with("nu", 0.3).unwrap();
    nitsche_neo_hookean::Contact::new(&p, &nitsche_neo_hookean::Coefficients { f: Coef::constant(vec![0.0; 2]), g, nc })
}

#[test]
fn the_nitsche_tangent_at_finite_strain_matches_finite_differences_and_is_symmetric_for_theta_one() {
    let (g, nc) = disc([0.5, -1.02], 1.0);
    let mut rng = Rng(0x5851_f42d_4c95_7f2d);
    for theta in [1.0, 0.0, -1.0] {
        let k = nitsche_neo_hookean(theta, g.clone(), nc.clone());
        for trial in 0..3 {
            let u = state(&mut rng, 0.05 * trial as f64);
            let (jac, err) = fd_error(&k, &u, &u);
            assert!(err < 1e-6, "theta {theta}, trial {trial}: tangent differs from finite differences by {err:e}");
            let (on, off) = switches(&k, &u);
            assert!(
                on > 0 && off > 0,
                "theta {theta}, trial {trial}: the active set is not mixed ({on} on, {off} off)"
            );
            if theta == 1.0 {
                // The variation of an energy: its tangent is that energy's Hessian.
                let scale = jac.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
                let skew = (0..12)
                    .flat_map(|i| (0..12).map(move |j| (i, j)))
                    .fold(0.0f64, |m, (i, j)| m.max((jac[i][j] - jac[j][i]).abs()));
                assert!(skew <= 1e-10 * scale, "trial {trial}: the tangent is not symmetric ({skew:e} of {scale:e})");
            }
        }
    }
}

#[test]
fn against_a_plane_with_a_linear_material_the_nitsche_law_is_that_of_small_strain() {
    let g = Coef::function(1, |y, _, out| out[0] = y[1] + 0.1).with_derivatives(|_, _, order, out| {
        out.fill(0.0);
        if order == 1 {
            out[1] = 1.0;
        }
    });
    let nc = Coef::constant(vec![0.0, -1.0]);
    let f = Coef::constant(vec![0.0, 0.0]);
    let tab = FacetTabulation::<2, 6>::new(ElementKind::TriangleP2, 8).unwrap();
    let (x, at) = (cell(), OnFacet { region: 0, facet: 0, h: H });
    let mut rng = Rng(0x0bad_5eed_1234_5678);
    for theta in [1.0, 0.0, -1.0] {
        let set = |name: &str, v: f64| (name.to_string(), v);
        let values = [set("gamma0", 50.0), set("theta", theta), set("E", 10.0), set("nu", 0.3)];
        let mut p = contact_nitsche_deformed::Params::default();
        let mut q = contact_nitsche::Params::default();
        for (name, v) in &values {
            p = p.with(name, *v).unwrap();
            q = q.with(name, *v).unwrap();
        }
        let coefs = contact_nitsche_deformed::Coefficients { f: f.clone(), g: g.clone(), nc: nc.clone() };
        let deformed = contact_nitsche_deformed::Contact::new(&p, &coefs);
        let small = contact_nitsche::Contact::new(
            &q,
            &contact_nitsche::Coefficients { f: f.clone(), g: g.clone(), nc: nc.clone() },
        );
        for _ in 0..3 {
            let u: [[f64; 2]; 6] = std::array::from_fn(|j| [0.02 * rng.next(), -0.1 + 0.2 * (x[j][0] - 0.5)]);
            let (on, off) = switches(&small, &u);
            assert!(on > 0 && off > 0, "theta {theta}: the active set is not mixed ({on} on, {off} off)");
            let a = facet_vector(&deformed, &tab, at, &x, &[&u], 0.0);
            let b = facet_vector(&small, &tab, at, &x, &[&u], 0.0);
            let scale = b.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
            let diff = a.iter().flatten().zip(b.iter().flatten()).fold(0.0f64, |m, (p, q)| m.max((p - q).abs()));
            assert!(scale > 0.0 && diff <= 1e-13 * scale, "theta {theta}: residuals differ by {diff:e} of {scale:e}");
            let (ka, kb) = (
                facet_matrix(&deformed, &tab, at, &x, &[&u], 0, 0.0),
                facet_matrix(&small, &tab, at, &x, &[&u], 0, 0.0),
            );
            let scale = kb.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
            let diff = ka.iter().flatten().zip(kb.iter().flatten()).fold(0.0f64, |m, (p, q)| m.max((p - q).abs()));
            assert!(diff <= 1e-13 * scale, "theta {theta}: tangents differ by {diff:e} of {scale:e}");
        }
    }
}
