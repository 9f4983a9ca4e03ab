//! `signorini._signorini`, the extension module of the Python package `signorini`
//! (python/signorini/ wraps it in classes): the command line's runs, checks, stages, listing
//! and verification, returning values instead of writing files. A run's options are read by the
//! command line's own parser ([`signorini::cli::run_options`]), so a keyword argument and its
//! `--option` are checked and refused alike, and a run gives the same numbers.

use pyo3::prelude::*;
use pyo3::types::PyDict;

mod failure;
mod results;
mod signals;

use failure::{Failure, wf_failure};

/// Reads the library (its forms and the meshes its problems name) from `root`, the copy the
/// installed package carries, instead of the source tree it was built from.
#[pyfunction]
fn _use_library(root: std::path::PathBuf) {
    signorini::library_dir::set(root);
}

/// The options of `signorini run` (name, takes a value, repeatable, help).
#[pyfunction]
fn run_options() -> Vec<(String, bool, bool, String)> {
    signorini::cli::run_option_list().into_iter().map(|o| (o.name, o.takes_value, o.repeated, o.help)).collect()
}

/// Runs `signorini run ARGS...` without writing anything it is not asked to (`--out`), and
/// returns its results; `watcher(row)` sees each row (a dict) as it is measured and stops the
/// run after that step by returning False. Ctrl-C stops the run after its step too.
#[pyfunction]
#[pyo3(signature = (args, watcher=None))]
fn run(py: Python<'_>, args: Vec<String>, watcher: Option<Py<PyAny>>) -> PyResult<Py<PyDict>> {
    let mut opts = signorini::cli::run_options(&args).map_err(|e| Failure::new_err(("option", e)))?;
    opts.keep_fields = true;
    opts.progress = false;
    // A stop asked for by an earlier run's Ctrl-C is not this run's.
    signorini::interrupt::clear();
    signorini::interrupt::set_poll(signals::poll);
    signals::take();
    let raised = std::sync::Mutex::new(None::<PyErr>);
    let watch = |seen: &signorini::problem::run::Seen| {
        let Some(w) = &watcher else { return true };
        Python::attach(|py| {
            let shown = results::row(py, seen).and_then(|row| w.call1(py, (row,)));
            match shown {
                Ok(r) => !r.bind(py).is(pyo3::types::PyBool::new(py, false)),
                Err(e) => {
                    *raised.lock().unwrap_or_else(|p| p.into_inner()) = Some(e);
                    false
                }
            }
        })
    };
    let outcome = py.detach(|| signorini::problem::run::run_watched(&opts, watcher.as_ref().map(|_| &watch as _)));
    let raised = raised.into_inner().unwrap_or_else(|p| p.into_inner()).or_else(signals::take);
    match outcome {
        Ok(r) => results::run(py, &r),
        Err(stopped) => {
            let partial = match &stopped.run {
                Some(r) => Some(results::run(py, r)?),
                None => None,
            };
            Err(failure::stopped(py, stopped.error, partial, raised))
        }
    }
}

/// The diagnostics of a .wf file (errors and warnings, located), and for a problem file the
/// line saying what was bound (None if it did not bind; its error is then a diagnostic).
#[pyfunction]
fn check(py: Python<'_>, path: std::path::PathBuf) -> PyResult<(Vec<Py<PyDict>>, Option<String>)> {
    use signorini::compiler;
    let compiled = match compiler::compile(&path, &signorini::driver::sources::LibraryLoader) {
        Ok(c) => c,
        // A file that cannot be read has no diagnostic to locate: an error of its own.
        Err(f) if f.diagnostics.is_empty() => return Err(wf_failure(f)),
        Err(f) => return Ok((failure::diagnostics(py, &f)?, None)),
    };
    let sources = &compiled.program.unit.sources;
    let mut out: Vec<Py<PyDict>> = (compiled.program.unit.warnings.iter())
        .map(|d| failure::diagnostic(py, &d.locate(sources)))
        .collect::<PyResult<_>>()?;
    if compiled.program.unit.problems.is_empty() {
        return Ok((out, None));
    }
    match signorini::problem::run::check(&path.to_string_lossy()) {
        Ok(line) => Ok((out, Some(line))),
        Err(signorini::error::CaseError::Wf(f)) => {
            out.extend(failure::diagnostics(py, &f)?);
            Ok((out, None))
        }
        Err(e) => {
            out.push(failure::unlocated(py, &path, &e.to_string())?);
            Ok((out, None))
        }
    }
}

/// A compilation stage of a .wf file as text (`signorini emit FILE --stage STAGE --dim D`).
#[pyfunction]
#[pyo3(signature = (path, stage="scheme", dim=2))]
fn emit(path: std::path::PathBuf, stage: &str, dim: usize) -> PyResult<String> {
    let stage = signorini::cli::Stage::named(stage).map_err(|e| Failure::new_err(("option", e)))?;
    if !(1..=3).contains(&dim) {
        return Err(Failure::new_err(("option", format!("dim must be 1, 2 or 3, not {dim}"))));
    }
    // The warnings go where the command line's go: stderr.
    let (text, warnings) = signorini::cli::stage_text(&path, stage, dim).map_err(wf_failure)?;
    eprint!("{warnings}");
    Ok(text)
}

/// The library: schemes, contact laws, form files, problems and references, as JSON.
#[pyfunction]
fn catalogue() -> PyResult<String> {
    serde_json::to_string(&signorini::cli::list::catalogue()).map_err(|e| Failure::new_err(("stopped", e.to_string())))
}

/// `signorini verify --scheme ... ARGS`: the scheme's verification as JSON and its Markdown
/// report; written to `out` when given.
#[pyfunction]
#[pyo3(signature = (args, out=None))]
fn verify(py: Python<'_>, args: Vec<String>, out: Option<std::path::PathBuf>) -> PyResult<(String, String)> {
    let methods = signorini::cli::verify_methods(&args).map_err(|e| Failure::new_err(("option", e)))?;
    let v = py
        .detach(|| signorini::verify::scheme::run(&methods, &mut |_| {}))
        .map_err(|e| failure::stopped(py, e, None, None))?;
    if let Some(dir) = out {
        v.write(&dir).map_err(|e| failure::stopped(py, e, None, None))?;
    }
    let json = serde_json::to_string(&v).map_err(|e| Failure::new_err(("stopped", e.to_string())))?;
    Ok((json, v.markdown()))
}

#[pymodule]
fn _signorini(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("Failure", m.py().get_type::<Failure>())?;
    m.add_function(wrap_pyfunction!(_use_library, m)?)?;
    m.add_function(wrap_pyfunction!(run_options, m)?)?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(check, m)?)?;
    m.add_function(wrap_pyfunction!(emit, m)?)?;
    m.add_function(wrap_pyfunction!(catalogue, m)?)?;
    m.add_function(wrap_pyfunction!(verify, m)?)?;
    Ok(())
}
