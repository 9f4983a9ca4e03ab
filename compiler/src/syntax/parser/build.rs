//! Pest pairs → AST items: imports, params, coefs, lets, fns, forms and functionals with their
//! integrals, schemes with their stages, and expressions (by precedence climbing).

use pest::iterators::Pair;
use pest::pratt_parser::{Assoc, Op, PrattParser};
use std::sync::LazyLock;

use super::Rule;
use crate::diagnostic::Diagnostic;
use crate::source::{FileId, Span};
use crate::syntax::ast::*;

static PRATT: LazyLock<PrattParser<Rule>> = LazyLock::new(|| {
    PrattParser::new()
        .op(Op::infix(Rule::add, Assoc::Left) | Op::infix(Rule::sub, Assoc::Left))
        .op(Op::infix(Rule::mul, Assoc::Left) | Op::infix(Rule::div, Assoc::Left))
        .op(Op::prefix(Rule::neg))
        .op(Op::infix(Rule::pow, Assoc::Right))
        .op(Op::postfix(Rule::index))
});

/// A string literal's content.
pub(super) fn unquote(s: &str) -> String {
    s[1..s.len() - 1].to_string()
}

pub(super) struct Builder {
    pub(super) file: FileId,
    pub(super) offset: usize,
}

impl Builder {
    /// The span of a pair without the whitespace pest may have consumed at its end.
    pub(super) fn span(&self, p: &Pair<Rule>) -> Span {
        let s = p.as_span();
        let trimmed = s.as_str().trim_end().len();
        Span::new(self.file, self.offset + s.start(), self.offset + s.start() + trimmed)
    }

    pub(super) fn ident(&self, p: Pair<Rule>) -> Ident {
        Ident { name: p.as_str().to_string(), span: self.span(&p) }
    }

    pub(super) fn item(&self, p: Pair<Rule>) -> Result<Item, Box<Diagnostic>> {
        let span = self.span(&p);
        let rule = p.as_rule();
        let mut it = p.into_inner();
        let mut next = || it.next().expect("grammar guarantees the child");
        Ok(match rule {
            Rule::import => {
                let mut target = next();
                let role = match target.as_rule() {
                    Rule::import_role => {
                        let role = self.ident(target.into_inner().next().expect("a role names itself"));
                        target = next();
                        Some(role)
                    }
                    _ => None,
                };
                let path = match target.as_rule() {
                    Rule::string => {
                        let s = target.as_str();
                        s[1..s.len() - 1].to_string()
                    }
                    _ => format!("{}.wf", target.as_str()),
                };
                Item::Import { path, span, role }
            }
            Rule::param => {
                let name = self.ident(next());
                let default = self.expr(next())?;
                let mut range = None;
                for r in it {
                    range = Some(self.range(r)?);
                }
                Item::Param { name, default, range, span }
            }
            Rule::coef => {
                let name = self.ident(next());
                let shape = match it.next().map(|s| s.as_str().to_string()) {
                    None => Shape::Scalar,
                    Some(s) if s == "vector" => Shape::Vector,
                    Some(s) if s == "tensor" => Shape::Tensor,
                    Some(_) => Shape::Scalar,
                };
                Item::Coef { name, shape, span }
            }
            Rule::let_decl => {
                let name = self.ident(next());
                let value = self.expr(next())?;
                Item::Let { name, value, span }
            }
            Rule::fn_decl => {
                let name = self.ident(next());
                let mut params = Vec::new();
                let mut body = None;
                for q in it {
                    match q.as_rule() {
                        Rule::ident_list => params = q.into_inner().map(|i| self.ident(i)).collect(),
                        _ => body = Some(self.expr(q)?),
                    }
                }
                Item::Fn { name, params, body: body.expect("fn has a body"), span }
            }
            Rule::form_decl => {
                let name = self.ident(next());
                let args = next();
                let mut fields = Vec::new();
                let mut test = None;
                for a in args.into_inner() {
                    match a.as_rule() {
                        Rule::ident_list => fields = a.into_inner().map(|i| self.ident(i)).collect(),
                        _ => test = Some(self.ident(a)),
                    }
                }
                let integrals = self.integrals(next())?;
                Item::Form { name, fields, test: Some(test.expect("form has a test function")), integrals, span }
            }
            Rule::scheme_decl => self.scheme(span, next(), it)?,
            Rule::problem_decl => Item::Problem(Box::new(self.problem(span, next(), it)?)),
            Rule::functional_decl => {
                let name = self.ident(next());
                let mut fields = Vec::new();
                let mut integrals = Vec::new();
                for q in it {
                    match q.as_rule() {
                        Rule::ident_list => fields = q.into_inner().map(|i| self.ident(i)).collect(),
                        _ => integrals = self.integrals(q)?,
                    }
                }
                Item::Form { name, fields, test: None, integrals, span }
            }
            r => unreachable!("not an item: {r:?}"),
        })
    }

