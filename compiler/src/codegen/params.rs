//! The parameter structs (the file's `Params`, one per scheme) with defaults, ranges as written,
//! getters and checked setters; and `Coefficients`, the case data.

use std::fmt::Write;

use signorini_descriptors::ParamRange;

use super::emit::{ADD, ATOM, MUL, UNARY, literal};
use super::names::{case_allowance, ident};
use crate::program::Program;
use crate::source::{SourceMap, Span};
use crate::syntax::ast::{self, BinOp, ExprKind};

/// A parameter as a generated struct declares it.
pub struct ParamDecl<'a> {
    pub name: &'a str,
    pub default: f64,
    pub range: Option<ParamRange>,
    /// The range as written, when declared.
    pub range_expr: Option<&'a ast::Range>,
    /// The default and range as written: `0.05 in [0, 1/3]`.
    pub written: String,
}

impl<'a> ParamDecl<'a> {
    /// A file's or a scheme's param, declared at `span`.
    pub fn new(
        sources: &SourceMap,
        name: &'a str,
        default: f64,
        range: Option<ParamRange>,
        range_expr: Option<&'a ast::Range>,
        span: Span,
    ) -> Self {
        ParamDecl { name, default, range, range_expr, written: crate::docs::written(sources, span) }
    }
}

/// The file's `Params`.
pub fn params_text(prog: &Program) -> String {
    let list: Vec<ParamDecl> = prog
        .params
        .iter()
        .map(|p| ParamDecl::new(&prog.sources, &p.name, p.default, p.range, p.range_expr.as_ref(), p.span))
        .collect();
    let doc = "/// Parameters, with the defaults and ranges declared in the source. Values are range-checked\n/// when set.\n";
    params_struct("Params", doc, &list)
}

/// A struct of named f64 parameters with defaults, ranges, getters and checked setters.
pub fn params_struct(name: &str, doc: &str, params: &[ParamDecl]) -> String {
    let mut s = String::new();
    let allow = case_allowance(params.iter().map(|p| ident(p.name)).collect::<Vec<_>>().iter().map(String::as_str));
    s.push_str(doc);
    // f64's default is 0.0: a struct whose defaults are all zero derives it.
    let derived = params.iter().all(|p| p.default.to_bits() == 0.0f64.to_bits());
    let derives = if derived { "Clone, Copy, Debug, Default, PartialEq" } else { "Clone, Copy, Debug, PartialEq" };
    let _ = writeln!(s, "#[derive({derives})]\n{allow}pub struct {name} {{");
    for p in params {
        let _ = writeln!(s, "{}: f64,", ident(p.name));
    }
    s.push_str("}\n");
    if !derived {
        let _ = writeln!(s, "impl Default for {name} {{ fn default() -> Self {{ {name} {{");
        for p in params {
            let _ = writeln!(s, "{}: {},", ident(p.name), literal(p.default).0);
        }
        s.push_str("} } }\n");
    }
    let _ = writeln!(s, "{allow}impl {name} {{");
    let names: Vec<String> = params.iter().map(|p| format!("{:?}", p.name)).collect();
    let _ =
        writeln!(s, "/// Parameter names, in declaration order.\npub const NAMES: &[&str] = &[{}];", names.join(", "));
    s.push_str("/// Declared ranges, in declaration order.\npub const RANGES: &[ParamRange] = &[\n");
    for p in params {
        s.push_str(&range_text(p));
    }
    s.push_str("];\n");
    for p in params {
        let _ = writeln!(
            s,
            "/// `{}` (default {}).\npub fn {}(&self) -> f64 {{ self.{} }}",
            p.name,
            p.written,
            ident(p.name),
            ident(p.name)
        );
    }
    s.push_str(&get_and_set(params));
    s.push_str("/// `set`, by value.\npub fn with(mut self, name: &str, value: f64) -> Result<Self, ParamError> { self.set(name, value)?; Ok(self) }\n");
    s.push_str("}\n");
    s
}

/// `ParamRange { ... }` of a parameter, its bounds as written where they are numbers and
/// arithmetic of them (evaluated by Rust as by the checker: the same operations on f64).
fn range_text(p: &ParamDecl) -> String {
    let r = p.range.unwrap_or(ParamRange::UNBOUNDED);
    let bound = |e: Option<&ast::Expr>, v: f64| e.and_then(as_rust).map_or_else(|| literal(v).0, |(t, _)| t);
    let (lo, hi) = (bound(p.range_expr.map(|r| &r.lo), r.lo), bound(p.range_expr.map(|r| &r.hi), r.hi));
    format!("ParamRange {{ lo: {lo}, lo_closed: {}, hi: {hi}, hi_closed: {} }},\n", r.lo_closed, r.hi_closed)
}

