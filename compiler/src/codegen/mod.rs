//! Rust code for a checked unit: a module with `Params` (defaults and ranges from the file),
//! `Coefficients` (the case data), and one struct per form implementing the runtime's
//! `Form` and `FormKernel<D, N>` for D = 1, 2, 3 and every node count N; a struct per scheme
//! implementing `TimeScheme`; and the unit's registry entry.
//!
//! Code is built as text, parsed by syn (so a generator bug is an error, not bad code), and
//! formatted by prettyplease for people to read. It is written to compile without a warning
//! (rustc's and clippy's): it imports what it uses, and keeps the file's names as written
//! (`#[allow(non_snake_case)]` on the items where one of them is not snake case).
//!
//! Modules: `emit` writes expressions (kernels and scheme coefficients alike), `kernel` the
//! element kernels, `forms` the form structs, `params` the parameter and coefficient structs,
//! `scheme` the schemes, `library` the registry entry, `descriptors` the runtime's descriptions
//! of them, `names` the identifiers.

mod descriptors;
mod emit;
mod forms;
mod kernel;
mod library;
pub mod names;
mod params;
mod scheme;

use std::collections::HashSet;
use std::fmt::Write;

use crate::ir::DimIr;
use crate::program::Program;
use names::{camel, case_allowance, ident};

/// Where the generated code finds the runtime (the facade re-exports it).
pub const DEFAULT_RUNTIME: &str = "::signorini::runtime";

pub struct Options {
    /// Path of the runtime crate in the generated code.
    pub runtime: String,
    /// Name of the generated module.
    pub module: String,
    /// Shown in the module's documentation.
    pub source_name: String,
}

/// What the generated code may import, by module of the runtime.
const IMPORTS: &[(&str, &[&str])] = &[
    (
        "descriptors",
        &[
            "Borrowed",
            "CoefInfo",
            "Combination",
            "InitialDesc",
            "Level",
            "ParamError",
            "ParamInfo",
            "ParamRange",
            "SchemeDesc",
            "SlotInfo",
            "SlotUse",
            "StageDesc",
            "TermDesc",
            "check_param",
        ],
    ),
    (
        "fem::kernel",
        &[
            "CellCtx",
            "Coef",
            "FacetCtx",
            "Form",
            "FormKernel",
            "FormMeta",
            "FunctionalKernel",
            "LocalMatrix",
            "LocalVector",
            "check_coef",
            "heaviside",
        ],
    ),
    ("library", &["Binding", "FormUnit", "LibraryError", "Made", "SchemeUnit", "Unit", "need_coef"]),
    ("time::scheme", &["TimeScheme"]),
];

/// Generated code of a unit, as a syn file (one `pub mod`), from its IR for every dimension of
/// `ir::DIMS` (in order; `crate::Compiled::irs`).
pub fn generate(prog: &Program, irs: &[&DimIr], opts: &Options) -> Result<syn::File, String> {
    module(prog, irs, opts).map(|(file, _)| file)
}

/// Generated code formatted for reading: what each scheme coefficient is for above it, and the
/// line count in a header comment.
pub fn pretty(prog: &Program, irs: &[&DimIr], opts: &Options) -> Result<String, String> {
    let (file, uses) = module(prog, irs, opts)?;
    let code = annotate(&prettyplease::unparse(&file), &uses);
    Ok(format!("// {} lines generated from {}\n{code}", code.lines().count(), opts.source_name))
}

/// Per scheme struct, what each of its coefficients is for (`Layout::uses`).
type CoefficientUses = Vec<(String, Vec<Vec<String>>)>;

fn module(prog: &Program, irs: &[&DimIr], opts: &Options) -> Result<(syn::File, CoefficientUses), String> {
    if irs.iter().any(|ir| ir.forms.iter().any(|f| f.pair)) {
        return Err(format!(
            "{} reads `opposite`: a contact pair's law is interpreted at run time, not compiled (keep it in forms/pairs/)",
            opts.source_name
        ));
    }
    let (items, uses) = items(prog, irs, opts);
    let text = module_text(&items, opts)?;
    let file =
        syn::parse_file(&text).map_err(|e| format!("internal error: generated code does not parse: {e}\n{text}"))?;
    Ok((file, uses))
}

