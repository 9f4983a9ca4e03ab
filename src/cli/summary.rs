//! What the command line prints of a run: its one-line summary (scheme, law, the params set,
//! the problem's own summary keys, Newton, time), the lines of the `run --all` table, and which
//! files ran interpreted.

use std::process::ExitCode;

pub(super) fn finish(result: Result<crate::problem::run::Run, crate::error::CaseError>) -> ExitCode {
    match result {
        Ok(r) => {
            let s = &r.summary;
            if let Some(files) = s.get("interpreted").and_then(|v| v.as_array()) {
                let files: Vec<String> = files.iter().filter_map(|f| f.as_str().map(str::to_string)).collect();
                interpreted_note(&files);
            }
            if let Some(files) = s.get("compiled_for_material").and_then(|v| v.as_array()) {
                for pair in files.iter().filter_map(|p| p.as_array()) {
                    let [file, material] = [0, 1].map(|k| pair.get(k).and_then(|v| v.as_str()).unwrap_or_default());
                    eprintln!(
                        "note: {file} was compiled at run time with the material {material} (its `import material = ...`): interpreted, same results as compiled"
                    );
                }
            }
            let text =
                |k: &str| s.get(k).map_or(String::new(), |v| v.as_str().map_or_else(|| v.to_string(), str::to_string));
            // The problem's own summary keys; null where a reducer found nothing.
            let own: Vec<String> = s
                .own
                .iter()
                .map(|k| format!("{k} {}", s.number(k).map_or("none".to_string(), crate::numbers::readable)))
                .collect();
            let set: Vec<String> = s
                .get("params")
                .and_then(|p| p.as_object())
                .map(|p| {
                    p.iter()
                        .filter(|(_, v)| v.get("source").and_then(|x| x.as_str()) != Some("file"))
                        .map(|(n, v)| format!("{n} = {}", v.get("value").map_or(String::new(), ToString::to_string)))
                        .collect()
                })
                .unwrap_or_default();
            let set = if set.is_empty() { String::new() } else { format!(" ({})", set.join(", ")) };
            println!(
                "{}: {} {}{set}, {} dofs, {} steps: {}; Newton {} (max {}), {:.2} s ({:.3} ms/step){}{}",
                text("case"),
                text("scheme"),
                text("contact"),
                text("dofs"),
                text("steps"),
                own.join(", "),
                text("newton_total"),
                text("newton_max"),
                s.number("wall_seconds").unwrap_or(f64::NAN),
                1e3 * s.number("seconds_per_step").unwrap_or(f64::NAN),
                pairs(s),
                s.number("peak_memory_bytes").map_or(String::new(), |b| format!(", peak memory {:.0} MB", b / 1e6))
            );
            expectations(s);
            ExitCode::SUCCESS
        }
        Err(e) => {
            super::print_error(e);
            ExitCode::FAILURE
        }
    }
}

/// One line per `expect` of the problem: the key against its expected value.
fn expectations(s: &crate::problem::outputs::Summary) {
    let Ok(list) = s.field::<Vec<crate::problem::summary::Expectation>>("expected") else { return };
    for x in list {
        if !x.applies {
            println!("  expect {}: not checked, its `when` does not hold on this run", x.key);
            continue;
        }
        let [value, expected, difference, within] = x.shown();
        let met = if x.met { "met" } else { "NOT MET" };
        println!("  expect {} = {expected} (is {value}, difference {difference}, within {within}): {met}", x.key);
    }
}

/// The contact pairs' cost, if the run has pairs: their assembly's share of the run's time,
/// and the search's.
fn pairs(s: &crate::problem::outputs::Summary) -> String {
    let Some(p) = s.get("pair_search") else { return String::new() };
    let number = |k: &str| p.get(k).and_then(|v| v.as_f64()).unwrap_or(f64::NAN);
    format!(
        ", pairs {:.0} % of it (search {:.2} s, {} indexes, {} queries)",
        100.0 * number("share_of_run"),
        number("search_seconds"),
        number("builds"),
        number("queries")
    )
}

/// Says which files ran interpreted, and how to compile them.
fn interpreted_note(files: &[String]) {
    for f in files {
        eprintln!(
            "note: {f} ran interpreted (compiled at run time, same results as compiled); to compile it, copy it into forms/ (a scheme: forms/schemes/) and rebuild"
        );
    }
}

/// The header of the `run --all` table (printed), and the problem's own summary keys it shows.
pub(super) fn all_header(s: &crate::problem::outputs::Summary) -> Vec<String> {
    let keys = s.own.clone();
    let names: Vec<String> = keys.iter().map(|k| format!("{k:>w$}", w = k.len().max(11))).collect();
    println!("{:<15} {:<16} {:<13} {} {:>7} {:>4}", "scheme", "contact", "mass", names.join(" "), "Newton", "max");
    keys
}

/// One line of the `run --all` table: the run's values of `keys`, and its Newton iterations.
pub(super) fn all_row(
    s: &crate::problem::outputs::Summary,
    keys: &[String],
    scheme: &str,
    contact: &str,
    mass: &str,
) -> String {
    let values: Vec<String> = keys
        .iter()
        .map(|k| {
            let w = k.len().max(11);
            format!("{:>w$}", s.number(k).map_or("—".to_string(), crate::numbers::readable))
        })
        .collect();
    let count = |k: &str| s.get(k).and_then(|v| v.as_u64()).unwrap_or(0);
    format!(
        "{scheme:<15} {contact:<16} {mass:<13} {} {:>7} {:>4}",
        values.join(" "),
        count("newton_total"),
        count("newton_max")
    )
}
