//! The previous time level a contact law's `prev` reads, as the stepper gives it, seen by a
//! contact form that records every call on the oscillator (one free dof): the initial problem's
//! `contact(u)` reads u⁰; TR-BDF2's trapezoidal stage (`contact(um)`) reads u at the step's
//! start and its BDF2 stage (`contact(u')`) reads um; HHT's new level (`contact(u')`) reads the
//! step's start, and its accepted level (`α·contact(u)`) the level before it, as that level's
//! own law did when it was new.

use std::cell::RefCell;
use std::rc::Rc;

use signorini::driver::{FilesInUse, Methods};
use signorini::runtime::fem::assembly::{Assembler, Quadrature};
use signorini::runtime::fem::bound::BoundForm;
use signorini::runtime::fem::kernel::Coef;
use signorini::runtime::fem::mesh::structured;
use signorini::runtime::library::Binding;
use signorini::runtime::linalg::{Matrix, Structure};
use signorini::runtime::nonlinear::newton::NewtonOptions;
use signorini::runtime::nonlinear::statics::Constraints;
use signorini::runtime::time::stepper::Stepper;

/// (argument, previous level) at the free dof, per call of the residual.
type Calls = Rc<RefCell<Vec<(f64, f64)>>>;

/// A contact law that reads `prev` and adds nothing: it records what it is given.
struct Recorder(Calls);

impl BoundForm for Recorder {
    fn name(&self) -> &str {
        "contact"
    }
    fn fields(&self) -> usize {
        1
    }
    fn previous(&self) -> bool {
        true
    }
    fn linear(&self) -> bool {
        false
    }
    fn piecewise(&self) -> bool {
        true
    }
    fn residual(&self, _: &Assembler, fields: &[&[f64]], _: f64, _: &mut [f64]) {
        assert_eq!(fields.len(), 2, "the argument and the previous level");
        self.0.borrow_mut().push((fields[0][0], fields[1][0]));
    }
    fn tangent(&self, _: &Assembler, fields: &[&[f64]], _: usize, _: f64, _: &mut Matrix) {
        assert_eq!(fields.len(), 2, "the argument and the previous level");
    }
    fn switches(&self, _: &Assembler, fields: &[&[f64]], _: usize, _: f64, _: &mut Vec<bool>) -> bool {
        assert_eq!(fields.len(), 2, "the argument and the previous level");
        self.piecewise()
    }
}

/// A stage's name, the calls it made, and its u-quantity.
type Stage = (String, Vec<(f64, f64)>, f64);

/// Per step: u at its start, and its stages.
struct Step {
    start: f64,
    stages: Vec<Stage>,
}

/// The initial problem's calls and `steps` steps of Δt = 0.3 of `scheme` from u = 1, v = 0.
fn record(scheme: &str, steps: usize) -> (Vec<(f64, f64)>, Vec<Step>) {
    let mesh = structured::interval(1, 0.0, 1.0);
    let asm = Assembler::new(&mesh);
    let methods = Methods { scheme: scheme.into(), ..Methods::default() }.set("elasticity.rho", 3.0);
    let in_use = FilesInUse::resolve(&methods, &[]).unwrap();
    let coefs = |name: &str| match name {
        "f" => Some(Coef::constant(vec![0.0])),
        "g" => Some(Coef::scalar(0.0)),
        "nc" => Some(Coef::constant(vec![-1.0])),
        _ => None,
    };
    let binding = Binding::new(Quadrature::default(), vec![("Gamma_C".into(), &[])], 1);
    let mut inst = in_use.forms.instantiate(&coefs, &binding).unwrap();
    let calls: Calls = Rc::default();
    let given: Vec<(&str, Box<dyn BoundForm>)> = vec![("contact", Box::new(Recorder(calls.clone())))];
    let forms = in_use.scheme_forms_with(&mut inst, given).unwrap();
    let mut constraints = Constraints::none(asm.size());
    constraints.fix(1);
    let scheme = in_use.time_scheme().unwrap();
    let mut stepper =
        Stepper::new(scheme, &asm, forms, constraints, Structure::General, NewtonOptions::default()).unwrap();
    assert!(stepper.reads_previous());
    let mut states: Vec<Vec<f64>> = stepper.desc().states.iter().map(|_| vec![0.0; 2]).collect();
    states[0][0] = 1.0;
    stepper.initialize(&mut states, 0.0).unwrap();
    let initial = std::mem::take(&mut *calls.borrow_mut());
    let mut out = Vec::new();
    for k in 0..steps {
        let start = states[0][0];
        let mut stages = Vec::new();
        stepper
            .step_observed(&mut states, 0.3 * k as f64, 0.3, &mut |view| {
                let u = view.value_of("u").expect("a displacement")[0];
                stages.push((view.name.to_string(), std::mem::take(&mut *calls.borrow_mut()), u));
            })
            .unwrap();
        out.push(Step { start, stages });
    }
    (initial, out)
}

#[test]
fn the_initial_problem_reads_the_initial_state() {
    let (initial, _) = record("newmark", 0);
    assert!(!initial.is_empty());
    assert!(initial.iter().all(|&(u, previous)| u == 1.0 && previous == 1.0), "{initial:?}");
}

#[test]
fn each_stage_of_trbdf2_reads_the_level_it_starts_from() {
    let (_, steps) = record("trbdf2", 3);
    for (k, step) in steps.iter().enumerate() {
        let [(first, trapezoidal, um), (second, bdf2, _)] = &step.stages[..] else {
            panic!("two stages, not {:?}", step.stages.iter().map(|s| &s.0).collect::<Vec<_>>())
        };
        assert_eq!((first.as_str(), second.as_str()), ("trapezoidal", "bdf2"));
        assert!(!trapezoidal.is_empty() && !bdf2.is_empty(), "step {k}: both stages evaluate the law");
        assert!(trapezoidal.iter().all(|&(_, p)| p == step.start), "step {k}: {trapezoidal:?} from {}", step.start);
        assert!(bdf2.iter().all(|&(_, p)| p == *um), "step {k}: {bdf2:?} from um = {um}");
        assert_ne!(*um, step.start, "step {k}: the two levels differ, so the test tells them apart");
    }
}

#[test]
fn hhts_accepted_level_reads_the_level_before_it_and_its_new_level_the_steps_start() {
    let (_, steps) = record("hht", 4);
    for (k, step) in steps.iter().enumerate().skip(1) {
        let before = steps[k - 1].start;
        let calls = &step.stages[0].1;
        // α·contact(u), the accepted level (at u exactly), reads the level before; contact(u'),
        // the new level (at u too on Newton's first evaluation), the step's start.
        let old: Vec<_> = calls.iter().filter(|&&(_, p)| p == before).collect();
        let new: Vec<_> = calls.iter().filter(|&&(_, p)| p == step.start).collect();
        assert!(!old.is_empty() && !new.is_empty(), "step {k}: both levels evaluated: {calls:?}");
        assert_eq!(old.len() + new.len(), calls.len(), "step {k}: {calls:?} read {before} or {}", step.start);
        assert!(old.iter().all(|&&(u, _)| u == step.start), "step {k}: {old:?} are the accepted level's");
        assert_ne!(before, step.start);
    }
}
