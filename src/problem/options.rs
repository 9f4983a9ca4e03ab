//! How to run a problem: the command line's or a case file's choices (files and params, mass,
//! cell size, mesh, times, Newton, outputs, checkpoints) over the problem's own, and the times a
//! run steps by.

use std::path::PathBuf;

use crate::driver::Methods;
use crate::runtime::fem::mesh::CellSize;
use crate::runtime::nonlinear::newton::NewtonOptions;
use crate::simulation::MassChoice;

/// How to run a problem: the command line's or a case file's choices over the problem's.
#[derive(Clone, Debug, PartialEq)]
pub struct Options {
    /// A library problem by name, or a problem file.
    pub problem: String,
    /// Scheme, contact law, extra forms, params (the problem's params among them).
    pub methods: Methods,
    pub mass: MassChoice,
    pub cell_size: CellSize,
    /// A Gmsh file instead of the problem's mesh.
    pub mesh: Option<PathBuf>,
    /// Run settings over the problem's `run` line.
    pub dt: Option<f64>,
    pub t_start: Option<f64>,
    pub t_end: Option<f64>,
    /// Adaptive steps, over the problem's `run adaptive = ...`.
    pub steps: StepOptions,
    pub newton: NewtonOptions,
    /// Options for PETSc's solvers (`-ksp_rtol 1e-8 -pc_type hypre`), over the defaults of the
    /// `petsc` solver.
    pub petsc_options: Option<String>,
    pub out: Option<PathBuf>,
    /// `out` is prepared (`output::prepare`, with this `--force`) once the run is bound, so
    /// that a run refused before it starts leaves no directory behind; `None`: `out` is used
    /// as it is.
    pub out_fresh: Option<bool>,
    pub vtu_every: usize,
    pub progress: bool,
    pub checkpoint_every: usize,
    pub resume: bool,
    /// The roles the user chose explicitly (`--scheme`, ...): the problem's `bind` lines give
    /// the others.
    pub chosen: Chosen,
    /// The run's last state and its mesh are kept in its [`Run`](super::outputs::Run) (for
    /// a host that reads them: the Python API).
    pub keep_fields: bool,
}

/// Which of the methods' files the user chose; a problem's `bind` replaces the library's
/// defaults only.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Chosen {
    pub scheme: bool,
    pub contact: bool,
    pub material: bool,
}

impl Chosen {
    /// Every role chosen: the methods are taken as they are (programs that build their own).
    pub fn all() -> Chosen {
        Chosen { scheme: true, contact: true, material: true }
    }
}

impl Options {
    pub fn new(problem: &str) -> Options {
        Options {
            problem: problem.to_string(),
            methods: Methods::default(),
            mass: MassChoice::default(),
            cell_size: CellSize::default(),
            mesh: None,
            dt: None,
            t_start: None,
            t_end: None,
            steps: StepOptions::default(),
            newton: NewtonOptions::default(),
            petsc_options: None,
            out: None,
            out_fresh: None,
            vtu_every: 0,
            progress: false,
            checkpoint_every: 0,
            resume: false,
            chosen: Chosen::default(),
            keep_fields: false,
        }
    }
}

/// Adaptive steps as the options ask for them (none: the problem's `run` line decides).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StepOptions {
    pub adaptive: Option<f64>,
    pub dt_min: Option<f64>,
    pub dt_max: Option<f64>,
    pub event_dt: Option<f64>,
}

/// The run's times (Δt, start, end): the problem's `run` line under the options; with
/// adaptive steps, Δt is the first step.
pub struct Times {
    pub dt: f64,
    pub t_start: f64,
    pub t_end: f64,
    pub adaptive: Option<crate::simulation::step_control::Adaptive>,
}
