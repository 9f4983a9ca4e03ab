//! Rust code for a checked unit: a module with `Params` (defaults and ranges from the file),
//! `Coefficients` (the case data), and one struct per form implementing the runtime's
//! `Form` and `FormKernel<D, N>` for D = 1, 2, 3 and every node count N.
//!
//! Code is built as text, parsed by syn (so a generator bug is an error, not bad code), and
//! formatted by prettyplease for people to read.

mod kernel;
mod library;
pub mod names;
mod scheme;

use std::fmt::Write;

use crate::ir::DimIr;
use crate::ir::graph::{Node, Sym};
use crate::program::Program;
use names::{camel, ident};

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

/// Generated code of a unit, as a syn file (one `pub mod`), from its IR for every dimension of
/// `ir::DIMS` (in order; `crate::Compiled::irs`).
pub fn generate(prog: &Program, irs: &[&DimIr], opts: &Options) -> Result<syn::File, String> {
    let text = module_text(prog, irs, opts);
    syn::parse_file(&text).map_err(|e| format!("internal error: generated code does not parse: {e}\n{text}"))
}

/// Generated code formatted for reading, with its line count in a header comment.
pub fn pretty(file: &syn::File, source_name: &str) -> String {
    let code = prettyplease::unparse(file);
    format!("// {} lines generated from {source_name}\n{code}", code.lines().count())
}

