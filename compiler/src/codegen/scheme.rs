//! Rust for a compiled scheme: a parameter struct named after the scheme, and its
//! `TimeScheme` implementation: the static description of stages, terms and updates, and the
//! evaluation of every coefficient for a step size.

use std::collections::HashMap;
use std::fmt::Write;

use super::names::ident;
use crate::ir::graph::{Graph, Node, NodeId, Sym};
use crate::scheme::{Affine, Quantity, SchemeIr, Term};

pub fn scheme_text(s: &SchemeIr, struct_name: &str) -> String {
    let params: Vec<(String, f64, Option<crate::check::ParamRange>)> =
        s.params.iter().map(|p| (p.name.clone(), p.default, p.range)).collect();
    let sig: Vec<String> = s.params.iter().map(|p| format!("{} = {}", p.name, p.default)).collect();
    let doc = format!("/// `scheme {}({})`: its parameters; it implements `TimeScheme`.\n", s.name, sig.join(", "));
    let mut out = super::params_struct(struct_name, &doc, &params);
    let mut coefs = Coefficients::default();
    let desc = describe(s, &mut coefs);
    let _ = writeln!(out, "impl TimeScheme for {struct_name} {{");
    let _ = writeln!(out, "const DESC: SchemeDesc = {desc};");
    out.push_str("fn coefficients(&self, dt: f64, t: f64, out: &mut [f64]) {\n");
    out.push_str(&coefs.code(&s.graph, s));
    out.push_str("}\n}\n");
    out
}

/// The coefficient nodes a description refers to, numbered in first-use order.
#[derive(Default)]
struct Coefficients {
    index: HashMap<NodeId, usize>,
    order: Vec<NodeId>,
}

impl Coefficients {
    fn of(&mut self, n: NodeId) -> usize {
        *self.index.entry(n).or_insert_with(|| {
            self.order.push(n);
            self.order.len() - 1
        })
    }

    /// Straight-line evaluation of the needed nodes, then the stores.
    fn code(&self, g: &Graph, s: &SchemeIr) -> String {
        let mut out = String::new();
        let nodes = g.reachable(self.order.iter().copied());
        let used_params: Vec<usize> = (0..s.params.len())
            .filter(|&i| nodes.iter().any(|&n| g.node(n) == Node::Sym(Sym::Param(i as u16))))
            .collect();
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
                Node::Sqrt(a) => format!("{}.sqrt()", name(a)),
                Node::Heaviside(a) => format!("heaviside({})", name(a)),
            };
            let _ = writeln!(out, "let c{n} = {text};");
        }
        for (k, &n) in self.order.iter().enumerate() {
            let _ = writeln!(out, "out[{k}] = {};", name(n));
        }
        out
    }
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

fn combination(g: &Graph, a: &Affine, c: &mut Coefficients) -> String {
    let unknown = if g.is_zero(a.unknown) { "None".to_string() } else { format!("Some({})", c.of(a.unknown)) };
    let known: Vec<String> = a.known.iter().map(|(q, k)| format!("({}, {})", level(*q), c.of(*k))).collect();
    format!("Combination {{ unknown: {unknown}, known: &[{}] }}", known.join(", "))
}

fn terms(g: &Graph, ts: &[Term], c: &mut Coefficients) -> String {
    let list: Vec<String> = ts
        .iter()
        .map(|t| {
            let coef = c.of(t.coef);
            let args: Vec<String> = t.args.iter().map(|a| combination(g, a, c)).collect();
            let time = c.of(t.time);
            format!("TermDesc {{ coef: {coef}, form: {:?}, args: &[{}], time: {time} }}", t.form, args.join(", "))
        })
        .collect();
    format!("&[{}]", list.join(", "))
}

fn describe(s: &SchemeIr, c: &mut Coefficients) -> String {
    let g = &s.graph;
    let states: Vec<String> = s.states.iter().map(|x| format!("{x:?}")).collect();
    let initial = match &s.initial {
        Some(i) => format!("Some(InitialDesc {{ state: {}, terms: {} }})", i.state, terms(g, &i.terms, c)),
        None => "None".into(),
    };
    let stages: Vec<String> = s
        .stages
        .iter()
        .map(|st| {
            let time = c.of(st.time);
            let quantities: Vec<String> = st.quantities.iter().map(|q| format!("{q:?}")).collect();
            let values: Vec<String> = st.values.iter().map(|v| combination(g, v, c)).collect();
            format!(
                "StageDesc {{ name: {:?}, time: {time}, quantities: &[{}], values: &[{}], terms: {} }}",
                st.name,
                quantities.join(", "),
                values.join(", "),
                terms(g, &st.terms, c)
            )
        })
        .collect();
    let updates: Vec<String> = s.updates.iter().map(|q| level(*q)).collect();
    format!(
        "SchemeDesc {{ name: {:?}, states: &[{}], initial: {initial}, stages: &[{}], updates: &[{}], coefficients: {} }}",
        s.name,
        states.join(", "),
        stages.join(", "),
        updates.join(", "),
        c.order.len()
    )
}