    pub(super) fn scheme(
        &self,
        span: Span,
        name: Pair<Rule>,
        rest: pest::iterators::Pairs<Rule>,
    ) -> Result<Item, Box<Diagnostic>> {
        let name = self.ident(name);
        let (mut params, mut states, mut initial, mut lets) = (Vec::new(), Vec::new(), None, Vec::new());
        let mut uses = Vec::new();
        let mut claims = Vec::new();
        let mut estimates = Vec::new();
        let mut stages: Vec<Stage> = Vec::new();
        // Items outside `stage` blocks form one implicit stage at t + dt.
        let mut implicit = Stage::default();
        for p in rest {
            match p.as_rule() {
                Rule::scheme_params => params = self.params(p.into_inner())?,
                Rule::uses_decl => {
                    let list = p.into_inner().next().expect("slot names");
                    uses.extend(list.into_inner().map(|i| self.ident(i)));
                }
                Rule::state_decl => {
                    let list = p.into_inner().next().expect("state names");
                    states.extend(list.into_inner().map(|i| self.ident(i)));
                }
                Rule::initial_decl => {
                    let span = self.span(&p);
                    let mut it = p.into_inner();
                    let unknown = self.ident(it.next().expect("initial unknown"));
                    let lhs = self.expr(it.next().expect("lhs"))?;
                    let rhs = self.expr(it.next().expect("rhs"))?;
                    initial = Some(Initial { unknown, residual: Residual { lhs, rhs, span }, span });
                }
                Rule::stage_block => {
                    let span = self.span(&p);
                    let mut stage = Stage { span: Some(span), ..Stage::default() };
                    for q in p.into_inner() {
                        match q.as_rule() {
                            Rule::ident => stage.name = Some(self.ident(q)),
                            Rule::expr => stage.at = Some(self.expr(q)?),
                            _ => self.stage_item(&mut stage, q)?,
                        }
                    }
                    stages.push(stage);
                }
                Rule::let_decl => {
                    let mut it = p.into_inner();
                    let name = self.ident(it.next().expect("let name"));
                    lets.push((name, self.expr(it.next().expect("let value"))?));
                }
                Rule::claim_decl => {
                    let mut it = p.into_inner();
                    let name = self.ident(it.next().expect("claim name"));
                    claims.push((name, self.expr(it.next().expect("claim value"))?));
                }
                Rule::estimate_decl => estimates.push(self.expr(p.into_inner().next().expect("estimate"))?),
                _ => self.stage_item(&mut implicit, p)?,
            }
        }
        let implicit_used = implicit.unknown.is_some() || !implicit.relates.is_empty() || implicit.residual.is_some();
        if implicit_used {
            if stages.is_empty() {
                stages.push(implicit);
            } else {
                let at = implicit
                    .relates
                    .first()
                    .map(|r| r.span)
                    .or(implicit.residual.as_ref().map(|r| r.span))
                    .unwrap_or(span);
                let d = Diagnostic::error(
                    "E0803",
                    "scheme items outside the `stage` blocks",
                    at,
                    "put this inside a stage",
                )
                .with_note("a scheme is either one implicit stage or a list of `stage NAME at TIME { ... }` blocks");
                return Err(Box::new(d));
            }
        }
        Ok(Item::Scheme { name, params, uses, states, lets, initial, claims, estimates, stages, span })
    }

    /// The params of a scheme or a problem: `name = default in RANGE, ...`.
    pub(super) fn params(&self, list: pest::iterators::Pairs<Rule>) -> Result<Vec<SchemeParam>, Box<Diagnostic>> {
        list.map(|q| {
            let span = self.span(&q);
            let mut it = q.into_inner();
            let name = self.ident(it.next().expect("param name"));
            let default = self.expr(it.next().expect("param default"))?;
            let range = it.next().map(|r| self.range(r)).transpose()?;
            Ok(SchemeParam { name, default, range, span })
        })
        .collect()
    }

    /// `name = expr` from its two pairs.
    pub(super) fn defined(
        &self,
        span: Span,
        name: Pair<Rule>,
        value: Option<Pair<Rule>>,
    ) -> Result<Defined, Box<Diagnostic>> {
        let name = self.ident(name);
        let value = self.expr(value.expect("grammar guarantees the value"))?;
        Ok(Defined { name, value, span })
    }

