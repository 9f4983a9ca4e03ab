//! A problem's summary keys (`summary NAME = EXPR`): expressions of reducers over the rows
//! (`max(penetration)`, `first(t, active_points)`, `at_max(...)`, `sum(...)`), of their values and of
//! the keys before, compiled once and evaluated on the finished series.

use super::ProblemFile;
use super::expr::{At, Exprs, PointFn};
use super::observe::placeholder;
use crate::compiler::ir::lower::Val;
use crate::compiler::syntax::ast::{Expr, ExprKind, Ident};
use crate::error::CaseError;

// A summary reducer over the rows: the catalogue's.
use crate::compiler::check::problem::SummaryReducer as Reduce;

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
/// difference, relative |value − expected| / |expected| or, when the expected value is 0,
/// absolute |value| (`absolute`), and whether it is within TOL.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize, PartialEq)]
pub struct Expectation {
    pub key: String,
    pub value: Option<f64>,
    pub expected: Option<f64>,
    pub difference: Option<f64>,
    /// The difference and the tolerance are absolute (the expected value is 0), not relative.
    pub absolute: bool,
    pub within: f64,
    pub met: bool,
    /// Whether its `when` holds on this run (an expectation that does not apply is not met,
    /// and not a failure).
    #[serde(default = "yes")]
    pub applies: bool,
}

fn yes() -> bool {
    true
}

impl Expectation {
    /// The value, the expected value, the difference (`1.7e-2 relative`, `3.1e-11 absolute`)
    /// and the tolerance as a table or a line shows them (`none` where there is none).
    pub fn shown(&self) -> [String; 4] {
        use crate::numbers::readable;
        let number = |x: Option<f64>| x.map_or("none".to_string(), readable);
        let kind = self.kind();
        [
            number(self.value),
            number(self.expected),
            self.difference.map_or("none".to_string(), |d| format!("{} {kind}", readable(d))),
            format!("{} {kind}", readable(self.within)),
        ]
    }

    /// `absolute` or `relative`: how the difference and the tolerance are measured.
    pub fn kind(&self) -> &'static str {
        if self.absolute { "absolute" } else { "relative" }
    }
}

/// The problem's summary keys, compiled.
pub struct SummaryKeys {
    /// The problem's keys, then one hidden key per expectation (its expected value).
    keys: Vec<Key>,
    /// Per expectation: the key it names, its tolerance, and whether its value compiled (an
    /// expected value these params make infinite, v0/μ at μ = 0, has none).
    expects: Vec<(String, f64, bool)>,
    /// Per expectation: whether its `when` holds on this run.
    applies: Vec<bool>,
    /// The keys left out of this run (they read a column left out, or such a key), and why.
    pub left_out: Vec<(String, String)>,
    columns: usize,
    /// The names the reducers' expression arguments read (not plain columns).
    read_by_expressions: Vec<String>,
}

