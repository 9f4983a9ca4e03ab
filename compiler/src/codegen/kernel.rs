//! Element kernels of one form in one dimension: its kernel plan (`ir::plan`) written out as
//! Rust, for each integral the residual and the tangent with respect to each field argument
//! as loops over quadrature points and local nodes, the plan's roots as straight-line code
//! (`emit`) and its terms as the sums over basis functions. What is left here is naming.

use std::collections::HashMap;
use std::fmt::Write;

use super::emit::{Emitter, UNARY};
use super::names::{Namer, ident, words};
use crate::ir::graph::{Graph, NodeId, Sym};
use crate::ir::plan::{self, Array, Basis, Body, Contract, Decided, Integral, Leaf, Root, Terms};
use crate::ir::{DimIr, FormIr};
use crate::program::Program;

/// Locals every kernel may define.
const RESERVED: &[&str] = &[
    "self",
    "ctx",
    "fields",
    "out",
    "wrt",
    "region",
    "q",
    "i",
    "j",
    "w",
    "phi",
    "dphi",
    "jac",
    "n",
    "scale",
    "x",
    "h",
    "t",
    "N",
    "geometry",
    "heaviside",
    "Params",
    "Coefficients",
    "total",
    "value",
    "gated",
    "std",
];

/// A method's parameters, named `_name` where its body does not read them.
fn params(body: &str, list: &[(&str, String)]) -> String {
    let words = words(body);
    let named: Vec<String> = list
        .iter()
        .map(|(name, ty)| if words.contains(*name) { format!("{name}: {ty}") } else { format!("_{name}: {ty}") })
        .collect();
    named.join(", ")
}

/// `match on { k => { ... } ... _ => other }` over the arms that have something to do, or an
/// `if` (`else { other }`) for a single one; `None` without any. `other` is the value of the
/// arms not listed, `None` for a method that returns nothing.
fn dispatch(on: &str, arms: Vec<(usize, String)>, other: Option<&str>) -> Option<String> {
    let otherwise = other.map_or(String::new(), |o| format!(" else {{\n{o}\n}}"));
    match arms.as_slice() {
        [] => None,
        // A boolean that is `true` elsewhere (a tangent that the switches do not decide for one
        // field): `wrt != k || ...`, not `if` around a literal (clippy's needless_bool).
        [(k, body)] if other == Some("true") && is_expression(body) => match body.trim() {
            "false" => Some(format!("{on} != {k}\n")),
            e => Some(format!("{on} != {k} || {e}\n")),
        },
        // One arm around another: one `if` (clippy's collapsible_if). The inner `if`'s `else`,
        // if any, is the outer one's too.
        [(k, body)] => match body.strip_prefix("if ").and_then(|rest| rest.split_once(" {\n")) {
            Some((inner, block)) => Some(format!("if {on} == {k} && {inner} {{\n{block}")),
            None => Some(format!("if {on} == {k} {{\n{body}}}{otherwise}\n")),
        },
        // Arms that are all boolean literals, as the default is: `matches!` (clippy's
        // match_like_matches_macro), listing the arms that differ from the default.
        _ if other.is_some_and(|o| o == "true" || o == "false")
            && arms.iter().all(|(_, b)| matches!(b.trim(), "true" | "false")) =>
        {
            let other = other.unwrap_or("true");
            let differ: Vec<String> =
                arms.iter().filter(|(_, b)| b.trim() != other).map(|(k, _)| k.to_string()).collect();
            let not = if other == "true" { "!" } else { "" };
            Some(match differ.is_empty() {
                true => format!("{other}\n"),
                false => format!("{not}matches!({on}, {})\n", differ.join(" | ")),
            })
        }
        _ => {
            let arms: String = arms.iter().map(|(k, body)| format!("{k} => {{\n{body}}}\n")).collect();
            Some(format!("match {on} {{\n{arms}_ => {}\n}}\n", other.unwrap_or("{}")))
        }
    }
}

