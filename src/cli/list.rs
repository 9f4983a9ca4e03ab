//! `signorini list`: the library as its files describe it.

use std::fmt::Write;

use crate::compiler::docs::first_sentence;
use crate::runtime::descriptors::ParamInfo;
use crate::runtime::library::Unit;

fn params(out: &mut String, params: &[ParamInfo]) {
    for p in params {
        let doc = if p.doc.is_empty() { String::new() } else { format!("  {}", first_sentence(&p.doc)) };
        let _ = writeln!(out, "    {:<8} = {:<22} {:<22}{doc}", p.name, p.written, p.declared);
    }
}

fn is_contact_law(u: &Unit) -> bool {
    u.forms.is_some_and(|f| f.slots.iter().any(|s| s.name == "contact"))
}

/// Every scheme, contact law and other form file, with params, defaults, ranges and docs.
pub fn text() -> String {
    let lib = crate::driver::library();
    let mut out = String::from("Schemes (--scheme NAME, or a .wf file):\n");
    for u in lib {
        for s in u.schemes {
            let slots: Vec<&str> = s.desc.uses.iter().map(|u| &*u.name).collect();
            let _ = writeln!(out, "  {:<16} {}", s.name, first_sentence(s.doc));
            let _ = writeln!(out, "    uses {}   ({})", slots.join(", "), u.file);
            params(&mut out, s.params);
        }
    }
    out.push_str("\nContact laws (--contact NAME, or a .wf file):\n");
    for u in lib.iter().filter(|u| is_contact_law(u)) {
        let short = u.name.strip_prefix("contact_").unwrap_or(u.name);
        let _ = writeln!(out, "  {:<16} {}", short, first_sentence(u.doc));
        print_forms(&mut out, u, true);
    }
    out.push_str("\nOther form files (--material NAME, --forms FILE.wf):\n");
    for u in lib.iter().filter(|u| u.forms.is_some() && !is_contact_law(u)) {
        let _ = writeln!(out, "  {:<16} {}", u.name, first_sentence(u.doc));
        print_forms(&mut out, u, false);
    }
    out.push_str("\nProblems (signorini run NAME, or a problem .wf file):\n");
    problems(&mut out);
    out.push_str("\nReferences (`reference NAME` in a problem; their functionals read as NAME(u)):\n");
    for r in crate::references::ALL {
        let _ = writeln!(out, "  {:<16} {}", r.name(), r.doc());
        for (a, doc) in r.args() {
            let _ = writeln!(out, "    {:<26} {doc}", format!("{a} = ..."));
        }
        for (f, doc) in r.functionals() {
            let _ = writeln!(out, "    {f:<26} {doc}");
        }
    }
    out.push_str("\nSet a param with --param NAME=VALUE (OWNER.NAME when two files declare NAME); a problem's params are also options: --NAME VALUE.\n");
    out
}

/// The library's problems, with their params and the run's defaults, from their files.
fn problems(out: &mut String) {
    use crate::compiler::docs::{declaration, file, location, written};
    for name in crate::problem::library_names() {
        let pf = match crate::problem::load(name) {
            Ok(pf) => pf,
            Err(e) => {
                let _ = writeln!(out, "  {name:<16} (does not check: {e})");
                continue;
            }
        };
        let sources = &pf.program.unit.sources;
        let text = sources.text(pf.problem().span.file);
        let _ = writeln!(out, "  {:<16} {}", pf.name(), first_sentence(&file(text)));
        let run: Vec<String> =
            pf.problem().run.iter().map(|d| format!("{} = {}", d.name.name, sources.slice(d.value.span))).collect();
        let _ = writeln!(out, "    run {}   ({})", run.join(", "), pf.file);
        for q in &pf.problem().params {
            let doc = declaration(sources, q.span);
            let doc = if doc.is_empty() { String::new() } else { format!("  {}", first_sentence(&doc)) };
            let at = location(sources, q.span);
            let _ = writeln!(out, "    {:<8} = {:<22} {:<22}{doc}", q.name.name, written(sources, q.span), at);
        }
    }
}

fn print_forms(out: &mut String, u: &Unit, own_params_only: bool) {
    let Some(f) = u.forms else { return };
    let slots: Vec<String> = f
        .slots
        .iter()
        .map(|s| if s.functional { format!("{} (functional)", s.name) } else { s.name.to_string() })
        .collect();
    let _ = writeln!(out, "    provides {}   ({})", slots.join(", "), u.file);
    let shown: Vec<ParamInfo> = f.params.iter().filter(|p| !own_params_only || p.owner == u.name).cloned().collect();
    params(out, &shown);
}