fn module_text(prog: &Program, irs: &[&DimIr], opts: &Options) -> String {
    let rt = &opts.runtime;
    let mut s = String::new();
    let _ = writeln!(s, "/// Kernels compiled from `{}` by signorini.", opts.source_name);
    let _ = writeln!(s, "pub mod {} {{", ident(&opts.module));
    s.push_str(
        "#![allow(non_snake_case, non_camel_case_types, unused_variables, unused_mut, unused_parens, unused_imports, clippy::all)]\n",
    );
    let _ = writeln!(
        s,
        "use {rt}::fem::kernel::{{CellCtx, Coef, FacetCtx, Form, FormKernel, FormMeta, FunctionalKernel, LocalMatrix, LocalVector, check_coef, heaviside}};"
    );
    let _ = writeln!(
        s,
        "use {rt}::descriptors::{{CoefInfo, ParamError, ParamInfo, ParamRange, SlotInfo, SlotUse, check_param}};"
    );
    let _ = writeln!(s, "use {rt}::library::{{Binding, FormUnit, LibraryError, Made, SchemeUnit, Unit, need_coef}};");
    let _ = writeln!(s, "use {rt}::fem::geometry;");
    if !prog.schemes.is_empty() {
        let _ =
            writeln!(s, "use {rt}::descriptors::{{Combination, InitialDesc, Level, SchemeDesc, StageDesc, TermDesc}};");
        let _ = writeln!(s, "use {rt}::time::scheme::TimeScheme;");
    }
    // Kernels for the forms declared in this file; imported files have modules of their own.
    let own: Vec<usize> = (0..prog.forms.len()).filter(|&i| prog.forms[i].span.file == prog.root).collect();
    if !own.is_empty() {
        s.push_str(&params_text(prog));
        s.push_str(&coefs_text(prog));
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
        let form = &prog.forms[fi];
        let sname = &struct_names[fi];
        let ir2 = &irs[1].forms[fi];
        let fields: Vec<String> = form.fields.iter().map(|f| format!("{:?}", f.name)).collect();
        let sig = format!(
            "{} {}({}{})",
            if form.test.is_some() { "form" } else { "functional" },
            form.name,
            form.fields.iter().map(|f| f.name.as_str()).collect::<Vec<_>>().join(", "),
            form.test.as_ref().map_or(String::new(), |t| format!("; {}", t.name))
        );
        let _ = writeln!(
            s,
            "/// `{sig}`{}",
            if ir2.linear { " (linear: its tangent does not depend on the fields)" } else { "" }
        );
        let _ = writeln!(s, "#[derive(Clone, Debug)]\npub struct {sname} {{ params: Params, coefs: Coefficients }}");
        let _ = writeln!(
            s,
            "impl {sname} {{ pub fn new(params: &Params, coefs: &Coefficients) -> Self {{ {sname} {{ params: *params, coefs: coefs.clone() }} }} }}"
        );
        let cell_degree = ir2
            .integrals
            .iter()
            .find(|i| i.cell)
            .map_or("None".to_string(), |i| format!("Some([{}, {}])", i.degree[0], i.degree[1]));
        let facets: Vec<String> = ir2
            .integrals
            .iter()
            .filter(|i| !i.cell)
            .map(|i| format!("({:?}, [{}, {}])", i.region, i.degree[0], i.degree[1]))
            .collect();
        let sites: Vec<String> = ir2
            .integrals
            .iter()
            .filter(|i| !i.cell)
            .map(|i| format!("{:?}", crate::docs::region_site(prog, &form.name, &i.region)))
            .collect();
        let _ = writeln!(
            s,
            "impl {sname} {{ pub const META: FormMeta = FormMeta {{ name: {:?}, fields: &[{}], test: {:?}, linear: {}, piecewise: {}, cell_degree: {cell_degree}, facets: &[{}], facet_sites: &[{}] }}; }}\nimpl Form for {sname} {{ fn meta(&self) -> &FormMeta {{ &Self::META }}\n{} }}",
            form.name,
            fields.join(", "),
            form.test.as_ref().map_or("", |t| t.name.as_str()),
            irs.iter().all(|ir| ir.forms[fi].linear),
            irs.iter().all(|ir| ir.forms[fi].integrals.iter().all(|i| i.tangents.iter().all(|t| t.piecewise))),
            facets.join(", "),
            sites.join(", "),
            time_dependence(prog, irs, fi)
        );
        for ir in irs {
            if form.test.is_some() {
                s.push_str(&kernel::form_impl(prog, ir, &ir.forms[fi], sname));
            } else {
                s.push_str(&kernel::functional_impl(prog, ir, &ir.forms[fi], sname));
            }
        }
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
    s.push_str("}\n");
    s
}

fn params_text(prog: &Program) -> String {
    let list: Vec<(String, f64, Option<crate::check::ParamRange>)> =
        prog.params.iter().map(|p| (p.name.clone(), p.default, p.range)).collect();
    let doc = "/// Parameters, with the defaults and ranges declared in the source. Values are range-checked\n/// when set.\n";
    params_struct("Params", doc, &list)
}

/// A struct of named f64 parameters with defaults, ranges, getters and checked setters.
fn params_struct(name: &str, doc: &str, params: &[(String, f64, Option<crate::check::ParamRange>)]) -> String {
    let mut s = String::new();
    let names: Vec<String> = params.iter().map(|p| format!("{:?}", p.0)).collect();
    s.push_str(doc);
    let _ = writeln!(s, "#[derive(Clone, Copy, Debug, PartialEq)]\npub struct {name} {{");
    for (p, _, _) in params {
        let _ = writeln!(s, "{}: f64,", ident(p));
    }
    s.push_str("}\n");
    let _ = writeln!(s, "impl Default for {name} {{ fn default() -> Self {{ {name} {{");
    for (p, default, _) in params {
        let _ = writeln!(s, "{}: {:?},", ident(p), default);
    }
    s.push_str("} } }\n");
    let _ = writeln!(s, "impl {name} {{");
    let _ = writeln!(
        s,
        "/// Parameter names, in declaration order.\npub const NAMES: &'static [&'static str] = &[{}];",
        names.join(", ")
    );
    s.push_str("/// Declared ranges, in declaration order.\npub const RANGES: &'static [ParamRange] = &[\n");
    for (p, _, range) in params {
        let r = range.unwrap_or(crate::check::ParamRange {
            lo: f64::NEG_INFINITY,
            lo_closed: false,
            hi: f64::INFINITY,
            hi_closed: false,
        });
        let _ = writeln!(
            s,
            "ParamRange {{ name: {p:?}, lo: {}, lo_closed: {}, hi: {}, hi_closed: {} }},",
            float(r.lo),
            r.lo_closed,
            float(r.hi),
            r.hi_closed
        );
    }
    s.push_str("];\n");
    for (p, default, range) in params {
        let range = range.map_or(String::new(), |r| format!(" in {}", r.describe()));
        let _ = writeln!(
            s,
            "/// `{p}` (default {default:?}{range}).\npub fn {}(&self) -> f64 {{ self.{} }}",
            ident(p),
            ident(p)
        );
    }
    s.push_str("/// The value of a parameter by name.\npub fn get(&self, name: &str) -> Option<f64> { match name {\n");
    for (p, _, _) in params {
        let _ = writeln!(s, "{p:?} => Some(self.{}),", ident(p));
    }
    s.push_str("_ => None } }\n");
    s.push_str("/// Sets a parameter by name, refusing unknown names and values outside the declared range.\n");
    if params.is_empty() {
        s.push_str("pub fn set(&mut self, name: &str, value: f64) -> Result<(), ParamError> { Err(ParamError::Unknown { name: name.to_string(), known: Self::NAMES }) }\n");
    } else {
        s.push_str("pub fn set(&mut self, name: &str, value: f64) -> Result<(), ParamError> { match name {\n");
        for (i, (p, _, _)) in params.iter().enumerate() {
            let _ = writeln!(s, "{p:?} => self.{} = check_param(&Self::RANGES[{i}], value)?,", ident(p));
        }
        s.push_str(
            "_ => return Err(ParamError::Unknown { name: name.to_string(), known: Self::NAMES }),\n} Ok(()) }\n",
        );
    }
    s.push_str("/// `set`, by value.\npub fn with(mut self, name: &str, value: f64) -> Result<Self, ParamError> { self.set(name, value)?; Ok(self) }\n");
    s.push_str("}\n");
    s
}

fn float(v: f64) -> String {
    if v == f64::INFINITY {
        "f64::INFINITY".into()
    } else if v == f64::NEG_INFINITY {
        "f64::NEG_INFINITY".into()
    } else {
        format!("{v:?}")
    }
}

/// `Form::time_dependent` of form `fi`: whether its integrands (in any dimension) read `t`, or
/// which coefs they read.
fn time_dependence(prog: &Program, irs: &[&DimIr], fi: usize) -> String {
    let mut time = false;
    let mut coefs: Vec<u16> = Vec::new();
    for ir in irs {
        let integrals = &ir.forms[fi].integrals;
        let roots = integrals.iter().flat_map(|i| i.f0.iter().chain(&i.f1).chain(&i.value).copied());
        for n in ir.graph.reachable(roots) {
            match ir.graph.node(n) {
                Node::Sym(Sym::Time) => time = true,
                Node::Sym(Sym::Coef { id, .. }) => coefs.push(id),
                _ => {}
            }
        }
    }
    if time {
        return String::new(); // the default: true
    }
    coefs.sort_unstable();
    coefs.dedup();
    let body = if coefs.is_empty() {
        "false".to_string()
    } else {
        coefs
            .iter()
            .map(|&id| format!("self.coefs.{}.time_dependent()", ident(&prog.coefs[id as usize].name)))
            .collect::<Vec<_>>()
            .join(" || ")
    };
    format!("fn time_dependent(&self) -> bool {{ {body} }}")
}

fn coefs_text(prog: &Program) -> String {
    let mut s = String::new();
    s.push_str("/// Case data (`coef` declarations): constants or functions of position and time.\n");
    s.push_str("#[derive(Clone, Debug");
    if prog.coefs.is_empty() {
        s.push_str(", Default");
    }
    s.push_str(")]\npub struct Coefficients {\n");
    for c in &prog.coefs {
        let _ = writeln!(s, "/// `coef {}: {}`\npub {}: Coef,", c.name, c.shape.name(), ident(&c.name));
    }
    s.push_str("}\n");
    s.push_str("impl Coefficients {\n/// Checks that every coef has the number of components its shape needs in dimension `dim`.\n");
    s.push_str("pub fn check(&self, dim: usize) -> Result<(), ::std::string::String> {\n");
    for c in &prog.coefs {
        let rank = c.shape.rank();
        let _ =
            writeln!(s, "check_coef({:?}, &self.{}, {rank}, dim).map_err(|e| e.to_string())?;", c.name, ident(&c.name));
    }
    s.push_str("Ok(()) }\n}\n");
    s
}
