//! (e) What the library's problems expect of themselves: every problem with `expect KEY =
//! VALUE within TOL` lines (a rigid-body limit, a friction bound), run at its defaults, its keys
//! against the values the mathematics gives. The problems are found in the library, not named
//! here.

use serde::Serialize;

use crate::error::CaseError;
use crate::problem::summary::Expectation;

/// One expectation of one problem's run.
#[derive(Clone, Debug, Serialize)]
pub struct LimitRow {
    pub problem: String,
    pub scheme: String,
    pub contact: String,
    pub expectation: Expectation,
}

/// Runs every library problem that declares expectations, at its defaults.
pub fn expectations(progress: &mut dyn FnMut(&str)) -> Result<Vec<LimitRow>, CaseError> {
    let mut rows = Vec::new();
    for name in crate::problem::library_names() {
        if crate::problem::load(name)?.problem().expects.is_empty() {
            continue;
        }
        progress(&format!("expectations: {name}"));
        let run = crate::problem::run::run(&crate::problem::options::Options::new(name))?;
        let text = |k: &str| run.summary.get(k).and_then(|v| v.as_str()).unwrap_or_default().to_string();
        for expectation in run.summary.field::<Vec<Expectation>>("expected")?.into_iter().filter(|x| x.applies) {
            rows.push(LimitRow {
                problem: name.to_string(),
                scheme: text("scheme"),
                contact: text("contact"),
                expectation,
            });
        }
    }
    Ok(rows)
}

/// The table, as Markdown.
pub fn markdown(rows: &[LimitRow]) -> String {
    let mut md = String::from(
        "### (e) Limits the problems expect\n\nEach library problem with `expect KEY = VALUE within TOL` lines, run at its defaults (`signorini run NAME` prints the same lines): the friction problems against the rigid body they approach and Coulomb's bound (docs/problems.md, Friction).\n\n| problem | scheme | contact | key | value | expected | difference | within | met |\n|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let x = &r.expectation;
        let [value, expected, difference, within] = x.shown();
        let met = if x.met { "yes" } else { "**no**" };
        md.push_str(&format!(
            "| {} | {} | {} | {} | {value} | {expected} | {difference} | {within} | {met} |\n",
            r.problem, r.scheme, r.contact, x.key
        ));
    }
    md
}