    pub(super) fn assignments(&self, p: Pair<Rule>) -> Result<Vec<Defined>, Box<Diagnostic>> {
        p.into_inner()
            .map(|q| {
                let span = self.span(&q);
                let mut it = q.into_inner();
                let name = it.next().expect("name");
                self.defined(span, name, it.next())
            })
            .collect()
    }

    pub(super) fn named_call(&self, p: Pair<Rule>) -> Result<NamedCall, Box<Diagnostic>> {
        let span = self.span(&p);
        let mut it = p.into_inner();
        let name = self.ident(it.next().expect("callee"));
        let args = it
            .map(|q| {
                let mut parts = q.into_inner();
                let name = self.ident(parts.next().expect("argument name"));
                Ok(NamedArg { name, value: self.expr(parts.next().expect("argument value"))? })
            })
            .collect::<Result<Vec<_>, Box<Diagnostic>>>()?;
        Ok(NamedCall { name, args, span })
    }

    /// `a < b and not (c > d or e >= f)`: `or` of `and`s of (negated) comparisons.
    pub(super) fn condition(&self, p: Pair<Rule>) -> Result<Condition, Box<Diagnostic>> {
        let one_or = |mut parts: Vec<Condition>, all: bool| {
            if parts.len() == 1 {
                parts.remove(0)
            } else if all {
                Condition::All(parts)
            } else {
                Condition::Any(parts)
            }
        };
        match p.as_rule() {
            Rule::condition | Rule::conjunction => {
                let all = p.as_rule() == Rule::conjunction;
                let parts = p.into_inner().map(|q| self.condition(q)).collect::<Result<Vec<_>, _>>()?;
                Ok(one_or(parts, all))
            }
            Rule::negation => {
                let mut it = p.into_inner().peekable();
                let negated = it.peek().is_some_and(|q| q.as_rule() == Rule::not_op);
                if negated {
                    it.next();
                }
                let inner = self.condition(it.next().expect("negated condition"))?;
                Ok(if negated { Condition::Not(Box::new(inner)) } else { inner })
            }
            _ => Ok(Condition::Compare(self.comparison(p)?)),
        }
    }

    pub(super) fn comparison(&self, p: Pair<Rule>) -> Result<Comparison, Box<Diagnostic>> {
        let span = self.span(&p);
        let mut it = p.into_inner();
        let lhs = self.expr(it.next().expect("lhs"))?;
        let op = match it.next().expect("comparison").as_str() {
            "<" => Compare::Less,
            "<=" => Compare::LessEqual,
            ">" => Compare::Greater,
            "==" => Compare::Equal,
            "!=" => Compare::NotEqual,
            _ => Compare::GreaterEqual,
        };
        let rhs = self.expr(it.next().expect("rhs"))?;
        Ok(Comparison { lhs, op, rhs, span })
    }

    pub(super) fn stage_item(&self, stage: &mut Stage, p: Pair<Rule>) -> Result<(), Box<Diagnostic>> {
        let span = self.span(&p);
        let rule = p.as_rule();
        let mut it = p.into_inner();
        match rule {
            Rule::let_decl => {
                let name = self.ident(it.next().expect("let name"));
                stage.lets.push((name, self.expr(it.next().expect("let value"))?));
            }
            Rule::unknown_decl => {
                let name = self.ident(it.next().expect("unknown name"));
                if let Some(prev) = &stage.unknown {
                    let d = Diagnostic::error("E0804", "a stage has one unknown", name.span, "second unknown")
                        .with_label(prev.span, "first unknown");
                    return Err(Box::new(d));
                }
                stage.unknown = Some(name);
            }
            Rule::new_decl => {
                let list = it.next().expect("new names");
                stage.news.extend(list.into_inner().map(|i| self.ident(i)));
            }
            Rule::relate_decl => {
                let name = self.ident(it.next().expect("relate name"));
                let value = self.expr(it.next().expect("relate value"))?;
                stage.relates.push(Relate { name, value, span });
            }
            Rule::residual_decl => {
                let lhs = self.expr(it.next().expect("lhs"))?;
                let rhs = self.expr(it.next().expect("rhs"))?;
                if let Some(prev) = &stage.residual {
                    let d = Diagnostic::error("E0804", "a stage has one residual", span, "second residual")
                        .with_label(prev.span, "first residual");
                    return Err(Box::new(d));
                }
                stage.residual = Some(Residual { lhs, rhs, span });
            }
            r => unreachable!("not a stage item: {r:?}"),
        }
        Ok(())
    }

