//! A problem's `fn`s, expanded where they are called: each call is replaced by the body with
//! the arguments in place of the parameters, in every expression of the problem (lets, coefs,
//! predicates, columns, keys, expectations). The body's other names mean what they mean where
//! it is called (the problem's params and lets, `x`, `t`, a column's `u`), as the inlining of
//! a form's `fn`s does.

use std::collections::HashMap;

use crate::diagnostic::Diagnostic;
use crate::source::Span;
use crate::syntax::ast::{BodySource, Condition, Expr, ExprKind, HeldAt, MeshSource, Problem, ProblemFn, RegionSource};

/// Calls nested deeper than this are taken for a recursion.
const MAX_DEPTH: usize = 32;

/// `p` with its `fn`s expanded; errors for a name taken twice or by a built-in, a wrong number
/// of arguments, and a recursion.
pub(in crate::check) fn expand(p: &Problem, diags: &mut Vec<Diagnostic>) -> Problem {
    let mut fns: HashMap<&str, &ProblemFn> = HashMap::new();
    for f in &p.fns {
        let builtin = crate::check::builtins::builtin(&f.name.name).is_some()
            || crate::check::BUILTIN_VALUES.contains(&f.name.name.as_str());
        if builtin {
            diags.push(
                Diagnostic::error(
                    "E0106",
                    format!("`{}` is a built-in name", f.name.name),
                    f.name.span,
                    "would hide it",
                )
                .with_help("give the function another name"),
            );
        } else if let Some(prev) = fns.insert(&f.name.name, f) {
            diags.push(
                Diagnostic::error("E0102", format!("`{}` is defined twice", f.name.name), f.name.span, "again here")
                    .with_label(prev.name.span, "first here"),
            );
        }
        super::distinct(f.params.iter(), "parameter", diags);
    }
    let mut out = p.clone();
    if fns.is_empty() {
        return out;
    }
    let mut expander = Expander { fns, diags, stack: Vec::new() };
    for e in exprs_mut(&mut out) {
        *e = expander.expr(e);
    }
    out
}

struct Expander<'p, 'd> {
    fns: HashMap<&'p str, &'p ProblemFn>,
    diags: &'d mut Vec<Diagnostic>,
    /// The calls being expanded (name, call site).
    stack: Vec<(String, Span)>,
}

impl Expander<'_, '_> {
    fn expr(&mut self, e: &Expr) -> Expr {
        let kind = match &e.kind {
            ExprKind::Number(_) | ExprKind::Name(_) => e.kind.clone(),
            ExprKind::Neg(a) => ExprKind::Neg(Box::new(self.expr(a))),
            ExprKind::Binary(op, a, b) => ExprKind::Binary(*op, Box::new(self.expr(a)), Box::new(self.expr(b))),
            ExprKind::Index(a, i) => ExprKind::Index(Box::new(self.expr(a)), Box::new(self.expr(i))),
            ExprKind::Vector(items) => ExprKind::Vector(items.iter().map(|a| self.expr(a)).collect()),
            ExprKind::Call(f, args) => {
                let args: Vec<Expr> = args.iter().map(|a| self.expr(a)).collect();
                let Some(def) = self.fns.get(f.name.as_str()).copied() else {
                    return Expr { kind: ExprKind::Call(f.clone(), args), span: e.span };
                };
                return self.call(def, args, e);
            }
        };
        Expr { kind, span: e.span }
    }

    /// The body of `def` with `args` in place of its parameters, expanded in turn.
    fn call(&mut self, def: &ProblemFn, args: Vec<Expr>, at: &Expr) -> Expr {
        // An expression that stands for the failed call, so that checking goes on.
        let failed = || Expr { kind: ExprKind::Number(0.0), span: at.span };
        if args.len() != def.params.len() {
            self.diags.push(
                Diagnostic::error(
                    "E0201",
                    format!("`{}` takes {} argument(s)", def.name.name, def.params.len()),
                    at.span,
                    format!("{} given", args.len()),
                )
                .with_label(def.span, "defined here"),
            );
            return failed();
        }
        if self.stack.iter().any(|(n, _)| *n == def.name.name) || self.stack.len() >= MAX_DEPTH {
            self.diags.push(
                Diagnostic::error("E0105", format!("`{}` calls itself", def.name.name), at.span, "recursive call")
                    .with_label(def.span, "defined here")
                    .with_note("functions are expanded where they are called, so they cannot be recursive"),
            );
            return failed();
        }
        let bound: Vec<(&str, Expr)> = def.params.iter().map(|p| p.name.as_str()).zip(args).collect();
        let body = substitute(&def.body, &bound);
        self.stack.push((def.name.name.clone(), at.span));
        let expanded = self.expr(&body);
        self.stack.pop();
        expanded
    }
}

