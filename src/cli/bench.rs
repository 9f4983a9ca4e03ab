//! `bench assemble`, `bench disc`, `bench sphere`, `bench balls`, `bench search`, `bench adaptive`:
//! the benchmarks run and their JSON written.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use super::fail;

pub(super) fn assemble(sizes: &[usize], factor: usize, repeats: usize, out: &Path) -> ExitCode {
    if sizes.iter().any(|&n| n == 0 || n > 2048) {
        super::print_error("--sizes must lie in 1..=2048");
        return ExitCode::FAILURE;
    }
    // The P2 plane-strain unknowns of the N×N mesh, 2 (2N + 1)², against the memory there is,
    // before anything is allocated.
    for (what, n) in sizes.iter().map(|&n| ("--sizes", n)).chain((factor > 0).then_some(("--factor", factor))) {
        let dofs = 2.0 * (2.0 * n as f64 + 1.0).powi(2);
        if let Err(e) = crate::resources::check(&format!("bench assemble {what} {n}"), dofs, 2, None) {
            return fail(e);
        }
    }
    let report = crate::bench::assemble(sizes, (factor > 0).then_some(factor), repeats, &mut |line| println!("{line}"));
    write_bench(&out.join("bench_assemble.json"), &report)
}

pub(super) fn sphere(
    max_dofs: usize,
    solvers: &[crate::runtime::linalg::Solver],
    ranks: &[usize],
    out: &Path,
) -> ExitCode {
    use crate::bench::sphere;
    let report = match sphere::sphere(max_dofs, solvers, ranks, out, &mut |line| println!("{line}")) {
        Ok(r) => r,
        Err(e) => return fail(e),
    };
    if let Err(e) = sphere::figure(&report, out) {
        return fail(e);
    }
    write_bench(&out.join("bench_sphere.json"), &report)
}

pub(super) fn disc(meshes: &[PathBuf], repeats: usize, out: &Path) -> ExitCode {
    let report = match crate::bench::disc::disc(meshes, repeats, &mut |line| println!("{line}")) {
        Ok(r) => r,
        Err(e) => {
            super::print_error(e);
            return ExitCode::FAILURE;
        }
    };
    write_bench(&out.join("bench_disc.json"), &report)
}

pub(super) fn adaptive(out: &Path) -> ExitCode {
    let report = match crate::bench::adaptive::adaptive(out, &mut |table| println!("{table}")) {
        Ok(r) => r,
        Err(e) => return fail(e),
    };
    let tables: Vec<String> = report.comparisons.iter().map(crate::bench::adaptive::table).collect();
    let md = out.join("bench_adaptive.md");
    if let Err(source) = std::fs::write(&md, tables.join("\n")) {
        return fail(crate::error::CaseError::Write { path: md.display().to_string(), source });
    }
    write_bench(&out.join("bench_adaptive.json"), &report)
}

pub(super) fn balls(max_dofs: usize, out: &Path) -> ExitCode {
    match crate::bench::balls::balls(max_dofs, out, &mut |line| println!("{line}")) {
        Ok(report) => write_bench(&out.join("bench_balls.json"), &report),
        Err(e) => fail(e),
    }
}

pub(super) fn search(repeats: usize, out: &Path) -> ExitCode {
    let report = crate::bench::search::search(repeats, &mut |line| println!("{line}"));
    write_bench(&out.join("bench_search.json"), &report)
}

/// Writes a benchmark's JSON and says where.
fn write_bench(path: &Path, report: &impl serde::Serialize) -> ExitCode {
    match crate::output::write_json(path, report) {
        Ok(()) => {
            println!("wrote {}", path.display());
            ExitCode::SUCCESS
        }
        Err(e) => {
            super::print_error(format_args!("cannot write {}: {e}", path.display()));
            ExitCode::FAILURE
        }
    }
}
