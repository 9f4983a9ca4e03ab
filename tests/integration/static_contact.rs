//! Static Signorini problems end to end (the library's `static_block` and `static_block_3d`
//! problems, `run static`): equilibrium of the contact resultant with the weight, penetration
//! under refinement, Newton iteration counts, and reuse of the factorization when the active
//! set does not change.

use signorini::driver::{Methods, Setting};
use signorini::forms::{contact_nitsche, elasticity};
use signorini::problem::run::{Options, Run, run as run_problem};
use signorini::runtime::fem::assembly::{Assembler, CellIntegral, Quadrature};
use signorini::runtime::fem::bound::Bound;
use signorini::runtime::fem::kernel::Coef;
use signorini::runtime::fem::mesh::Facet;
use signorini::runtime::fem::mesh::structured::{self, Diagonal};
use signorini::runtime::linalg::Structure;
use signorini::runtime::nonlinear::newton::{Newton, NewtonOptions};
use signorini::runtime::nonlinear::statics::{Constraints, StaticContact};

fn methods() -> Vec<(&'static str, f64)> {
    vec![("nitsche", 1.0), ("nitsche", 0.0), ("nitsche", -1.0), ("penalty", f64::NAN)]
}

/// The block (`static_block`, or `static_block_3d`) with the contact law, θ and problem params.
fn block(problem: &str, contact: &str, theta: f64, params: &[(&str, f64)]) -> Options {
    let mut methods = Methods { contact: contact.into(), ..Methods::default() };
    if !theta.is_nan() {
        methods = methods.set("theta", theta);
    }
    for (name, value) in params {
        methods.params.push(Setting { name: name.to_string(), value: *value, origin: "test".into() });
    }
    let mut o = Options::new(problem);
    o.chosen.contact = true;
    o.methods = methods;
    o
}

fn run(problem: &str, contact: &str, theta: f64, params: &[(&str, f64)]) -> Run {
    run_problem(&block(problem, contact, theta, params)).unwrap_or_else(|e| panic!("{contact} θ = {theta}: {e}"))
}

fn number(r: &Run, key: &str) -> f64 {
    r.summary.number(key).unwrap_or_else(|| panic!("no `{key}` in the summary"))
}

#[test]
fn contact_resultant_equals_the_weight_in_2d_and_3d() {
    for (contact, theta) in methods() {
        for (problem, degree, cells) in
            [("static_block", 2.0, 8.0), ("static_block_3d", 1.0, 8.0), ("static_block_3d", 2.0, 4.0)]
        {
            let params: &[(&str, f64)] =
                if problem == "static_block" { &[("cells", cells)] } else { &[("cells", cells), ("degree", degree)] };
            let s = run(problem, contact, theta, params);
            let rel = number(&s, "force_error").abs();
            assert!(rel < 1e-8, "{contact} θ = {theta}, {problem} P{degree}: force {:e} off the weight", rel);
            let newton = number(&s, "newton_total");
            assert!(newton <= 10.0, "{contact} θ = {theta}, {problem}: {newton} iterations");
            assert_eq!(number(&s, "symbolic_factorizations"), 1.0, "{contact} θ = {theta}, {problem} P{degree}");
        }
    }
}

#[test]
fn penetration_decreases_under_refinement() {
    for (contact, theta) in methods() {
        let p: Vec<f64> = [4.0, 8.0, 16.0]
            .iter()
            .map(|&cells| number(&run("static_block", contact, theta, &[("cells", cells)]), "max_penetration"))
            .collect();
        assert!(p[0] > p[1] && p[1] > p[2] && p[2] > 0.0, "{contact} θ = {theta}: {p:?}");
    }
}

#[test]
fn on_a_curved_obstacle_newton_finds_a_partial_contact_zone() {
    for (contact, theta) in methods() {
        let s = run("static_block", contact, theta, &[("curvature", 0.5)]);
        let rel = number(&s, "force_error").abs();
        assert!(rel < 1e-8, "{contact} θ = {theta}: force {rel:e} off the weight");
        let points = 2 * 8 * 4; // bottom facets × Gauss points
        let active = number(&s, "active_points") as usize;
        assert!(active > 0 && active < points / 2, "{active} of {points} points active");
        // From the all-active start, semi-smooth Newton releases the edges a few points at a
        // time: more iterations than on the plane, but a bounded number.
        let newton = number(&s, "newton_total");
        assert!(newton <= 20.0, "{contact} θ = {theta}: {newton} iterations");
    }
}

/// The 2D block's mesh: [-1, 1] × [0, 1], P2, h = 1/8.
fn block_mesh() -> signorini::runtime::fem::mesh::Mesh {
    structured::rectangle(16, 8, [-1.0, 1.0], [0.0, 1.0], Diagonal::Right, 2)
}

