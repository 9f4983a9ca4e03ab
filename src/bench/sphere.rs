//! `signorini bench sphere`: time per step and peak memory of the bouncing sphere against its
//! size, for each solver (direct, block-Jacobi Krylov, PETSc). Each run is its own process (`run PROBLEM`,
//! the problem and the options of forms/library.toml's `[bench]`: from just before the first
//! contact through it), so that its peak memory is its own. Its built-in balls (radius 10) of
//! 2·half cells per diameter have 3(4·half + 1)³ P2 unknowns.

use std::path::{Path, PathBuf};
use std::process::Command;

use serde::{Deserialize, Serialize};

use crate::error::CaseError;
use crate::plot::Curve;
use crate::runtime::linalg::Solver;

/// Cells per radius of the balls tried, smallest first: 15k, 47k, 108k, 274k, 555k, 985k dofs.
const HALVES: [usize; 6] = [4, 6, 8, 11, 14, 17];
/// The direct solver is tried up to this many unknowns: one factorization at 108k takes about
/// 100 s and 4.6 GB, and through contact it still refactors (11 times in 50 steps at 47k).
pub const DIRECT_LIMIT: usize = 60_000;

pub fn dofs(half: usize) -> usize {
    3 * (4 * half + 1).pow(3)
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SphereTiming {
    pub dofs: usize,
    pub h: f64,
    pub solver: String,
    pub steps: usize,
    /// Median step time of the stepping, and the whole run (setup included) per step.
    pub median_step_ms: f64,
    pub ms_per_step_with_setup: f64,
    pub newton_total: usize,
    pub factorizations: usize,
    pub krylov_iterations: usize,
    /// Krylov iterations per linear solve (NaN for a direct solver; none in older files).
    #[serde(default)]
    pub iterations_per_solve: Option<f64>,
    /// MPI ranks the run used.
    #[serde(default = "one")]
    pub ranks: usize,
    pub peak_memory_bytes: Option<u64>,
    pub first_contact: Option<f64>,
    /// What the run ran with: the scheme, the contact law and its params, Δt and the end time
    /// (none in older files).
    #[serde(default)]
    pub scheme: Option<String>,
    #[serde(default)]
    pub contact: Option<String>,
    #[serde(default)]
    pub contact_params: Vec<(String, f64)>,
    #[serde(default)]
    pub dt: Option<f64>,
    #[serde(default)]
    pub t_end: Option<f64>,
    /// PETSc's runs: the cost model of a step's Krylov solves (see [`Model`]).
    #[serde(default)]
    pub model: Option<Model>,
}

/// Matrix reads per Krylov iteration of CG with PETSc's block Jacobi, the sphere's
/// preconditioner: CG's product, and ILU(0)'s two triangular solves, whose factors L and U
/// have the matrix's pattern and so read its entries once more. (GAMG, were it chosen, reads
/// the finest matrix about 8 times: CG's product, the residual restricted to the next level,
/// and Chebyshev's two smoothings of 3 products, as `-log_view -pc_mg_log` on the 47k sphere
/// showed.)
pub const PRODUCTS_PER_ITERATION: f64 = 2.0;

/// A step's Krylov solves as memory traffic: each fine-level product reads the matrix (AIJ:
/// 8-byte values, 4-byte column indices and row offsets) once, at the triad's bandwidth of as
/// many threads as there are processes.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Model {
    pub matrix_bytes: f64,
    pub products_per_step: f64,
    pub bandwidth_gb_s: f64,
    pub model_ms_per_step: f64,
    /// The median step over the model: what the step spends beyond reading the matrix.
    pub measured_over_model: f64,
}

impl Model {
    fn new(dofs: usize, nnz: usize, iterations_per_step: f64, bandwidth: f64, median_ms: f64) -> Model {
        let matrix_bytes = 12.0 * nnz as f64 + 4.0 * (dofs + 1) as f64;
        let products_per_step = PRODUCTS_PER_ITERATION * iterations_per_step;
        let model_ms_per_step = 1e3 * products_per_step * matrix_bytes / bandwidth;
        Model {
            matrix_bytes,
            products_per_step,
            bandwidth_gb_s: bandwidth / 1e9,
            model_ms_per_step,
            measured_over_model: median_ms / model_ms_per_step,
        }
    }
}

