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
use crate::driver::{Active, ParamValue, Setup};
use crate::runtime::assembly::Assembler;
use crate::runtime::evaluate::facet_samples;
use crate::runtime::kernel::Coef;
use crate::runtime::mesh::structured::{self, Diagonal};
use crate::runtime::mesh::{CellSize, Mesh};
use crate::runtime::newton::{NewtonOptions, NewtonReport};
use crate::runtime::problem::Constraints;
use crate::simulation::statics::{self, StaticProblem};

/// The block's material (E = 100, ν = 0.3, ρ = 1) and γ0 (θ = 1 needs γ0 ≳ 20 E), over the
/// files' defaults.
pub const OVERRIDES: &[(&str, f64)] = &[("E", 100.0), ("nu", 0.3), ("rho", 1.0), ("gamma0", 5000.0)];

#[derive(Clone, Debug, PartialEq)]
pub struct Options {
    /// The contact law, material and params (the scheme is not used).
    pub setup: Setup,
    pub dim: usize,
    pub degree: u32,
    pub h: f64,
    pub gravity: f64,
    /// Curvature of the obstacle (0: the plane).
    pub curvature: f64,
    /// What `h` means in γ = γ0/h.
    pub cell_size: CellSize,
    pub newton: NewtonOptions,
    pub out: Option<PathBuf>,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            setup: Setup::default(),
            dim: 2,
            degree: 2,
            h: 0.125,
            gravity: 1.0,
            curvature: 0.0,
            cell_size: CellSize::Diameter,
            newton: NewtonOptions::default(),
            out: None,
        }
    }
}

#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    pub case: &'static str,
    /// The contact law (its file stem).
    pub contact: String,
    /// Every param of the form files, with its value and where it comes from.
    pub params: std::collections::BTreeMap<String, ParamValue>,
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
    let dofs = match opts.dim {
        2 => 2.0 * (4 * n(1.0) + 1) as f64 * (2 * n(1.0) + 1) as f64,
        _ => {
            let p = opts.degree.clamp(1, 2) as usize;
            3.0 * ((p * 2 * n(0.5) + 1).pow(2) * (p * n(1.0) + 1)) as f64
        }
    };
    crate::resources::check("static-block", dofs, opts.dim, Some(opts.h))?;
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
    let mut mesh = mesh;
    mesh.set_cell_size(opts.cell_size);
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
    let active = Active::resolve_forms(&opts.setup, OVERRIDES)?;
    let density = active.params.get("rho").unwrap_or(1.0);
    let gravity = opts.gravity;
    let coefs = move |name: &str| match name {
        "g" => Some(Coef::of_position(1, move |x, out| {
            out[0] = x[d - 1] + c * x[..d - 1].iter().map(|v| v * v).sum::<f64>()
        })),
        "nc" => Some(Coef::constant((0..d).map(|k| if k == d - 1 { -1.0 } else { 0.0 }).collect::<Vec<_>>())),
        "f" => {
            Some(Coef::constant((0..d).map(|k| if k == d - 1 { -density * gravity } else { 0.0 }).collect::<Vec<_>>()))
        }
        _ => None,
    };
    let asm = Assembler::new(&mesh);
    let n = asm.size();
    let gap = |x: &[f64]| x[d - 1] + opts.curvature * x[..d - 1].iter().map(|v| v * v).sum::<f64>();
    // Start with the block pushed into the obstacle below its largest gap, so that every contact
    // point is active and the first Jacobian is not singular (at u = 0 the block would float,
    // or pivot on one point of a curved obstacle: H(0) = 0). Newton then releases points.
    let deepest =
        mesh.region_nodes(mesh.region("bottom")?).iter().map(|&i| gap(mesh.node(i as usize))).fold(0.0, f64::max);
    let mut u = vec![0.0; n];
    u.iter_mut().skip(d - 1).step_by(d).for_each(|x| *x = -(deepest + 1e-6 * opts.h));
    // Four Gauss points per edge in 2D, a degree-4 rule on faces in 3D: exact for the smooth
    // parts, and resolves the edge of the contact zone.
    let contact_degree = if d == 2 { 7 } else { 4 };
    let problem = StaticProblem {
        coefs: &coefs,
        contact: "bottom",
        contact_degree: Some(contact_degree),
        constraints: sliding_constraints(&mesh),
        newton: opts.newton,
    };
    let solution = statics::solve(&asm, problem, &active, u)?;
    let u = &solution.u;
    let samples = facet_samples(&mesh, solution.contact_facets, contact_degree, u);
    let max_penetration = samples.iter().map(|s| (-s.value[d - 1] - gap(&s.x)).max(0.0)).fold(0.0, f64::max);
    let counters = solution.counters;
    let summary = Summary {
        case: "static-block",
        contact: active.contact_name().to_string(),
        params: active.params.values(),
        curvature: opts.curvature,
        dim: d,
        degree: mesh.kind.degree(),
        h: opts.h,
        cells: mesh.num_cells(),
        dofs: n,
        weight: density * opts.gravity * mesh.measure(),
        contact_force: solution.contact_force[d - 1],
        max_penetration,
        active_points: solution.active_points,
        newton_iterations: solution.newton.iterations(),
        newton: solution.newton,
        symbolic_factorizations: counters.symbolic,
        numeric_factorizations: counters.numeric,
        wall_seconds: start.elapsed().as_secs_f64(),
    };
    if let Some(dir) = &opts.out {
        let path = dir.join("summary.json");
        crate::output::write_json(&path, &summary)
            .map_err(|source| CaseError::Write { path: path.display().to_string(), source })?;
    }
    Ok(summary)
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
