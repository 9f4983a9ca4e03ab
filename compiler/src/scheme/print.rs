//! Readable dump of a compiled scheme (`signorini emit --stage scheme`): each stage's new
//! quantities in terms of the unknown and the known levels, and its residual terms.

use std::fmt::Write;

use super::{Affine, Quantity, SchemeIr, Term};
use crate::ir::graph::{Graph, Node, NodeId, Sym};

/// The scheme with every coefficient simplified (see `simplify::scheme`).
pub fn print(s: &SchemeIr) -> String {
    let mut shown = s.clone();
    super::simplify::scheme(&mut shown);
    print_as_is(&shown)
}

fn print_as_is(s: &SchemeIr) -> String {
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
    // The lets the coefficients refer to, in source order, as defined.
    let used = s.graph.reachable(coefficients(s));
    for &id in &used {
        if let Some(name) = s.graph.names.get(&id)
            && !matches!(s.graph.node(id), Node::Sym(_) | Node::Const(_))
        {
            let _ = writeln!(out, "  let {name} = {}", definition(&s.graph, id));
        }
    }
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
    if let Some(e) = &s.estimate {
        let _ = writeln!(out, "  estimate {}", affine(&s.graph, e, "", &names));
    }
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

/// Every coefficient node of a compiled scheme.
fn coefficients(s: &SchemeIr) -> Vec<NodeId> {
    let mut out = Vec::new();
    let term = |t: &Term, out: &mut Vec<NodeId>| {
        out.extend([t.coef, t.time]);
        for a in &t.args {
            out.push(a.unknown);
            out.extend(a.known.iter().map(|(_, c)| *c));
        }
    };
    for t in s.initial.iter().flat_map(|i| &i.terms) {
        term(t, &mut out);
    }
    for st in &s.stages {
        out.push(st.time);
        for v in &st.values {
            out.push(v.unknown);
            out.extend(v.known.iter().map(|(_, c)| *c));
        }
        for t in &st.terms {
            term(t, &mut out);
        }
    }
    if let Some(e) = &s.estimate {
        out.extend(e.known.iter().map(|(_, c)| *c));
    }
    out
}

/// `c1·q1 + c2·q2 - c3·q3`: unit coefficients omitted, negative ones subtracted.
fn affine(g: &Graph, a: &Affine, unknown: &str, names: &dyn Fn(Quantity) -> String) -> String {
    let mut parts: Vec<(bool, String)> = Vec::new();
    let mut push = |c: NodeId, level: String| {
        let (negative, magnitude) = match g.node(c) {
            Node::Neg(x) => (true, Some(x)),
            Node::Const(b) if f64::from_bits(b) < 0.0 => (true, None),
            _ => (false, Some(c)),
        };
        let text = match (magnitude, g.as_const(c)) {
            (_, Some(v)) if v.abs() == 1.0 => level,
            (_, Some(v)) => format!("{}·{level}", v.abs()),
            (Some(m), None) => format!("{}·{level}", factor(g, m)),
            (None, None) => level,
        };
        parts.push((negative, text));
    };
    if !g.is_zero(a.unknown) {
        push(a.unknown, unknown.to_string());
    }
    for (q, c) in &a.known {
        push(*c, names(*q));
    }
    let mut out = String::new();
    for (i, (negative, text)) in parts.iter().enumerate() {
        match (i, negative) {
            (0, false) => out.push_str(text),
            (0, true) => out.push_str(&format!("-{text}")),
            (_, false) => out.push_str(&format!(" + {text}")),
            (_, true) => out.push_str(&format!(" - {text}")),
        }
    }
    if out.is_empty() { "0".into() } else { out }
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

/// A let's definition: the expression of its node, not its own name.
fn definition(g: &Graph, id: NodeId) -> String {
    expr(g, id).0
}

/// Text and precedence (1 sum, 2 product, 3 unary, 4 atom); a let is its name.
fn infix(g: &Graph, id: NodeId) -> (String, u8) {
    match (g.names.get(&id), g.node(id)) {
        (Some(name), n) if !matches!(n, Node::Const(_) | Node::Sym(Sym::Dt | Sym::Time)) => (name.clone(), 4),
        _ => expr(g, id),
    }
}

/// Terms of a sum (through nested sums and negations, not through lets other than the root),
/// with their signs.
fn summands(g: &Graph, id: NodeId, root: bool, negative: bool, out: &mut Vec<(bool, NodeId)>) {
    let named = !root && g.names.contains_key(&id);
    match g.node(id) {
        Node::Add(a, b) if !named => {
            summands(g, a, false, negative, out);
            summands(g, b, false, negative, out);
        }
        Node::Neg(a) if !named => summands(g, a, false, !negative, out),
        Node::Const(b) if f64::from_bits(b) < 0.0 => out.push((!negative, id)),
        _ => out.push((negative, id)),
    }
}

/// Factors of a product (through nested products, not through lets other than the root).
fn factors(g: &Graph, id: NodeId, root: bool, out: &mut Vec<NodeId>) {
    match g.node(id) {
        Node::Mul(a, b) if root || !g.names.contains_key(&id) => {
            factors(g, a, false, out);
            factors(g, b, false, out);
        }
        _ => out.push(id),
    }
}

/// The expression of a node, its precedence: 1 sum, 2 product, 3 unary, 4 atom.
fn expr(g: &Graph, id: NodeId) -> (String, u8) {
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
        Node::Add(..) => {
            // Positive terms first, time first among them: `t + gs*dt`, `2 - gs`.
            let mut terms = Vec::new();
            summands(g, id, true, false, &mut terms);
            terms.sort_by_key(|&(negative, n)| (negative, g.node(n) != Node::Sym(Sym::Time)));
            let mut out = String::new();
            for (i, (negative, n)) in terms.into_iter().enumerate() {
                let text = match g.as_const(n) {
                    Some(c) => format!("{}", c.abs()),
                    None => wrap(infix(g, n), 2),
                };
                let sep = match (i, negative) {
                    (0, false) => "",
                    (0, true) => "-",
                    (_, false) => " + ",
                    (_, true) => " - ",
                };
                out.push_str(sep);
                out.push_str(&text);
            }
            (out, 1)
        }
        Node::Mul(..) => {
            // Constants, params, dt, t, then the rest: `2*gs*dt`.
            let mut fs = Vec::new();
            factors(g, id, true, &mut fs);
            fs.sort_by_key(|&n| match g.node(n) {
                Node::Const(_) => 0,
                Node::Sym(Sym::Param(i)) => 1 + u32::from(i),
                Node::Sym(Sym::Dt) => 1 << 17,
                Node::Sym(Sym::Time) => 1 << 18,
                _ => 1 << 19,
            });
            let texts: Vec<String> = fs.iter().map(|&n| wrap(infix(g, n), 3)).collect();
            (texts.join("*"), 2)
        }
        Node::Div(a, b) => (format!("{}/{}", wrap(infix(g, a), 2), wrap(infix(g, b), 3)), 2),
        Node::Neg(a) => (format!("-{}", wrap(infix(g, a), 3)), 3),
        Node::Powi(a, k) => (format!("{}^{k}", wrap(infix(g, a), 4)), 4),
        Node::Powf(a, p) => (format!("{}^{}", wrap(infix(g, a), 4), f64::from_bits(p)), 4),
        Node::Sqrt(a) => (format!("sqrt({})", scalar(g, a)), 4),
        Node::Heaviside(a) | Node::Step(a) => (format!("H({})", scalar(g, a)), 4),
        Node::Func(f, a) => (format!("{}({})", f.name(), scalar(g, a)), 4),
        Node::Atan2(y, x) => (format!("atan2({}, {})", scalar(g, y), scalar(g, x)), 4),
        // Schemes read no coef.
        Node::CoefAt { .. } => ("?".into(), 4),
    }
}