fn one() -> usize {
    1
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Report {
    pub max_dofs: usize,
    pub runs: Vec<SphereTiming>,
}

/// The command that runs `exe` on `ranks` MPI processes (itself, for one).
fn launch(exe: &Path, ranks: usize) -> Command {
    if ranks == 1 {
        return Command::new(exe);
    }
    let mut command = Command::new("mpirun");
    command.args(["-n", &ranks.to_string()]).arg(exe);
    // Open MPI refuses to run as root unless told that it is meant.
    #[cfg(unix)]
    // SAFETY: getuid has no preconditions.
    if unsafe { libc::getuid() } == 0 {
        command.env("OMPI_ALLOW_RUN_AS_ROOT", "1").env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1");
    }
    command
}

fn run_one(
    exe: &Path,
    half: usize,
    solver: &str,
    ranks: usize,
    bandwidth: &mut dyn FnMut(usize) -> f64,
    dir: &Path,
) -> Result<SphereTiming, CaseError> {
    let h = 10.0 / half as f64;
    let bench = &crate::settings::get().bench;
    let problem = &bench.sphere;
    let label = if ranks == 1 { solver.to_string() } else { format!("{solver}-{ranks}ranks") };
    let out = dir.join(format!("{problem}-{}-{label}", dofs(half)));
    let mut command = launch(exe, ranks);
    command
        .args(["run", problem.as_str(), "--h", &h.to_string()])
        .args(&bench.sphere_options)
        .args(["--solver", solver, "--out"])
        .arg(&out);
    let what = format!("run {problem} --h {h} --solver {solver} on {ranks} process(es)");
    let s = super::run_summary(&mut command, &what, &out)?;
    let num = |k: &str| s.get(k).and_then(serde_json::Value::as_f64).unwrap_or(f64::NAN);
    let int = |k: &str| s.get(k).and_then(serde_json::Value::as_u64).unwrap_or(0) as usize;
    let contact = s.get("contact").and_then(|v| v.as_str()).map(str::to_string);
    let params: std::collections::BTreeMap<String, crate::driver::ParamValue> =
        s.get("params").and_then(|p| serde_json::from_value(p.clone()).ok()).unwrap_or_default();
    let steps = int("steps").max(1);
    let model = (solver == "petsc").then(|| {
        let per_step = int("krylov_iterations") as f64 / steps as f64;
        Model::new(int("dofs"), int("matrix_nnz"), per_step, bandwidth(ranks), 1e3 * num("step_median_seconds"))
    });
    Ok(SphereTiming {
        model,
        dofs: int("dofs"),
        h,
        solver: solver.into(),
        steps: int("steps"),
        median_step_ms: 1e3 * num("step_median_seconds"),
        ms_per_step_with_setup: 1e3 * num("seconds_per_step"),
        newton_total: int("newton_total"),
        factorizations: int("factorizations"),
        krylov_iterations: int("krylov_iterations"),
        iterations_per_solve: (solver != "direct" && int("linear_solves") > 0)
            .then(|| int("krylov_iterations") as f64 / int("linear_solves") as f64),
        ranks,
        peak_memory_bytes: s.get("peak_memory_bytes").and_then(serde_json::Value::as_u64),
        first_contact: s.get("first_contact").and_then(serde_json::Value::as_f64),
        scheme: s.get("scheme").and_then(|v| v.as_str()).map(str::to_string),
        contact: contact.clone(),
        contact_params: contact.map_or_else(Vec::new, |c| crate::driver::params::declared_by(&params, &c)),
        dt: s.get("dt").and_then(serde_json::Value::as_f64),
        t_end: s.get("t_end").and_then(serde_json::Value::as_f64),
    })
}

/// Every ball up to `max_dofs` unknowns with each of `solvers` (none: direct, iterative, and
/// PETSc when built with it), the direct one where it fits; PETSc's on each number of MPI
/// processes of `ranks` (the others on one).
pub fn sphere(
    max_dofs: usize,
    solvers: &[Solver],
    ranks: &[usize],
    dir: &Path,
    progress: &mut dyn FnMut(&str),
) -> Result<Report, CaseError> {
    let exe: PathBuf = std::env::current_exe().map_err(|e| CaseError::Option(format!("cannot find myself: {e}")))?;
    let mut chosen = solvers.to_vec();
    if chosen.is_empty() {
        chosen = vec![Solver::Direct, Solver::Iterative];
        if cfg!(feature = "petsc") {
            chosen.push(Solver::Petsc);
        }
    }
    let names: Vec<String> = chosen
        .iter()
        .map(|s| serde_json::to_value(s).ok().and_then(|v| v.as_str().map(str::to_string)).unwrap_or_default())
        .collect();
    let mut runs = Vec::new();
    // The triad's bandwidth on n threads, measured once each.
    let mut measured: Vec<(usize, f64)> = Vec::new();
    let mut bandwidth = |n: usize| match measured.iter().find(|(m, _)| *m == n) {
        Some((_, b)) => *b,
        None => {
            let b = super::bandwidth::triad(n);
            measured.push((n, b));
            b
        }
    };
    for half in HALVES.into_iter().filter(|&h| dofs(h) <= max_dofs) {
        for solver in names.iter().map(String::as_str) {
            if solver == "direct" && dofs(half) > DIRECT_LIMIT {
                continue;
            }
            let counts: &[usize] = if solver == "petsc" { ranks } else { &[1] };
            for &n in counts {
                let r = run_one(&exe, half, solver, n, &mut bandwidth, &dir.join("bench_sphere_runs"))?;
                progress(&format!(
                    "{} dofs, {solver} on {n}: {:.1} ms/step (median), {:.1} ms/step with setup, {:.1} iterations per solve, peak {:.0} MB",
                    r.dofs,
                    r.median_step_ms,
                    r.ms_per_step_with_setup,
                    r.iterations_per_solve.unwrap_or(f64::NAN),
                    r.peak_memory_bytes.map_or(f64::NAN, |b| b as f64 / 1e6)
                ));
                if let Some(m) = &r.model {
                    progress(&format!(
                        "    model: {:.1} products of {:.0} MB per step at {:.1} GB/s = {:.1} ms; measured {:.2}× that",
                        m.products_per_step,
                        m.matrix_bytes / 1e6,
                        m.bandwidth_gb_s,
                        m.model_ms_per_step,
                        m.measured_over_model
                    ));
                }
                runs.push(r);
            }
        }
    }
    Ok(Report { max_dofs, runs })
}

/// The last run's `dir/bench_sphere.json`, if there is one.
pub fn read(dir: &Path) -> Option<Result<Report, String>> {
    let path = dir.join("bench_sphere.json");
    let text = std::fs::read_to_string(&path).ok()?;
    Some(serde_json::from_str(&text).map_err(|e| format!("{}: {e}", path.display())))
}

/// `dir/bench_sphere.png`: log-log time per step and peak memory against unknowns.
pub fn figure(report: &Report, dir: &Path) -> Result<(), CaseError> {
    let series = |solver: &str, f: fn(&SphereTiming) -> f64| -> Vec<(f64, f64)> {
        report
            .runs
            .iter()
            .filter(|r| r.solver == solver)
            .map(|r| ((r.dofs as f64).log10(), f(r)))
            .filter(|(_, y)| y.is_finite() && *y > 0.0)
            .map(|(x, y)| (x, y.log10()))
            .collect()
    };
    let curves = |f: fn(&SphereTiming) -> f64| {
        vec![
            Curve { label: "direct", points: series("direct", f), dashed: false },
            Curve { label: "iterative", points: series("iterative", f), dashed: true },
            Curve { label: "petsc", points: series("petsc", f), dashed: true },
        ]
    };
    let path = dir.join("bench_sphere.png");
    let problem = &crate::settings::get().bench.sphere;
    let title = |what: &str| format!("{problem}: {what}");
    crate::plot::panels(
        &path,
        "log₁₀ unknowns",
        &[
            (&title("time per step (whole run, setup included)"), "log₁₀ ms", curves(|r| r.ms_per_step_with_setup)),
            (&title("median step"), "log₁₀ ms", curves(|r| r.median_step_ms)),
            (&title("peak memory"), "log₁₀ MB", curves(|r| r.peak_memory_bytes.map_or(f64::NAN, |b| b as f64 / 1e6))),
        ],
    )
    .map_err(|e| CaseError::Write { path: path.display().to_string(), source: std::io::Error::other(e) })
}
