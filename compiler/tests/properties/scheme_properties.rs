//! Random Newmark-family schemes: whatever the coefficients and whichever level is the
//! unknown, the compiled stage (each new quantity as an affine function of the unknown and the
//! known states) satisfies the relations the file declares, at random states, unknowns, Δt
//! and parameter values.

use std::path::Path;

use proptest::prelude::*;
use signorini_compiler::scheme::{Quantity, SchemeIr, eval_all};
use signorini_compiler::{MemLoader, compile_text};

/// u' = u + dt v + dt²(c1 a + beta a'), v' = v + dt(c3 a + c4 a'), beta a param.
fn source(c: [f64; 4], unknown: &str) -> String {
    let [c1, beta, c3, c4] = c;
    format!(
        "scheme rnd(beta = {beta} in [0.01, 1]) {{
  uses mass, stiffness, load
  state u, v, a
  initial a: mass(a) + stiffness(u) == load(t)
  unknown {unknown}
  relate u' = u + dt*v + dt^2*({c1}*a + beta*a')
  relate v' = v + dt*({c3}*a + {c4}*a')
  residual mass(a') + stiffness(u') == load(t + dt)
}}
"
    )
}

/// The values of the stage's new quantities, by name, for states `states` and unknown `w`.
fn stage_values(s: &SchemeIr, params: &[f64], dt: f64, t: f64, states: &[f64], w: f64) -> Vec<(String, f64)> {
    let stage = &s.stages[0];
    stage
        .quantities
        .iter()
        .zip(&stage.values)
        .map(|(name, a)| {
            let mut roots = vec![a.unknown];
            roots.extend(a.known.iter().map(|(_, c)| *c));
            let c = eval_all(&s.graph, &roots, params, dt, t);
            let mut v = c[0] * w;
            for ((q, _), ck) in a.known.iter().zip(&c[1..]) {
                let Quantity::State(i) = q else { panic!("a one-stage scheme knows only states") };
                v += ck * states[*i];
            }
            (name.clone(), v)
        })
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    #[test]
    fn eliminated_relations_satisfy_the_declared_ones(
        c in prop::array::uniform4(1u32..=20).prop_map(|k| k.map(|k| k as f64 / 20.0)),
        which in 0usize..3,
        states in prop::array::uniform3(-10.0f64..10.0),
        w in -10.0f64..10.0,
        log_dt in -4.0f64..0.0,
        t in 0.0f64..10.0,
    ) {
        let unknown = ["u'", "v'", "a'"][which];
        let text = source(c, unknown);
        let compiled = compile_text(Path::new("rnd.wf"), &text, &MemLoader::default())
            .unwrap_or_else(|f| panic!("{}\n{text}", f.rendered));
        let s = &compiled.schemes()[0];
        let dt = 10f64.powf(log_dt);
        let params = [c[1]];
        let values = stage_values(s, &params, dt, t, &states, w);
        let get = |name: &str| values.iter().find(|(n, _)| n == name).map(|(_, v)| *v)
            .unwrap_or_else(|| panic!("no quantity {name} in {values:?}"));
        prop_assert_eq!(&s.stages[0].quantities[0], unknown);
        prop_assert_eq!(get(unknown), w);
        let [u, v, a] = states;
        let (u1, v1, a1) = (get("u'"), get("v'"), get("a'"));
        let [c1, beta, c3, c4] = c;
        // Each relation to round-off of its largest term.
        let r1 = u1 - (u + dt * v + dt * dt * (c1 * a + beta * a1));
        let s1 = [u1, u, dt * v, dt * dt * c1 * a, dt * dt * beta * a1].iter().fold(0.0f64, |m, x| m.max(x.abs()));
        prop_assert!(r1.abs() <= 1e-12 * s1, "u' relation off by {r1:e} (scale {s1:e}), unknown {unknown}");
        let r2 = v1 - (v + dt * (c3 * a + c4 * a1));
        let s2 = [v1, v, dt * c3 * a, dt * c4 * a1].iter().fold(0.0f64, |m, x| m.max(x.abs()));
        prop_assert!(r2.abs() <= 1e-12 * s2, "v' relation off by {r2:e} (scale {s2:e}), unknown {unknown}");
    }
}
