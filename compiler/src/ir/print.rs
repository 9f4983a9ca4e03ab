//! Readable dump of the IR (`signorini emit --stage ir`): the shared nodes in topological
//! order, then each integral's test-function coefficients and tangent coefficients.

use std::fmt::Write;

use super::graph::{Graph, Node, NodeId, Sym};
use super::{DimIr, TangentIr};

pub fn print(ir: &DimIr, params: &[String], coefs: &[String]) -> String {
    let g = &ir.graph;
    let d = ir.dim;
    let mut roots = Vec::new();
    for f in &ir.forms {
        for i in &f.integrals {
            roots.extend(i.f0.iter().chain(&i.f1).copied());
            roots.extend(i.tangents.iter().flat_map(TangentIr::nodes));
        }
    }
    let mut out = String::new();
    let _ = writeln!(out, "// dimension {d}");
    for id in g.reachable(roots) {
        if matches!(g.node(id), Node::Const(_) | Node::Sym(_)) {
            continue;
        }
        let name = g.names.get(&id).map(|n| format!("  // {n}")).unwrap_or_default();
        let _ = writeln!(out, "%{id} = {}{name}", node(g, id, params, coefs));
    }
    for f in &ir.forms {
        let _ = writeln!(
            out,
            "\n{} {}({}{}){}",
            if f.test.is_some() { "form" } else { "functional" },
            f.name,
            f.fields.join(", "),
            f.test.as_ref().map_or(String::new(), |t| format!("; {t}")),
            if f.linear { "  [linear]" } else { "" }
        );
        for i in &f.integrals {
            let _ = writeln!(out, "  int({})  degree P1 {} P2 {}", i.region, i.degree[0], i.degree[1]);
            if let Some(v) = i.value {
                list(&mut out, g, "value", &[v], params, coefs);
            }
            list(&mut out, g, "f0", &i.f0, params, coefs);
            list(&mut out, g, "f1", &i.f1, params, coefs);
            for (a, t) in i.tangents.iter().enumerate() {
                let arg = &f.fields[a];
                list(&mut out, g, &format!("d{arg}.c00"), &t.c00, params, coefs);
                list(&mut out, g, &format!("d{arg}.c01"), &t.c01, params, coefs);
                list(&mut out, g, &format!("d{arg}.c10"), &t.c10, params, coefs);
                list(&mut out, g, &format!("d{arg}.c11"), &t.c11, params, coefs);
            }
        }
    }
    out
}

fn list(out: &mut String, g: &Graph, label: &str, ids: &[NodeId], params: &[String], coefs: &[String]) {
    let nonzero: Vec<String> = ids
        .iter()
        .enumerate()
        .filter(|(_, n)| !g.is_zero(**n))
        .map(|(k, n)| format!("[{k}] {}", operand(g, *n, params, coefs)))
        .collect();
    if !nonzero.is_empty() {
        let _ = writeln!(out, "    {label}: {}", nonzero.join(", "));
    }
}

fn operand(g: &Graph, id: NodeId, params: &[String], coefs: &[String]) -> String {
    match g.node(id) {
        Node::Const(b) => format!("{:?}", f64::from_bits(b)),
        Node::Sym(s) => sym(s, params, coefs),
        _ => format!("%{id}"),
    }
}

fn node(g: &Graph, id: NodeId, params: &[String], coefs: &[String]) -> String {
    let o = |x: NodeId| operand(g, x, params, coefs);
    match g.node(id) {
        Node::Const(_) | Node::Sym(_) => o(id),
        Node::Add(a, b) => format!("add {} {}", o(a), o(b)),
        Node::Mul(a, b) => format!("mul {} {}", o(a), o(b)),
        Node::Neg(a) => format!("neg {}", o(a)),
        Node::Div(a, b) => format!("div {} {}", o(a), o(b)),
        Node::Powi(a, k) => format!("powi {} {k}", o(a)),
        Node::Powf(a, p) => format!("powf {} {}", o(a), f64::from_bits(p)),
        Node::Sqrt(a) => format!("sqrt {}", o(a)),
        Node::Heaviside(a) => format!("H {}", o(a)),
        Node::Step(a) => format!("step {}", o(a)),
        Node::Func(f, a) => format!("{} {}", f.name(), o(a)),
        Node::Atan2(y, x) => format!("atan2 {} {}", o(y), o(x)),
        Node::CoefAt { id: c, comp, dirs, point } => {
            let at: Vec<String> = g.point(point).iter().map(|&p| o(p)).collect();
            let name = coefs.get(c as usize).map_or("coef", String::as_str);
            format!("{name}[{comp}] d{:?} at {}", dirs.as_slice(), at.join(" "))
        }
    }
}

pub fn sym(s: Sym, params: &[String], coefs: &[String]) -> String {
    match s {
        Sym::Param(i) => params.get(i as usize).cloned().unwrap_or_else(|| format!("param{i}")),
        Sym::Field { arg, comp } => format!("u{arg}[{comp}]"),
        Sym::FieldGrad { arg, comp, dir } => format!("grad_u{arg}[{comp}][{dir}]"),
        Sym::Test { comp } => format!("v[{comp}]"),
        Sym::TestGrad { comp, dir } => format!("grad_v[{comp}][{dir}]"),
        Sym::Normal(k) => format!("n[{k}]"),
        Sym::CellDiameter => "h".into(),
        Sym::Coord(k) => format!("x[{k}]"),
        Sym::Time => "t".into(),
        Sym::Dt => "dt".into(),
        Sym::Seed(k) => format!("seed{k}"),
        Sym::Coef { id, comp } => format!("{}[{comp}]", coefs.get(id as usize).map_or("coef", String::as_str)),
        Sym::Opposite(f) => format!("opposite({})", sym(f.own(), params, coefs)),
        Sym::FieldHess { arg, comp, dir, along } => format!("hess_u{arg}[{comp}][{dir}][{along}]"),
        Sym::NormalRate { comp, along } => format!("dn[{comp}][{along}]"),
    }
}
