//! `signorini run hertz-static`: a cylinder (2D, plane strain) or a ball (3D) of radius R
//! pressed onto the rigid plane {x_d = 0} by a uniform body force of resultant F, against
//! Hertz's half-width (radius), peak pressure and pressure profile.
//!
//! The model is the half (x ≥ 0) or the quarter (x, y ≥ 0) of the body, with the normal
//! displacement held on the symmetry planes; figures are for the whole body.

use std::path::PathBuf;
use std::time::Instant;

use serde::Serialize;

use super::closed_form;
use super::{OVERRIDES, material, meshes, profile};
use crate::cases::CaseError;
use crate::driver::{Active, ParamValue, Setup};
use crate::runtime::assembly::Assembler;
use crate::runtime::linalg::Solver;
use crate::runtime::mesh::CellSize;
use crate::runtime::newton::NewtonOptions;
use crate::simulation::statics::{self, StaticProblem};

/// The default force makes Hertz's contact zone a tenth of the radius: small enough for the
/// half-space theory (its neglected terms are O((a/R)²)), large enough to resolve.
pub const CONTACT_RATIO: f64 = 0.1;

#[derive(Clone, Debug, PartialEq)]
pub struct Options {
    /// The contact law, material and params (the scheme is not used).
    pub setup: Setup,
    pub dim: usize,
    /// Refinement level of the built-in graded mesh (0 is the coarsest).
    pub level: usize,
    /// A Gmsh mesh of the same half (quarter) body instead of the built-in one.
    pub mesh: Option<PathBuf>,
    /// Force on the whole body (per unit length in 2D); default: Hertz's a = R / 10.
    pub force: Option<f64>,
    pub cell_size: CellSize,
    pub newton: NewtonOptions,
    pub out: Option<PathBuf>,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            setup: Setup::default(),
            dim: 2,
            level: 2,
            mesh: None,
            force: None,
            cell_size: CellSize::Diameter,
            // Without a mass term, Jacobi-CG on the stiffness converges slowly: factorize.
            newton: NewtonOptions { solver: Solver::Direct, ..NewtonOptions::default() },
            out: None,
        }
    }
}

/// Half-width (2D) or contact radius (3D), and peak pressure.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Figures {
    #[serde(skip_serializing_if = "Option::is_none")]
    pub half_width: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub contact_radius: Option<f64>,
    pub peak_pressure: f64,
}

impl Figures {
    fn new(dim: usize, size: f64, peak_pressure: f64) -> Figures {
        let (half_width, contact_radius) = if dim == 2 { (Some(size), None) } else { (None, Some(size)) };
        Figures { half_width, contact_radius, peak_pressure }
    }

    /// The half-width or the radius.
    pub fn size(&self) -> f64 {
        self.half_width.or(self.contact_radius).unwrap_or(f64::NAN)
    }
}

#[derive(Clone, Debug, Serialize)]
pub struct Measured {
    #[serde(flatten)]
    pub figures: Figures,
    /// ‖p_h − p_Hertz‖ / ‖p_Hertz‖ in L² on Γ_C's projection onto the plane.
    pub profile_l2_error: f64,
    /// The vertical resultant of the contact force on the whole body.
    pub force: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    pub case: &'static str,
    pub contact: String,
    pub params: std::collections::BTreeMap<String, ParamValue>,
    pub dim: usize,
    pub radius: f64,
    pub young: f64,
    pub poisson: f64,
    pub density: f64,
    /// The load on the whole body (per unit length in 2D).
    pub force: f64,
    pub mesh: String,
    pub cells: usize,
    pub dofs: usize,
    /// The smallest cell diameter on the contact boundary.
    pub h_contact: f64,
    pub measured: Measured,
    pub hertz: Figures,
    /// (measured − Hertz) / Hertz.
    pub relative_error: Figures,
    pub newton_iterations: usize,
    pub wall_seconds: f64,
}