/// Formatted code with `// uses` comments above each `out[k] = ...;` of each scheme's
/// `fn coefficients` (prettyplease drops comments, so they go into its output): a statement
/// starts at the body's indentation, its wrapped lines deeper.
fn annotate(code: &str, uses: &CoefficientUses) -> String {
    let mut out = String::with_capacity(code.len() + code.len() / 4);
    let mut scheme: Option<&[Vec<String>]> = None;
    // The indentation of the `fn coefficients` being annotated, and how many `out[k]` so far.
    let mut body: Option<(usize, usize)> = None;
    for line in code.lines() {
        let text = line.trim_start();
        let indent = line.len() - text.len();
        if let Some(name) = text.strip_prefix("impl TimeScheme for ").and_then(|r| r.strip_suffix(" {")) {
            scheme = uses.iter().find(|(s, _)| s == name).map(|(_, u)| u.as_slice());
        } else if let Some((at, seen)) = &mut body {
            if indent == *at && text == "}" {
                debug_assert_eq!(Some(*seen), scheme.map(<[_]>::len), "every coefficient annotated");
                body = None;
                scheme = None;
            } else if let Some(k) = (indent == *at + 4).then(|| assignment(text)).flatten()
                && let Some(lines) = scheme.and_then(|u| u.get(k))
            {
                *seen += 1;
                for l in lines.iter().flat_map(|l| wrapped(l, COMMENT_WIDTH.saturating_sub(indent + 3))) {
                    let _ = writeln!(out, "{}// {l}", &line[..indent]);
                }
            }
        } else if scheme.is_some() && text.starts_with("fn coefficients(") {
            body = Some((indent, 0));
        }
        out.push_str(line);
        out.push('\n');
    }
    out
}

/// Where comment lines end, about where prettyplease ends code lines.
const COMMENT_WIDTH: usize = 100;

/// `text` in lines of at most `width` characters (but for a longer word), each clause (up to a
/// `; `) on a line of its own when it does not fit on the current one; continued lines are
/// indented by two.
fn wrapped(text: &str, width: usize) -> Vec<String> {
    let len = |s: &str| s.chars().count();
    let mut lines = vec![String::new()];
    for clause in text.split_inclusive("; ").map(str::trim_end) {
        let line = lines.last().expect("one line");
        if !line.trim().is_empty() && len(line) + 1 + len(clause) > width {
            lines.push("  ".into());
        }
        for word in clause.split(' ') {
            let line = lines.last_mut().expect("one line");
            if line.trim().is_empty() {
                line.push_str(word);
            } else if len(line) + 1 + len(word) <= width {
                line.push(' ');
                line.push_str(word);
            } else {
                lines.push(format!("  {word}"));
            }
        }
    }
    lines
}

/// `k` of a statement `out[k] = ...`.
fn assignment(text: &str) -> Option<usize> {
    let (k, rest) = text.strip_prefix("out[")?.split_once(']')?;
    rest.starts_with(" =").then(|| k.parse().ok()).flatten()
}

/// The module around its items, with the imports they use.
fn module_text(items: &str, opts: &Options) -> Result<String, String> {
    let tokens: proc_macro2::TokenStream =
        items.parse().map_err(|e| format!("internal error: generated code does not parse: {e}\n{items}"))?;
    let mut used = HashSet::new();
    identifiers(tokens, &mut used);
    let rt = &opts.runtime;
    let module = ident(&opts.module);
    let mut s = String::new();
    let _ = writeln!(s, "/// Kernels compiled from `{}` by signorini.", opts.source_name);
    s.push_str(case_allowance(std::iter::once(module.as_str())));
    let _ = writeln!(s, "pub mod {module} {{");
    for (path, names) in IMPORTS {
        let names: Vec<&str> = names.iter().copied().filter(|n| used.contains(*n)).collect();
        match names.as_slice() {
            [] => {}
            [one] => {
                let _ = writeln!(s, "use {rt}::{path}::{one};");
            }
            _ => {
                let _ = writeln!(s, "use {rt}::{path}::{{{}}};", names.join(", "));
            }
        }
    }
    if used.contains("geometry") {
        let _ = writeln!(s, "use {rt}::fem::geometry;");
    }
    s.push_str(items);
    s.push_str("}\n");
    Ok(s)
}

/// The identifiers of a token stream (not those inside literals: strings, docs).
fn identifiers(tokens: proc_macro2::TokenStream, out: &mut HashSet<String>) {
    for t in tokens {
        match t {
            proc_macro2::TokenTree::Ident(i) => {
                out.insert(i.to_string());
            }
            proc_macro2::TokenTree::Group(g) => identifiers(g.stream(), out),
            _ => {}
        }
    }
}

