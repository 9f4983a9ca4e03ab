//! What a problem's run writes: its summary (the shared keys and the problem's own, in order),
//! series.csv with the shown columns, stages.csv for multi-stage schemes, summary.json, and the
//! problem's figure of its `plot` lines.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::Serialize;

use super::{ProblemFile, ProblemParam};
use crate::driver::{FilesInUse, ParamValue};
use crate::error::CaseError;

/// A finished run: its summary and rows (every column, shown or not).
pub struct Run {
    /// summary.json's keys in order: the shared ones, with the problem's own after `steps`.
    pub summary: Summary,
    /// Every column's name, in row order.
    pub columns: Vec<String>,
    /// (time, values) per row.
    pub rows: Vec<(f64, Vec<f64>)>,
    /// The `contact` slot's switch at each of its quadrature points, per row (the active set).
    pub switches: Vec<Vec<bool>>,
    /// Multi-stage schemes: (stage name, time, values) at every intermediate stage.
    pub stages: Vec<(String, f64, Vec<f64>)>,
    /// Newton's report (each stage's residuals) of every step this process took: none for the
    /// initial row, nor for the steps before a resume.
    pub newton: Vec<crate::runtime::time::stepper::StepReport>,
    /// The last state and the mesh, when the options keep them (`keep_fields`).
    pub fields: Option<Box<Fields>>,
}

/// A run's last state, with its mesh: u and v by node, `mesh.dim()` values each.
pub struct Fields {
    pub t: f64,
    pub u: Vec<f64>,
    /// None for a static problem, and a scheme without a velocity state.
    pub v: Option<Vec<f64>>,
    pub mesh: crate::runtime::fem::mesh::Mesh,
}

impl Run {
    /// Where each named column is in a row's values (typed views of a problem's rows).
    pub fn indices<S: AsRef<str>>(&self, names: &[S], problem: &str) -> Result<Vec<usize>, CaseError> {
        names
            .iter()
            .map(|n| {
                let n = n.as_ref();
                self.columns
                    .iter()
                    .position(|c| c == n)
                    .ok_or_else(|| CaseError::Option(format!("the {problem} problem file has no column `{n}`")))
            })
            .collect()
    }

    /// A column's values over the rows.
    pub fn column(&self, name: &str) -> Option<Vec<f64>> {
        let i = self.columns.iter().position(|c| c == name)?;
        Some(self.rows.iter().map(|r| r.1[i]).collect())
    }
}

/// A run's summary: keys in order.
#[derive(Default)]
pub struct Summary {
    pub keys: Vec<(String, serde_json::Value)>,
    /// The problem's own keys (`summary NAME = ...`).
    pub own: Vec<String>,
}

impl Summary {
    pub fn get(&self, key: &str) -> Option<&serde_json::Value> {
        self.keys.iter().find(|(k, _)| k == key).map(|(_, v)| v)
    }

    /// A number of the summary (`None` when absent or null).
    pub fn number(&self, key: &str) -> Option<f64> {
        self.get(key)?.as_f64()
    }

    /// A key of the summary, as its type (null when absent).
    pub fn field<T: serde::de::DeserializeOwned>(&self, k: &str) -> Result<T, CaseError> {
        let v = self.get(k).cloned().unwrap_or(serde_json::Value::Null);
        serde_json::from_value(v).map_err(|e| CaseError::Option(format!("the summary's `{k}`: {e}")))
    }
}

impl Serialize for Summary {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut map = s.serialize_map(Some(self.keys.len()))?;
        for (k, v) in &self.keys {
            map.serialize_entry(k, v)?;
        }
        map.end()
    }
}

/// A value as JSON (non-finite numbers become null, as serde_json writes them).
pub(super) fn json<T: Serialize + ?Sized>(v: &T) -> serde_json::Value {
    serde_json::to_value(v).unwrap_or(serde_json::Value::Null)
}

/// Every param in effect: the problem's, the scheme's and the form files', and each body's own
/// (`BODY.name`).
pub(super) fn all_params(
    in_use: &FilesInUse,
    params: &[ProblemParam],
    pf: &ProblemFile,
) -> BTreeMap<String, ParamValue> {
    let mut out = in_use.forms.params.values();
    out.extend(in_use.forms.body_values());
    out.extend(in_use.forms.pair_values());
    for q in params {
        let declared = pf.problem().params.iter().find(|d| d.name.name == q.name).map(|d| d.span);
        let line = declared.map_or(0, |s| pf.program.unit.sources.line_col(s.file, s.start).0);
        out.insert(
            format!("{}.{}", pf.name(), q.name),
            ParamValue { value: q.value, source: q.source, declared: format!("{}:{line}", pf.file) },
        );
    }
    out
}

pub(super) fn write_outputs(dir: &Path, pf: &ProblemFile, run: &Run, shown: &[bool]) -> Result<(), CaseError> {
    let header: Vec<&str> = std::iter::once("t")
        .chain(run.columns.iter().zip(shown).filter(|(_, s)| **s).map(|(c, _)| c.as_str()))
        .collect();
    let header = header.join(",");
    // Each value as the shortest text that reads back to the same double; the time as its
    // level is written (`numbers::time`).
    let line = |t: f64, values: &[f64]| {
        let mut s = crate::numbers::time(t);
        for (v, _) in values.iter().zip(shown).filter(|(_, s)| **s) {
            s.push(',');
            s.push_str(&crate::numbers::shortest(*v));
        }
        s.push('\n');
        s
    };
    let mut csv = format!("{header}\n");
    run.rows.iter().for_each(|(t, v)| csv.push_str(&line(*t, v)));
    let err = |path: PathBuf| move |source| CaseError::Write { path: path.display().to_string(), source };
    crate::output::write_atomic(&dir.join("series.csv"), csv.as_bytes()).map_err(err(dir.join("series.csv")))?;
    crate::output::write_json(&dir.join("summary.json"), &run.summary).map_err(err(dir.join("summary.json")))?;
    if !run.stages.is_empty() {
        let mut csv = format!("stage,{header}\n");
        for (stage, t, values) in &run.stages {
            csv.push_str(&format!("{stage},{}", line(*t, values)));
        }
        crate::output::write_atomic(&dir.join("stages.csv"), csv.as_bytes()).map_err(err(dir.join("stages.csv")))?;
    }
    let plots = &pf.problem().plots;
    if plots.is_empty() {
        return Ok(());
    }
    use crate::plot::Curve;
    let panels: Vec<(&str, &str, Vec<Curve>)> = plots
        .iter()
        .map(|pl| {
            let curves = pl
                .columns
                .iter()
                .filter_map(|c| {
                    let i = run.columns.iter().position(|n| *n == c.name)?;
                    let points = run.rows.iter().map(|(t, v)| (*t, v[i])).collect();
                    Some(Curve { label: c.name.as_str(), points, dashed: false })
                })
                .collect();
            (pl.title.as_str(), pl.title.as_str(), curves)
        })
        .collect();
    crate::plot::panels(&dir.join(format!("{}.png", pf.name())), "t", &panels)
        .map_err(|e| CaseError::Write { path: dir.display().to_string(), source: std::io::Error::other(e) })
}