/// Whether a body is one expression (no statement, no block).
fn is_expression(body: &str) -> bool {
    let e = body.trim();
    !e.contains(['\n', ';', '{']) && !e.starts_with("if ")
}

/// A method of a kernel trait: its name, its parameters after `&self` with their types and its
/// return type (empty for none).
type Method = (&'static str, Vec<(&'static str, String)>, &'static str);

/// The methods of `FormKernel<d, N>` that a form may override, in the order they are written.
fn form_methods(d: usize) -> [Method; 6] {
    let (vec, mat, fields) =
        (format!("&mut LocalVector<{d}, N>"), format!("&mut LocalMatrix<{d}, N>"), format!("&[&LocalVector<{d}, N>]"));
    let (cctx, fctx) = (format!("&CellCtx<'_, {d}, N>"), format!("&FacetCtx<'_, {d}, N>"));
    let switches = "&mut Vec<bool>".to_string();
    let wrt = "usize".to_string();
    let region = "usize".to_string();
    [
        ("cell_residual", vec![("ctx", cctx.clone()), ("fields", fields.clone()), ("out", vec.clone())], ""),
        (
            "cell_tangent",
            vec![("ctx", cctx.clone()), ("fields", fields.clone()), ("wrt", wrt.clone()), ("out", mat.clone())],
            "",
        ),
        (
            "cell_switches",
            vec![("ctx", cctx), ("fields", fields.clone()), ("wrt", wrt.clone()), ("out", switches.clone())],
            " -> bool",
        ),
        (
            "facet_residual",
            vec![("region", region.clone()), ("ctx", fctx.clone()), ("fields", fields.clone()), ("out", vec)],
            "",
        ),
        (
            "facet_tangent",
            vec![
                ("region", region.clone()),
                ("ctx", fctx.clone()),
                ("fields", fields.clone()),
                ("wrt", wrt.clone()),
                ("out", mat),
            ],
            "",
        ),
        (
            "facet_switches",
            vec![("region", region), ("ctx", fctx), ("fields", fields), ("wrt", wrt), ("out", switches)],
            " -> bool",
        ),
    ]
}

/// `impl<const N: usize> FormKernel<D, N> for Struct { ... }`.
pub fn form_impl(prog: &Program, ir: &DimIr, form: &FormIr, struct_name: &str) -> String {
    let d = ir.dim;
    let plan = plan::form(prog, ir, form);
    let kernel = Kernel { prog, g: &ir.graph, d, form };
    let residual = |i: &Integral| i.residual.as_ref().map(|b| kernel.emit(i.cell, b));
    // One arm per field argument with something to do.
    let per_field = |i: &Integral| {
        let arms = i.tangents.iter().enumerate().filter_map(|(a, b)| Some((a, kernel.emit(i.cell, b.as_ref()?))));
        dispatch("wrt", arms.collect(), None)
    };
    // The switches of each field argument, and whether the tangent depends on the fields only
    // through them at these points (the trait's default, `true`, where nothing is listed).
    let switches_per_field = |i: &Integral| {
        let arms = i.decided.iter().zip(&i.switches).enumerate().filter_map(|(a, (decided, b))| {
            let b = b.as_ref().map_or(String::new(), |b| kernel.emit(i.cell, b));
            match decided {
                Decided::Always if b.is_empty() => None,
                Decided::Always => Some((a, format!("{b}true\n"))),
                Decided::Gated => Some((a, format!("let mut gated = true;\n{b}gated\n"))),
                Decided::Never => Some((a, format!("{b}false\n"))),
            }
        });
        dispatch("wrt", arms.collect(), Some("true"))
    };
    // One arm per boundary region with something to do.
    let per_region = |f: &dyn Fn(&Integral) -> Option<String>, other: Option<&str>| {
        dispatch("region", plan.facets.iter().enumerate().filter_map(|(r, i)| f(i).map(|b| (r, b))).collect(), other)
    };
    let cell = plan.cell.as_ref();
    let bodies = [
        cell.and_then(residual),
        cell.and_then(per_field),
        cell.and_then(switches_per_field),
        per_region(&residual, None),
        per_region(&per_field, None),
        per_region(&switches_per_field, Some("true")),
    ];
    let mut s = String::new();
    let _ = writeln!(s, "impl<const N: usize> FormKernel<{d}, N> for {struct_name} {{");
    // Methods with nothing to add keep the trait's default (which adds nothing).
    for ((name, list, ret), text) in form_methods(d).into_iter().zip(bodies) {
        if let Some(text) = text {
            let _ = writeln!(s, "fn {name}(&self, {}){ret} {{\n{text}}}", params(&text, &list));
        }
    }
    s.push_str("}\n");
    s
}

