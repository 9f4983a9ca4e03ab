//! `run hertz-impact`: its options and its one-line report.

use std::path::PathBuf;
use std::process::ExitCode;

use super::{MethodArgs, fail};
use crate::cases::hertz::impact;
use crate::runtime::linalg::Solver;
use crate::runtime::newton::NewtonOptions;
use crate::simulation::MassChoice;

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
