//! `check`, `emit` and `mesh info`: what signorini says about a .wf file (its diagnostics, its
//! integrals' quadrature degrees, a problem bound to its mesh, a compilation stage) or a mesh
//! file, without running anything.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use super::Stage;
use crate::compiler;

pub(super) fn check(files: &[PathBuf]) -> ExitCode {
    let mut failed = false;
    for f in files {
        match compiler::compile(f, &crate::driver::sources::LibraryLoader) {
            Ok(compiled) => {
                eprint!("{}", compiled.warnings);
                print!("{}", quadrature_degrees(f, &compiled));
                // A problem is also bound: its mesh and regions, the coefs of the files in use.
                if !compiled.program.unit.problems.is_empty() {
                    match crate::problem::run::check(&f.to_string_lossy()) {
                        Ok(line) => println!("{line}"),
                        Err(e) => {
                            eprintln!("{e}");
                            failed = true;
                        }
                    }
                }
            }
            Err(e) => {
                eprint!("{e}");
                failed = true;
            }
        }
    }
    if failed { ExitCode::FAILURE } else { ExitCode::SUCCESS }
}

/// Each integral's quadrature degree on P1 and P2 elements (2D): the estimate, or the one the
/// file sets with `int(REGION, degree = K)`.
fn quadrature_degrees(file: &Path, compiled: &compiler::Compiled) -> String {
    let mut out = String::new();
    let unit = &compiled.program.unit;
    // The file's own forms (an imported file's are in its own report).
    let own = |name: &str| unit.forms.iter().any(|f| f.name == name && f.span.file == unit.root);
    for form in compiled.ir(2).forms.iter().filter(|f| own(&f.name)) {
        for i in &form.integrals {
            let how = if i.degree == i.estimated {
                format!("estimated; `int({}, degree = K)` sets it", i.region)
            } else {
                format!("set in the file; estimated {} and {}", i.estimated[0], i.estimated[1])
            };
            out.push_str(&format!(
                "{}: {} over {}: quadrature degree {} on P1, {} on P2 ({how})\n",
                file.display(),
                form.name,
                i.region,
                i.degree[0],
                i.degree[1]
            ));
        }
    }
    out
}

/// A compilation stage of `file` as `emit` prints it, with the file's rendered warnings.
pub fn stage_text(file: &Path, stage: Stage, dim: usize) -> Result<(String, String), compiler::Failure> {
    let compiled = compiler::compile(file, &crate::driver::sources::LibraryLoader)?;
    let stage = match stage {
        Stage::Ast => compiler::Stage::Ast,
        Stage::Ir => compiler::Stage::Ir,
        Stage::Scheme => compiler::Stage::Scheme,
        Stage::Rust => compiler::Stage::Rust,
        Stage::Energy => compiler::Stage::Energy,
    };
    Ok((compiled.print(stage, dim)?, compiled.warnings))
}

pub(super) fn emit(file: &Path, stage: Stage, dim: usize) -> ExitCode {
    match stage_text(file, stage, dim) {
        Ok((text, warnings)) => {
            eprint!("{warnings}");
            print!("{text}");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprint!("{e}");
            ExitCode::FAILURE
        }
    }
}

pub(super) fn mesh_info(file: &Path) -> ExitCode {
    match crate::runtime::fem::mesh::gmsh::read(file) {
        Ok(mesh) => {
            let regions: serde_json::Map<String, serde_json::Value> = mesh
                .regions
                .iter()
                .map(|r| (r.name.clone(), serde_json::json!({ "facets": r.facets.len() })))
                .collect();
            let groups: serde_json::Map<String, serde_json::Value> =
                mesh.cell_groups.iter().map(|(n, c)| (n.clone(), serde_json::json!({ "cells": c.len() }))).collect();
            let info = serde_json::json!({
                "file": file.display().to_string(),
                "dimension": mesh.dim(),
                "nodes": mesh.num_nodes(),
                "cells": { mesh.kind.name(): mesh.num_cells() },
                "boundary_facets": mesh.boundary_facets().len(),
                "regions": regions,
                "cell_groups": groups,
                "measure": mesh.measure(),
                "max_cell_diameter": mesh.max_diameter(),
                "warnings": mesh.warnings,
            });
            println!("{}", serde_json::to_string_pretty(&info).expect("JSON of plain values"));
            ExitCode::SUCCESS
        }
        Err(e) => {
            super::print_error(e);
            ExitCode::FAILURE
        }
    }
}
