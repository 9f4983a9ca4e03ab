//! Errors as the package raises them: one exception type, `Failure(kind, message,
//! diagnostics, partial)`, which python/signorini/ turns into its classes by `kind`: `wf` (a
//! .wf file that does not check; its located diagnostics), `option` (a bad argument),
//! `interrupted` (Ctrl-C; the rows up to there), `stopped` (a run that failed; the rows up to
//! there). The message is the command line's.

use pyo3::prelude::*;
use pyo3::types::PyDict;
use signorini::compiler::{Failure as WfFailure, Located};
use signorini::error::CaseError;

pyo3::create_exception!(_signorini, Failure, pyo3::exceptions::PyException, "A run, check or emit that failed.");

/// A diagnostic as a dict: severity, code, message, file, line, column, end_line, end_column,
/// label, notes, help, rendered.
pub fn diagnostic(py: Python<'_>, d: &Located) -> PyResult<Py<PyDict>> {
    let out = PyDict::new(py);
    out.set_item("severity", d.severity.word())?;
    out.set_item("code", d.code)?;
    out.set_item("message", &d.message)?;
    out.set_item("file", d.file.display().to_string())?;
    out.set_item("line", d.line)?;
    out.set_item("column", d.column)?;
    out.set_item("end_line", d.end_line)?;
    out.set_item("end_column", d.end_column)?;
    out.set_item("label", &d.label)?;
    out.set_item("notes", &d.notes)?;
    out.set_item("help", &d.help)?;
    out.set_item("rendered", &d.rendered)?;
    Ok(out.unbind())
}

/// Every diagnostic of a failure.
pub fn diagnostics(py: Python<'_>, f: &WfFailure) -> PyResult<Vec<Py<PyDict>>> {
    f.diagnostics.iter().map(|d| diagnostic(py, d)).collect()
}

/// An error that is not located in a .wf file (a mesh that cannot be read), as a diagnostic of
/// `file` with no code or position.
pub fn unlocated(py: Python<'_>, file: &std::path::Path, message: &str) -> PyResult<Py<PyDict>> {
    let out = PyDict::new(py);
    for (k, v) in [("severity", "error"), ("message", message), ("rendered", message)] {
        out.set_item(k, v)?;
    }
    out.set_item("file", file.display().to_string())?;
    for k in ["code", "line", "column", "end_line", "end_column", "help"] {
        out.set_item(k, py.None())?;
    }
    out.set_item("label", "")?;
    out.set_item("notes", Vec::<String>::new())?;
    Ok(out.unbind())
}

/// A compiler failure as `Failure("wf", ...)`; one without diagnostics (a file that cannot be
/// read) as `Failure("option", ...)`.
pub fn wf_failure(f: WfFailure) -> PyErr {
    if f.diagnostics.is_empty() {
        return Failure::new_err(("option", f.rendered.trim_end().trim_start_matches("error: ").to_string()));
    }
    Python::attach(|py| match diagnostics(py, &f) {
        Ok(list) => Failure::new_err(("wf", f.rendered.trim_end().to_string(), list)),
        Err(e) => e,
    })
}

/// Why a run stopped, with its rows up to there: an exception its watcher raised first (its
/// own, with the rows as `partial`), else `Failure` of the error's kind.
pub fn stopped(py: Python<'_>, error: CaseError, partial: Option<Py<PyDict>>, raised: Option<PyErr>) -> PyErr {
    let partial = partial.map_or_else(|| py.None(), |p| p.into_any());
    let interrupted = matches!(error, CaseError::Interrupted { .. });
    if let Some(e) = raised {
        // Ctrl-C: the run's own stop, raised as KeyboardInterrupt by the package; an exception
        // of the watcher: that exception, as Python would raise it.
        if !(interrupted && e.is_instance_of::<pyo3::exceptions::PyKeyboardInterrupt>(py)) {
            let _ = e.value(py).setattr("partial", partial);
            return e;
        }
    }
    let message = error.to_string();
    match error {
        CaseError::Wf(f) => match diagnostics(py, &f) {
            Ok(list) => Failure::new_err(("wf", message, list, partial)),
            Err(e) => e,
        },
        CaseError::Option(_) | CaseError::CaseFile(_) => {
            Failure::new_err(("option", message, Vec::<Py<PyDict>>::new(), partial))
        }
        CaseError::Interrupted { .. } => Failure::new_err(("interrupted", message, Vec::<Py<PyDict>>::new(), partial)),
        _ => Failure::new_err(("stopped", message, Vec::<Py<PyDict>>::new(), partial)),
    }
}
