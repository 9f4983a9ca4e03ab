//! A body falling onto an obstacle, as the report, `verify`, the benchmarks and the tests read
//! it: the bouncing disc (`forms/problems/disc.wf`, the default), the sphere (`sphere.wf`), or
//! any problem file with their columns, run by the one driver ([`crate::problem::run`]); this
//! module gives its rows and summary typed fields. The obstacle's normal is the vertical axis,
//! y in 2D and z in 3D: the fields `u_vertical_*`, `v_vertical_mean` and `f_vertical_contact`
//! of [`Row`] hold that component, read from the columns the file names after its axis
//! (`uy_mean`, `fy_contact` and the summary key `min_uy_mean` for the disc; `uz_mean`,
//! `fz_contact` and `min_uz_mean` for the sphere). Its runs take the driver's [`Options`]; the mesh
//! size of the built-in generator is the problem's param `h`.

use serde::{Deserialize, Serialize};

use super::{Common, count, number};
use crate::error::CaseError;
use crate::problem::run::{Chosen, Options};

/// The disc's run with its file's mesh and times and a run's defaults: the problem of
/// forms/library.toml's `cases.disc`, with the methods as given (no `bind` line replaces them).
/// Another problem with the disc's columns runs with `problem` set (`sphere`).
pub fn options() -> Options {
    Options { chosen: Chosen::all(), ..Options::new(&crate::settings::get().cases.disc) }
}

/// One row of `series.csv`.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Row {
    pub t: f64,
    pub energy: f64,
    /// ½vᵀMv (with the mass the scheme uses).
    pub kinetic: f64,
    pub energy_aug: f64,
    /// Mass-weighted mean of the vertical displacement (the centre of mass's).
    pub u_vertical_mean: f64,
    /// Plain mean of the nodes' vertical displacements (GetFEM's benchmark reports this one).
    pub u_vertical_mean_nodal: f64,
    /// Mass-weighted mean of the vertical velocity: the centre of mass's (NaN for a scheme
    /// without `v`).
    pub v_vertical_mean: f64,
    /// The vertical displacement of the lowest node.
    pub u_vertical_lowest: f64,
    /// The vertical force of the obstacle on the body.
    pub f_vertical_contact: f64,
    /// The measure of the contact zone's points where the gap is closed (u_N ≥ g): a length
    /// for the disc, an area for the sphere.
    pub contact_area: f64,
    pub active_points: usize,
    /// The contact switches at every contact quadrature point (the active set).
    #[serde(skip)]
    pub switches: Vec<bool>,
    pub penetration: f64,
    pub newton: usize,
}

/// The disc's summary: the keys of every run ([`Common`], read through `Deref`) and the disc's
/// own.
#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    #[serde(flatten)]
    pub common: Common,
    pub mesh: String,
    pub cells: usize,
    /// Time of the first step that ends with an active contact point.
    pub first_contact: Option<f64>,
    pub max_penetration: f64,
    /// The lowest the centre of mass went (the smallest `u_vertical_mean`).
    pub min_u_vertical_mean: f64,
    pub energy_aug_initial: f64,
    pub energy_aug_final: f64,
    /// The largest kinetic energy ½vᵀMv over the run (at impact): the disc's energy scale, as
    /// E_aug(0) = 0.
    pub kinetic_energy_max: f64,
    pub seconds_per_step: f64,
    /// Time inside the time stepper alone (no setup, measurements or output), in total and
    /// the median over steps.
    pub stepping_seconds: f64,
    pub step_median_seconds: f64,
    /// Numeric factorizations of the stage Jacobians (the rest of the Newton iterations reuse one;
    /// with the iterative solver: preconditioner setups).
    pub factorizations: usize,
    /// Changes of the active set solved by a low-rank correction of the last factorization
    /// instead of a new one.
    pub low_rank_updates: usize,
    /// Stored entries of the step matrix and of its Cholesky factor (direct solver).
    pub matrix_nnz: usize,
    pub factor_nnz: Option<usize>,
    /// The linear solver asked for, and the Krylov iterations over the run (0: direct).
    pub solver: crate::runtime::linalg::Solver,
    pub krylov_iterations: usize,
    /// The process's peak resident memory at the end of the run (Linux), in bytes.
    pub peak_memory_bytes: Option<u64>,
}

