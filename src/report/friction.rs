//! Section 6 of the report: friction. The problems of forms/library.toml's `[[report.friction]]`
//! (their expectations and figures: the rolling disc against the rigid disc, the sheared
//! block's reaction against Coulomb's bound and Tresca's threshold), and the problem of
//! `[report.friction_table]` with every library scheme × frictional law (a law that provides
//! `friction_work`).

use std::fmt::Write;
use std::path::Path;

use super::table::{Failures, Table};
use crate::driver::Methods;
use crate::error::CaseError;
use crate::numbers::readable;
use crate::problem::run::{Options, run};
use crate::problem::summary::Expectation;

pub fn section(out: &Path, progress: &mut dyn FnMut(&str)) -> Result<String, CaseError> {
    let settings = &crate::settings::get().report;
    let dir = out.join("friction");
    let table = &settings.friction_table;
    let mut problems: Vec<&str> = settings.friction.iter().map(|f| f.problem.as_str()).collect();
    problems.push(&table.problem);
    problems.dedup();
    let runs: Vec<String> = problems.iter().map(|p| format!("`run {p}`")).collect();
    let mut md = format!("## 6. Friction ({})\n\n", runs.join(", "));
    md.push_str("What the problems expect of themselves (`expect` lines: the rigid-body limits, Coulomb's bound; docs/problems.md, Friction), run at their defaults with the law shown:\n\n");
    let mut expected = Table::new(&["run", "contact", "key", "value", "expected", "difference", "within", "met"]);
    let mut figures = String::new();
    for (k, f) in settings.friction.iter().enumerate() {
        progress(&format!("friction: {}", f.label));
        let sub = format!("{}_{k}", f.problem);
        let mut opts = Options::new(&f.problem);
        let mut methods = Methods::default();
        if !f.contact.is_empty() {
            methods.contact = f.contact.clone();
            opts.chosen.contact = true;
        }
        for (name, value) in &f.params {
            methods = methods.set(name, *value);
        }
        opts.methods = methods;
        opts.out = Some(dir.join(&sub));
        let s = run(&opts)?.summary;
        let contact = s.get("contact").and_then(|v| v.as_str()).unwrap_or_default().to_string();
        for x in s.field::<Vec<Expectation>>("expected")?.into_iter().filter(|x| x.applies) {
            let [value, expected_value, difference, within] = x.shown();
            let met = if x.met { "yes" } else { "**no**" };
            expected.row([
                f.label.clone(),
                contact.clone(),
                x.key,
                value,
                expected_value,
                difference,
                within,
                met.into(),
            ]);
        }
        let _ = writeln!(figures, "![{}](friction/{sub}/{}.png)\n", f.label, f.problem);
    }
    md.push_str(&expected.markdown());
    md.push('\n');
    md.push_str(&figures);
    let params: Vec<String> = table.params.iter().map(|(k, v)| format!("{k} = {v}")).collect();
    let _ = write!(
        md,
        "`{}` ({}{}) with every library scheme and frictional law at their defaults (the keys: docs/problems.md, Friction; the balances: docs/mathematics.md §3), Newton's iterations, and the time per step.\n\n",
        table.problem,
        params.join(", "),
        table.t_start.map_or(String::new(), |t| format!(", from t = {}", readable(t)))
    );
    let mut header = vec!["scheme", "law"];
    header.extend(table.keys.iter().map(String::as_str));
    header.extend(["Newton iterations (total)", "ms per step"]);
    let mut rows = Table::new(&header);
    let failures = Failures::new(out);
    for scheme in crate::driver::all_schemes() {
        for law in crate::driver::frictional_contact_names() {
            progress(&format!("friction: {} {scheme} {law}", table.problem));
            let mut methods = Methods { scheme: scheme.into(), contact: law.into(), ..Methods::default() };
            for (name, value) in &table.params {
                methods = methods.set(name, *value);
            }
            let mut opts = Options::new(&table.problem);
            opts.chosen.scheme = true;
            opts.chosen.contact = true;
            opts.t_start = table.t_start;
            let mut row = vec![scheme.to_string()];
            match super::past_the_guard(methods, |methods| run(&Options { methods, ..opts.clone() })) {
                Ok((r, note)) => {
                    let s = r.summary;
                    let get = |k: &str| s.number(k).unwrap_or(f64::NAN);
                    row.push(format!("{law}{}", note.map_or(String::new(), |n| format!(" ({n})"))));
                    row.extend(table.keys.iter().map(|k| format!("{:.4e}", get(k))));
                    row.extend([get("newton_total").to_string(), format!("{:.2}", 1e3 * get("seconds_per_step"))]);
                }
                Err(e) => {
                    row.push(law.to_string());
                    row.push(failures.cell(&format!("friction_{scheme}_{law}"), &e.to_string()));
                    row.resize(header.len(), String::new());
                }
            }
            rows.row_vec(row);
        }
    }
    md.push_str(&rows.markdown());
    md.push('\n');
    Ok(md)
}