    pub(super) fn range(&self, p: Pair<Rule>) -> Result<Range, Box<Diagnostic>> {
        let span = self.span(&p);
        let mut it = p.into_inner();
        let lo_closed = it.next().map(|b| b.as_str() == "[").unwrap_or(true);
        let lo = self.expr(it.next().expect("range lower bound"))?;
        let hi = self.expr(it.next().expect("range upper bound"))?;
        let hi_closed = it.next().map(|b| b.as_str() == "]").unwrap_or(true);
        Ok(Range { lo, lo_closed, hi, hi_closed, span })
    }

    pub(super) fn integrals(&self, p: Pair<Rule>) -> Result<Vec<Integral>, Box<Diagnostic>> {
        let mut out = Vec::new();
        let mut sign = 1.0;
        let mut sign_span: Option<Span> = None;
        for q in p.into_inner() {
            match q.as_rule() {
                Rule::sign => {
                    sign = if q.as_str() == "-" { -1.0 } else { 1.0 };
                    sign_span = Some(self.span(&q));
                }
                _ => {
                    let mut span = self.span(&q);
                    if let Some(s) = sign_span.take() {
                        span = s.to(span);
                    }
                    let mut it = q.into_inner();
                    let region = self.ident(it.next().expect("integral region"));
                    let mut next = it.next().expect("integrand");
                    let (mut degree, mut both_sides) = (None, None);
                    loop {
                        match next.as_rule() {
                            Rule::degree_arg => {
                                let number = next.into_inner().next().expect("degree");
                                let value = number.as_str().parse::<f64>().unwrap_or(f64::NAN);
                                degree = Some((value, self.span(&number)));
                            }
                            Rule::both_sides => both_sides = Some(self.span(&next)),
                            _ => break,
                        }
                        next = it.next().expect("integrand");
                    }
                    let integrand = self.expr(next)?;
                    out.push(Integral { sign, region, degree, both_sides, integrand, span });
                    sign = 1.0;
                }
            }
        }
        Ok(out)
    }

    pub(super) fn expr(&self, p: Pair<Rule>) -> Result<Expr, Box<Diagnostic>> {
        PRATT
            .map_primary(|q| self.primary(q))
            .map_prefix(|op, rhs| {
                let rhs = rhs?;
                let span = self.span(&op).to(rhs.span);
                Ok(Expr { kind: ExprKind::Neg(Box::new(rhs)), span })
            })
            .map_infix(|lhs, op, rhs| {
                let (lhs, rhs) = (lhs?, rhs?);
                let op = match op.as_rule() {
                    Rule::add => BinOp::Add,
                    Rule::sub => BinOp::Sub,
                    Rule::mul => BinOp::Mul,
                    Rule::div => BinOp::Div,
                    _ => BinOp::Pow,
                };
                let span = lhs.span.to(rhs.span);
                Ok(Expr { kind: ExprKind::Binary(op, Box::new(lhs), Box::new(rhs)), span })
            })
            .map_postfix(|lhs, op| {
                let lhs = lhs?;
                let span = lhs.span.to(self.span(&op));
                let index = self.expr(op.into_inner().next().expect("index expression"))?;
                Ok(Expr { kind: ExprKind::Index(Box::new(lhs), Box::new(index)), span })
            })
            .parse(p.into_inner())
    }

    pub(super) fn primary(&self, p: Pair<Rule>) -> Result<Expr, Box<Diagnostic>> {
        let span = self.span(&p);
        Ok(match p.as_rule() {
            Rule::number => match p.as_str().parse::<f64>() {
                Ok(v) if v.is_finite() => Expr { kind: ExprKind::Number(v), span },
                _ => {
                    let d =
                        Diagnostic::error("E0003", "number out of range", span, "not a finite double-precision number");
                    return Err(Box::new(d));
                }
            },
            Rule::ident => Expr { kind: ExprKind::Name(self.ident(p)), span },
            Rule::call => {
                let mut it = p.into_inner();
                let name = self.ident(it.next().expect("callee"));
                let args = it.map(|a| self.expr(a)).collect::<Result<Vec<_>, _>>()?;
                Expr { kind: ExprKind::Call(name, args), span }
            }
            Rule::vector => {
                let items = p.into_inner().map(|a| self.expr(a)).collect::<Result<Vec<_>, _>>()?;
                Expr { kind: ExprKind::Vector(items), span }
            }
            Rule::expr => {
                // Parenthesised: keep the span of the parentheses' content.
                self.expr(p)?
            }
            r => unreachable!("not a primary: {r:?}"),
        })
    }
}