impl SummaryKeys {
    /// `columns`: every column's name, in row order; `applies`: per expectation, whether its
    /// `when` holds ([`applies`]).
    /// `left_out`: the columns this run does not measure; the keys and expectations that read
    /// them are left out too.
    pub fn new(
        pf: &ProblemFile,
        ex: &mut Exprs,
        columns: &[String],
        mut applies: Vec<bool>,
        left_out: &[String],
    ) -> Result<SummaryKeys, CaseError> {
        let mut absent: Vec<String> = left_out.to_vec();
        let mut skipped: Vec<(String, String)> = Vec::new();
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
            let mut read = Vec::new();
            names_in(value, &mut read);
            if let Some(missing) = read.iter().find(|n| absent.contains(n)) {
                match expect {
                    Some(i) => {
                        expects[i].2 = false;
                        applies[i] = false;
                    }
                    None => {
                        skipped.push((name.clone(), format!("it reads `{missing}`, left out")));
                        absent.push(name);
                    }
                }
                continue;
            }
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
        Ok(SummaryKeys { keys, expects, applies, left_out: skipped, columns: columns.len(), read_by_expressions })
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
            .zip(&self.applies)
            .map(|((key, within, ok), applies)| {
                let expected = if *ok { expected.next().flatten() } else { None };
                let value = all.iter().find(|(k, _)| k == key).and_then(|(_, v)| *v);
                let absolute = expected == Some(0.0);
                let difference =
                    value.zip(expected).map(|(v, e)| if absolute { v.abs() } else { (v - e).abs() / e.abs() });
                let met = *applies && difference.is_some_and(|r| r <= *within);
                Expectation {
                    key: key.clone(),
                    value,
                    expected,
                    difference,
                    absolute,
                    within: *within,
                    met,
                    applies: *applies,
                }
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
                        Reduce::Integral => {
                            let points: Vec<(f64, f64)> =
                                rows.iter().map(|row| (row.0, arg(a, row))).filter(|(_, v)| !v.is_nan()).collect();
                            points.windows(2).fold(0.0, |s, w| s + 0.5 * (w[1].0 - w[0].0) * (w[0].1 + w[1].1))
                        }
                        Reduce::Crest => {
                            let points: Vec<(f64, f64)> =
                                rows.iter().map(|row| (row.0, arg(a, row))).filter(|(_, v)| !v.is_nan()).collect();
                            crest(&points)?
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

/// The largest of the values (t, f), refined by the parabola through it and its neighbours:
/// the peak of a smooth f between two rows, exact for a quadratic one (the largest value itself
/// at the first or last row, or where the parabola does not open downwards). None without rows.
fn crest(points: &[(f64, f64)]) -> Option<f64> {
    let (i, &(t1, f1)) = points.iter().enumerate().max_by(|a, b| a.1.1.total_cmp(&b.1.1))?;
    let (Some(&(t0, f0)), Some(&(t2, f2))) = (i.checked_sub(1).and_then(|j| points.get(j)), points.get(i + 1)) else {
        return Some(f1);
    };
    // f = f1 + b·s + c·s² with s = t − t1, through the three rows.
    let (s0, s2) = (t0 - t1, t2 - t1);
    let (d0, d2) = ((f0 - f1) / s0, (f2 - f1) / s2);
    let c = (d2 - d0) / (s2 - s0);
    let b = d2 - c * s2;
    Some(if c < 0.0 { f1 - b * b / (4.0 * c) } else { f1 })
}

/// `e` with each reducer call replaced by a placeholder; the calls are collected.
fn summary_rewrite(e: &Expr, calls: &mut Vec<(Reduce, Vec<Expr>)>) -> Expr {
    let kind = match &e.kind {
        ExprKind::Call(f, args) => {
            // A function of a number (`sqrt`): kept, its argument rewritten.
            let Some(r) = crate::compiler::check::problem::summary_reducer(&f.name) else {
                let args = args.iter().map(|a| summary_rewrite(a, calls)).collect();
                return Expr { kind: ExprKind::Call(f.clone(), args), span: e.span };
            };
            calls.push((r.reducer, args.clone()));
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
    out.extend(crate::compiler::check::problem::names_in(e).into_iter().map(|id| id.name.clone()));
}

/// Per `expect` line, whether its `when` holds on this run: a condition of the problem's params
/// and `let`s and of the params of the files in use (by name, as `set` names them). A param
/// only files not in use declare (another law's `F`) makes it not apply; a name no file of the
/// library declares either is an error at it.
pub fn applies(pf: &ProblemFile, ex: &mut Exprs, files: &crate::driver::params::Table) -> Result<Vec<bool>, CaseError> {
    use crate::compiler::Diagnostic;
    let mut out = Vec::new();
    for x in &pf.problem().expects {
        let Some(when) = &x.when else {
            out.push(true);
            continue;
        };
        let mut names = Vec::new();
        for c in when.comparisons() {
            names.extend(crate::compiler::check::problem::names_in(&c.lhs));
            names.extend(crate::compiler::check::problem::names_in(&c.rhs));
        }
        let mut extra: Vec<(String, Val)> = Vec::new();
        let mut in_use = true;
        for id in names {
            if ex.constant(&id.name).is_some() || extra.iter().any(|(n, _)| *n == id.name) {
                continue;
            }
            match files.lookup(&id.name) {
                Ok(Some(value)) => extra.push((id.name.clone(), ex.low.constant_val(value))),
                Ok(None) if crate::driver::library_declares(&id.name) => in_use = false,
                Ok(None) => {
                    let p = pf.problem();
                    let own = p.params.iter().map(|q| &q.name).chain(p.lets.iter().map(|l| &l.name));
                    let known: Vec<String> = own.map(|n| n.name.clone()).chain(files.names()).collect();
                    let mut d = Diagnostic::error(
                        "E0101",
                        format!("unknown param `{}`", id.name),
                        id.span,
                        "no file declares it",
                    )
                    .with_note(format!(
                        "`when` reads the problem's params and `let`s, and the params of the files in use: {}",
                        known.join(", ")
                    ));
                    if let Some(s) = crate::compiler::check::suggest_name(&id.name, known.iter().map(String::as_str)) {
                        d = d.with_help(format!("did you mean `{s}`?"));
                    }
                    return Err(pf.render(d));
                }
                Err(choices) => {
                    return Err(pf.render(crate::compiler::check::problem::ambiguous_param(id, &choices).with_help(
                        "compare a problem param the problem sets it from (`when F == mu` after `set F = mu`)",
                    )));
                }
            }
        }
        if !in_use {
            out.push(false);
            continue;
        }
        let mut holds = Vec::new();
        for c in when.comparisons() {
            let lhs = ex.scalar_with(&c.lhs, &extra).map_err(|e| pf.render(*e))?;
            let rhs = ex.scalar_with(&c.rhs, &extra).map_err(|e| pf.render(*e))?;
            holds.push(c.op.holds(lhs, rhs));
        }
        out.push(when.holds(&mut holds.into_iter()));
    }
    Ok(out)
}

#[cfg(test)]
mod crest_tests {
    /// Exact on a parabola sampled at uneven times; the largest sample at an end stays.
    #[test]
    fn the_crest_of_a_parabola_is_its_vertex() {
        let f = |t: f64| 2.0 - 3.0 * (t - 0.37) * (t - 0.37);
        let points: Vec<(f64, f64)> = [0.0, 0.1, 0.3, 0.45, 0.8, 1.0].iter().map(|&t| (t, f(t))).collect();
        assert!((super::crest(&points).unwrap() - 2.0).abs() < 1e-12);
        let rising: Vec<(f64, f64)> = [0.0, 0.1, 0.2].iter().map(|&t| (t, t)).collect();
        assert_eq!(super::crest(&rising), Some(0.2));
        assert_eq!(super::crest(&[]), None);
    }
}
