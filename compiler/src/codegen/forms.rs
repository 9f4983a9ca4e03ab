//! The struct of a form of the file: its params and coefs, `META` (arguments, linearity,
//! quadrature degrees), `Form` (with when it depends on time), and its kernels in every
//! dimension.

use std::fmt::Write;

use super::kernel;
use super::names::{case_allowance, ident, locals};
use crate::ir::DimIr;
use crate::ir::graph::{Node, Sym};
use crate::program::Program;

/// The items of form `fi`, a struct named `sname`.
pub fn form_items(prog: &Program, irs: &[&DimIr], fi: usize, sname: &str) -> String {
    let mut s = String::new();
    let form = &prog.forms[fi];
    let ir2 = &irs[1].forms[fi];
    let fields: Vec<String> = form.fields.iter().map(|f| format!("Borrowed({:?})", f.name)).collect();
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
    let _ = writeln!(
        s,
        "#[derive(Clone, Debug)]\npub struct {sname} {{\n/// The file's params.\npub params: Params,\n/// The case data.\npub coefs: Coefficients,\n}}"
    );
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
        .map(|i| format!("(Borrowed({:?}), [{}, {}])", i.region, i.degree[0], i.degree[1]))
        .collect();
    let sites: Vec<String> = ir2
        .integrals
        .iter()
        .filter(|i| !i.cell)
        .map(|i| format!("Borrowed({:?})", crate::docs::region_site(prog, &form.name, &i.region)))
        .collect();
    let _ = writeln!(
        s,
        "impl {sname} {{ pub const META: FormMeta = FormMeta {{ name: Borrowed({:?}), fields: Borrowed(&[{}]), test: Borrowed({:?}), linear: {}, piecewise: {}, previous: {}, cell_degree: {cell_degree}, facets: Borrowed(&[{}]), facet_sites: Borrowed(&[{}]), tangential: {} }}; }}\nimpl Form for {sname} {{ fn meta(&self) -> &FormMeta {{ &Self::META }}\n{} }}",
        form.name,
        fields.join(", "),
        form.test.as_ref().map_or("", |t| t.name.as_str()),
        irs.iter().all(|ir| ir.forms[fi].linear),
        irs.iter().all(|ir| ir.forms[fi].integrals.iter().all(|i| i.tangents.iter().all(|t| t.piecewise))),
        irs.iter().any(|ir| ir.forms[fi].previous),
        facets.join(", "),
        sites.join(", "),
        crate::docs::tangential_site(prog, &form.name).map_or("None".to_string(), |s| format!("Some(Borrowed({s:?}))")),
        time_dependence(prog, irs, fi)
    );
    for ir in irs {
        let text = if form.test.is_some() {
            kernel::form_impl(prog, ir, &ir.forms[fi], sname)
        } else {
            kernel::functional_impl(prog, ir, &ir.forms[fi], sname)
        };
        s.push_str(case_allowance(locals(&text)));
        s.push_str(&text);
    }
    s
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
