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
            Item::Import { path, .. } => out.push_str(&format!("{head}import {path:?}\n")),
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
            Item::Scheme { name, params, uses, states, lets, initial, claims, stages, .. } => {
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
                    out.push_str(&format!("  {sign} int({}) {}\n", i.region.name, expr(&i.integrand)));
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
    }
}
