//! Readable dump of the AST (`signorini emit --stage ast`): one item per block, expressions as
//! fully parenthesised prefix terms, so precedence and spans can be checked by eye.

use super::ast::*;
use crate::source::SourceMap;

pub fn print_file(file: &File, sources: &SourceMap) -> String {
    let mut out = String::new();
    for item in &file.items {
        let span = item.span();
        let (line, col) = sources.line_col(span.file, span.start);
        let head = format!("{line}:{col} ");
        match item {
            Item::Import { path, role: None, .. } => out.push_str(&format!("{head}import {path:?}\n")),
            Item::Import { path, role: Some(r), .. } => out.push_str(&format!("{head}import {} = {path:?}\n", r.name)),
            Item::Param { name, default, range, .. } => {
                out.push_str(&format!("{head}param {} = {}", name.name, expr(default)));
                if let Some(r) = range {
                    out.push_str(&format!(
                        " in {}{}, {}{}",
                        if r.lo_closed { "[" } else { "(" },
                        expr(&r.lo),
                        expr(&r.hi),
                        if r.hi_closed { "]" } else { ")" }
                    ));
                }
                out.push('\n');
            }
            Item::Coef { name, shape, .. } => out.push_str(&format!("{head}coef {}: {}\n", name.name, shape.name())),
            Item::Let { name, value, .. } => out.push_str(&format!("{head}let {} = {}\n", name.name, expr(value))),
            Item::Fn { name, params, body, .. } => {
                let ps: Vec<_> = params.iter().map(|p| p.name.as_str()).collect();
                out.push_str(&format!("{head}fn {}({}) = {}\n", name.name, ps.join(", "), expr(body)));
            }
            Item::Scheme { name, params, uses, states, lets, initial, claims, estimates, stages, .. } => {
                let ps: Vec<String> =
                    params.iter().map(|p| format!("{} = {}", p.name.name, expr(&p.default))).collect();
                out.push_str(&format!("{head}scheme {}({})\n", name.name, ps.join(", ")));
                let us: Vec<&str> = uses.iter().map(|s| s.name.as_str()).collect();
                out.push_str(&format!("  uses {}\n", us.join(", ")));
                let ss: Vec<&str> = states.iter().map(|s| s.name.as_str()).collect();
                out.push_str(&format!("  state {}\n", ss.join(", ")));
                for (n, v) in lets {
                    out.push_str(&format!("  let {} = {}\n", n.name, expr(v)));
                }
                for (n, v) in claims {
                    out.push_str(&format!("  claim {} = {}\n", n.name, expr(v)));
                }
                for e in estimates {
                    out.push_str(&format!("  estimate {}\n", expr(e)));
                }
                if let Some(i) = initial {
                    out.push_str(&format!(
                        "  initial {}: {} == {}\n",
                        i.unknown.name,
                        expr(&i.residual.lhs),
                        expr(&i.residual.rhs)
                    ));
                }
                for st in stages {
                    let at = st.at.as_ref().map_or("(t + dt)".to_string(), expr);
                    out.push_str(&format!("  stage {} at {at}\n", st.name.as_ref().map_or("_", |n| n.name.as_str())));
                    for (n, v) in &st.lets {
                        out.push_str(&format!("    let {} = {}\n", n.name, expr(v)));
                    }
                    if let Some(u) = &st.unknown {
                        out.push_str(&format!("    unknown {}\n", u.name));
                    }
                    if !st.news.is_empty() {
                        let ns: Vec<&str> = st.news.iter().map(|n| n.name.as_str()).collect();
                        out.push_str(&format!("    new {}\n", ns.join(", ")));
                    }
                    for r in &st.relates {
                        out.push_str(&format!("    relate {} = {}\n", r.name.name, expr(&r.value)));
                    }
                    if let Some(r) = &st.residual {
                        out.push_str(&format!("    residual {} == {}\n", expr(&r.lhs), expr(&r.rhs)));
                    }
                }
            }
            Item::Problem(p) => {
                let ps: Vec<String> =
                    p.params.iter().map(|q| format!("{} = {}", q.name.name, expr(&q.default))).collect();
                out.push_str(&format!("{head}problem {}({})\n", p.name.name, ps.join(", ")));
                problem(p, &mut out);
            }
            Item::Form { name, fields, test, integrals, .. } => {
                let fs: Vec<_> = fields.iter().map(|p| p.name.as_str()).collect();
                match test {
                    Some(test) => {
                        out.push_str(&format!("{head}form {}({}; {})\n", name.name, fs.join(", "), test.name))
                    }
                    None => out.push_str(&format!("{head}functional {}({})\n", name.name, fs.join(", "))),
                }
                for i in integrals {
                    let sign = if i.sign < 0.0 { "-" } else { "+" };
                    let degree = i.degree.map_or(String::new(), |(k, _)| format!(", degree = {k}"));
                    let sides = if i.both_sides.is_some() { ", both_sides" } else { "" };
                    out.push_str(&format!("  {sign} int({}{degree}{sides}) {}\n", i.region.name, expr(&i.integrand)));
                }
            }
        }
    }
    out
}

