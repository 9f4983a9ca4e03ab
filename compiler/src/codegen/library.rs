//! The registry entry of a generated module: its params (with docs and declaration sites), coefs
//! and slots as data (as `describe` builds them), and the functions that instantiate its forms
//! and schemes by slot name.

use std::fmt::Write;

use super::descriptors;
use super::names::{case_allowance, ident};
use crate::docs;
use crate::program::Program;
use crate::scheme::SchemeIr;

/// `PARAMS`, `COEFS`, `SLOTS` and `make` for the forms declared in the file (`own`: form index
/// and struct name).
pub fn forms_items(prog: &Program, own: &[(usize, &str)]) -> String {
    let mut s = String::new();
    let params: Vec<String> = crate::describe::params(prog)
        .iter()
        .enumerate()
        .map(|(i, p)| descriptors::param(p, &format!("Params::RANGES[{i}]")))
        .collect();
    let _ = writeln!(
        s,
        "/// Every param the forms read (imports included), in `Params` order.\npub const PARAMS: &[ParamInfo] = &[{}];",
        params.join(", ")
    );
    let coefs: Vec<String> = crate::describe::coefs(prog).iter().map(descriptors::coef).collect();
    let _ = writeln!(s, "/// The case data the forms read.\npub const COEFS: &[CoefInfo] = &[{}];", coefs.join(", "));
    let slots: Vec<String> = crate::describe::slots(prog).iter().map(descriptors::slot).collect();
    let _ = writeln!(
        s,
        "/// The forms and functionals of this file.\npub const SLOTS: &[SlotInfo] = &[{}];",
        slots.join(", ")
    );
    s.push_str("/// Instantiates every form of this file on a mesh: param values in `PARAMS` order, coefs by name.\n");
    let coefs = if prog.coefs.is_empty() { "_coefs" } else { "coefs" };
    let _ = writeln!(
        s,
        "pub fn make<'m>(values: &[f64], {coefs}: &dyn Fn(&str) -> Option<Coef>, bind: &Binding<'m>) -> Result<Made<'static, 'm>, LibraryError> {{"
    );
    s.push_str("let mut params = Params::default();\n");
    s.push_str("for (name, value) in Params::NAMES.iter().zip(values) { params.set(name, *value)?; }\n");
    let fields: Vec<String> = prog
        .coefs
        .iter()
        .enumerate()
        .map(|(i, c)| format!("{}: need_coef(coefs, &COEFS[{i}])?", ident(&c.name)))
        .collect();
    let _ = writeln!(s, "let coefs = Coefficients {{ {} }};", fields.join(", "));
    s.push_str("coefs.check(bind.dim).map_err(LibraryError::Coef)?;\n");
    let made: Vec<String> = own
        .iter()
        .map(|&(fi, sname)| {
            let f = &prog.forms[fi];
            let how = if f.test.is_some() { "form" } else { "functional" };
            format!("({:?}, bind.{how}({sname}::new(&params, &coefs))?)", f.name)
        })
        .collect();
    let _ = writeln!(s, "Ok(vec![{}])\n}}", made.join(", "));
    s
}

/// A scheme's `SchemeUnit` expression, after the items it refers to (its `make` function).
pub fn scheme_unit(prog: &Program, sch: &SchemeIr, struct_name: &str) -> (String, String) {
    let src = &prog.sources;
    let make = format!("make_{}", ident(&sch.name));
    let mut items = String::new();
    let _ = writeln!(
        items,
        "/// Scheme `{}` with param values in declaration order.\n{}fn {make}(values: &[f64]) -> Result<Box<dyn TimeScheme>, LibraryError> {{\nlet mut scheme = {struct_name}::default();\nfor (name, value) in {struct_name}::NAMES.iter().zip(values) {{ scheme.set(name, *value)?; }}\nOk(Box::new(scheme))\n}}",
        sch.name,
        case_allowance([make.as_str()])
    );
    let params: Vec<String> = crate::describe::scheme_params(prog, sch)
        .iter()
        .enumerate()
        .map(|(i, p)| descriptors::param(p, &format!("{struct_name}::RANGES[{i}]")))
        .collect();
    let unit = format!(
        "SchemeUnit {{ name: {:?}, doc: {:?}, params: &[{}], desc: &{struct_name}::DESC, make: {make} }}",
        sch.name,
        docs::declaration(src, sch.span),
        params.join(", ")
    );
    (items, unit)
}
