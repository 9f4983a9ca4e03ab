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
}

fn one() -> usize {
    1
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Report {
    pub max_dofs: usize,
    pub runs: Vec<SphereTiming>,
}

fn run_one(exe: &Path, half: usize, solver: &str, dir: &Path) -> Result<SphereTiming, CaseError> {
    let h = 10.0 / half as f64;
    let bench = &crate::settings::get().bench;
    let problem = &bench.sphere;
    let out = dir.join(format!("{problem}-{}-{solver}", dofs(half)));
    let status = Command::new(exe)
        .args(["run", problem.as_str(), "--h", &h.to_string()])
        .args(&bench.sphere_options)
        .args(["--solver", solver, "--out"])
        .arg(&out)
        .output()
        .map_err(|e| CaseError::Option(format!("cannot run {}: {e}", exe.display())))?;
    if !status.status.success() {
        return Err(CaseError::Option(format!(
            "run {problem} --h {h} --solver {solver} failed: {}",
            String::from_utf8_lossy(&status.stderr).trim()
        )));
    }
    let path = out.join("summary.json");
    let text = std::fs::read_to_string(&path)
        .map_err(|source| CaseError::Write { path: path.display().to_string(), source })?;
    let s: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| CaseError::Option(format!("{}: {e}", path.display())))?;
    let num = |k: &str| s.get(k).and_then(serde_json::Value::as_f64).unwrap_or(f64::NAN);
    let int = |k: &str| s.get(k).and_then(serde_json::Value::as_u64).unwrap_or(0) as usize;
    let contact = s.get("contact").and_then(|v| v.as_str()).map(str::to_string);
    let params: std::collections::BTreeMap<String, crate::driver::ParamValue> =
        s.get("params").and_then(|p| serde_json::from_value(p.clone()).ok()).unwrap_or_default();
    Ok(SphereTiming {
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
        ranks: 1,
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
/// PETSc when built with it), the direct one where it fits.
pub fn sphere(
    max_dofs: usize,
    solvers: &[Solver],
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
    for half in HALVES.into_iter().filter(|&h| dofs(h) <= max_dofs) {
        for solver in names.iter().map(String::as_str) {
            if solver == "direct" && dofs(half) > DIRECT_LIMIT {
                continue;
            }
            let r = run_one(&exe, half, solver, &dir.join("bench_sphere_runs"))?;
            progress(&format!(
                "{} dofs, {solver}: {:.1} ms/step (median), {:.1} ms/step with setup, {:.1} iterations per solve, peak {:.0} MB",
                r.dofs,
                r.median_step_ms,
                r.ms_per_step_with_setup,
                r.iterations_per_solve.unwrap_or(f64::NAN),
                r.peak_memory_bytes.map_or(f64::NAN, |b| b as f64 / 1e6)
            ));
            runs.push(r);
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
