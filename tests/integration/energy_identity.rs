//! Every library scheme's derived energy identity (`emit --stage energy`) against the runtime's
//! own stepper, the one runs use: on verify's oscillator (M = K = 1, no load, no contact) the
//! kept energy changes by exactly −D from step to step, at the defaults and at ωΔt = 0.3 and 3.
//! A scheme whose stage unknown is no state's end level (TR-BDF2's first stage) is checked
//! against the compiled stages instead (the compiler's property tests).

use std::path::Path;

use signorini::compiler::scheme::energy::classify::Identity;
use signorini::compiler::scheme::energy::evaluate::Operators;
use signorini::compiler::scheme::energy::window::Free;
use signorini::compiler::scheme::{Quantity, SchemeIr};
use signorini::driver::{self, Methods};

/// M = K = 1 on the oscillator's one free dof; its linear material's discrete gradient is the
/// stiffness at the midpoint; no load, no contact.
struct Unit;

impl Operators for Unit {
    fn mass(&self, x: &[f64]) -> Vec<f64> {
        x.to_vec()
    }
    fn stiffness(&self, x: &[f64]) -> Vec<f64> {
        x.to_vec()
    }
    fn apply(&self, slot: &str, args: &[Vec<f64>], _: f64) -> Vec<f64> {
        match (slot, args) {
            ("stiffness_dg", [x, y]) => x.iter().zip(y).map(|(a, b)| 0.5 * (a + b)).collect(),
            _ => vec![0.0; args.first().map_or(1, Vec::len)],
        }
    }
}

fn ir(name: &str) -> SchemeIr {
    let path = format!("forms/schemes/{name}.wf");
    let (program, _) = signorini::compiler::check_path(Path::new(&path), &signorini::compiler::FsLoader)
        .unwrap_or_else(|f| panic!("{f}"));
    program.schemes.into_iter().next().unwrap()
}

/// The states at the start of each of `steps` steps and the next (dof 0 only), from u = 1, v = 0.
fn stepped(name: &str, dt: f64, steps: usize) -> Vec<Vec<f64>> {
    let methods = Methods { scheme: name.into(), ..Methods::default() };
    signorini::verify::with_oscillator(&methods, |st| {
        let mut states: Vec<Vec<f64>> = st.desc().states.iter().map(|_| vec![0.0; 2]).collect();
        states[0][0] = 1.0;
        st.initialize(&mut states, 0.0).unwrap();
        let mut out = vec![states.iter().map(|s| s[0]).collect::<Vec<f64>>()];
        for k in 0..steps {
            st.step(&mut states, k as f64 * dt, dt).unwrap();
            out.push(states.iter().map(|s| s[0]).collect());
        }
        out
    })
    .unwrap()
}

#[test]
fn every_identity_closes_on_the_runtime_s_own_steps() {
    let mut checked = Vec::new();
    for name in driver::all_schemes() {
        let s = ir(name);
        let id = Identity::derive(&s).unwrap_or_else(|e| panic!("{name}: {e:?}"));
        // The state each stage's unknown ends as.
        let ends: Option<Vec<usize>> = (0..s.stages.len())
            .map(|k| s.updates.iter().position(|q| *q == Quantity::Stage { stage: k, index: 0 }))
            .collect();
        let Some(ends) = ends else { continue };
        let params: Vec<f64> = s.params.iter().map(|p| p.default).collect();
        for dt in [0.3f64, 3.0] {
            // An explicit scheme within its limit.
            let dt = if s.claims.iter().any(|(c, _)| c == "cfl") { dt.min(1.0) } else { dt };
            let run = stepped(name, dt, 6);
            for n in 1..5 {
                let x: Vec<Vec<f64>> = id
                    .free()
                    .iter()
                    .map(|f| match *f {
                        Free::State(i) => vec![run[n][i]],
                        Free::Unknown(k) => vec![run[n + 1][ends[k]]],
                        Free::Previous(i) => vec![run[n - 1][i]],
                        Free::PreviousUnknown(k) => vec![run[n][ends[k]]],
                    })
                    .collect();
                let b = id.balance(&s, &Unit, &params, dt, n as f64 * dt, &x);
                assert!(
                    b.gap().abs() <= 1e-11 * (1.0 + b.scale()),
                    "{name}, dt = {dt}, step {n}: Ẽ {} → {}, W {}, D {}: off by {:e}",
                    b.kept_before,
                    b.kept_after,
                    b.work,
                    b.dissipation,
                    b.gap()
                );
                assert!(b.dissipation >= -1e-14, "{name}: D = {:e}", b.dissipation);
            }
        }
        checked.push(name);
    }
    assert!(checked.len() >= 8, "{checked:?}");
}
