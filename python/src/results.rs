//! A run's results as Python values: numpy arrays of the rows, stages and final fields, the
//! mesh, and the summary as JSON text (python/signorini/ reads it with `json.loads`).

use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use signorini::problem::run::{Fields, Run, Seen};
use signorini::runtime::fem::mesh::Mesh;

/// A flat vector as a numpy array of `cols` columns (one dimension when `cols` is None).
fn array<'py, T: numpy::Element>(py: Python<'py>, values: Vec<T>, cols: Option<usize>) -> PyResult<Bound<'py, PyAny>> {
    let rows = cols.map(|c| values.len().checked_div(c).unwrap_or(0));
    let flat = PyArray1::from_vec(py, values);
    match (cols, rows) {
        (Some(c), Some(r)) => Ok(flat.reshape([r, c])?.into_any()),
        _ => Ok(flat.into_any()),
    }
}

/// A row seen during the run: `{"t": t, column: value, ...}`.
pub fn row(py: Python<'_>, seen: &Seen) -> PyResult<Py<PyDict>> {
    let out = PyDict::new(py);
    out.set_item("t", seen.t)?;
    for (c, v) in seen.columns.iter().zip(seen.values) {
        out.set_item(c, *v)?;
    }
    out.set_item("t_end", seen.t_end)?;
    Ok(out.unbind())
}

/// A finished (or stopped) run: `columns`, `t` and `values` (rows × columns), `stages` (names,
/// t, values), `summary` (JSON), `fields` (t, u, v by node) and `mesh`.
pub fn run(py: Python<'_>, r: &Run) -> PyResult<Py<PyDict>> {
    let out = PyDict::new(py);
    let width = r.columns.len();
    out.set_item("columns", &r.columns)?;
    out.set_item("t", array(py, r.rows.iter().map(|(t, _)| *t).collect(), None)?)?;
    out.set_item("values", array(py, r.rows.iter().flat_map(|(_, v)| v.iter().copied()).collect(), Some(width))?)?;
    let stages = PyDict::new(py);
    stages.set_item("stage", r.stages.iter().map(|(s, _, _)| s.as_str()).collect::<Vec<_>>())?;
    stages.set_item("t", array(py, r.stages.iter().map(|(_, t, _)| *t).collect(), None)?)?;
    stages.set_item(
        "values",
        array(py, r.stages.iter().flat_map(|(_, _, v)| v.iter().copied()).collect(), Some(width))?,
    )?;
    out.set_item("stages", stages)?;
    let summary =
        serde_json::to_string(&r.summary).map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))?;
    out.set_item("summary", summary)?;
    if let Some(f) = &r.fields {
        out.set_item("fields", fields(py, f)?)?;
    }
    Ok(out.unbind())
}

fn fields<'py>(py: Python<'py>, f: &Fields) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    let dim = f.mesh.dim();
    out.set_item("t", f.t)?;
    out.set_item("u", array(py, f.u.clone(), Some(dim))?)?;
    match &f.v {
        Some(v) => out.set_item("v", array(py, v.clone(), Some(dim))?)?,
        None => out.set_item("v", py.None())?,
    }
    out.set_item("mesh", mesh(py, &f.mesh)?)?;
    Ok(out)
}

/// The mesh: `kind` (Gmsh's element name), `coords` (nodes × dim), `cells` (cells × nodes per
/// cell, Gmsh's node order), `regions` (name → facets × nodes per facet), `cell_groups` (name
/// → cells) and `bodies` (name → cells).
fn mesh<'py>(py: Python<'py>, m: &Mesh) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    let per_cell = m.kind.nodes();
    out.set_item("kind", m.kind.name())?;
    out.set_item("coords", array(py, m.coords.clone(), Some(m.dim()))?)?;
    let cells: Vec<i64> = m.cells.iter().map(|&n| i64::from(n)).collect();
    out.set_item("cells", array(py, cells, Some(per_cell))?)?;
    let regions = PyDict::new(py);
    for r in &m.regions {
        let mut nodes = Vec::new();
        let mut width = 0;
        for f in &r.facets {
            let local = m.kind.facet_nodes(f.local as usize);
            width = local.len();
            let cell = &m.cells[f.cell as usize * per_cell..][..per_cell];
            nodes.extend(local.iter().map(|&i| i64::from(cell[i])));
        }
        regions.set_item(&r.name, array(py, nodes, Some(width))?)?;
    }
    out.set_item("regions", regions)?;
    let groups = PyDict::new(py);
    for (name, cells) in &m.cell_groups {
        groups.set_item(name, array(py, cells.iter().map(|&c| i64::from(c)).collect(), None)?)?;
    }
    out.set_item("cell_groups", groups)?;
    let bodies = PyDict::new(py);
    for b in &m.bodies {
        let cells: Vec<i64> = (0..b.cells.len()).filter(|&c| b.cells[c]).map(|c| c as i64).collect();
        bodies.set_item(&b.name, array(py, cells, None)?)?;
    }
    out.set_item("bodies", bodies)?;
    Ok(out)
}