/// `e` with each name of `bound` replaced by its expression.
fn substitute(e: &Expr, bound: &[(&str, Expr)]) -> Expr {
    let sub = |a: &Expr| Box::new(substitute(a, bound));
    let kind = match &e.kind {
        ExprKind::Name(id) => match bound.iter().find(|(n, _)| *n == id.name) {
            Some((_, value)) => return value.clone(),
            None => e.kind.clone(),
        },
        ExprKind::Number(_) => e.kind.clone(),
        ExprKind::Neg(a) => ExprKind::Neg(sub(a)),
        ExprKind::Binary(op, a, b) => ExprKind::Binary(*op, sub(a), sub(b)),
        ExprKind::Index(a, i) => ExprKind::Index(sub(a), sub(i)),
        ExprKind::Vector(items) => ExprKind::Vector(items.iter().map(|a| substitute(a, bound)).collect()),
        ExprKind::Call(f, args) => ExprKind::Call(f.clone(), args.iter().map(|a| substitute(a, bound)).collect()),
    };
    Expr { kind, span: e.span }
}

/// Every expression of a problem, to rewrite in place.
fn exprs_mut(p: &mut Problem) -> Vec<&mut Expr> {
    let mut out: Vec<&mut Expr> = Vec::new();
    for m in &mut p.mesh {
        if let MeshSource::Generator(call) = m {
            out.extend(call.args.iter_mut().map(|a| &mut a.value));
        }
    }
    for b in &mut p.bodies {
        if let BodySource::Generator(call) = &mut b.source {
            out.extend(call.args.iter_mut().map(|a| &mut a.value));
        }
        out.extend(b.sets.iter_mut().chain(&mut b.initial).map(|d| &mut d.value));
    }
    for r in &mut p.regions {
        for s in &mut r.sources {
            region_exprs(s, &mut out);
        }
    }
    let defined = p.sets.iter_mut().chain(&mut p.coefs).chain(&mut p.initial).chain(&mut p.summary);
    let defined = defined.chain(p.series.iter_mut().map(|(d, _)| d)).chain(&mut p.run).chain(&mut p.quadrature);
    out.extend(defined.chain(&mut p.lets).map(|d| &mut d.value));
    for o in &mut p.obstacles {
        out.extend(o.shape.args.iter_mut().map(|a| &mut a.value));
    }
    for pair in &mut p.pairs {
        out.extend(pair.reach.as_mut().into_iter().chain(pair.sets.iter_mut().map(|d| &mut d.value)));
    }
    for d in &mut p.dirichlet {
        if let HeldAt::Nearest { point, .. } = &mut d.on {
            out.push(point);
        }
        out.extend(d.component.as_mut());
        out.push(&mut d.value);
    }
    out.extend(p.neumann.iter_mut().map(|b| &mut b.value));
    for x in &mut p.expects {
        out.push(&mut x.value);
        out.push(&mut x.within);
        if let Some(c) = &mut x.when {
            condition_exprs(c, &mut out);
        }
    }
    out.extend(p.reference_args.iter_mut().map(|a| &mut a.value));
    out
}

fn region_exprs<'p>(s: &'p mut RegionSource, out: &mut Vec<&'p mut Expr>) {
    match s {
        RegionSource::Group { condition, .. } | RegionSource::Boundary { condition, .. } => {
            if let Some(c) = condition {
                condition_exprs(c, out);
            }
        }
        RegionSource::Region(_) => {}
        RegionSource::Union(parts, _) => parts.iter_mut().for_each(|part| region_exprs(part, out)),
    }
}

fn condition_exprs<'p>(c: &'p mut Condition, out: &mut Vec<&'p mut Expr>) {
    match c {
        Condition::Compare(cmp) => {
            out.push(&mut cmp.lhs);
            out.push(&mut cmp.rhs);
        }
        Condition::All(parts) | Condition::Any(parts) => parts.iter_mut().for_each(|part| condition_exprs(part, out)),
        Condition::Not(inner) => condition_exprs(inner, out),
    }
}
