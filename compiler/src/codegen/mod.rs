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
    let items = items(prog, irs, opts);
    let text = module_text(&items, opts)?;
    syn::parse_file(&text).map_err(|e| format!("internal error: generated code does not parse: {e}\n{text}"))
}

/// Generated code formatted for reading, with its line count in a header comment.
pub fn pretty(file: &syn::File, source_name: &str) -> String {
    let code = prettyplease::unparse(file);
    format!("// {} lines generated from {source_name}\n{code}", code.lines().count())
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
fn items(prog: &Program, irs: &[&DimIr], opts: &Options) -> String {
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
    for sch in &prog.schemes {
        let mut name = camel(&sch.name);
        while taken.contains(&name) || struct_names.contains(&name) {
            name.push_str("Scheme");
        }
        struct_names.push(name.clone());
        s.push_str(&scheme::scheme_text(prog, sch, &name));
        let (items, unit) = library::scheme_unit(prog, sch, &name);
        s.push_str(&items);
        scheme_units.push(unit);
    }
    let forms_unit = if own.is_empty() {
        "None".to_string()
    } else {
        let own_names: Vec<(usize, &str)> = own.iter().map(|&fi| (fi, struct_names[fi].as_str())).collect();
        s.push_str(&library::forms_items(prog, &own_names));
        "Some(FormUnit { params: PARAMS, coefs: COEFS, slots: SLOTS, make })".to_string()
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
    s
}
