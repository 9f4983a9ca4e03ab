//! `run hertz-static` and `run hertz-impact`: their options and their one-line reports.

use std::path::PathBuf;
use std::process::ExitCode;

use super::{MethodArgs, fail};
use crate::cases::hertz::{impact, statics};
use crate::runtime::linalg::Solver;
use crate::runtime::newton::NewtonOptions;
use crate::simulation::MassChoice;

#[derive(clap::Args)]
pub struct HertzStaticArgs {
    /// The contact law and params (E = 50, ν = 0.25, γ0 = 5000 here); the scheme is not used.
    #[command(flatten)]
    methods: MethodArgs,
    #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u8).range(2..=3))]
    dim: u8,
    /// Level of the built-in graded mesh (0: coarsest; 2D 0–3, 3D 0–3).
    #[arg(long, default_value_t = 2)]
    level: usize,
    /// A Gmsh mesh of the half cylinder (quarter ball) with regions contact, symmetry_x
    /// (and symmetry_y), like assets/meshes/hertz_*.geo; default: the built-in level.
    #[arg(long)]
    mesh: Option<PathBuf>,
    /// The force on the whole body (per unit length in 2D); default: Hertz's a = R/10.
    #[arg(long, allow_hyphen_values = true)]
    load: Option<f64>,
    /// Directory for summary.json and profile.png.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Linear solver of each Newton iteration: direct, iterative or auto (as for `run sphere`).
    /// Direct by default: without a mass term, Jacobi-CG on the stiffness converges slowly.
    #[arg(long, value_parser = Solver::parse, default_value = "direct")]
    solver: Solver,
}

#[derive(clap::Args)]
pub struct HertzImpactArgs {
    /// Scheme, contact law and params (E = 50, ν = 0.25, γ0 = 5000 here).
    #[command(flatten)]
    methods: MethodArgs,
    #[arg(long, value_enum, default_value_t = MassChoice::Consistent)]
    mass: MassChoice,
    /// Level of the built-in graded quarter ball (0–3).
    #[arg(long, default_value_t = 0)]
    level: usize,
    /// A Gmsh mesh of the quarter ball with regions contact, symmetry_x and symmetry_y.
    #[arg(long)]
    mesh: Option<PathBuf>,
    /// Impact speed.
    #[arg(long, default_value_t = impact::SPEED, allow_hyphen_values = true)]
    speed: f64,
    /// Time step (default: Hertz's contact time / 200).
    #[arg(long, allow_hyphen_values = true)]
    dt: Option<f64>,
    /// Directory for series.csv, summary.json and force.png.
    #[arg(long)]
    out: Option<PathBuf>,
    #[arg(long, value_parser = Solver::parse, default_value = "auto")]
    solver: Solver,
}

pub(super) fn run_static(a: HertzStaticArgs) -> ExitCode {
    let setup = match a.methods.setup() {
        Ok(s) => s,
        Err(e) => return fail(e),
    };
    let opts = statics::Options {
        setup,
        cell_size: a.methods.cell_size,
        dim: a.dim as usize,
        level: a.level,
        mesh: a.mesh,
        force: a.load,
        out: match super::out_dir(a.out) {
            Ok(dir) => dir,
            Err(e) => return fail(e),
        },
        newton: NewtonOptions { solver: a.solver, line_search: a.methods.line_search, ..Default::default() },
    };
    match statics::run(&opts) {
        Ok(s) => {
            let what = if s.dim == 2 { "half-width" } else { "contact radius" };
            println!(
                "hertz-static {}D ({}, {}, {} dofs): {what} {:.5} (Hertz {:.5}, {:+.2}%), peak pressure {:.5} (Hertz {:.5}, {:+.2}%), profile L2 error {:.2}%, {} Newton iterations, {:.2} s",
                s.dim,
                s.contact,
                s.mesh,
                s.dofs,
                s.measured.figures.size(),
                s.hertz.size(),
                100.0 * s.relative_error.size(),
                s.measured.figures.peak_pressure,
                s.hertz.peak_pressure,
                100.0 * s.relative_error.peak_pressure,
                100.0 * s.measured.profile_l2_error,
                s.newton_iterations,
                s.wall_seconds
            );
            ExitCode::SUCCESS
        }
        Err(e) => fail(e),
    }
}

pub(super) fn run_impact(a: HertzImpactArgs) -> ExitCode {
    let setup = match a.methods.setup() {
        Ok(s) => s,
        Err(e) => return fail(e),
    };
    let opts = impact::Options {
        setup,
        cell_size: a.methods.cell_size,
        level: a.level,
        mesh: a.mesh,
        speed: a.speed,
        dt: a.dt,
        mass: a.mass,
        newton: NewtonOptions { solver: a.solver, line_search: a.methods.line_search, ..Default::default() },
        out: match super::out_dir(a.out) {
            Ok(dir) => dir,
            Err(e) => return fail(e),
        },
        progress: std::io::IsTerminal::is_terminal(&std::io::stdout()),
    };
    match impact::run(&opts) {
        Ok(run) => {
            let s = &run.summary;
            let (m, h, e) = (&s.measured, &s.hertz, &s.relative_error);
            println!(
                "hertz-impact ({}, {}, {}, {} dofs, Δt {:.4}): contact duration {:.4} (Hertz {:.4}, {:+.2}%), peak force {:.4} (Hertz {:.4}, {:+.2}%), contact radius {:.4} (Hertz {:.4}, {:+.2}%), restitution {:.4}, {:.1} s",
                s.scheme,
                s.contact,
                s.mesh,
                s.dofs,
                s.dt,
                m.contact_duration,
                h.contact_duration,
                100.0 * e.contact_duration,
                m.peak_force,
                h.peak_force,
                100.0 * e.peak_force,
                m.contact_radius,
                h.contact_radius,
                100.0 * e.contact_radius,
                s.restitution,
                s.wall_seconds
            );
            ExitCode::SUCCESS
        }
        Err(e) => fail(e),
    }
}
