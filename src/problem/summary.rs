//! A problem's summary keys (`summary NAME = EXPR`): expressions of reducers over the rows
//! (`max(penetration)`, `first(t, active_points)`, `at_max(...)`, `sum(...)`), of their values and of
//! the keys before, compiled once and evaluated on the finished series.

use super::ProblemFile;
use super::expr::{At, Exprs, PointFn};
use super::observe::placeholder;
use crate::compiler::ir::lower::Val;
use crate::compiler::syntax::ast::{Expr, ExprKind, Ident};
use crate::error::CaseError;

/// A summary reducer over the rows.
#[derive(Clone, Copy)]
enum Reduce {
    Initial,
    Final,
    Min,
    Max,
    Sum,
    /// The first argument at the first row where the second is positive.
    First,
    /// The first argument at the first row where the second is largest (NaN rows left out).
    AtMax,
}

/// A reducer's argument: a column as it is (`None`: the row's time), or an expression of the
/// row (its columns, `t` and the keys before).
enum Arg {
    Column(Option<usize>),
    Expr(PointFn),
}

/// One summary key: its reducers and its expression of their values and the keys before it.
struct Key {
    name: String,
    reduces: Vec<(Reduce, Vec<Arg>)>,
    f: PointFn,
}

/// `expect KEY = VALUE within TOL`, measured: the key's value, the expected one, their
/// relative difference |value − expected| / |expected| (absolute, |value|, when the expected
/// value is 0) and whether it is within TOL.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize, PartialEq)]
pub struct Expectation {
    pub key: String,
    pub value: Option<f64>,
    pub expected: Option<f64>,
    pub relative: Option<f64>,
    pub within: f64,
    pub met: bool,
}

impl Expectation {
    /// The value, the expected value and the relative difference as a table shows them
    /// (`none` where there is none).
    pub fn shown(&self) -> [String; 3] {
        let number = |x: Option<f64>| x.map_or("none".to_string(), |x| format!("{x:.6}"));
        [number(self.value), number(self.expected), self.relative.map_or("none".to_string(), |r| format!("{r:.2e}"))]
    }
}

/// The problem's summary keys, compiled.
pub struct SummaryKeys {
    /// The problem's keys, then one hidden key per expectation (its expected value).
    keys: Vec<Key>,
    /// Per expectation: the key it names, its tolerance, and whether its value compiled (an
    /// expected value these params make infinite, v0/μ at μ = 0, has none).
    expects: Vec<(String, f64, bool)>,
    columns: usize,
    /// The names the reducers' expression arguments read (not plain columns).
    read_by_expressions: Vec<String>,
}

impl SummaryKeys {
    /// `columns`: every column's name, in row order.
    pub fn new(pf: &ProblemFile, ex: &mut Exprs, columns: &[String]) -> Result<SummaryKeys, CaseError> {
        let mut keys: Vec<Key> = Vec::new();
        let mut read_by_expressions = Vec::new();
        // In a reducer's argument: column i is measured value i, key j is measured value
        // columns + j.
        let mut row_scope: Vec<(String, Val)> =
            columns.iter().enumerate().map(|(i, c)| (c.clone(), ex.measured(i, 1))).collect();
        let p = pf.problem();
        let mut expects: Vec<(String, f64, bool)> = p
            .expects
            .iter()
            .map(|x| (x.key.name.clone(), crate::compiler::check::const_value(&x.within).unwrap_or(0.0), true))
            .collect();
        let hidden = p.expects.iter().enumerate().map(|(i, x)| (Some(i), format!("#expect {}", x.key.name), &x.value));
        let all = p.summary.iter().map(|d| (None, d.name.name.clone(), &d.value)).chain(hidden);
        for (expect, name, value) in all {
            let mut calls = Vec::new();
            let rewritten = summary_rewrite(value, &mut calls);
            let mut reduces = Vec::new();
            for (r, args) in calls {
                let mut compiled = Vec::new();
                for a in &args {
                    compiled.push(match &a.kind {
                        ExprKind::Name(n) if n.name == "t" => Arg::Column(None),
                        ExprKind::Name(n) if columns.contains(&n.name) => {
                            Arg::Column(columns.iter().position(|c| *c == n.name))
                        }
                        _ => {
                            names_in(a, &mut read_by_expressions);
                            let val = ex.lower(a, &row_scope).map_err(|e| pf.render(*e))?;
                            Arg::Expr(ex.function(&val, a).map_err(|e| pf.render(*e))?)
                        }
                    });
                }
                reduces.push((r, compiled));
            }
            // Reducer i is measured value i; key j is measured value reducers + j.
            let mut scope: Vec<(String, Val)> =
                (0..reduces.len()).map(|i| (placeholder(i), ex.measured(i, 1))).collect();
            for (j, k) in keys.iter().enumerate() {
                scope.push((k.name.clone(), ex.measured(reduces.len() + j, 1)));
            }
            let compiled = ex.lower(&rewritten, &scope).and_then(|val| ex.function(&val, value));
            let f = match (compiled, expect) {
                (Ok(f), _) => f,
                (Err(_), Some(i)) => {
                    expects[i].2 = false;
                    continue;
                }
                (Err(e), None) => return Err(pf.render(*e)),
            };
            row_scope.push((name.clone(), ex.measured(columns.len() + keys.len(), 1)));
            keys.push(Key { name, reduces, f });
        }
        Ok(SummaryKeys { keys, expects, columns: columns.len(), read_by_expressions })
    }