/// `impl<const N: usize> FunctionalKernel<D, N> for Struct { ... }`: the value of each
/// integral of a functional.
pub fn functional_impl(prog: &Program, ir: &DimIr, form: &FormIr, struct_name: &str) -> String {
    let d = ir.dim;
    let plan = plan::form(prog, ir, form);
    let kernel = Kernel { prog, g: &ir.graph, d, form };
    let body = |i: &Integral| {
        let b = i.value.as_ref().map_or(String::new(), |b| kernel.emit(i.cell, b));
        format!("let mut total = 0.0;\n{b}total\n")
    };
    let fields = format!("&[&LocalVector<{d}, N>]");
    let mut s = String::new();
    let _ = writeln!(s, "impl<const N: usize> FunctionalKernel<{d}, N> for {struct_name} {{");
    // A functional without a volume (facet) integral keeps the trait's default: 0.
    if let Some(cell) = &plan.cell {
        let text = body(cell);
        let list = [("ctx", format!("&CellCtx<'_, {d}, N>")), ("fields", fields.clone())];
        let _ = writeln!(s, "fn cell_value(&self, {}) -> f64 {{\n{text}}}", params(&text, &list));
    }
    let arms: Vec<String> =
        plan.facets.iter().enumerate().map(|(r, i)| format!("{r} => {{\n{}}}\n", body(i))).collect();
    if !arms.is_empty() {
        let text = format!("match region {{\n{}_ => 0.0,\n}}\n", arms.concat());
        let list = [("region", "usize".to_string()), ("ctx", format!("&FacetCtx<'_, {d}, N>")), ("fields", fields)];
        let _ = writeln!(s, "fn facet_value(&self, {}) -> f64 {{\n{text}}}", params(&text, &list));
    }
    s.push_str("}\n");
    s
}

/// What the Rust of a planned body needs besides the plan: the names of the params, coefs and
/// fields it reads.
struct Kernel<'a> {
    prog: &'a Program,
    g: &'a Graph,
    d: usize,
    form: &'a FormIr,
}

/// The leaves of a body: their names, and the lines that read them from the context.
struct Leaves {
    leaf: HashMap<Sym, String>,
    /// Before the loop: params, field dofs, `t` and `h`.
    prologue: String,
    /// Per field argument: its dofs and its value (`None` when not read).
    field_val: Vec<Option<(String, String)>>,
    /// Per field argument: its dofs and its gradient.
    field_grad: Vec<Option<(String, String)>>,
    /// The local of each coef of the plan's `coefs`.
    coefs: Vec<String>,
    uses_normal: bool,
}

