//! The static driver every static case shares: the `stiffness`, `load` and `contact` forms of
//! the files in use, bound by slot name on a mesh, and semi-smooth Newton on K u + C(u) = F.

use crate::driver::FormsInUse;
use crate::error::CaseError;
use crate::runtime::fem::assembly::{Assembler, Quadrature};
use crate::runtime::fem::bound::BoundFunctional;
use crate::runtime::fem::kernel::Coef;
use crate::runtime::fem::mesh::Facet;
use crate::runtime::fem::mesh::inverted::most_inverted;
use crate::runtime::library::Binding;
use crate::runtime::linalg::{Counters, Structure};
use crate::runtime::nonlinear::newton::{Newton, NewtonError, NewtonOptions, NewtonReport};
use crate::runtime::nonlinear::problem::NonlinearProblem;
use crate::runtime::nonlinear::statics::{Constraints, StaticContact};

/// What a static case gives the driver.
pub struct StaticProblem<'p> {
    /// The case's coefficients by name (`f`, `g`, `nc`, ...).
    pub coefs: &'p dyn Fn(&str) -> Option<Coef>,
    /// The mesh region bound to the forms' `Gamma_C` (none: the contact law integrates over no
    /// facet, and Dirichlet conditions must hold the body).
    pub contact: Option<&'p str>,
    /// The other regions the forms may integrate over (a load's), bound by their names.
    pub regions: &'p [String],
    /// The contact pairs a pair law integrates over.
    pub pairs: &'p [crate::runtime::fem::pair::PairRegions],
    /// Degree of the contact term's facet rule (None: the form's own choice).
    pub contact_degree: Option<u32>,
    pub constraints: Constraints,
    pub newton: NewtonOptions,
    /// The time the loads and the contact (its obstacle) are taken at.
    pub t: f64,
}

/// The converged state and what the cases measure with.
pub struct StaticSolution<'m> {
    pub u: Vec<f64>,
    pub newton: NewtonReport,
    pub counters: Counters,
    /// The resultant of the contact force on the body, per direction.
    pub contact_force: Vec<f64>,
    /// Contact quadrature points whose switch is on.
    pub active_points: usize,
    pub contact_facets: &'m [Facet],
    /// What the contact pairs' search and assembly cost the solve (none without pairs).
    pub search: crate::runtime::fem::search_cost::SearchCost,
    /// `contact_pressure` and `contact_trial` of the contact law, bound on the contact region.
    pub contact_pressure: Option<Box<dyn BoundFunctional + 'm>>,
    pub contact_trial: Option<Box<dyn BoundFunctional + 'm>>,
}

/// Binds the files in use on `asm`'s mesh and solves from `initial` (which should put some
/// contact point in contact: with none, K alone is singular along the free directions).
pub fn solve<'m>(
    asm: &'m Assembler<'m>,
    problem: StaticProblem<'_>,
    forms: &FormsInUse,
    initial: Vec<f64>,
) -> Result<StaticSolution<'m>, CaseError> {
    let d = asm.mesh().dim();
    let n = asm.size();
    let facets = match problem.contact {
        Some(name) => asm.region(name)?,
        None => &[],
    };
    // Every file's forms are bound twice (the volume terms with their own rules, the contact
    // with the problem's facet rule): both bindings name every region a form may read.
    let mut regions = vec![("Gamma_C".to_string(), facets)];
    for name in problem.regions {
        regions.push((name.clone(), asm.region(name)?));
    }
    let bodies = &asm.mesh().bodies;
    let pairs: Vec<_> = problem.pairs.iter().map(|p| p.on(asm.mesh())).collect();
    let volume = Binding { bodies, pairs: pairs.clone(), ..Binding::new(Quadrature::default(), regions.clone(), d) };
    let boundary =
        Binding { bodies, pairs, ..Binding::new(Quadrature { cell: None, facet: problem.contact_degree }, regions, d) };
    let missing = |what: &str| {
        CaseError::Option(format!("a static case needs a `{what}` form, which the files in use do not provide"))
    };
    let mut inst = forms.instantiate(problem.coefs, &volume)?;
    let stiffness = inst.take_form("stiffness").ok_or_else(|| missing("stiffness"))?;
    let load_form = inst.take_form("load").ok_or_else(|| missing("load"))?;
    let mut on_boundary = forms.instantiate(problem.coefs, &boundary)?;
    let contact = on_boundary.take_form("contact").ok_or_else(|| missing("contact"))?;
    let mut load = vec![0.0; n];
    load_form.residual(asm, &[], problem.t, &mut load);
    let mut static_problem = StaticContact::new(asm, stiffness, load, contact, problem.constraints, Structure::Auto);
    let mut u = initial;
    if u.len() != n {
        return Err(CaseError::Option(format!("the initial state has {} values, the mesh {n} unknowns", u.len())));
    }
    static_problem.constraints.impose(&mut u);
    // A law's `prev` (a frictional slip) is measured from the initial state.
    static_problem.previous.clone_from(&u);
    static_problem.time = problem.t;
    // `--solver auto` factorizes here: without a mass term, Jacobi-CG on the stiffness alone
    // converges slowly (the threshold of `auto` is measured on time steps).
    let mut options = problem.newton;
    if options.solver == crate::runtime::linalg::Solver::Auto && !options.solver.petsc() {
        options.solver = crate::runtime::linalg::Solver::Direct;
    }
    let mut newton = Newton::new(options);
    // A NaN is explained by a cell turned inside out, where there is one.
    let report = newton.solve(&mut static_problem, &mut u).map_err(|e| match e {
        NewtonError::NonFinite { .. } if let Some(cell) = most_inverted(asm.mesh(), &u) => CaseError::Diverged(format!(
            "the static equilibrium was not found ({e}): at Newton's last iterate {cell}, where a finite-strain material's stress is not defined (ln J, F⁻¹); start from a guess closer to the equilibrium (`initial u`), or move the held values less"
        )),
        e => CaseError::Newton(e),
    })?;
    let contact_force = super::resultant(&static_problem.contact_residual(&u), d);
    let mut set = Vec::new();
    static_problem.active_set(&u, &mut set);
    Ok(StaticSolution {
        u,
        newton: report,
        counters: newton.counters(),
        contact_force,
        active_points: set.iter().filter(|b| **b).count(),
        search: static_problem.contact.search_cost(),
        contact_facets: facets,
        contact_pressure: on_boundary.take_functional("contact_pressure"),
        contact_trial: on_boundary.take_functional("contact_trial"),
    })
}
