//! Readable dump of a compiled scheme (`signorini emit --stage scheme`): each stage's new
//! quantities in terms of the unknown and the known levels, and its residual terms.

use std::fmt::Write;

use super::{Affine, Quantity, SchemeIr, Term};
use crate::ir::graph::{Graph, Node, NodeId, Sym};

pub fn print(s: &SchemeIr) -> String {
    let mut out = String::new();
    let params: Vec<String> = s.params.iter().map(|p| format!("{} = {}", p.name, p.default)).collect();
    let _ = writeln!(out, "scheme {}({})", s.name, params.join(", "));
    let slots: Vec<String> = s
        .slots
        .iter()
        .map(|u| if u.fields == 0 { format!("{}(t)", u.name) } else { format!("{}/{}", u.name, u.fields) })
        .collect();
    let _ = writeln!(out, "  uses {}", slots.join(", "));
    let _ = writeln!(out, "  states {}", s.states.join(", "));
    let names = |q: Quantity| match q {
        Quantity::State(i) => s.states[i].clone(),
        Quantity::Stage { stage, index } => s.stages.get(stage).map_or("?".into(), |st| st.quantities[index].clone()),
    };
    if let Some(init) = &s.initial {
        let _ = writeln!(out, "  initial: solve for {}", s.states[init.state]);
        for t in &init.terms {
            let _ = writeln!(out, "    {}", term(&s.graph, t, &s.states[init.state], &names));
        }
    }
    for st in &s.stages {
        let _ = writeln!(out, "  stage {} at {}  (unknown {})", st.name, scalar(&s.graph, st.time), st.quantities[0]);
        for (q, v) in st.quantities.iter().zip(&st.values).skip(1) {
            let _ = writeln!(out, "    {q} = {}", affine(&s.graph, v, &st.quantities[0], &names));
        }
        let _ = writeln!(out, "    residual:");
        for t in &st.terms {
            let _ = writeln!(out, "      {}", term(&s.graph, t, &st.quantities[0], &names));
        }
    }
    let updates: Vec<String> =
        s.updates.iter().enumerate().map(|(i, q)| format!("{} ← {}", s.states[i], names(*q))).collect();
    let _ = writeln!(out, "  update {}", updates.join(", "));
    out
}

fn term(g: &Graph, t: &Term, unknown: &str, names: &dyn Fn(Quantity) -> String) -> String {
    let args: Vec<String> = if t.args.is_empty() {
        vec![format!("t = {}", scalar(g, t.time))]
    } else {
        t.args.iter().map(|a| affine(g, a, unknown, names)).collect()
    };
    let (coef, prec) = infix(g, t.coef);
    let coef = if prec < 2 { format!("({coef})") } else { coef };
    format!("{coef} · {}({})", t.form, args.join("; "))
}

fn affine(g: &Graph, a: &Affine, unknown: &str, names: &dyn Fn(Quantity) -> String) -> String {
    let mut parts = Vec::new();
    if !g.is_zero(a.unknown) {
        parts.push(format!("{}·{unknown}", factor(g, a.unknown)));
    }
    for (q, c) in &a.known {
        parts.push(format!("{}·{}", factor(g, *c), names(*q)));
    }
    if parts.is_empty() { "0".into() } else { parts.join(" + ") }
}

/// A coefficient in front of a level: parenthesised unless a product or an atom.
fn factor(g: &Graph, id: NodeId) -> String {
    let (t, p) = infix(g, id);
    if p < 2 { format!("({t})") } else { t }
}

/// A scalar coefficient as an infix expression, parenthesised by precedence.
pub fn scalar(g: &Graph, id: NodeId) -> String {
    infix(g, id).0
}

/// Text and precedence (1 sum, 2 product, 3 unary, 4 atom).
fn infix(g: &Graph, id: NodeId) -> (String, u8) {
    let wrap = |(t, p): (String, u8), min: u8| if p < min { format!("({t})") } else { t };
    match g.node(id) {
        Node::Const(b) => {
            let v = f64::from_bits(b);
            (format!("{v}"), if v < 0.0 { 3 } else { 4 })
        }
        Node::Sym(Sym::Dt) => ("dt".into(), 4),
        Node::Sym(Sym::Time) => ("t".into(), 4),
        Node::Sym(Sym::Param(_)) => (g.names.get(&id).cloned().unwrap_or_else(|| "param".into()), 4),
        Node::Sym(_) => ("?".into(), 4),
        Node::Add(a, b) => match g.node(b) {
            Node::Neg(x) => (format!("{} - {}", wrap(infix(g, a), 1), wrap(infix(g, x), 2)), 1),
            _ => (format!("{} + {}", wrap(infix(g, a), 1), wrap(infix(g, b), 2)), 1),
        },
        Node::Mul(a, b) => (format!("{}*{}", wrap(infix(g, a), 2), wrap(infix(g, b), 3)), 2),
        Node::Div(a, b) => (format!("{}/{}", wrap(infix(g, a), 2), wrap(infix(g, b), 3)), 2),
        Node::Neg(a) => (format!("-{}", wrap(infix(g, a), 3)), 3),
        Node::Powi(a, k) => (format!("{}^{k}", wrap(infix(g, a), 4)), 4),
        Node::Sqrt(a) => (format!("sqrt({})", scalar(g, a)), 4),
        Node::Heaviside(a) => (format!("H({})", scalar(g, a)), 4),
    }
}