/// A constant expression of the source as Rust, with its precedence: numbers, `inf`, `pi`,
/// negation and `+ - * /`, which Rust rounds as the checker does. Not powers or functions
/// (`sin(1)`): libm's results are not correctly rounded, so such a bound is written as the
/// checker's value, whose bits the range checks of the checker and of the code then share.
fn as_rust(e: &ast::Expr) -> Option<(String, u8)> {
    let wrap = |(t, p): (String, u8), min: u8| if p < min { format!("({t})") } else { t };
    match &e.kind {
        ExprKind::Number(v) => Some(literal(*v)),
        ExprKind::Name(id) if id.name == "inf" => Some(("f64::INFINITY".into(), ATOM)),
        ExprKind::Name(id) if id.name == "pi" => Some(("std::f64::consts::PI".into(), ATOM)),
        ExprKind::Neg(a) => Some((format!("-{}", wrap(as_rust(a)?, UNARY)), UNARY)),
        ExprKind::Binary(op, a, b) => {
            let (sign, prec) = match op {
                BinOp::Add => ("+", ADD),
                BinOp::Sub => ("-", ADD),
                BinOp::Mul => ("*", MUL),
                BinOp::Div => ("/", MUL),
                BinOp::Pow => return None,
            };
            Some((format!("{} {sign} {}", wrap(as_rust(a)?, prec), wrap(as_rust(b)?, prec + 1)), prec))
        }
        _ => None,
    }
}

/// `get` and `set` by name.
fn get_and_set(params: &[ParamDecl]) -> String {
    let mut s = String::new();
    s.push_str("/// The value of a parameter by name.\n");
    if params.is_empty() {
        s.push_str("pub fn get(&self, _name: &str) -> Option<f64> { None }\n");
    } else {
        s.push_str("pub fn get(&self, name: &str) -> Option<f64> { match name {\n");
        for p in params {
            let _ = writeln!(s, "{:?} => Some(self.{}),", p.name, ident(p.name));
        }
        s.push_str("_ => None } }\n");
    }
    s.push_str("/// Sets a parameter by name, refusing unknown names and values outside the declared range.\n");
    if params.is_empty() {
        s.push_str("pub fn set(&mut self, name: &str, _value: f64) -> Result<(), ParamError> { Err(ParamError::unknown(name, Self::NAMES)) }\n");
    } else {
        s.push_str("pub fn set(&mut self, name: &str, value: f64) -> Result<(), ParamError> { match name {\n");
        for (i, p) in params.iter().enumerate() {
            let _ =
                writeln!(s, "{:?} => self.{} = check_param(name, &Self::RANGES[{i}], value)?,", p.name, ident(p.name));
        }
        s.push_str("_ => return Err(ParamError::unknown(name, Self::NAMES)),\n} Ok(()) }\n");
    }
    s
}

/// `Coefficients`, the case data.
pub fn coefs_text(prog: &Program) -> String {
    let mut s = String::new();
    let allow =
        case_allowance(prog.coefs.iter().map(|c| ident(&c.name)).collect::<Vec<_>>().iter().map(String::as_str));
    s.push_str("/// Case data (`coef` declarations): constants or functions of position and time.\n");
    s.push_str("#[derive(Clone, Debug");
    if prog.coefs.is_empty() {
        s.push_str(", Default");
    }
    let _ = writeln!(s, ")]\n{allow}pub struct Coefficients {{");
    for c in &prog.coefs {
        let _ = writeln!(s, "/// `coef {}: {}`\npub {}: Coef,", c.name, c.shape.name(), ident(&c.name));
    }
    s.push_str("}\n");
    s.push_str("impl Coefficients {\n/// Checks that every coef has the number of components its shape needs in dimension `dim`.\n");
    let dim = if prog.coefs.is_empty() { "_dim" } else { "dim" };
    let _ = writeln!(s, "pub fn check(&self, {dim}: usize) -> Result<(), String> {{");
    for c in &prog.coefs {
        let rank = c.shape.rank();
        let _ =
            writeln!(s, "check_coef({:?}, &self.{}, {rank}, dim).map_err(|e| e.to_string())?;", c.name, ident(&c.name));
    }
    s.push_str("Ok(()) }\n}\n");
    s
}
