//! `signorini list`: the library as its files describe it, gathered once as data
//! ([`catalogue`]: what the Python API returns) and printed as text ([`text`]).

use std::fmt::Write;

use serde::Serialize;

use crate::compiler::docs::first_sentence;
use crate::runtime::descriptors::ParamInfo;
use crate::runtime::library::Unit;

/// The library: its schemes, contact laws, other form files, problems and references.
#[derive(Serialize)]
pub struct Catalogue {
    pub schemes: Vec<Entry>,
    pub contact_laws: Vec<Entry>,
    pub forms: Vec<Entry>,
    pub problems: Vec<Entry>,
    pub references: Vec<Reference>,
}

/// A scheme, form file or problem: its name, first sentence of doc, file, what it uses or
/// provides (slots; a problem's `run` settings) and its params.
#[derive(Serialize)]
pub struct Entry {
    pub name: String,
    pub doc: String,
    pub file: String,
    /// A scheme's slots (`uses`), a form file's (`provides`), a problem's `run` settings.
    pub items: Vec<String>,
    pub params: Vec<Param>,
}

/// A param as its file declares it.
#[derive(Serialize)]
pub struct Param {
    pub name: String,
    /// The default and range as written (`0.05 in [0, 1/3]`).
    pub written: String,
    /// `file.wf:line`.
    pub declared: String,
    pub doc: String,
}

/// A reference a problem may name, with its arguments and functionals (name, doc).
#[derive(Serialize)]
pub struct Reference {
    pub name: String,
    pub doc: String,
    pub args: Vec<(String, String)>,
    pub functionals: Vec<(String, String)>,
}

fn param(p: &ParamInfo) -> Param {
    Param {
        name: p.name.to_string(),
        written: p.written.to_string(),
        declared: p.declared.to_string(),
        doc: first_sentence(&p.doc).to_string(),
    }
}

fn is_contact_law(u: &Unit) -> bool {
    u.forms.is_some_and(|f| f.slots.iter().any(|s| s.name == "contact"))
}

/// A form file's entry: its slots (functionals marked) and params (a contact law's own only).
fn form_entry(u: &Unit, name: &str, own_params_only: bool) -> Option<Entry> {
    let f = u.forms?;
    let items = f
        .slots
        .iter()
        .map(|s| if s.functional { format!("{} (functional)", s.name) } else { s.name.to_string() })
        .collect();
    let params = f.params.iter().filter(|p| !own_params_only || p.owner == u.name).map(param).collect();
    Some(Entry {
        name: name.to_string(),
        doc: first_sentence(u.doc).to_string(),
        file: u.file.to_string(),
        items,
        params,
    })
}

/// Every scheme, contact law, other form file, problem and reference of the library.
pub fn catalogue() -> Catalogue {
    let lib = crate::driver::library();
    let schemes = lib
        .iter()
        .flat_map(|u| {
            u.schemes.iter().map(|s| Entry {
                name: s.name.to_string(),
                doc: first_sentence(s.doc).to_string(),
                file: u.file.to_string(),
                items: s.desc.uses.iter().map(|u| u.name.to_string()).collect(),
                params: s.params.iter().map(param).collect(),
            })
        })
        .collect();
    let contact_laws = (lib.iter().filter(|u| is_contact_law(u)))
        .filter_map(|u| form_entry(u, u.name.strip_prefix("contact_").unwrap_or(u.name), true))
        .collect();
    let forms = (lib.iter().filter(|u| u.forms.is_some() && !is_contact_law(u)))
        .filter_map(|u| form_entry(u, u.name, false))
        .collect();
    let references = crate::references::ALL
        .iter()
        .map(|r| {
            let own = |v: Vec<(&str, &str)>| v.into_iter().map(|(a, d)| (a.to_string(), d.to_string())).collect();
            Reference {
                name: r.name().into(),
                doc: r.doc().into(),
                args: own(r.args()),
                functionals: own(r.functionals()),
            }
        })
        .collect();
    Catalogue { schemes, contact_laws, forms, problems: problems(), references }
}

/// The library's problems, with their params and the run's defaults, from their files; one
/// that does not check says why in its doc.
fn problems() -> Vec<Entry> {
    use crate::compiler::docs::{declaration, file, location, written};
    let mut out = Vec::new();
    for name in crate::problem::library_names() {
        let pf = match crate::problem::load(name) {
            Ok(pf) => pf,
            Err(e) => {
                let doc = format!("(does not check: {e})");
                out.push(Entry { name: name.into(), doc, file: String::new(), items: Vec::new(), params: Vec::new() });
                continue;
            }
        };
        let sources = &pf.program.unit.sources;
        let text = sources.text(pf.problem().span.file);
        let items =
            pf.problem().run.iter().map(|d| format!("{} = {}", d.name.name, sources.slice(d.value.span))).collect();
        let params = (pf.problem().params.iter())
            .map(|q| Param {
                name: q.name.name.clone(),
                written: written(sources, q.span),
                declared: location(sources, q.span),
                doc: first_sentence(&declaration(sources, q.span)).to_string(),
            })
            .collect();
        out.push(Entry {
            name: pf.name().into(),
            doc: first_sentence(&file(text)).into(),
            file: pf.file.clone(),
            items,
            params,
        });
    }
    out
}

fn params(out: &mut String, params: &[Param]) {
    for p in params {
        let doc = if p.doc.is_empty() { String::new() } else { format!("  {}", p.doc) };
        let _ = writeln!(out, "    {:<8} = {:<22} {:<22}{doc}", p.name, p.written, p.declared);
    }
}

/// A section's entries, each with its line of items (`uses`, `provides`, `run`) and params.
fn section(out: &mut String, title: &str, entries: &[Entry], items: &str) {
    out.push_str(title);
    for e in entries {
        let _ = writeln!(out, "  {:<16} {}", e.name, e.doc);
        if !e.file.is_empty() {
            let _ = writeln!(out, "    {items} {}   ({})", e.items.join(", "), e.file);
        }
        params(out, &e.params);
    }
}

/// Every scheme, contact law and other form file, with params, defaults, ranges and docs.
pub fn text() -> String {
    let c = catalogue();
    let mut out = String::new();
    section(&mut out, "Schemes (--scheme NAME, or a .wf file):\n", &c.schemes, "uses");
    section(&mut out, "\nContact laws (--contact NAME, or a .wf file):\n", &c.contact_laws, "provides");
    section(&mut out, "\nOther form files (--material NAME, --forms FILE.wf):\n", &c.forms, "provides");
    section(&mut out, "\nProblems (signorini run NAME, or a problem .wf file):\n", &c.problems, "run");
    out.push_str("\nReferences (`reference NAME` in a problem; their functionals read as NAME(u)):\n");
    for r in &c.references {
        let _ = writeln!(out, "  {:<16} {}", r.name, r.doc);
        for (a, doc) in &r.args {
            let _ = writeln!(out, "    {:<26} {doc}", format!("{a} = ..."));
        }
        for (f, doc) in &r.functionals {
            let _ = writeln!(out, "    {f:<26} {doc}");
        }
    }
    out.push_str("\nSet a param with --param NAME=VALUE (OWNER.NAME when two files declare NAME); a problem's params are also options: --NAME VALUE.\n");
    out
}
