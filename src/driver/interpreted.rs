//! Scheme files given by path, run at once: compiled at run time to the description the macro
//! prints (`compiler::scheme::layout`), their coefficients evaluated from the expression DAG.

use std::path::Path;
use std::sync::Arc;

use crate::compiler::ir::eval::Program;
use crate::compiler::ir::graph::{Graph, NodeId};
use crate::compiler::scheme::layout::{Layout, layout};
use crate::compiler::scheme::{SchemeIr, scheme_leaf};
use crate::compiler::{check_path, describe, docs};
use crate::driver::sources::LibraryLoader;
use crate::error::CaseError;
use crate::runtime::descriptors::{ParamInfo, SchemeDesc, check_param};
use crate::runtime::library::LibraryError;
use crate::runtime::time::scheme::TimeScheme;

/// A scheme compiled at run time.
pub struct Interpreted {
    pub file: String,
    pub desc: Arc<SchemeDesc>,
    pub params: Vec<ParamInfo>,
    pub doc: String,
    graph: Graph,
    coefficients: Vec<NodeId>,
}

/// Its instance with param values: the coefficients as one program of the IR evaluator.
struct Running {
    desc: Arc<SchemeDesc>,
    program: Program,
    values: Vec<f64>,
}

impl TimeScheme for Running {
    fn desc(&self) -> &SchemeDesc {
        &self.desc
    }
    fn coefficients(&self, dt: f64, t: f64, out: &mut [f64]) {
        let leaves: Vec<f64> = self.program.syms().iter().map(|&s| scheme_leaf(s, &self.values, dt, t)).collect();
        self.program.run(&leaves, &mut Vec::new(), out);
    }
}

/// Compiles the scheme file at `path` (its only scheme, or the one named `name`).
pub fn load(path: &Path, name: Option<&str>) -> Result<Interpreted, CaseError> {
    let (prog, warnings) = check_path(path, &LibraryLoader).map_err(CaseError::Wf)?;
    if !warnings.is_empty() {
        eprint!("{warnings}");
    }
    let s: &SchemeIr = match (name, prog.schemes.as_slice()) {
        (_, []) => return Err(CaseError::CaseFile(format!("{} declares no scheme", path.display()))),
        (None, [one]) => one,
        (Some(n), all) => all.iter().find(|s| s.name == n).ok_or_else(|| {
            let names: Vec<&str> = all.iter().map(|s| s.name.as_str()).collect();
            CaseError::CaseFile(format!("{} has no scheme `{n}` (it has: {})", path.display(), names.join(", ")))
        })?,
        (None, all) => {
            let names: Vec<&str> = all.iter().map(|s| s.name.as_str()).collect();
            return Err(CaseError::CaseFile(format!(
                "{} declares several schemes ({}): name one",
                path.display(),
                names.join(", ")
            )));
        }
    };
    let Layout { desc, coefficients, .. } = layout(s, &prog.sources);
    Ok(Interpreted {
        file: path.display().to_string(),
        desc: Arc::new(desc),
        params: describe::scheme_params(&prog, s),
        doc: docs::declaration(&prog.sources, s.span),
        graph: s.graph.clone(),
        coefficients,
    })
}

impl Interpreted {
    /// An instance with param values in declaration order (range-checked).
    pub fn instance(&self, values: &[f64]) -> Result<Box<dyn TimeScheme>, LibraryError> {
        for (p, v) in self.params.iter().zip(values) {
            check_param(&p.name, &p.range, *v)?;
        }
        Ok(Box::new(Running {
            desc: Arc::clone(&self.desc),
            program: Program::new(&self.graph, &self.coefficients),
            values: values.to_vec(),
        }))
    }
}
