use proptest::prelude::*;

use super::*;
use crate::scheme::affine::eval;

fn library_scheme(name: &str) -> SchemeIr {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../forms/schemes");
    let (prog, _) = crate::check_path(&dir.join(format!("{name}.wf")), &crate::source::FsLoader)
        .unwrap_or_else(|f| panic!("{}", f.rendered));
    prog.schemes.into_iter().next().expect("a scheme")
}

const LIBRARY: &[&str] =
    &["central", "genalpha", "hht", "hht_imex", "hht_unweighted", "hybrid", "midpoint", "newmark", "trbdf2"];

#[test]
fn trbdf2_pivot_times_its_inverse_is_exactly_minus_one() {
    // -((gs*dt)^2/4*(1/((gs*dt)^2/4))), as the elimination builds it.
    let mut g = Graph::default();
    let (gs, dt) = (g.sym(Sym::Param(0)), g.sym(Sym::Dt));
    let (one, four) = (g.one(), g.constant(4.0));
    let gsdt = g.mul(gs, dt);
    let sq = g.powi(gsdt, 2);
    let pivot = g.div(sq, four);
    let inv = g.div(one, pivot);
    let prod = g.mul(pivot, inv);
    let e = g.neg(prod);
    let s = simplify(&mut g, e);
    assert_eq!(g.as_const(s), Some(-1.0));
    assert_eq!(eval(&g, s, &[2.0 - 2f64.sqrt()], 0.37, 0.0), -1.0);
}

#[test]
fn newmark_ratio_is_one() {
    // dt^2/2*(2*beta)/(beta*dt^2)
    let mut g = Graph::default();
    let (beta, dt) = (g.sym(Sym::Param(0)), g.sym(Sym::Dt));
    let two = g.constant(2.0);
    let dt2 = g.powi(dt, 2);
    let half = g.div(dt2, two);
    let tb = g.mul(two, beta);
    let num = g.mul(half, tb);
    let den = g.mul(beta, dt2);
    let e = g.div(num, den);
    let s = simplify(&mut g, e);
    assert_eq!(g.as_const(s), Some(1.0));
}

#[test]
fn a_sum_times_its_inverse_cancels_in_any_spelling() {
    let mut g = Graph::default();
    let gs = g.sym(Sym::Param(0));
    let (one, two) = (g.one(), g.constant(2.0));
    let a = g.sub(one, gs); // 1 - gs
    let b = g.sub(gs, one); // gs - 1
    let twice = g.mul(two, b); // 2*(gs - 1)
    let e = g.div(a, twice);
    let s = simplify(&mut g, e);
    assert_eq!(g.as_const(s), Some(-0.5));
    // (1 - gs)^2 / (1 - gs) = 1 - gs, one sum.
    let sq = g.powi(a, 2);
    let e = g.div(sq, a);
    let s = simplify(&mut g, e);
    assert_eq!(Normalizer::default().expr(&g, s), Normalizer::default().expr(&g, a));
    assert_eq!(eval(&g, s, &[0.25], 1.0, 0.0), 0.75);
}

#[test]
fn like_terms_combine_and_constants_fold_exactly() {
    let mut g = Graph::default();
    let (gs, dt) = (g.sym(Sym::Param(0)), g.sym(Sym::Dt));
    let (two, three, third) = (g.constant(2.0), g.constant(3.0), g.constant(1.0 / 3.0));
    let x = g.mul(gs, dt);
    let y = g.mul(two, x); // 2·gs·dt
    let z = g.mul(dt, gs); // the same product, other order
    let w = g.mul(three, z);
    let sum = g.add(x, y);
    let e = g.sub(sum, w); // gs·dt + 2·gs·dt − 3·gs·dt
    let s = simplify(&mut g, e);
    assert_eq!(g.as_const(s), Some(0.0));
    // 3·(1/3)·gs = gs: the f64 1/3 is the rational 1/3.
    let p = g.mul(three, third);
    let e = g.mul(p, gs);
    let e = g.add(e, dt);
    let s = simplify(&mut g, e);
    let expected = g.add(gs, dt);
    assert_eq!(s, expected);
}

#[test]
fn overflow_keeps_the_original_node() {
    let mut g = Graph::default();
    let gs = g.sym(Sym::Param(0));
    let c = g.constant(1.0 / 1021.0);
    let sum = g.add(gs, c);
    // (gs + 1/1021)^64: the content 1021^-64 does not fit an i128.
    let e = g.powi(sum, 64);
    assert_eq!(simplify(&mut g, e), e);
}

#[test]
fn lets_come_back_as_names() {
    let s = library_scheme("trbdf2");
    let text = crate::scheme::print::print(&s);
    assert!(text.contains("v' = 1/c·u'"), "{text}");
    let s = library_scheme("hht");
    let text = crate::scheme::print::print(&s);
    assert!(text.contains("a' = 1/(beta*dt^2)·u'"), "{text}");
}

/// Every library scheme's coefficients: the TR-BDF2 trapezoidal stage is 4/(gs·dt)² etc.
#[test]
fn library_coefficients_are_simplified() {
    let mut s = library_scheme("trbdf2");
    scheme(&mut s);
    let g = &s.graph;
    let am = &s.stages[0].values[2];
    assert_eq!(
        g.as_const(am.known.iter().find(|(q, _)| *q == super::super::Quantity::State(2)).unwrap().1),
        Some(-1.0)
    );
    // vm no longer depends on a (its coefficient cancels exactly).
    let vm = &s.stages[0].values[1];
    assert!(!vm.known.iter().any(|(q, _)| *q == super::super::Quantity::State(2)));
}

/// Samples of the scheme parameters inside their ranges.
fn in_range(p: &super::super::SchemeParamInfo, x: f64) -> f64 {
    match p.range {
        Some(r) if r.lo.is_finite() && r.hi.is_finite() => {
            let v = r.lo + x * (r.hi - r.lo);
            if r.contains(v) { v } else { p.default }
        }
        _ => p.default * (0.5 + x),
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Every node of every library scheme's coefficient graph (the unsimplified
    /// coefficients and all their subexpressions are still there) simplifies to a node
    /// with the same value: within 1e-12 of the size of the terms that cancel in it.
    #[test]
    fn simplified_nodes_evaluate_like_the_originals(
        which in 0..LIBRARY.len(), xs in prop::collection::vec(0.01f64..0.99, 4), log_dt in -4.0f64..0.5, t in 0.0f64..10.0
    ) {
        let mut s = library_scheme(LIBRARY[which]);
        let params: Vec<f64> = s.params.iter().zip(&xs).map(|(p, x)| in_range(p, *x)).collect();
        let dt = 10f64.powf(log_dt);
        let g = &mut s.graph;
        let mut simp = Simplifier::new(g);
        for id in 0..g.len() as NodeId {
            let new = simp.node(g, id);
            let (x, scale) = value_and_scale(g, id, &params, dt, t);
            let y = eval(g, new, &params, dt, t);
            if x.is_finite() {
                prop_assert!((x - y).abs() <= 1e-12 * scale.max(y.abs()),
                    "{}: node {id}: {x} became {y} (scale {scale})", LIBRARY[which]);
            }
        }
    }
}