    /// The (column, of) pairs of `at_max(column, of)` whose column no other reducer reads: the
    /// column is needed only at the rows where `of` reaches a new maximum ([`Observer::defer`]).
    pub fn at_max_columns(&self, names: &[String]) -> Vec<(usize, usize)> {
        let reads = |c: usize, except: Option<(usize, usize)>| {
            self.read_by_expressions.contains(&names[c])
                || self.keys.iter().flat_map(|k| &k.reduces).any(|(r, args)| {
                    let pair = match (r, &args[..]) {
                        (Reduce::AtMax, [Arg::Column(Some(e)), Arg::Column(Some(w))]) => Some((*e, *w)),
                        _ => None,
                    };
                    pair != except && args.iter().any(|a| matches!(a, Arg::Column(Some(i)) if *i == c))
                })
        };
        let mut out = Vec::new();
        for (r, args) in self.keys.iter().flat_map(|k| &k.reduces) {
            if let (Reduce::AtMax, [Arg::Column(Some(e)), Arg::Column(Some(w))]) = (r, &args[..])
                && !reads(*e, Some((*e, *w)))
                && !out.contains(&(*e, *w))
            {
                out.push((*e, *w));
            }
        }
        out
    }

    /// The problem's keys and their values over `rows` (time, values), null where a reducer has
    /// none; and its expectations.
    pub fn values(&self, rows: &[(f64, Vec<f64>)]) -> (Vec<(String, Option<f64>)>, Vec<Expectation>) {
        let mut all = self.all_values(rows);
        let compiled = self.expects.iter().filter(|e| e.2).count();
        let mut expected = all.split_off(all.len() - compiled).into_iter().map(|(_, v)| v);
        let expectations = self
            .expects
            .iter()
            .map(|(key, within, ok)| {
                let expected = if *ok { expected.next().flatten() } else { None };
                let value = all.iter().find(|(k, _)| k == key).and_then(|(_, v)| *v);
                let relative =
                    value.zip(expected).map(|(v, e)| if e == 0.0 { v.abs() } else { (v - e).abs() / e.abs() });
                let met = relative.is_some_and(|r| r <= *within);
                Expectation { key: key.clone(), value, expected, relative, within: *within, met }
            })
            .collect();
        (all, expectations)
    }

