//! `signorini run static-block`: an elastic block resting on the rigid plane {x_d = 0} under
//! its own weight, frictionless, with contact by Nitsche's method or by penalty.
//!
//! The block is [-1, 1] × [0, 1] in 2D (plane strain, P2) and [-½, ½]² × [0, 1] in 3D (P1 or
//! P2). Only the rigid sliding modes are removed: u_x = 0 at the bottom centre in 2D; in 3D
//! u_x = u_y = 0 there and u_y = 0 at the bottom point (½, 0, 0) (no rotation about z).
//!
//! With `curvature` c > 0 the obstacle is the paraboloid x_d = −c|x'|² (x' the horizontal
//! coordinates), measured along −e_d: g = x_d + c|x'|². The block then touches only around
//! its centre, and Newton has a real active set to find.

use std::path::PathBuf;
use std::time::Instant;

use serde::Serialize;

use super::CaseError;
use crate::forms::{nitsche, penalty};
use crate::runtime::assembly::{Assembler, Kernel, Quadrature};
use crate::runtime::evaluate::facet_samples;
use crate::runtime::kernel::Coef;
use crate::runtime::linalg::Structure;
use crate::runtime::mesh::Mesh;
use crate::runtime::mesh::structured::{self, Diagonal};
use crate::runtime::newton::{Newton, NewtonOptions, NewtonReport};
use crate::runtime::problem::{Constraints, ContactTerm, StaticContact};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum ContactMethod {
    Nitsche,
    Penalty,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Options {
    pub contact: ContactMethod,
    pub theta: f64,
    pub gamma0: f64,
    pub dim: usize,
    pub degree: u32,
    pub h: f64,
    pub young: f64,
    pub poisson: f64,
    pub density: f64,
    pub gravity: f64,
    /// Curvature of the obstacle (0: the plane).
    pub curvature: f64,
    pub newton: NewtonOptions,
    pub out: Option<PathBuf>,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            contact: ContactMethod::Nitsche,
            theta: 1.0,
            gamma0: 5000.0,
            dim: 2,
            degree: 2,
            h: 0.125,
            young: 100.0,
            poisson: 0.3,
            density: 1.0,
            gravity: 1.0,
            curvature: 0.0,
            newton: NewtonOptions::default(),
            out: None,
        }
    }
}

#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    pub case: &'static str,
    pub contact: ContactMethod,
    pub theta: f64,
    pub gamma0: f64,
    pub curvature: f64,
    pub dim: usize,
    pub degree: u32,
    pub h: f64,
    pub cells: usize,
    pub dofs: usize,
    /// ρ g |Ω|.
    pub weight: f64,
    /// Vertical resultant of the contact term on the block.
    pub contact_force: f64,
    /// max over contact quadrature points of (u_N − g)₊.
    pub max_penetration: f64,
    pub active_points: usize,
    pub newton_iterations: usize,
    pub newton: NewtonReport,
    pub symbolic_factorizations: usize,
    pub numeric_factorizations: usize,
    pub wall_seconds: f64,
}

/// Builds the block mesh with its `bottom` region.
pub fn mesh(opts: &Options) -> Result<Mesh, CaseError> {
    if !(opts.h > 0.0 && opts.h <= 1.0) {
        return Err(CaseError::Option(format!("--h must be in (0, 1], not {}", opts.h)));
    }
    let n = |len: f64| ((len / opts.h).round() as usize).max(1);
    let mesh = match opts.dim {
        2 => {
            if opts.degree != 2 {
                return Err(CaseError::Option("the 2D block is P2 (--degree 2)".into()));
            }
            structured::rectangle(2 * n(1.0), n(1.0), [-1.0, 1.0], [0.0, 1.0], Diagonal::Right, 2)
        }
        3 => {
            if !(1..=2).contains(&opts.degree) {
                return Err(CaseError::Option(format!("--degree must be 1 or 2, not {}", opts.degree)));
            }
            let m = 2 * n(0.5);
            structured::cuboid([m, m, n(1.0)], [-0.5, 0.5], [-0.5, 0.5], [0.0, 1.0], opts.degree)
        }
        d => return Err(CaseError::Option(format!("--dim must be 2 or 3, not {d}"))),
    };
    mesh.validate()?;
    Ok(mesh)
}

