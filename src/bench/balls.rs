//! `signorini bench balls`: what contact between bodies costs an impact step against the size
//! of the bodies. The problem of forms/library.toml's `[bench]` (two balls colliding) runs at
//! each size in its own process, with the options given there (from just before the contact
//! through it), and its summary gives the pair forms' search and assembly time: their share
//! of the steps is what the pairs cost. Its built-in balls of 2·half cells per diameter have
//! 2 · 3(4·half + 1)³ P2 unknowns.

use std::path::{Path, PathBuf};
use std::process::Command;

use serde::{Deserialize, Serialize};

use crate::error::CaseError;

/// Cells per radius of the balls tried, smallest first: 4.4k, 29k, 94k and 146k unknowns.
const HALVES: [usize; 4] = [2, 4, 6, 7];

pub fn dofs(half: usize) -> usize {
    2 * 3 * (4 * half + 1).pow(3)
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct BallsTiming {
    pub dofs: usize,
    pub h: f64,
    pub steps: usize,
    pub newton_total: usize,
    pub krylov_iterations: usize,
    /// The steps' time (setup aside), their median, and the whole run's.
    pub stepping_seconds: f64,
    pub median_step_ms: f64,
    pub wall_seconds: f64,
    /// The pair forms over the run: spatial indexes built, facing points looked for, the
    /// search's seconds and the pair assembly's (residuals, tangents and functionals, the
    /// search included).
    pub pair_indexes: u64,
    pub pair_queries: u64,
    pub search_seconds: f64,
    pub pair_seconds: f64,
    /// The pair assembly over the steps' time: at most its share of a step (it also counts the
    /// initial acceleration's evaluation, outside the steps).
    pub pair_share_of_steps: f64,
    /// The search per query (µs): flat with the size when the search is n log n overall.
    pub search_us_per_query: f64,
    pub peak_memory_bytes: Option<u64>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Report {
    pub problem: String,
    pub options: Vec<String>,
    pub max_dofs: usize,
    pub runs: Vec<BallsTiming>,
}

/// Every size up to `max_dofs` unknowns, each in its own process.
pub fn balls(max_dofs: usize, dir: &Path, progress: &mut dyn FnMut(&str)) -> Result<Report, CaseError> {
    let exe: PathBuf = std::env::current_exe().map_err(|e| CaseError::Option(format!("cannot find myself: {e}")))?;
    let bench = &crate::settings::get().bench;
    let mut runs = Vec::new();
    for half in HALVES.into_iter().filter(|&h| dofs(h) <= max_dofs) {
        let r = run_one(&exe, half, &dir.join("bench_balls_runs"))?;
        progress(&format!(
            "{} dofs: {} steps, median {:.0} ms/step; pairs {:.1} % of the steps ({:.2} s, search {:.2} s: {} queries, {:.2} µs each), peak {:.0} MB",
            r.dofs,
            r.steps,
            r.median_step_ms,
            100.0 * r.pair_share_of_steps,
            r.pair_seconds,
            r.search_seconds,
            r.pair_queries,
            r.search_us_per_query,
            r.peak_memory_bytes.map_or(f64::NAN, |b| b as f64 / 1e6)
        ));
        runs.push(r);
    }
    Ok(Report { problem: bench.balls.clone(), options: bench.balls_options.clone(), max_dofs, runs })
}

fn run_one(exe: &Path, half: usize, dir: &Path) -> Result<BallsTiming, CaseError> {
    let h = 1.0 / half as f64;
    let bench = &crate::settings::get().bench;
    let problem = &bench.balls;
    let out = dir.join(format!("{problem}-{}", dofs(half)));
    let mut command = Command::new(exe);
    command
        .args(["run", problem.as_str(), "--param", &format!("h={h}")])
        .args(&bench.balls_options)
        .args(["--force", "--out"])
        .arg(&out);
    let s = super::run_summary(&mut command, &format!("run {problem} --param h={h}"), &out)?;
    let num = |v: &serde_json::Value, k: &str| v.get(k).and_then(serde_json::Value::as_f64).unwrap_or(f64::NAN);
    let int = |v: &serde_json::Value, k: &str| v.get(k).and_then(serde_json::Value::as_u64).unwrap_or(0);
    let Some(pairs) = s.get("pair_search") else {
        return Err(CaseError::Option(format!(
            "{}: no `pair_search` (a problem without contact pairs?)",
            out.join("summary.json").display()
        )));
    };
    let stepping_seconds = num(&s, "stepping_seconds");
    let (search_seconds, pair_seconds) = (num(pairs, "search_seconds"), num(pairs, "assembly_seconds"));
    let pair_queries = int(pairs, "queries");
    Ok(BallsTiming {
        dofs: int(&s, "dofs") as usize,
        h,
        steps: int(&s, "steps") as usize,
        newton_total: int(&s, "newton_total") as usize,
        krylov_iterations: int(&s, "krylov_iterations") as usize,
        stepping_seconds,
        median_step_ms: 1e3 * num(&s, "step_median_seconds"),
        wall_seconds: num(&s, "wall_seconds"),
        pair_indexes: int(pairs, "builds"),
        pair_queries,
        search_seconds,
        pair_seconds,
        pair_share_of_steps: pair_seconds / stepping_seconds,
        search_us_per_query: 1e6 * search_seconds / pair_queries.max(1) as f64,
        peak_memory_bytes: s.get("peak_memory_bytes").and_then(serde_json::Value::as_u64),
    })
}