pub fn expr(e: &Expr) -> String {
    match &e.kind {
        ExprKind::Number(v) => format!("{v:?}"),
        ExprKind::Name(n) => n.name.clone(),
        ExprKind::Call(f, args) => {
            let a: Vec<_> = args.iter().map(expr).collect();
            format!("{}({})", f.name, a.join(", "))
        }
        ExprKind::Neg(a) => format!("(neg {})", expr(a)),
        ExprKind::Binary(op, a, b) => format!("({} {} {})", op.symbol(), expr(a), expr(b)),
        ExprKind::Vector(items) => {
            let a: Vec<_> = items.iter().map(expr).collect();
            format!("[{}]", a.join(", "))
        }
        ExprKind::Index(a, i) => format!("(index {} {})", expr(a), expr(i)),
    }
}

fn named_call(c: &NamedCall) -> String {
    let a: Vec<_> = c.args.iter().map(|a| format!("{} = {}", a.name.name, expr(&a.value))).collect();
    format!("{}({})", c.name.name, a.join(", "))
}

fn region_source(s: &RegionSource) -> String {
    let (head, c) = match s {
        RegionSource::Group { name, condition, .. } => (format!("group {name:?}"), condition),
        RegionSource::Boundary { condition, .. } => ("boundary".to_string(), condition),
        RegionSource::Region(id) => return id.name.clone(),
        RegionSource::Union(parts, _) => {
            let parts: Vec<String> = parts.iter().map(|p| format!("({})", region_source(p))).collect();
            return parts.join(" + ");
        }
    };
    c.as_ref().map_or(head.clone(), |c| format!("{head} where {}", condition(c)))
}

/// A condition, parenthesised where `or` sits inside `and` or `not`.
fn condition(c: &Condition) -> String {
    let inner = |c: &Condition| match c {
        Condition::Any(_) => format!("({})", condition(c)),
        _ => condition(c),
    };
    match c {
        Condition::Compare(c) => format!("{} {} {}", expr(&c.lhs), c.op.symbol(), expr(&c.rhs)),
        Condition::All(parts) => parts.iter().map(inner).collect::<Vec<_>>().join(" and "),
        Condition::Any(parts) => parts.iter().map(condition).collect::<Vec<_>>().join(" or "),
        Condition::Not(c) => match **c {
            Condition::Compare(_) => format!("not {}", condition(c)),
            _ => format!("not ({})", condition(c)),
        },
    }
}