/// Solves the case; writes `summary.json` into `opts.out` if set.
pub fn run(opts: &Options) -> Result<Summary, CaseError> {
    let start = Instant::now();
    let mesh = mesh(opts)?;
    let d = opts.dim;
    let c = opts.curvature;
    if !(c >= 0.0 && c.is_finite()) {
        return Err(CaseError::Option(format!("--curvature must be a finite number ≥ 0, not {c}")));
    }
    let gap = Coef::function(1, move |x, _, out| out[0] = x[d - 1] + c * x[..d - 1].iter().map(|v| v * v).sum::<f64>());
    let down = Coef::constant((0..d).map(|k| if k == d - 1 { -1.0 } else { 0.0 }).collect::<Vec<_>>());
    let force =
        Coef::constant((0..d).map(|k| if k == d - 1 { -opts.density * opts.gravity } else { 0.0 }).collect::<Vec<_>>());
    let bad = |e: crate::runtime::kernel::ParamError| CaseError::Option(e.to_string());
    let mut summary = match opts.contact {
        ContactMethod::Nitsche => {
            let p = nitsche::Params::default()
                .with("E", opts.young)
                .and_then(|p| p.with("nu", opts.poisson))
                .and_then(|p| p.with("rho", opts.density))
                .and_then(|p| p.with("gamma0", opts.gamma0))
                .and_then(|p| p.with("theta", opts.theta))
                .map_err(bad)?;
            let c = nitsche::Coefficients { f: force, g: gap, nc: down };
            // θ = 1 gives a symmetric tangent (Cholesky; LU if γ0 is too small for coercivity).
            let structure = if opts.theta == 1.0 { Structure::SymmetricPositiveDefinite } else { Structure::General };
            solve(
                opts,
                &mesh,
                &nitsche::Stiffness::new(&p, &c),
                &nitsche::Load::new(&p, &c),
                nitsche::Contact::new(&p, &c),
                structure,
            )?
        }
        ContactMethod::Penalty => {
            let p = penalty::Params::default()
                .with("E", opts.young)
                .and_then(|p| p.with("nu", opts.poisson))
                .and_then(|p| p.with("rho", opts.density))
                .and_then(|p| p.with("gamma0", opts.gamma0))
                .map_err(bad)?;
            let c = penalty::Coefficients { f: force, g: gap, nc: down };
            let structure = Structure::SymmetricPositiveDefinite;
            solve(
                opts,
                &mesh,
                &penalty::Stiffness::new(&p, &c),
                &penalty::Load::new(&p, &c),
                penalty::Contact::new(&p, &c),
                structure,
            )?
        }
    };
    summary.wall_seconds = start.elapsed().as_secs_f64();
    if let Some(dir) = &opts.out {
        let path = dir.join("summary.json");
        crate::output::write_json(&path, &summary)
            .map_err(|source| CaseError::Write { path: path.display().to_string(), source })?;
    }
    Ok(summary)
}

fn solve<S: Kernel, L: Kernel, C: Kernel>(
    opts: &Options,
    mesh: &Mesh,
    stiffness: &S,
    load: &L,
    contact: C,
    structure: Structure,
) -> Result<Summary, CaseError> {
    let d = opts.dim;
    let asm = Assembler::new(mesh);
    let n = asm.size();
    let quad = Quadrature::default();
    let mut l = vec![0.0; n];
    asm.cell_residual(load, quad, &[], 0.0, &mut l);
    let facets = asm.region("bottom")?;
    // Four Gauss points per edge in 2D, a degree-4 rule on faces in 3D: exact for the smooth
    // parts, and resolves the edge of the contact zone.
    let contact_quad = Quadrature { cell: None, facet: Some(if d == 2 { 7 } else { 4 }) };
    let term = ContactTerm { form: contact, region: "Gamma_C".into(), facets, quadrature: contact_quad };
    let constraints = sliding_constraints(mesh);
    let mut problem = StaticContact::new(&asm, stiffness, quad, l, term, constraints, structure);
    // Start with the block pushed into the obstacle below its largest gap, so that every contact
    // point is active and the first Jacobian is not singular (at u = 0 the block would float,
    // or pivot on one point of a curved obstacle: H(0) = 0). Newton then releases points.
    let gap = |x: &[f64]| x[d - 1] + opts.curvature * x[..d - 1].iter().map(|v| v * v).sum::<f64>();
    let deepest =
        mesh.region_nodes(mesh.region("bottom")?).iter().map(|&i| gap(mesh.node(i as usize))).fold(0.0, f64::max);
    let mut u = vec![0.0; n];
    u.iter_mut().skip(d - 1).step_by(d).for_each(|x| *x = -(deepest + 1e-6 * opts.h));
    problem.constraints.zero(&mut u);
    let mut newton = Newton::new(opts.newton);
    let report = newton.solve(&mut problem, &mut u)?;
    // Vertical resultant: C(u) tested with e_d is minus the upward force on the block.
    let c = problem.contact_residual(&u);
    let contact_force = -c.iter().skip(d - 1).step_by(d).sum::<f64>();
    let samples = facet_samples(mesh, facets, contact_quad.facet.unwrap_or(4), &u);
    let max_penetration = samples.iter().map(|s| (-s.value[d - 1] - gap(&s.x)).max(0.0)).fold(0.0, f64::max);
    let mut set = Vec::new();
    use crate::runtime::newton::NonlinearProblem;
    problem.active_set(&u, &mut set);
    let counters = newton.counters();
    Ok(Summary {
        case: "static-block",
        contact: opts.contact,
        theta: opts.theta,
        gamma0: opts.gamma0,
        curvature: opts.curvature,
        dim: d,
        degree: mesh.kind.degree(),
        h: opts.h,
        cells: mesh.num_cells(),
        dofs: n,
        weight: opts.density * opts.gravity * mesh.measure(),
        contact_force,
        max_penetration,
        active_points: set.iter().filter(|b| **b).count(),
        newton_iterations: report.iterations(),
        newton: report,
        symbolic_factorizations: counters.symbolic,
        numeric_factorizations: counters.numeric,
        wall_seconds: 0.0,
    })
}

/// Dirichlet conditions that remove the rigid sliding modes and nothing more.
fn sliding_constraints(mesh: &Mesh) -> Constraints {
    let d = mesh.dim();
    let mut c = Constraints::none(mesh.num_nodes() * d);
    let nearest = |target: &[f64]| {
        (0..mesh.num_nodes())
            .min_by(|&a, &b| {
                let da: f64 = mesh.node(a).iter().zip(target).map(|(x, y)| (x - y).powi(2)).sum();
                let db: f64 = mesh.node(b).iter().zip(target).map(|(x, y)| (x - y).powi(2)).sum();
                da.total_cmp(&db)
            })
            .expect("a mesh has nodes")
    };
    if d == 2 {
        c.fix(nearest(&[0.0, 0.0]) * d);
    } else {
        let centre = nearest(&[0.0, 0.0, 0.0]);
        c.fix(centre * d);
        c.fix(centre * d + 1);
        c.fix(nearest(&[0.5, 0.0, 0.0]) * d + 1);
    }
    c
}