deref_to_common!(Summary);

pub struct Run {
    pub summary: Summary,
    pub series: Vec<Row>,
    /// Multi-stage schemes: the measures at every intermediate stage (`stages.csv`); the
    /// Newton column is 0 there (the step's count is in `series`).
    pub stages: Vec<StageRow>,
}

/// The measures at an intermediate stage's time.
#[derive(Clone, Debug)]
pub struct StageRow {
    /// The stage's name in the scheme's file.
    pub stage: String,
    pub row: Row,
}

/// Runs the problem; writes its outputs into `opts.out` if set.
pub fn run(opts: &Options) -> Result<Run, CaseError> {
    from_problem(opts, &crate::problem::run::run(opts)?)
}

/// The problem file's run as the disc's rows and summary (its columns by name).
fn from_problem(opts: &Options, run: &crate::problem::run::Run) -> Result<Run, CaseError> {
    // The vertical axis: the last one whose mean displacement the file measures (z in 3D, y in
    // 2D).
    let a = ['z', 'y', 'x'].into_iter().find(|a| run.columns.iter().any(|c| *c == format!("u{a}_mean"))).unwrap_or('y');
    let s = &run.summary;
    let (common, _) = Common::read(opts, s)?;
    let names = [
        "energy".to_string(),
        "kinetic".to_string(),
        "energy_aug".to_string(),
        format!("u{a}_mean"),
        format!("u{a}_mean_nodal"),
        format!("v{a}_mean"),
        format!("u{a}_lowest"),
        format!("f{a}_contact"),
        "contact_area".to_string(),
        "active_points".to_string(),
        "penetration".to_string(),
        "newton".to_string(),
    ];
    let index = run.indices(&names, &common.case)?;
    let row = |t: f64, v: &[f64], switches: Vec<bool>| Row {
        t,
        energy: v[index[0]],
        kinetic: v[index[1]],
        energy_aug: v[index[2]],
        u_vertical_mean: v[index[3]],
        u_vertical_mean_nodal: v[index[4]],
        v_vertical_mean: v[index[5]],
        u_vertical_lowest: v[index[6]],
        f_vertical_contact: v[index[7]],
        contact_area: v[index[8]],
        active_points: v[index[9]] as usize,
        switches,
        penetration: v[index[10]],
        newton: v[index[11]] as usize,
    };
    let series: Vec<Row> = run.rows.iter().zip(&run.switches).map(|((t, v), s)| row(*t, v, s.clone())).collect();
    let stages =
        run.stages.iter().map(|(name, t, v)| StageRow { stage: name.clone(), row: row(*t, v, Vec::new()) }).collect();
    let summary = Summary {
        mesh: s.field("mesh")?,
        cells: count(s, "cells"),
        first_contact: s.number("first_contact"),
        max_penetration: number(s, "max_penetration"),
        min_u_vertical_mean: number(s, &format!("min_u{a}_mean")),
        energy_aug_initial: number(s, "energy_aug_initial"),
        energy_aug_final: number(s, "energy_aug_final"),
        kinetic_energy_max: number(s, "kinetic_energy_max"),
        seconds_per_step: number(s, "seconds_per_step"),
        stepping_seconds: number(s, "stepping_seconds"),
        step_median_seconds: number(s, "step_median_seconds"),
        factorizations: count(s, "factorizations"),
        low_rank_updates: count(s, "low_rank_updates"),
        matrix_nnz: count(s, "matrix_nnz"),
        factor_nnz: s.get("factor_nnz").and_then(|v| v.as_u64()).map(|v| v as usize),
        solver: opts.newton.solver,
        krylov_iterations: count(s, "krylov_iterations"),
        peak_memory_bytes: s.get("peak_memory_bytes").and_then(|v| v.as_u64()),
        common,
    };
    Ok(Run { summary, series, stages })
}