    /// Every key's value, the hidden expected values last.
    fn all_values(&self, rows: &[(f64, Vec<f64>)]) -> Vec<(String, Option<f64>)> {
        let mut out: Vec<(String, Option<f64>)> = Vec::new();
        // A row as measured values: its columns, then the keys so far.
        let mut at_row: Vec<Vec<f64>> = vec![vec![0.0]; self.columns + self.keys.len()];
        let mut scratch = Vec::new();
        for key in &self.keys {
            for (j, (_, v)) in out.iter().enumerate() {
                at_row[self.columns + j][0] = v.unwrap_or(f64::NAN);
            }
            let mut arg = |a: &Arg, r: &(f64, Vec<f64>)| -> f64 {
                match a {
                    Arg::Column(c) => c.map_or(r.0, |i| r.1[i]),
                    Arg::Expr(f) => {
                        for (slot, v) in at_row.iter_mut().zip(&r.1) {
                            slot[0] = *v;
                        }
                        let mut o = [0.0];
                        f.eval(&At { t: r.0, measured: &at_row, ..At::default() }, &mut scratch, &mut o);
                        o[0]
                    }
                }
            };
            let measured: Option<Vec<Vec<f64>>> = key
                .reduces
                .iter()
                .map(|(r, args)| {
                    let a = &args[0];
                    Some(vec![match r {
                        Reduce::Initial => arg(a, rows.first()?),
                        Reduce::Final => arg(a, rows.last()?),
                        Reduce::Min | Reduce::Max => {
                            let mut values = Vec::new();
                            for row in rows {
                                if args.get(1).is_none_or(|w| arg(w, row) > 0.0) {
                                    values.push(arg(a, row));
                                }
                            }
                            match r {
                                Reduce::Min => values.into_iter().fold(f64::INFINITY, f64::min),
                                _ => values.into_iter().fold(f64::NEG_INFINITY, f64::max),
                            }
                        }
                        Reduce::Sum => {
                            rows.iter().map(|row| arg(a, row)).filter(|v| !v.is_nan()).fold(0.0, |s, v| s + v)
                        }
                        Reduce::First => {
                            let row = rows.iter().find(|row| arg(&args[1], row) > 0.0)?;
                            arg(a, row)
                        }
                        Reduce::AtMax => {
                            let mut best: Option<(f64, &(f64, Vec<f64>))> = None;
                            for row in rows {
                                let w = arg(&args[1], row);
                                if !w.is_nan() && best.is_none_or(|(b, _)| w > b) {
                                    best = Some((w, row));
                                }
                            }
                            arg(a, best?.1)
                        }
                    }])
                })
                .collect();
            let value = measured.map(|mut m| {
                m.extend(out.iter().map(|(_, v)| vec![v.unwrap_or(f64::NAN)]));
                let mut o = [0.0];
                key.f.eval(&At { measured: &m, ..At::default() }, &mut scratch, &mut o);
                o[0]
            });
            out.push((key.name.clone(), value));
        }
        out
    }
}

/// `e` with each reducer call replaced by a placeholder; the calls are collected.
fn summary_rewrite(e: &Expr, calls: &mut Vec<(Reduce, Vec<Expr>)>) -> Expr {
    let kind = match &e.kind {
        ExprKind::Call(f, args) => {
            let r = match f.name.as_str() {
                "initial" => Reduce::Initial,
                "final" => Reduce::Final,
                "min" => Reduce::Min,
                "max" => Reduce::Max,
                "sum" => Reduce::Sum,
                "first" => Reduce::First,
                "at_max" => Reduce::AtMax,
                // A function of a number (`sqrt`): kept, its argument rewritten.
                _ => {
                    let args = args.iter().map(|a| summary_rewrite(a, calls)).collect();
                    return Expr { kind: ExprKind::Call(f.clone(), args), span: e.span };
                }
            };
            calls.push((r, args.clone()));
            ExprKind::Name(Ident { name: placeholder(calls.len() - 1), span: e.span })
        }
        ExprKind::Neg(a) => ExprKind::Neg(Box::new(summary_rewrite(a, calls))),
        ExprKind::Binary(op, a, b) => {
            ExprKind::Binary(*op, Box::new(summary_rewrite(a, calls)), Box::new(summary_rewrite(b, calls)))
        }
        other => other.clone(),
    };
    Expr { kind, span: e.span }
}

/// Every name an expression reads.
fn names_in(e: &Expr, out: &mut Vec<String>) {
    match &e.kind {
        ExprKind::Name(n) => out.push(n.name.clone()),
        ExprKind::Neg(a) => names_in(a, out),
        ExprKind::Binary(_, a, b) => {
            names_in(a, out);
            names_in(b, out);
        }
        ExprKind::Call(_, args) => args.iter().for_each(|a| names_in(a, out)),
        ExprKind::Vector(items) => items.iter().for_each(|a| names_in(a, out)),
        ExprKind::Index(a, i) => {
            names_in(a, out);
            names_in(i, out);
        }
        _ => {}
    }
}