/// The local of a root: its IR list and its indices in it (`c10_k_l_m`).
fn root_name(r: &Root, d: usize) -> String {
    let (list, rank) = match r.array {
        Array::F0 => ("f0", 1),
        Array::F1 => ("f1", 2),
        Array::C00 => ("c00", 2),
        Array::C01 => ("c01", 3),
        Array::C10 => ("c10", 3),
        Array::C11 => ("c11", 4),
        Array::Switch => return format!("s_{}", r.at),
        Array::Gate => return format!("gate_{}", r.at),
        Array::Value => return "value".into(),
    };
    let mut ix = Vec::new();
    let mut rest = r.at;
    for _ in 0..rank {
        ix.push((rest % d).to_string());
        rest /= d;
    }
    ix.reverse();
    format!("{list}_{}", ix.join("_"))
}

/// `φ` or `∂_l φ` at node `node`.
fn basis_at(basis: Basis, node: &str) -> String {
    match basis {
        Basis::Phi => format!("phi[{node}]"),
        Basis::Dphi(l) => format!("dphi[{node}][{l}]"),
    }
}

impl Kernel<'_> {
    fn emit(&self, cell: bool, body: &Body) -> String {
        let names: Vec<String> = body.roots.iter().map(|r| root_name(r, self.d)).collect();
        let nodes: Vec<NodeId> = body.roots.iter().map(|r| r.node).collect();
        let mut namer = self.namer(&names);
        let leaves = self.leaves(body, &mut namer);
        let coefs: Vec<String> = self.prog.coefs.iter().map(|c| ident(&c.name)).collect();
        let emitter = Emitter::new(self.g, &leaves.leaf).with_coefs(&coefs);
        let varies = |s: Sym| !body.leaf(s).is_some_and(Leaf::hoisted);
        let lines = emitter.bind(&nodes, varies, true, &mut namer);
        let mut weighted = String::new();
        let weight = if body.weighted() { "w * " } else { "" };
        for (name, &node) in names.iter().zip(&nodes) {
            let (text, prec) = emitter.value(node, &lines);
            let text = if prec < UNARY && !weight.is_empty() { format!("({text})") } else { text };
            let _ = writeln!(weighted, "let {name} = {weight}{text};");
        }
        let mut s = String::new();
        s.push_str(&leaves.prologue);
        s.push_str(&lines.invariant);
        s.push_str("for q in 0..ctx.tab.len() {\n");
        s.push_str(&self.point(cell, body, &leaves));
        s.push_str(&lines.varying);
        s.push_str(&weighted);
        match &body.contract {
            Contract::Residual { rows } => s.push_str(&residual_loop(rows, &names)),
            Contract::Tangent { a, b } => s.push_str(&self.tangent_loop(a, b, &names)),
            Contract::Switches { count } => {
                let (set, gates) = names.split_at(*count);
                for name in set {
                    let _ = writeln!(s, "out.push({name} > 0.0);");
                }
                // Off (a ≤ 0; NaN is not off) at every gate: see `form_impl`.
                let off: Vec<String> = gates.iter().map(|n| format!("{n} <= 0.0")).collect();
                if !off.is_empty() {
                    let _ = writeln!(s, "gated &= {};", off.join(" && "));
                }
            }
            Contract::Value => {
                let _ = writeln!(s, "total += {};", names[0]);
            }
        }
        s.push_str("}\n");
        s
    }

    /// The body's locals: the kernel's own, the roots and the tangent's rows taken.
    fn namer(&self, roots: &[String]) -> Namer {
        let d = self.d;
        let mut namer = Namer::new(RESERVED);
        for name in roots {
            namer.fresh(name);
        }
        for k in 0..d {
            for m in 0..d {
                namer.fresh(&format!("a_{k}_{m}"));
                for n in 0..d {
                    namer.fresh(&format!("b_{k}_{m}_{n}"));
                }
            }
        }
        namer
    }

    /// Names of the leaves the body reads, and the prologue that reads the cell-constant ones.
    fn leaves(&self, body: &Body, namer: &mut Namer) -> Leaves {
        let mut prologue = String::new();
        let mut params: HashMap<u16, String> = HashMap::new();
        for leaf in &body.leaves {
            if let Leaf::Param(i) = *leaf {
                let pname = &self.prog.params[i as usize].name;
                let local = namer.fresh(pname);
                let _ = writeln!(prologue, "let {local} = self.params.{};", ident(pname));
                params.insert(i, local);
            }
        }
        // The previous time level (`prev`), when read, is one more field after the arguments.
        let nfields = self.form.fields.len() + usize::from(self.form.previous);
        let mut field_val = vec![None; nfields];
        let mut field_grad = vec![None; nfields];
        for a in 0..nfields {
            let uses_val = body.leaves.iter().any(|l| matches!(l, Leaf::Value { arg, .. } if *arg as usize == a));
            let uses_grad = body.leaves.iter().any(|l| matches!(l, Leaf::Grad { arg, .. } if *arg as usize == a));
            if uses_val || uses_grad {
                let fname = self.form.fields.get(a).map_or("previous", String::as_str);
                let dofs = namer.fresh(fname);
                let _ = writeln!(prologue, "let {dofs} = fields[{a}];");
                if uses_val {
                    field_val[a] = Some((dofs.clone(), namer.fresh(&format!("{fname}_val"))));
                }
                if uses_grad {
                    field_grad[a] = Some((dofs.clone(), namer.fresh(&format!("grad_{fname}"))));
                }
            }
        }
        let coefs: Vec<String> = body.coefs.iter().map(|c| namer.fresh(&self.prog.coefs[c.id as usize].name)).collect();
        let local = |v: &Option<(String, String)>| v.as_ref().expect("named above").1.clone();
        let mut leaf: HashMap<Sym, String> = HashMap::new();
        for (&s, &l) in body.prog.syms().iter().zip(&body.leaves) {
            let name = match l {
                Leaf::Param(i) => params[&i].clone(),
                Leaf::Value { arg, comp } => format!("{}[{comp}]", local(&field_val[arg as usize])),
                Leaf::Grad { arg, comp, dir } => format!("{}[{comp}][{dir}]", local(&field_grad[arg as usize])),
                Leaf::Normal(k) => format!("n[{k}]"),
                Leaf::CellDiameter => "h".into(),
                Leaf::Coord(k) => format!("x[{k}]"),
                Leaf::Time => "t".into(),
                Leaf::Coef { id, comp, .. } => {
                    let c = body.coefs.iter().position(|c| c.id == id).expect("laid out");
                    format!("{}[{comp}]", coefs[c])
                }
                Leaf::Zero => "0.0".into(),
            };
            leaf.insert(s, name);
        }
        // Coefs are functions of position and time.
        if body.leaves.contains(&Leaf::Time) || !coefs.is_empty() || body.coefs_at {
            prologue.push_str("let t = ctx.t;\n");
        }
        if body.leaves.contains(&Leaf::CellDiameter) {
            prologue.push_str("let h = ctx.h;\n");
        }
        let uses_normal = body.leaves.iter().any(|l| matches!(l, Leaf::Normal(_)));
        Leaves { leaf, prologue, field_val, field_grad, coefs, uses_normal }
    }

    /// The geometry, coefs and fields at quadrature point `q`.
    fn point(&self, cell: bool, body: &Body, leaves: &Leaves) -> String {
        let field_vals = leaves.field_val.iter().any(Option::is_some);
        let need_phi = field_vals || body.uses_x || body.contract.reads_phi();
        let weighted = body.weighted();
        let normal = !cell && (weighted || leaves.uses_normal);
        let mut s = String::new();
        if need_phi {
            s.push_str("let phi = &ctx.tab.phi[q];\n");
        }
        if weighted || body.uses_dphi || normal {
            s.push_str("let jac = geometry::jacobian(ctx.coords, &ctx.tab.dphi[q]);\n");
        }
        if normal {
            let n = if leaves.uses_normal { "n" } else { "_" };
            let scale = if weighted { "scale" } else { "_" };
            let _ = writeln!(s, "let ({n}, {scale}) = geometry::facet_normal(&jac, ctx.ref_normal);");
        }
        match (weighted, cell) {
            (false, _) => {}
            (true, true) => s.push_str("let w = ctx.tab.weights[q] * jac.det.abs();\n"),
            (true, false) => s.push_str("let w = ctx.tab.weights[q] * scale;\n"),
        }
        if body.uses_dphi {
            s.push_str("let dphi = geometry::physical_gradients(&jac, &ctx.tab.dphi[q]);\n");
        }
        if body.uses_x {
            s.push_str("let x = geometry::interpolate(ctx.coords, phi);\n");
        }
        for (c, local) in body.coefs.iter().zip(&leaves.coefs) {
            let name = ident(&self.prog.coefs[c.id as usize].name);
            let _ = writeln!(s, "let mut {local} = [0.0; {}];\nself.coefs.{name}.eval(&x, t, &mut {local});", c.len);
        }
        for (dofs, val) in leaves.field_val.iter().flatten() {
            let _ = writeln!(s, "let {val} = geometry::interpolate({dofs}, phi);");
        }
        for (dofs, grad) in leaves.field_grad.iter().flatten() {
            let _ = writeln!(s, "let {grad} = geometry::gradient({dofs}, &dphi);");
        }
        s
    }

    /// out[i][k][j][m] += a[k][m]·φ_j + Σ_n b[k][m][n]·∂_n φ_j, with a and b summed from the
    /// plan's terms at test node i.
    fn tangent_loop(&self, a: &[Terms], b: &[Terms], names: &[String]) -> String {
        let d = self.d;
        let sum = |terms: &Terms| {
            let terms: Vec<String> =
                terms.iter().map(|&(basis, r)| format!("{} * {}", basis_at(basis, "i"), names[r as usize])).collect();
            terms.join(" + ")
        };
        let mut rows = String::new();
        let mut a_names = vec![None; d * d];
        let mut b_names = vec![None; d * d * d];
        for k in 0..d {
            for m in 0..d {
                let km = k * d + m;
                if !a[km].is_empty() {
                    let name = format!("a_{k}_{m}");
                    let _ = writeln!(rows, "let {name} = {};", sum(&a[km]));
                    a_names[km] = Some(name);
                }
                for n in 0..d {
                    if !b[km * d + n].is_empty() {
                        let name = format!("b_{k}_{m}_{n}");
                        let _ = writeln!(rows, "let {name} = {};", sum(&b[km * d + n]));
                        b_names[km * d + n] = Some(name);
                    }
                }
            }
        }
        let mut cols = String::new();
        for k in 0..d {
            for m in 0..d {
                let mut terms = Vec::new();
                if let Some(a) = &a_names[k * d + m] {
                    terms.push(format!("{a} * phi[j]"));
                }
                for n in 0..d {
                    if let Some(b) = &b_names[(k * d + m) * d + n] {
                        terms.push(format!("{b} * dphi[j][{n}]"));
                    }
                }
                if !terms.is_empty() {
                    let _ = writeln!(cols, "out[i][{k}][j][{m}] += {};", terms.join(" + "));
                }
            }
        }
        format!("for i in 0..N {{\n{rows}for j in 0..N {{\n{cols}}}\n}}\n")
    }
}

/// out[j][k] += Σ root·basis over the terms of row k.
fn residual_loop(rows: &[Terms], names: &[String]) -> String {
    let mut s = String::from("for j in 0..N {\n");
    for (k, terms) in rows.iter().enumerate() {
        if !terms.is_empty() {
            let terms: Vec<String> =
                terms.iter().map(|&(basis, r)| format!("{} * {}", names[r as usize], basis_at(basis, "j"))).collect();
            let _ = writeln!(s, "out[j][{k}] += {};", terms.join(" + "));
        }
    }
    s.push_str("}\n");
    s
}