/// One symbolic analysis per pattern; a second solve with a 1% heavier load keeps the active
/// set, so it reuses the numeric factorization and converges in one (linear) step.
#[test]
fn factorization_is_reused_while_the_active_set_is_unchanged() {
    let mesh = block_mesh();
    let asm = Assembler::new(&mesh);
    let n = asm.size();
    let (stiffness, load) = elastic(&asm);
    let contact = nitsche_contact(
        asm.region("bottom").unwrap(),
        Coef::function(1, |x, _, o| o[0] = x[1] + 0.5 * x[0] * x[0]),
        Quadrature { cell: None, facet: Some(7) },
    );
    let mut constraints = Constraints::none(n);
    let centre = (0..mesh.num_nodes()).find(|&i| mesh.node(i) == [0.0, 0.0]).unwrap();
    constraints.fix(2 * centre);
    let mut problem = StaticContact::new(
        &asm,
        Box::new(stiffness),
        load.clone(),
        contact,
        constraints,
        Structure::SymmetricPositiveDefinite,
    );
    let mut u = vec![0.0; n];
    // Below the deepest gap (0.5 at the corners): every contact point active at the start.
    u.iter_mut().skip(1).step_by(2).for_each(|x| *x = -0.5 - 1e-7);
    let mut newton = Newton::new(NewtonOptions::default());
    let first = newton.solve(&mut problem, &mut u).unwrap();
    let after_first = newton.counters();
    assert_eq!(after_first.symbolic, 1);
    assert_eq!(after_first.numeric, first.history.iter().filter(|i| i.refactored).count());
    problem.set_load(load.iter().map(|l| 1.01 * l).collect());
    let second = newton.solve(&mut problem, &mut u).unwrap();
    let after_second = newton.counters();
    assert_eq!(second.iterations(), 1, "{second:?}");
    assert!(!second.history[0].refactored);
    assert_eq!(after_second.numeric, after_first.numeric, "refactored although the active set did not change");
    assert_eq!(after_second.symbolic, 1);
}

/// Newton's failures are typed and carry the history: an iteration limit, and a singular
/// Jacobian (a block that never touches the obstacle floats: nothing fixes its vertical
/// translation).
#[test]
fn newton_failures_are_typed_errors_with_history() {
    use signorini::error::CaseError;
    use signorini::runtime::nonlinear::newton::NewtonError;
    let mut o = block("static_block", "nitsche", 1.0, &[("curvature", 0.5)]);
    o.newton.max_iterations = 2;
    match run_problem(&o) {
        Err(CaseError::Newton(NewtonError::IterationLimit { report, threshold })) => {
            assert_eq!(report.iterations(), 2);
            assert!(report.history.last().unwrap().residual > threshold);
            let text = CaseError::Newton(NewtonError::IterationLimit { report, threshold }).to_string();
            assert!(text.contains("did not converge in 2 iterations"), "{text}");
        }
        Err(other) => panic!("expected an iteration limit, got {other:?}"),
        Ok(_) => panic!("expected an iteration limit, got a solution"),
    }

    let mesh = block_mesh();
    let asm = Assembler::new(&mesh);
    let n = asm.size();
    let (stiffness, load) = elastic(&asm);
    let contact = nitsche_contact(
        asm.region("bottom").unwrap(),
        Coef::function(1, |x, _, o| o[0] = x[1] + 10.0),
        Quadrature::default(),
    );
    let mut problem = StaticContact::new(
        &asm,
        Box::new(stiffness),
        load,
        contact,
        Constraints::none(n),
        Structure::SymmetricPositiveDefinite,
    );
    let mut u = vec![0.0; n];
    match Newton::new(NewtonOptions::default()).solve(&mut problem, &mut u) {
        Err(NewtonError::Linear { report, source }) => {
            assert_eq!(report.iterations(), 0);
            assert!(source.to_string().contains("singular"), "{source}");
        }
        other => panic!("expected a singular Jacobian, got {other:?}"),
    }
}

/// Stiffness (E = 100) and the load of f = (0, −1), from the compiled elasticity file.
fn elastic<'a>(asm: &Assembler) -> (Bound<'a, elasticity::Stiffness>, Vec<f64>) {
    let p = elasticity::Params::default().with("E", 100.0).unwrap();
    let c = elasticity::Coefficients { f: Coef::constant(vec![0.0, -1.0]) };
    let q = Quadrature::default();
    let mut load = vec![0.0; asm.size()];
    asm.cell_residual(CellIntegral::all(&elasticity::Load::new(&p, &c), q), &[], 0.0, &mut load);
    (Bound { kernel: elasticity::Stiffness::new(&p, &c), quadrature: q, regions: vec![], cells: None }, load)
}

/// Nitsche contact (θ = 1, γ0 = 5000, E = 100) with the obstacle below at gap `g`.
fn nitsche_contact(
    facets: &[Facet],
    g: Coef,
    quadrature: Quadrature,
) -> Box<dyn signorini::runtime::fem::bound::BoundForm + '_> {
    let p = contact_nitsche::Params::default().with("E", 100.0).and_then(|p| p.with("gamma0", 5000.0)).unwrap();
    let c =
        contact_nitsche::Coefficients { f: Coef::constant(vec![0.0, -1.0]), g, nc: Coef::constant(vec![0.0, -1.0]) };
    Box::new(Bound {
        kernel: contact_nitsche::Contact::new(&p, &c),
        quadrature,
        regions: vec![("Gamma_C".into(), facets)],
        cells: None,
    })
}
