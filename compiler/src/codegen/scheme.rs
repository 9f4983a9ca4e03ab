//! Rust for a compiled scheme: a parameter struct named after the scheme, and its
//! `TimeScheme` implementation: the static description of stages, terms and updates, and the
//! evaluation of every coefficient for a step size.

use std::fmt::Write;

use super::names::ident;
use crate::ir::graph::{Graph, Node, NodeId, Sym};
use crate::program::Program;
use crate::scheme::layout::{self, Combination, Layout, TermLayout};
use crate::scheme::{Quantity, SchemeIr};

pub fn scheme_text(prog: &Program, s: &SchemeIr, struct_name: &str) -> String {
    let params: Vec<(String, f64, Option<crate::check::ParamRange>)> =
        s.params.iter().map(|p| (p.name.clone(), p.default, p.range)).collect();
    let sig: Vec<String> = s.params.iter().map(|p| format!("{} = {}", p.name, p.default)).collect();
    let doc = format!("/// `scheme {}({})`: its parameters; it implements `TimeScheme`.\n", s.name, sig.join(", "));
    let mut out = super::params_struct(struct_name, &doc, &params);
    let layout = layout::layout(s);
    let desc = describe(prog, s, &layout);
    let _ = writeln!(out, "impl {struct_name} {{ pub const DESC: SchemeDesc = {desc}; }}");
    let _ = writeln!(out, "impl TimeScheme for {struct_name} {{");
    out.push_str("fn desc(&self) -> &SchemeDesc { &Self::DESC }\n");
    out.push_str("fn coefficients(&self, dt: f64, t: f64, out: &mut [f64]) {\n");
    out.push_str(&coefficient_code(&layout.coefficients, &s.graph, s));
    out.push_str("}\n}\n");
    out
}

/// Straight-line evaluation of the needed nodes, then the stores.
fn coefficient_code(order: &[NodeId], g: &Graph, s: &SchemeIr) -> String {
    let mut out = String::new();
    let nodes = g.reachable(order.iter().copied());
    let used_params: Vec<usize> =
        (0..s.params.len()).filter(|&i| nodes.iter().any(|&n| g.node(n) == Node::Sym(Sym::Param(i as u16)))).collect();
    for i in used_params {
        let _ = writeln!(out, "let {} = self.{};", ident(&s.params[i].name), ident(&s.params[i].name));
    }
    let name = |n: NodeId| -> String {
        match g.node(n) {
            Node::Const(b) => literal(f64::from_bits(b)),
            Node::Sym(Sym::Param(i)) => ident(&s.params[i as usize].name),
            Node::Sym(Sym::Dt) => "dt".into(),
            Node::Sym(Sym::Time) => "t".into(),
            Node::Sym(_) => "f64::NAN".into(),
            _ => format!("c{n}"),
        }
    };
    for &n in &nodes {
        let text = match g.node(n) {
            Node::Const(_) | Node::Sym(_) => continue,
            Node::Add(a, b) => format!("{} + {}", name(a), name(b)),
            Node::Mul(a, b) => format!("{} * {}", name(a), name(b)),
            Node::Div(a, b) => format!("{} / {}", name(a), name(b)),
            Node::Neg(a) => format!("-{}", name(a)),
            Node::Powi(a, k) => format!("{}.powi({k})", name(a)),
            Node::Powf(a, p) => format!("{}.powf({:?})", name(a), f64::from_bits(p)),
            Node::Sqrt(a) => format!("{}.sqrt()", name(a)),
            Node::Heaviside(a) => format!("heaviside({})", name(a)),
        };
        let _ = writeln!(out, "let c{n} = {text};");
    }
    for (k, &n) in order.iter().enumerate() {
        let _ = writeln!(out, "out[{k}] = {};", name(n));
    }
    out
}

fn literal(v: f64) -> String {
    if v.is_nan() {
        return "f64::NAN".into();
    }
    if v.is_infinite() {
        return if v > 0.0 { "f64::INFINITY".into() } else { "f64::NEG_INFINITY".into() };
    }
    let s = format!("{v:?}");
    let s = if s.contains(['.', 'e', 'E']) { s } else { format!("{s}.0") };
    if v < 0.0 { format!("({s})") } else { s }
}

fn level(q: Quantity) -> String {
    match q {
        Quantity::State(i) => format!("Level::State({i})"),
        Quantity::Stage { stage, index } => format!("Level::Stage({stage}, {index})"),
    }
}

fn combination(c: &Combination) -> String {
    let unknown = c.unknown.map_or("None".to_string(), |k| format!("Some({k})"));
    let known: Vec<String> = c.known.iter().map(|(q, k)| format!("({}, {k})", level(*q))).collect();
    format!("Combination {{ unknown: {unknown}, known: &[{}] }}", known.join(", "))
}

fn terms(ts: &[TermLayout]) -> String {
    let list: Vec<String> = ts
        .iter()
        .map(|t| {
            let args: Vec<String> = t.args.iter().map(combination).collect();
            format!(
                "TermDesc {{ coef: {}, form: {:?}, args: &[{}], time: {} }}",
                t.coef,
                t.slot,
                args.join(", "),
                t.time
            )
        })
        .collect();
    format!("&[{}]", list.join(", "))
}

fn describe(prog: &Program, s: &SchemeIr, layout: &Layout) -> String {
    let uses: Vec<String> = s
        .slots
        .iter()
        .map(|u| {
            format!(
                "SlotUse {{ name: {:?}, fields: {}, declared: {:?} }}",
                u.name,
                u.fields,
                crate::docs::location_col(&prog.sources, u.span)
            )
        })
        .collect();
    let states: Vec<String> = s.states.iter().map(|x| format!("{x:?}")).collect();
    let initial = match &layout.initial {
        Some((state, ts)) => format!("Some(InitialDesc {{ state: {state}, terms: {} }})", terms(ts)),
        None => "None".into(),
    };
    let stages: Vec<String> = layout
        .stages
        .iter()
        .map(|st| {
            let quantities: Vec<String> = st.quantities.iter().map(|q| format!("{q:?}")).collect();
            let values: Vec<String> = st.values.iter().map(combination).collect();
            format!(
                "StageDesc {{ name: {:?}, time: {}, quantities: &[{}], values: &[{}], terms: {} }}",
                st.name,
                st.time,
                quantities.join(", "),
                values.join(", "),
                terms(&st.terms)
            )
        })
        .collect();
    let updates: Vec<String> = s.updates.iter().map(|q| level(*q)).collect();
    format!(
        "SchemeDesc {{ name: {:?}, uses: &[{}], states: &[{}], initial: {initial}, stages: &[{}], updates: &[{}], coefficients: {} }}",
        s.name,
        uses.join(", "),
        states.join(", "),
        stages.join(", "),
        updates.join(", "),
        layout.coefficients.len()
    )
}
