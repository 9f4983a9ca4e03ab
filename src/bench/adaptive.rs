//! `signorini bench adaptive`: each problem of forms/library.toml's `[[bench.adaptive]]` run with
//! its fixed steps and with adaptive ones, each in its own process, side by side: the steps
//! they took, what they cost, and the compared summary keys, against a reference run of fine
//! fixed steps (each run's difference from it is its time discretization's error) or, for keys
//! that are errors against an exact solution, with the fixed run taken at the adaptive run's
//! number of steps.

use std::path::{Path, PathBuf};
use std::process::Command;

use serde::{Deserialize, Serialize};

use crate::error::CaseError;
use crate::settings::AdaptiveBench;

/// One run's steps, cost and compared values.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Ran {
    pub options: Vec<String>,
    pub steps: usize,
    pub factorizations: usize,
    pub wall_seconds: f64,
    pub values: Vec<f64>,
    /// The adaptive run's counts (its summary's `adaptive`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub adaptive: Option<serde_json::Value>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Comparison {
    pub problem: String,
    pub tolerance: f64,
    pub keys: Vec<String>,
    pub fixed: Ran,
    pub adaptive: Ran,
    /// The fixed run at the adaptive run's number of steps (`same_steps`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub same_steps: Option<Ran>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reference: Option<Ran>,
    /// The fixed run's steps over the adaptive run's.
    pub fewer_steps: f64,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Report {
    pub comparisons: Vec<Comparison>,
}

pub fn adaptive(dir: &Path, progress: &mut dyn FnMut(&str)) -> Result<Report, CaseError> {
    let exe: PathBuf = std::env::current_exe().map_err(|e| CaseError::Option(format!("cannot find myself: {e}")))?;
    let runs = dir.join("bench_adaptive_runs");
    let mut comparisons = Vec::new();
    for b in &crate::settings::get().bench.adaptive {
        let c = compare(&exe, b, &runs)?;
        progress(&table(&c));
        comparisons.push(c);
    }
    Ok(Report { comparisons })
}

fn compare(exe: &Path, b: &AdaptiveBench, dir: &Path) -> Result<Comparison, CaseError> {
    let named = |what: &str| dir.join(format!("{}-{what}", b.problem));
    let tolerance = ["--adaptive".to_string(), b.tolerance.to_string()];
    let adaptive = run(exe, b, &tolerance, &named("adaptive"))?;
    let (fixed, summary) = run_with_summary(exe, b, &[], &named("fixed"))?;
    let same_steps = match b.same_steps {
        true => {
            // The fixed run's interval, in the adaptive run's number of steps.
            let dt = summary.get("dt").and_then(serde_json::Value::as_f64).unwrap_or(f64::NAN);
            let dt = dt * fixed.steps as f64 / adaptive.steps.max(1) as f64;
            Some(run(exe, b, &["--dt".to_string(), dt.to_string()], &named("same-steps"))?)
        }
        false => None,
    };
    let reference = match &b.reference {
        Some(options) => Some(run(exe, b, options, &named("reference"))?),
        None => None,
    };
    Ok(Comparison {
        problem: b.problem.clone(),
        tolerance: b.tolerance,
        keys: b.compare.clone(),
        fewer_steps: fixed.steps as f64 / adaptive.steps.max(1) as f64,
        fixed,
        adaptive,
        same_steps,
        reference,
    })
}

fn run(exe: &Path, b: &AdaptiveBench, more: &[String], out: &Path) -> Result<Ran, CaseError> {
    Ok(run_with_summary(exe, b, more, out)?.0)
}

/// `run PROBLEM` with the bench's options and `more`, writing to `out`.
fn run_with_summary(
    exe: &Path,
    b: &AdaptiveBench,
    more: &[String],
    out: &Path,
) -> Result<(Ran, serde_json::Value), CaseError> {
    let mut command = Command::new(exe);
    command.args(["run", b.problem.as_str()]).args(&b.options).args(more).args(["--force", "--out"]).arg(out);
    let what = format!("run {} {}", b.problem, more.join(" "));
    let s = super::run_summary(&mut command, &what, out)?;
    let num = |k: &str| s.get(k).and_then(serde_json::Value::as_f64).unwrap_or(f64::NAN);
    let int = |k: &str| s.get(k).and_then(serde_json::Value::as_u64).unwrap_or(0) as usize;
    let values = b.compare.iter().map(|k| num(k)).collect();
    let ran = Ran {
        options: b.options.iter().chain(more).cloned().collect(),
        steps: int("steps"),
        factorizations: int("factorizations"),
        wall_seconds: num("wall_seconds"),
        values,
        adaptive: s.get("adaptive").cloned(),
    };
    Ok((ran, s))
}

/// The comparison as a markdown table: a row per run, a column per key; with a reference, each
/// value's difference from it below.
pub fn table(c: &Comparison) -> String {
    let mut s = format!(
        "## {} (adaptive tolerance {}: {:.1}× fewer steps)\n\n| run | steps | factorizations | wall s | {} |\n|---|---|---|---|{}\n",
        c.problem,
        c.tolerance,
        c.fewer_steps,
        c.keys.join(" | "),
        "---|".repeat(c.keys.len())
    );
    let mut row = |name: &str, r: &Ran| {
        let values: Vec<String> = r
            .values
            .iter()
            .enumerate()
            .map(|(i, v)| match &c.reference {
                Some(re) if name != "reference" => format!("{} ({:+.2e})", figure(*v), v - re.values[i]),
                _ => figure(*v),
            })
            .collect();
        s.push_str(&format!(
            "| {name} | {} | {} | {:.2} | {} |\n",
            r.steps,
            r.factorizations,
            r.wall_seconds,
            values.join(" | ")
        ));
    };
    row("fixed", &c.fixed);
    row("adaptive", &c.adaptive);
    if let Some(r) = &c.same_steps {
        row("fixed, as many steps", r);
    }
    if let Some(r) = &c.reference {
        row("reference", r);
    }
    s
}

/// Six decimals, or exponent form for a value below 10⁻³.
fn figure(x: f64) -> String {
    if x != 0.0 && x.abs() < 1e-3 { format!("{x:.3e}") } else { format!("{x:.6}") }
}
