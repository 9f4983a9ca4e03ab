//! Rust for a compiled scheme: a parameter struct named after the scheme, and its
//! `TimeScheme` implementation: its description (the layout's, printed by `descriptors`), and
//! the evaluation of every coefficient for a step size (written by `emit`, as the kernels are).
//! What each coefficient is for (`Layout::uses`) goes back to the caller: prettyplease drops
//! comments, so they are written into the formatted text (`super::annotate`).

use std::collections::HashMap;
use std::fmt::Write;

use super::emit::Emitter;
use super::names::{Namer, case_allowance, ident};
use super::params::{ParamDecl, params_struct};
use crate::ir::graph::{Node, NodeId, Sym};
use crate::program::Program;
use crate::scheme::SchemeIr;
use crate::scheme::layout;

/// The scheme's items, and per coefficient the lines saying what it is for.
pub fn scheme_text(prog: &Program, s: &SchemeIr, struct_name: &str) -> (String, Vec<Vec<String>>) {
    let params: Vec<ParamDecl> = s
        .params
        .iter()
        .map(|p| ParamDecl::new(&prog.sources, &p.name, p.default, p.range, p.range_expr.as_ref(), p.span))
        .collect();
    let sig: Vec<String> = params.iter().map(|p| format!("{} = {}", p.name, p.written)).collect();
    let doc = format!("/// `scheme {}({})`: its parameters; it implements `TimeScheme`.\n", s.name, sig.join(", "));
    let mut out = params_struct(struct_name, &doc, &params);
    let layout = layout::layout(s, &prog.sources);
    let desc = super::descriptors::scheme(&layout.desc);
    let _ = writeln!(out, "impl {struct_name} {{ pub const DESC: SchemeDesc = {desc}; }}");
    let coefficients = coefficients_fn(&layout.coefficients, s);
    out.push_str(case_allowance(super::names::locals(&coefficients)));
    let _ = writeln!(out, "impl TimeScheme for {struct_name} {{");
    out.push_str("fn desc(&self) -> &SchemeDesc { &Self::DESC }\n");
    out.push_str(&coefficients);
    out.push_str("}\n");
    (out, layout.uses)
}

/// `fn coefficients`: every coefficient of the layout, `out[k]`, by the one emitter: the
/// scheme's params and `let`s by their names, shared subexpressions once, the rest inline.
fn coefficients_fn(order: &[NodeId], s: &SchemeIr) -> String {
    let g = &s.graph;
    let nodes = g.reachable(order.iter().copied());
    let mut namer = Namer::new(&["self", "dt", "t", "out", "std", "f64", "heaviside"]);
    let mut leaf: HashMap<Sym, String> = HashMap::new();
    let mut body = String::new();
    for &n in &nodes {
        let Node::Sym(sym) = g.node(n) else { continue };
        let name = match sym {
            Sym::Param(i) => {
                let p = &s.params[i as usize].name;
                let local = namer.fresh(p);
                let _ = writeln!(body, "let {local} = self.{};", ident(p));
                local
            }
            Sym::Dt => "dt".into(),
            Sym::Time => "t".into(),
            _ => "f64::NAN".into(),
        };
        leaf.insert(sym, name);
    }
    let emitter = Emitter::new(g, &leaf);
    let lines = emitter.bind(order, |_| false, false, &mut namer);
    body.push_str(&lines.invariant);
    for (k, &n) in order.iter().enumerate() {
        let _ = writeln!(body, "out[{k}] = {};", emitter.value(n, &lines).0);
    }
    let words = super::names::words(&body);
    let arg = |name: &str| if words.contains(name) { name.to_string() } else { format!("_{name}") };
    format!("fn coefficients(&self, {}: f64, {}: f64, out: &mut [f64]) {{\n{body}}}\n", arg("dt"), arg("t"))
}