/// The module's items: params and coefs and a struct per form of the file (imported files
/// have modules of their own), a struct per scheme, and `UNIT`.
fn items(prog: &Program, irs: &[&DimIr], opts: &Options) -> (String, CoefficientUses) {
    let mut s = String::new();
    let own: Vec<usize> = (0..prog.forms.len()).filter(|&i| prog.forms[i].span.file == prog.root).collect();
    if !own.is_empty() {
        s.push_str(&params::params_text(prog));
        s.push_str(&params::coefs_text(prog));
    }
    let taken: Vec<String> = vec!["Params".into(), "Coefficients".into()];
    let mut struct_names: Vec<String> = Vec::new();
    for form in &prog.forms {
        let mut name = camel(&form.name);
        while taken.contains(&name) || struct_names.contains(&name) {
            name.push_str("Form");
        }
        struct_names.push(name);
    }
    for &fi in &own {
        s.push_str(&forms::form_items(prog, irs, fi, &struct_names[fi]));
    }
    let mut scheme_units = Vec::new();
    let mut uses = Vec::new();
    for sch in &prog.schemes {
        let mut name = camel(&sch.name);
        while taken.contains(&name) || struct_names.contains(&name) {
            name.push_str("Scheme");
        }
        struct_names.push(name.clone());
        let (items, coefficients) = scheme::scheme_text(prog, sch, &name);
        s.push_str(&items);
        uses.push((name.clone(), coefficients));
        let (items, unit) = library::scheme_unit(prog, sch, &name);
        s.push_str(&items);
        scheme_units.push(unit);
    }
    let forms_unit = if own.is_empty() {
        "None".to_string()
    } else {
        let own_names: Vec<(usize, &str)> = own.iter().map(|&fi| (fi, struct_names[fi].as_str())).collect();
        s.push_str(&library::forms_items(prog, &own_names));
        let roles: Vec<String> = prog.roles.iter().map(|r| format!("({:?}, {:?})", r.name, r.read)).collect();
        format!("Some(FormUnit {{ params: PARAMS, coefs: COEFS, slots: SLOTS, roles: &[{}], make }})", roles.join(", "))
    };
    let _ = writeln!(
        s,
        "/// What `{}` tells the runtime about itself: params, coefs, slots, schemes.\npub const UNIT: Unit = Unit {{ name: {:?}, file: {:?}, doc: {:?}, forms: {forms_unit}, schemes: &[{}] }};",
        opts.source_name,
        opts.module,
        opts.source_name,
        crate::docs::file(prog.sources.text(prog.root)),
        scheme_units.join(", ")
    );
    (s, uses)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Only `out[k]` statements of a scheme's `fn coefficients` get their comment, above
    /// the first line of a statement prettyplease wrapped.
    #[test]
    fn coefficient_comments_go_above_their_statements() {
        let code = "\
impl TimeScheme for Euler {
    fn coefficients(&self, dt: f64, t: f64, out: &mut [f64]) {
        let tmp1 = dt
            * 2.0;
        out[0] = 1.0;
        out[1] = tmp1 * tmp1 * tmp1 * tmp1 * tmp1 * tmp1 * tmp1 * tmp1 * tmp1 * tmp1 * tmp1
            + out[0];
    }
    fn other(&self, out: &mut [f64]) {
        out[0] = 2.0;
    }
}
impl Other for Euler {
    fn coefficients(&self, out: &mut [f64]) {
        out[0] = 3.0;
    }
}
";
        let uses = vec![("Euler".to_string(), vec![vec!["stage `s`: weight of `mass(a')`".to_string()], vec![]])];
        let want = "\
impl TimeScheme for Euler {
    fn coefficients(&self, dt: f64, t: f64, out: &mut [f64]) {
        let tmp1 = dt
            * 2.0;
        // stage `s`: weight of `mass(a')`
        out[0] = 1.0;
        out[1] = tmp1 * tmp1 * tmp1 * tmp1 * tmp1 * tmp1 * tmp1 * tmp1 * tmp1 * tmp1 * tmp1
            + out[0];
    }
    fn other(&self, out: &mut [f64]) {
        out[0] = 2.0;
    }
}
impl Other for Euler {
    fn coefficients(&self, out: &mut [f64]) {
        out[0] = 3.0;
    }
}
";
        assert_eq!(annotate(code, &uses), want);
    }

    #[test]
    fn long_comments_break_between_clauses_then_words() {
        let text = "stage `s`: coefficient of `u` in `u'`; coefficient of `v` in `v'`; weight of `mass(a')`";
        assert_eq!(
            wrapped(text, 50),
            ["stage `s`: coefficient of `u` in `u'`;", "  coefficient of `v` in `v'`; weight of `mass(a')`"]
        );
        assert_eq!(
            wrapped(text, 30),
            ["stage `s`: coefficient of `u`", "  in `u'`;", "  coefficient of `v` in `v'`;", "  weight of `mass(a')`"]
        );
        assert_eq!(wrapped("short; enough", 50), ["short; enough"]);
    }
}
