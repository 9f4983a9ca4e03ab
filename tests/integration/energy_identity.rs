//! Every library scheme's derived energy identity (`emit --stage energy`) against the runtime's
//! own stepper, the one runs use: on verify's oscillator (M = K = 1, no load, no contact) the
//! kept energy changes by exactly −D from step to step, at the defaults and at ωΔt = 0.3 and 3.
//! On a bar of 10 P1 elements that hits an obstacle with penalty contact, the identity holds
//! through the impact with the contact force opaque, to round-off (Newton solves its steps to
//! it). A scheme whose stage unknown is no state's end level (TR-BDF2's first stage) is checked
//! against the compiled stages instead (the compiler's property tests).

use std::path::Path;

use signorini::compiler::scheme::energy::classify::Identity;
use signorini::compiler::scheme::energy::evaluate::Operators;
use signorini::compiler::scheme::energy::window::Free;
use signorini::compiler::scheme::{Quantity, SchemeIr};
use signorini::driver::{self, FilesInUse, Methods};
use signorini::runtime::fem::assembly::{Assembler, Quadrature};
use signorini::runtime::fem::kernel::Coef;
use signorini::runtime::fem::mesh::structured;
use signorini::runtime::library::Binding;
use signorini::runtime::linalg::Structure;
use signorini::runtime::nonlinear::newton::NewtonOptions;
use signorini::runtime::nonlinear::statics::Constraints;
use signorini::runtime::time::stepper::Stepper;

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

/// The stepper's own bound forms, as the identity reads them.
struct Bound<'s, 'a>(&'s Stepper<'a>, f64);

impl Operators for Bound<'_, '_> {
    fn mass(&self, x: &[f64]) -> Vec<f64> {
        self.0.apply("mass", &[x], self.1).expect("mass")
    }
    fn stiffness(&self, x: &[f64]) -> Vec<f64> {
        self.0.apply("stiffness", &[x], self.1).expect("stiffness")
    }
    fn apply(&self, slot: &str, args: &[Vec<f64>], t: f64) -> Vec<f64> {
        let fields: Vec<&[f64]> = args.iter().map(Vec::as_slice).collect();
        self.0.apply(slot, &fields, t).unwrap_or_else(|| panic!("no form bound to `{slot}`"))
    }
}

/// A free bar [0, 1] (E = 1, ρ = 1) moving at v = −1 towards an obstacle 0.05 beyond its left
/// end, penalty contact there; every library scheme with one unknown per stage that ends as a
/// state, at its defaults, through the impact.
#[test]
fn every_identity_closes_through_a_penalty_impact() {
    let mesh = structured::interval(10, 0.0, 1.0);
    let asm = Assembler::new(&mesh);
    let left = mesh.regions.iter().find(|r| r.name == "left").unwrap().facets.clone();
    let coefs = |name: &str| match name {
        "f" => Some(Coef::constant(vec![0.0])),
        "g" => Some(Coef::scalar(0.05)),
        "nc" => Some(Coef::constant(vec![-1.0])),
        _ => None,
    };
    let mut checked = Vec::new();
    for name in driver::all_schemes() {
        let s = ir(name);
        let ends: Option<Vec<usize>> = (0..s.stages.len())
            .map(|k| s.updates.iter().position(|q| *q == Quantity::Stage { stage: k, index: 0 }))
            .collect();
        let Some(ends) = ends else { continue };
        let id = Identity::derive(&s).unwrap();
        let methods =
            Methods { scheme: name.into(), contact: "penalty".into(), ..Methods::default() }.set("gamma0", 100.0);
        let in_use = FilesInUse::resolve(&methods, &[]).unwrap();
        let binding = Binding::new(Quadrature::default(), vec![("Gamma_C".into(), left.as_slice())], 1);
        let mut inst = in_use.forms.instantiate(&coefs, &binding).unwrap();
        let forms = in_use.scheme_forms_with(&mut inst, Vec::new()).unwrap();
        let scheme = in_use.time_scheme().unwrap();
        let mut stepper = Stepper::new(
            scheme,
            &asm,
            forms,
            Constraints::none(asm.size()),
            Structure::General,
            NewtonOptions::default(),
        )
        .unwrap();
        let dt = if s.claims.iter().any(|(c, _)| c == "cfl") { 0.002 } else { 0.01 };
        let mut states: Vec<Vec<f64>> = stepper.desc().states.iter().map(|_| vec![0.0; asm.size()]).collect();
        let v = s.states.iter().position(|n| n == "v").unwrap();
        states[v].iter_mut().for_each(|x| *x = -1.0);
        stepper.initialize(&mut states, 0.0).unwrap();
        let steps = (0.2 / dt) as usize;
        let mut run = vec![states.clone()];
        for k in 0..steps {
            stepper.step(&mut states, k as f64 * dt, dt).unwrap();
            run.push(states.clone());
        }
        // The impact happened: the left end went past the obstacle's 0.05 and came back.
        assert!(run.iter().any(|x| x[0][0] < -0.05), "{name}: no contact");
        let params: Vec<f64> = s.params.iter().map(|p| p.default).collect();
        let mut worst = 0.0f64;
        for n in 1..steps - 1 {
            let x: Vec<Vec<f64>> = id
                .free()
                .iter()
                .map(|f| match *f {
                    Free::State(i) => run[n][i].clone(),
                    Free::Unknown(k) => run[n + 1][ends[k]].clone(),
                    Free::Previous(i) => run[n - 1][i].clone(),
                    Free::PreviousUnknown(k) => run[n][ends[k]].clone(),
                })
                .collect();
            let ops = Bound(&stepper, n as f64 * dt);
            let b = id.balance(&s, &ops, &params, dt, n as f64 * dt, &x);
            worst = worst.max(b.gap().abs() / (1.0 + b.scale()));
            // Ẽ of the states the run holds (what the energy guard reads) is the identity's at
            // the step's ends, where Ẽ is kept at one level.
            if let (Some(before), Some(after)) =
                (id.kept_at(&s, &ops, &params, dt, &run[n]), id.kept_at(&s, &ops, &params, dt, &run[n + 1]))
            {
                let scale = 1.0 + b.scale();
                assert!(
                    (before - b.kept_before).abs() <= 1e-12 * scale,
                    "{name}: Ẽ {before} against {}",
                    b.kept_before
                );
                assert!((after - b.kept_after).abs() <= 1e-12 * scale, "{name}: Ẽ' {after} against {}", b.kept_after);
            }
        }
        // Newton solves these steps to round-off: about 1e-15 of the scale is what is seen.
        assert!(worst <= 1e-10, "{name}: the identity misses by {worst:e} of its scale");
        checked.push((name, worst));
    }
    assert!(checked.len() >= 9, "{checked:?}");
}
