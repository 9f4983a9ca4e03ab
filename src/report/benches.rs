//! The report's benchmark sections: the last `bench sphere` and `bench disc` runs in the
//! report's directory (they take too long to run with it), tabulated.

use std::fmt::Write;
use std::path::Path;

use super::bench_methods;
use super::table::Table;
use crate::numbers::readable;

/// `bench sphere` takes an hour at full size: the report shows its last run in this directory.
pub(super) fn sphere(out: &Path) -> String {
    let mut md = String::new();
    md.push_str("## 7. Solvers for size (`signorini bench sphere`)\n\n");
    match crate::bench::sphere::read(out) {
        Some(Ok(bench)) => {
            let first = bench.runs.first();
            let methods = first.map_or_else(String::new, |r| {
                bench_methods(r.scheme.as_deref(), r.contact.as_deref(), &r.contact_params)
            });
            let steps = first.map_or_else(String::new, |r| match (r.dt, r.t_end) {
                (Some(dt), Some(t_end)) => {
                    format!("{} steps of Δt = {} to t = {}", r.steps, readable(dt), readable(t_end))
                }
                _ => format!("{} steps", r.steps),
            });
            let _ = writeln!(
                md,
                "Time per step and peak memory of the bouncing sphere against its size ({methods}; {steps}), from `bench_sphere.json` in this directory:\n"
            );
            let mut table = Table::new(&[
                "unknowns",
                "solver",
                "ms per step, whole run",
                "median step (ms)",
                "Newton iterations",
                "factorizations",
                "Krylov iterations",
                "peak memory (MB)",
            ]);
            for r in &bench.runs {
                let iterations = if r.solver == "direct" { "—".to_string() } else { r.krylov_iterations.to_string() };
                let memory = r.peak_memory_bytes.map_or("—".to_string(), |b| format!("{:.0}", b as f64 / 1e6));
                table.row([
                    r.dofs.to_string(),
                    r.solver.to_string(),
                    format!("{:.0}", r.ms_per_step_with_setup),
                    format!("{:.0}", r.median_step_ms),
                    r.newton_total.to_string(),
                    r.factorizations.to_string(),
                    iterations,
                    memory,
                ]);
            }
            md.push_str(&table.markdown());
            if out.join("bench_sphere.png").exists() {
                md.push_str("\n![bench sphere](bench_sphere.png)\n");
            }
            md.push('\n');
        }
        Some(Err(e)) => {
            let _ = writeln!(md, "`bench_sphere.json` in this directory cannot be read: {e}\n");
        }
        None => {
            let _ = writeln!(
                md,
                "Not run: `signorini bench sphere --out {}` writes bench_sphere.json and the log-log plot this section shows.\n",
                out.display()
            );
        }
    }
    md
}

/// The runs `bench disc` times beside the default one on each mesh (forms/library.toml's
/// `[bench]`): the explicit scheme, the frictional laws and the finite-strain material, each
/// against the default step.
fn beside_default(bench: &crate::bench::disc::Report) -> String {
    let mut table = Table::new(&[
        "mesh",
        "run",
        "ms per step (mean)",
        "× the default step",
        "Newton iterations",
        "factorizations per 1000 steps",
    ]);
    let mut rows = 0;
    for m in &bench.meshes {
        let name =
            std::path::Path::new(&m.mesh).file_name().map_or(m.mesh.clone(), |f| f.to_string_lossy().into_owned());
        let mut row = |run: String, ms: f64, newton: String, factorizations: f64| {
            rows += 1;
            table.row([
                name.clone(),
                run,
                format!("{ms:.3}"),
                format!("{:.2}", ms / m.ms_per_step),
                newton,
                format!("{factorizations:.0}"),
            ]);
        };
        if let Some(e) = &m.explicit {
            let per_1000 = 1000.0 * e.factorizations as f64 / m.steps.max(1) as f64;
            row(
                format!("{} ({} mass, Δt = {})", e.scheme, e.mass, readable(e.dt)),
                e.ms_per_step,
                "—".into(),
                per_1000,
            );
        }
        for f in &m.frictional {
            row(format!("contact {}", f.contact), f.ms_per_step, f.newton_total.to_string(), f.factorizations_per_1000);
        }
        for f in &m.finite_strain {
            let chord = if f.chord { ", chord Newton" } else { "" };
            row(
                format!("{} with {}{chord}", f.material, f.contact),
                f.ms_per_step,
                f.newton_total.to_string(),
                f.factorizations_per_1000,
            );
        }
    }
    if rows == 0 {
        return String::new();
    }
    format!(
        "Beside the default run, on the same meshes (Δt as above, except an explicit scheme's above its critical step):\n\n{}\n",
        table.markdown()
    )
}

/// The last `bench disc` run in this directory.
pub(super) fn disc(out: &Path) -> String {
    let mut md = String::new();
    md.push_str("## 8. Time per step of the disc (`signorini bench disc`)\n\n");
    match crate::bench::disc::read(out) {
        Some(Ok(bench)) => {
            let _ = writeln!(
                md,
                "Timed: {}; Δt = {}, to t = {}; the stepper alone, medians of {} runs, from `bench_disc.json` in this directory. The model: one residual product and one pair of triangular solves per step, as bytes read at STREAM's triad bandwidth (one thread, arrays out of cache); the in-cache model reads the same bytes at the triad bandwidth of a working set of their size.\n",
                bench_methods(bench.scheme.as_deref(), bench.contact.as_deref(), &bench.contact_params),
                readable(bench.dt),
                readable(bench.t_end),
                bench.repeats
            );
            let mut table = Table::new(&[
                "mesh",
                "unknowns",
                "ms per step (mean)",
                "median step (ms)",
                "factorizations per 1000 steps",
                "low-rank updates per 1000 steps",
                "nnz(K)",
                "nnz(L)",
                "model (ms)",
                "STREAM GB/s",
                "measured/model",
                "median step/model",
                "in-cache model (ms)",
                "in-cache GB/s",
                "measured/in-cache model",
            ]);
            for m in &bench.meshes {
                let name = std::path::Path::new(&m.mesh)
                    .file_name()
                    .map_or(m.mesh.clone(), |f| f.to_string_lossy().into_owned());
                table.row([
                    name,
                    m.dofs.to_string(),
                    format!("{:.3}", m.ms_per_step),
                    format!("{:.3}", m.median_step_ms),
                    format!("{:.0}", m.factorizations_per_1000),
                    format!("{:.0}", m.low_rank_updates_per_1000),
                    m.matrix_nnz.to_string(),
                    m.factor_nnz.map_or("—".into(), |n| n.to_string()),
                    format!("{:.3}", m.model_ms),
                    format!("{:.1}", m.stream_gb_s),
                    format!("{:.2}", m.measured_over_model),
                    format!("{:.2}", m.median_over_model),
                    format!("{:.3}", m.cache_model_ms),
                    format!("{:.1}", m.cache_gb_s),
                    format!("{:.2}", m.measured_over_cache_model),
                ]);
            }
            md.push_str(&table.markdown());
            md.push('\n');
            md.push_str(&beside_default(&bench));
        }
        Some(Err(e)) => {
            let _ = writeln!(md, "`bench_disc.json` in this directory cannot be read: {e}\n");
        }
        None => {
            let _ = writeln!(
                md,
                "Not run: `signorini bench disc --mesh FILE.msh ... --out {}` writes bench_disc.json, which this section tabulates.\n",
                out.display()
            );
        }
    }
    md
}