/// Solves the case; writes summary.json and profile.png into `opts.out` if set.
pub fn run(opts: &Options) -> Result<Summary, CaseError> {
    let start = Instant::now();
    let d = opts.dim;
    let (mut mesh, mesh_name) = meshes::load(d, opts.level, opts.mesh.as_deref())?;
    mesh.set_cell_size(opts.cell_size);
    let active = Active::resolve_forms(&opts.setup, OVERRIDES)?;
    let material = material(&active)?;
    let e_star = material.contact_modulus();
    let radius = meshes::RADIUS;
    let force = opts.force.unwrap_or_else(|| closed_form::force_for(d, radius, e_star, CONTACT_RATIO * radius));
    if !(force > 0.0 && force.is_finite()) {
        return Err(CaseError::Option(format!("--force must be a positive number, not {force}")));
    }
    let (a, p0) = closed_form::static_contact(d, radius, e_star, force);
    // The body force whose resultant on the whole body (of exact measure) is F.
    let coefs = crate::cases::above_plane(d, 0.0, force / meshes::body_measure(d));
    let asm = Assembler::new(&mesh);
    // Start pushed down by Hertz's approach scale a²/R: the points within about √2 a are in
    // contact, so the first Jacobian is regular along x_d.
    let mut u = vec![0.0; asm.size()];
    u.iter_mut().skip(d - 1).step_by(d).for_each(|x| *x = -a * a / radius);
    let problem = StaticProblem {
        coefs: &coefs,
        contact: meshes::CONTACT,
        contact_degree: None,
        constraints: meshes::symmetry(&mesh)?,
        newton: opts.newton,
    };
    let solution = statics::solve(&asm, problem, &active, u)?;
    let pressure = solution.contact_pressure.as_ref().ok_or_else(|| {
        CaseError::Option("the contact law provides no `contact_pressure` functional to measure".into())
    })?;
    let samples = profile::sample(&asm, pressure.as_ref(), &solution.u);
    let zone = profile::zone(d, &samples, a).map_err(CaseError::Option)?;
    let measured = Measured {
        figures: Figures::new(d, zone.size, zone.peak_pressure),
        profile_l2_error: profile::l2_error(&samples, |r| closed_form::pressure(a, p0, r)),
        force: meshes::copies(d) * solution.contact_force[d - 1],
    };
    let hertz = Figures::new(d, a, p0);
    let summary = Summary {
        case: "hertz-static",
        contact: active.contact_name().to_string(),
        params: active.params.values(),
        dim: d,
        radius,
        young: material.young,
        poisson: material.poisson,
        density: material.density,
        force,
        mesh: mesh_name,
        cells: mesh.num_cells(),
        dofs: asm.size(),
        h_contact: solution
            .contact_facets
            .iter()
            .map(|f| mesh.cell_diameter(f.cell as usize))
            .fold(f64::INFINITY, f64::min),
        relative_error: Figures::new(d, zone.size / a - 1.0, zone.peak_pressure / p0 - 1.0),
        measured,
        hertz,
        newton_iterations: solution.newton.iterations(),
        wall_seconds: start.elapsed().as_secs_f64(),
    };
    if let Some(dir) = &opts.out {
        let path = dir.join("summary.json");
        crate::output::write_json(&path, &summary)
            .map_err(|source| CaseError::Write { path: path.display().to_string(), source })?;
        plot(&dir.join("profile.png"), &samples, d, a, p0)
            .map_err(|e| CaseError::Write { path: dir.join("profile.png").display().to_string(), source: e })?;
    }
    Ok(summary)
}

/// The measured profile (ring averages) against Hertz's.
fn plot(path: &std::path::Path, samples: &[profile::Sample], dim: usize, a: f64, p0: f64) -> std::io::Result<()> {
    use crate::plot::Curve;
    let hertz: Vec<(f64, f64)> =
        (0..=200).map(|i| 1.5 * a * i as f64 / 200.0).map(|r| (r, closed_form::pressure(a, p0, r))).collect();
    let measured = profile::binned(samples, 1.5 * a, 60);
    let axis = if dim == 2 {
        "x (distance from the first contact point)"
    } else {
        "r (distance from the first contact point)"
    };
    crate::plot::panels(
        path,
        axis,
        &[(
            "contact pressure",
            "p",
            vec![
                Curve { label: "computed (ring averages)", points: measured, dashed: false },
                Curve { label: "Hertz p0 √(1 − r²/a²)", points: hertz, dashed: true },
            ],
        )],
    )
    .map_err(std::io::Error::other)
}