fn problem(p: &Problem, out: &mut String) {
    let line = |out: &mut String, what: &str, d: &Defined| {
        out.push_str(&format!("  {what} {} = {}\n", d.name.name, expr(&d.value)));
    };
    for m in &p.mesh {
        match m {
            MeshSource::File { path, .. } => out.push_str(&format!("  mesh {path:?}\n")),
            MeshSource::Generator(c) => out.push_str(&format!("  mesh {}\n", named_call(c))),
        }
    }
    for f in &p.fns {
        let params: Vec<&str> = f.params.iter().map(|a| a.name.as_str()).collect();
        out.push_str(&format!("  fn {}({}) = {}\n", f.name.name, params.join(", "), expr(&f.body)));
    }
    for b in &p.bodies {
        let source = match &b.source {
            BodySource::Group { name, .. } => format!("group {name:?}"),
            BodySource::Generator(c) => named_call(c),
        };
        out.push_str(&format!("  body {} = {source}\n", b.name.name));
        for d in b.sets.iter().map(|d| ("set", d)).chain(b.initial.iter().map(|d| ("initial", d))) {
            out.push_str(&format!("    {} {} = {}\n", d.0, d.1.name.name, expr(&d.1.value)));
        }
    }
    for r in &p.regions {
        let sources: Vec<String> = r.sources.iter().map(region_source).collect();
        let body = r.body.as_ref().map_or(String::new(), |b| format!(" (in body {})", b.name));
        out.push_str(&format!("  region {} = {}{body}\n", r.name.name, sources.join(" else ")));
    }
    for b in &p.binds {
        out.push_str(&format!("  {}\n", bind(b)));
    }
    if p.run_static.is_some() {
        out.push_str("  run static\n");
    }
    let groups: [(&str, &Vec<Defined>); 6] = [
        ("run", &p.run),
        ("quadrature", &p.quadrature),
        ("set", &p.sets),
        ("let", &p.lets),
        ("coef", &p.coefs),
        ("initial", &p.initial),
    ];
    for (what, list) in groups {
        for d in list {
            line(out, what, d);
        }
    }
    for o in &p.obstacles {
        let on = o.region.as_ref().map_or(String::new(), |r| format!(" on {}", r.name));
        out.push_str(&format!("  obstacle {}{on}\n", named_call(&o.shape)));
    }
    for pair in &p.pairs {
        let within = pair.reach.as_ref().map_or(String::new(), |r| format!(" within {}", expr(r)));
        let by = pair.by.as_ref().map_or(String::new(), |b| format!(" by {}", b.name));
        out.push_str(&format!("  contact {} with {}{within}{by}\n", pair.own.name, pair.facing.name));
        for b in &pair.binds {
            out.push_str(&format!("    {}\n", bind(b)));
        }
        for d in &pair.sets {
            out.push_str(&format!("    set {} = {}\n", d.name.name, expr(&d.value)));
        }
    }
    for d in &p.dirichlet {
        let k = d.component.as_ref().map_or(String::new(), |k| format!("[{}]", expr(k)));
        let on = match &d.on {
            HeldAt::Region(r) => r.name.clone(),
            HeldAt::Nearest { point, .. } => format!("nearest({})", expr(point)),
        };
        out.push_str(&format!("  dirichlet {on}: {}{k} = {}\n", d.field.name, expr(&d.value)));
    }
    for b in &p.neumann {
        out.push_str(&format!("  neumann {}: {} = {}\n", b.region.name, b.kind.name, expr(&b.value)));
    }
    for (d, written) in &p.series {
        let required = if p.required.iter().any(|r| r.name == d.name.name) { " required" } else { "" };
        out.push_str(&format!(
            "  {} {} = {}{required}\n",
            if *written { "series" } else { "observe" },
            d.name.name,
            expr(&d.value)
        ));
    }
    for d in &p.summary {
        line(out, "summary", d);
    }
    for x in &p.expects {
        let when = x.when.as_ref().map_or(String::new(), |c| format!(" when {}", condition(c)));
        out.push_str(&format!("  expect {} = {} within {}{when}\n", x.key.name, expr(&x.value), expr(&x.within)));
    }
    for pl in &p.plots {
        let c: Vec<&str> = pl.columns.iter().map(|c| c.name.as_str()).collect();
        out.push_str(&format!("  plot {:?}: {}\n", pl.title, c.join(", ")));
    }
    if let Some(r) = &p.reference {
        let call = NamedCall { name: r.clone(), args: p.reference_args.clone(), span: r.span };
        let text = if p.reference_args.is_empty() { r.name.clone() } else { named_call(&call) };
        out.push_str(&format!("  reference {text}\n"));
    }
}

/// `bind ROLE = TARGET`, a path quoted.
fn bind(b: &Bind) -> String {
    let target = if b.is_path { format!("{:?}", b.target) } else { b.target.clone() };
    format!("bind {} = {target}", b.role.name)
}
