//! Element kernels of one form in one dimension: for each integral, the residual and the
//! tangent with respect to each field argument, as loops over quadrature points and local
//! nodes with the pointwise coefficients written out as straight-line code (`emit`).

use std::collections::{HashMap, HashSet};
use std::fmt::Write;

use super::emit::{Emitter, UNARY};
use super::names::{Namer, ident, words};
use crate::ir::graph::{Graph, NodeId, Sym};
use crate::ir::{DimIr, FormIr, IntegralIr};
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

/// A method of a kernel trait: its name, its parameters after `&self` with their types, its
/// return type (empty for none), and its body, if it has something to do.
type Method<'a> = (&'a str, Vec<(&'a str, String)>, &'a str, Option<String>);

/// `impl<const N: usize> FormKernel<D, N> for Struct { ... }`.
pub fn form_impl(prog: &Program, ir: &DimIr, form: &FormIr, struct_name: &str) -> String {
    let d = ir.dim;
    let g = &ir.graph;
    let body = |integral: &IntegralIr, mode: Mode| Body { prog, g, d, form, integral, mode }.emit();
    // One arm per field argument with something to do.
    let per_field = |integral: &IntegralIr, mode: fn(usize) -> Mode| {
        let arms = (0..form.fields.len()).map(|a| (a, body(integral, mode(a)))).filter(|(_, b)| !b.is_empty());
        dispatch("wrt", arms.collect(), None)
    };
    // The switches of each field argument, and whether the tangent depends on the fields only
    // through them at these points (the trait's default, `true`, where nothing is listed).
    let switches_per_field = |integral: &IntegralIr| {
        let arms = (0..form.fields.len()).filter_map(|a| {
            let b = body(integral, Mode::Switches(a));
            let t = &integral.tangents[a];
            match (t.piecewise, &t.gates) {
                (true, _) if b.is_empty() => None,
                (true, _) => Some((a, format!("{b}true\n"))),
                (false, Some(g)) if !g.is_empty() => Some((a, format!("let mut gated = true;\n{b}gated\n"))),
                (false, _) => Some((a, format!("{b}false\n"))),
            }
        });
        dispatch("wrt", arms.collect(), Some("true"))
    };
    let cell = form.integrals.iter().find(|i| i.cell);
    let facets: Vec<&IntegralIr> = form.integrals.iter().filter(|i| !i.cell).collect();
    // One arm per boundary region with something to do.
    let per_region = |f: &dyn Fn(&IntegralIr) -> Option<String>, other: Option<&str>| {
        dispatch("region", facets.iter().enumerate().filter_map(|(r, i)| f(i).map(|b| (r, b))).collect(), other)
    };
    let nonempty = |b: String| (!b.is_empty()).then_some(b);
    let (vec, mat, fields) =
        (format!("&mut LocalVector<{d}, N>"), format!("&mut LocalMatrix<{d}, N>"), format!("&[&LocalVector<{d}, N>]"));
    let (cctx, fctx) = (format!("&CellCtx<'_, {d}, N>"), format!("&FacetCtx<'_, {d}, N>"));
    let switches = "&mut Vec<bool>".to_string();
    let wrt = "usize".to_string();
    let region = "usize".to_string();
    // Methods with nothing to add keep the trait's default (which adds nothing).
    let methods: [Method; 6] = [
        (
            "cell_residual",
            vec![("ctx", cctx.clone()), ("fields", fields.clone()), ("out", vec.clone())],
            "",
            cell.and_then(|i| nonempty(body(i, Mode::Residual))),
        ),
        (
            "cell_tangent",
            vec![("ctx", cctx.clone()), ("fields", fields.clone()), ("wrt", wrt.clone()), ("out", mat.clone())],
            "",
            cell.and_then(|i| per_field(i, Mode::Tangent)),
        ),
        (
            "cell_switches",
            vec![("ctx", cctx), ("fields", fields.clone()), ("wrt", wrt.clone()), ("out", switches.clone())],
            " -> bool",
            cell.and_then(switches_per_field),
        ),
        (
            "facet_residual",
            vec![("region", region.clone()), ("ctx", fctx.clone()), ("fields", fields.clone()), ("out", vec)],
            "",
            per_region(&|i| nonempty(body(i, Mode::Residual)), None),
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
            per_region(&|i| per_field(i, Mode::Tangent), None),
        ),
        (
            "facet_switches",
            vec![("region", region), ("ctx", fctx), ("fields", fields), ("wrt", wrt), ("out", switches)],
            " -> bool",
            per_region(&switches_per_field, Some("true")),
        ),
    ];
    let mut s = String::new();
    let _ = writeln!(s, "impl<const N: usize> FormKernel<{d}, N> for {struct_name} {{");
    for (name, list, ret, text) in methods {
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
    let g = &ir.graph;
    let body = |integral: &IntegralIr| {
        let b = Body { prog, g, d, form, integral, mode: Mode::Value }.emit();
        format!("let mut total = 0.0;\n{b}total\n")
    };
    let fields = format!("&[&LocalVector<{d}, N>]");
    let mut s = String::new();
    let _ = writeln!(s, "impl<const N: usize> FunctionalKernel<{d}, N> for {struct_name} {{");
    // A functional without a volume (facet) integral keeps the trait's default: 0.
    if let Some(cell) = form.integrals.iter().find(|i| i.cell) {
        let text = body(cell);
        let list = [("ctx", format!("&CellCtx<'_, {d}, N>")), ("fields", fields.clone())];
        let _ = writeln!(s, "fn cell_value(&self, {}) -> f64 {{\n{text}}}", params(&text, &list));
    }
    let arms: Vec<String> = form
        .integrals
        .iter()
        .filter(|i| !i.cell)
        .enumerate()
        .map(|(r, i)| format!("{r} => {{\n{}}}\n", body(i)))
        .collect();
    if !arms.is_empty() {
        let text = format!("match region {{\n{}_ => 0.0,\n}}\n", arms.concat());
        let list = [("region", "usize".to_string()), ("ctx", format!("&FacetCtx<'_, {d}, N>")), ("fields", fields)];
        let _ = writeln!(s, "fn facet_value(&self, {}) -> f64 {{\n{text}}}", params(&text, &list));
    }
    s.push_str("}\n");
    s
}

#[derive(Clone, Copy, PartialEq)]
enum Mode {
    Residual,
    Tangent(usize),
    /// Signs of the active-set switches of the tangent with respect to a field.
    Switches(usize),
    /// The integral of a functional.
    Value,
}

struct Body<'a> {
    prog: &'a Program,
    g: &'a Graph,
    d: usize,
    form: &'a FormIr,
    integral: &'a IntegralIr,
    mode: Mode,
}

/// A weighted pointwise coefficient: its local name and node.
struct Output {
    name: String,
    node: NodeId,
}

type Outputs = Vec<(&'static str, Vec<Option<Output>>)>;

fn output(outputs: &Outputs, kind: &str, flat: usize) -> Option<String> {
    outputs.iter().find(|(k, _)| *k == kind)?.1.get(flat)?.as_ref().map(|o| o.name.clone())
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
    /// The coefs read, and their locals.
    coefs: Vec<(u16, String)>,
    uses_x: bool,
    uses_normal: bool,
}

impl Body<'_> {
    fn emit(&self) -> String {
        let g = self.g;
        let outputs = self.outputs();
        let roots: Vec<NodeId> = outputs.iter().flat_map(|(_, l)| l.iter().flatten()).map(|o| o.node).collect();
        if roots.is_empty() {
            return String::new();
        }
        let nodes = g.reachable(roots.iter().copied());
        let syms: HashSet<Sym> = nodes
            .iter()
            .filter_map(|&n| if let crate::ir::graph::Node::Sym(s) = g.node(n) { Some(s) } else { None })
            .collect();
        let mut namer = self.namer(&outputs);
        let leaves = self.leaves(&syms, &mut namer);
        let emitter = Emitter::new(g, &leaves.leaf);
        // Constant over the cell: hoisted out of the quadrature loop.
        let varies = |s: Sym| !matches!(s, Sym::Param(_) | Sym::CellDiameter | Sym::Time);
        let lines = emitter.bind(&roots, varies, true, &mut namer);
        // Weighted outputs (switches are signs: no weight).
        let mut weighted = String::new();
        let weight = if matches!(self.mode, Mode::Switches(_)) { "" } else { "w * " };
        for o in outputs.iter().flat_map(|(_, l)| l.iter().flatten()) {
            let (text, prec) = emitter.value(o.node, &lines);
            let text = if prec < UNARY && !weight.is_empty() { format!("({text})") } else { text };
            let _ = writeln!(weighted, "let {} = {weight}{text};", o.name);
        }
        let mut s = String::new();
        s.push_str(&leaves.prologue);
        s.push_str(&lines.invariant);
        s.push_str("for q in 0..ctx.tab.len() {\n");
        s.push_str(&self.point(&outputs, &leaves));
        s.push_str(&lines.varying);
        s.push_str(&weighted);
        match self.mode {
            Mode::Residual => s.push_str(&self.residual_loop(&outputs)),
            Mode::Tangent(_) => s.push_str(&self.tangent_loop(&outputs)),
            Mode::Switches(_) => {
                let names = |kind: &'static str| {
                    outputs
                        .iter()
                        .filter(move |(k, _)| *k == kind)
                        .flat_map(|(_, l)| l.iter().flatten())
                        .map(|o| &o.name)
                };
                for name in names("s") {
                    let _ = writeln!(s, "out.push({name} > 0.0);");
                }
                // Off (a ≤ 0; NaN is not off) at every gate: see `form_impl`.
                let off: Vec<String> = names("gate").map(|n| format!("{n} <= 0.0")).collect();
                if !off.is_empty() {
                    let _ = writeln!(s, "gated &= {};", off.join(" && "));
                }
            }
            Mode::Value => s.push_str("total += value;\n"),
        }
        s.push_str("}\n");
        s
    }

    /// The pointwise coefficients this body needs, by the index conventions of ir::TangentIr.
    fn outputs(&self) -> Outputs {
        let (d, g) = (self.d, self.g);
        let idx = |v: &[usize]| v.iter().map(|x| x.to_string()).collect::<Vec<_>>().join("_");
        let mut outputs: Outputs = Vec::new();
        let mut add = |kind: &'static str, nodes: &[NodeId], dims: usize| {
            let list = nodes
                .iter()
                .enumerate()
                .map(|(flat, &n)| {
                    if g.is_zero(n) {
                        return None;
                    }
                    let mut ix = Vec::new();
                    let mut rest = flat;
                    for _ in 0..dims {
                        ix.push(rest % d);
                        rest /= d;
                    }
                    ix.reverse();
                    Some(Output { name: format!("{kind}_{}", idx(&ix)), node: n })
                })
                .collect();
            outputs.push((kind, list));
        };
        match self.mode {
            Mode::Residual => {
                add("f0", &self.integral.f0, 1);
                add("f1", &self.integral.f1, 2);
            }
            Mode::Tangent(a) => {
                let t = &self.integral.tangents[a];
                add("c00", &t.c00, 2);
                add("c01", &t.c01, 3);
                add("c10", &t.c10, 3);
                add("c11", &t.c11, 4);
            }
            Mode::Value => {
                let node = self.integral.value.expect("functionals have a value");
                outputs.push(("value", vec![(!g.is_zero(node)).then(|| Output { name: "value".into(), node })]));
            }
            Mode::Switches(a) => {
                let t = &self.integral.tangents[a];
                let list = t.switches.iter().enumerate();
                outputs.push(("s", list.map(|(k, &node)| Some(Output { name: format!("s_{k}"), node })).collect()));
                if !t.piecewise {
                    let gates = t.gates.iter().flatten().enumerate();
                    let gates = gates.map(|(k, &node)| Some(Output { name: format!("gate_{k}"), node }));
                    outputs.push(("gate", gates.collect()));
                }
            }
        }
        outputs
    }

    /// The body's locals: the kernel's own, the outputs and the tangent's rows taken.
    fn namer(&self, outputs: &Outputs) -> Namer {
        let d = self.d;
        let mut namer = Namer::new(RESERVED);
        for (_, list) in outputs {
            for o in list.iter().flatten() {
                namer.fresh(&o.name);
            }
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
    fn leaves(&self, syms: &HashSet<Sym>, namer: &mut Namer) -> Leaves {
        let mut leaf: HashMap<Sym, String> = HashMap::new();
        let mut prologue = String::new();
        let mut params: Vec<u16> =
            syms.iter().filter_map(|s| if let Sym::Param(i) = s { Some(*i) } else { None }).collect();
        params.sort_unstable();
        for i in params {
            let pname = &self.prog.params[i as usize].name;
            let local = namer.fresh(pname);
            let _ = writeln!(prologue, "let {local} = self.params.{};", ident(pname));
            leaf.insert(Sym::Param(i), local);
        }
        // The previous time level (`prev`), when read, is one more field after the arguments.
        let nfields = self.form.fields.len() + usize::from(self.form.previous);
        let mut field_val = vec![None; nfields];
        let mut field_grad = vec![None; nfields];
        for a in 0..nfields {
            let uses_val = syms.iter().any(|s| matches!(s, Sym::Field { arg, .. } if *arg as usize == a));
            let uses_grad = syms.iter().any(|s| matches!(s, Sym::FieldGrad { arg, .. } if *arg as usize == a));
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
        let mut coef_ids: Vec<u16> =
            syms.iter().filter_map(|s| if let Sym::Coef { id, .. } = s { Some(*id) } else { None }).collect();
        coef_ids.sort_unstable();
        coef_ids.dedup();
        let coefs: Vec<(u16, String)> =
            coef_ids.iter().map(|&id| (id, namer.fresh(&self.prog.coefs[id as usize].name))).collect();
        for s in syms {
            let name = match *s {
                Sym::Param(_) => continue,
                Sym::Field { arg, comp } => {
                    format!("{}[{comp}]", field_val[arg as usize].as_ref().expect("named above").1)
                }
                Sym::FieldGrad { arg, comp, dir } => {
                    format!("{}[{comp}][{dir}]", field_grad[arg as usize].as_ref().expect("named above").1)
                }
                Sym::Normal(k) => format!("n[{k}]"),
                Sym::CellDiameter => "h".into(),
                Sym::Coord(k) => format!("x[{k}]"),
                Sym::Time => "t".into(),
                Sym::Dt => "dt".into(), // never in a form
                Sym::Coef { id, comp } => {
                    format!("{}[{comp}]", coefs.iter().find(|(i, _)| *i == id).expect("named above").1)
                }
                Sym::Test { .. } | Sym::TestGrad { .. } => "0.0".into(), // linear forms: never reached
            };
            leaf.insert(*s, name);
        }
        // Coefs are functions of position and time.
        if syms.contains(&Sym::Time) || !coefs.is_empty() {
            prologue.push_str("let t = ctx.t;\n");
        }
        if syms.contains(&Sym::CellDiameter) {
            prologue.push_str("let h = ctx.h;\n");
        }
        let uses_x = syms.iter().any(|s| matches!(s, Sym::Coord(_))) || !coefs.is_empty();
        let uses_normal = syms.iter().any(|s| matches!(s, Sym::Normal(_)));
        Leaves { leaf, prologue, field_val, field_grad, coefs, uses_x, uses_normal }
    }

    /// The geometry, coefs and fields at quadrature point `q`.
    fn point(&self, outputs: &Outputs, leaves: &Leaves) -> String {
        let needs = |kinds: &[&str]| outputs.iter().any(|(k, l)| kinds.contains(k) && l.iter().any(Option::is_some));
        let field_vals = leaves.field_val.iter().any(Option::is_some);
        let field_grads = leaves.field_grad.iter().any(Option::is_some);
        let need_phi = field_vals || leaves.uses_x || needs(&["f0", "c00", "c01", "c10"]);
        let need_dphi = field_grads || needs(&["f1", "c01", "c10", "c11"]);
        // Switches are signs: they need no quadrature weight.
        let weighted = !matches!(self.mode, Mode::Switches(_));
        let normal = !self.integral.cell && (weighted || leaves.uses_normal);
        let mut s = String::new();
        if need_phi {
            s.push_str("let phi = &ctx.tab.phi[q];\n");
        }
        if weighted || need_dphi || normal {
            s.push_str("let jac = geometry::jacobian(ctx.coords, &ctx.tab.dphi[q]);\n");
        }
        if normal {
            let n = if leaves.uses_normal { "n" } else { "_" };
            let scale = if weighted { "scale" } else { "_" };
            let _ = writeln!(s, "let ({n}, {scale}) = geometry::facet_normal(&jac, ctx.ref_normal);");
        }
        match (weighted, self.integral.cell) {
            (false, _) => {}
            (true, true) => s.push_str("let w = ctx.tab.weights[q] * jac.det.abs();\n"),
            (true, false) => s.push_str("let w = ctx.tab.weights[q] * scale;\n"),
        }
        if need_dphi {
            s.push_str("let dphi = geometry::physical_gradients(&jac, &ctx.tab.dphi[q]);\n");
        }
        if leaves.uses_x {
            s.push_str("let x = geometry::interpolate(ctx.coords, phi);\n");
        }
        for (id, local) in &leaves.coefs {
            let c = &self.prog.coefs[*id as usize];
            let len = crate::ir::lower::components(c.shape, self.d);
            let _ = writeln!(
                s,
                "let mut {local} = [0.0; {len}];\nself.coefs.{}.eval(&x, t, &mut {local});",
                ident(&c.name)
            );
        }
        for (dofs, val) in leaves.field_val.iter().flatten() {
            let _ = writeln!(s, "let {val} = geometry::interpolate({dofs}, phi);");
        }
        for (dofs, grad) in leaves.field_grad.iter().flatten() {
            let _ = writeln!(s, "let {grad} = geometry::gradient({dofs}, &dphi);");
        }
        s
    }

    fn residual_loop(&self, outputs: &Outputs) -> String {
        let get = |kind: &str, flat: usize| output(outputs, kind, flat);
        let d = self.d;
        let mut s = String::from("for j in 0..N {\n");
        for k in 0..d {
            let mut terms = Vec::new();
            if let Some(o) = get("f0", k) {
                terms.push(format!("{o} * phi[j]"));
            }
            for l in 0..d {
                if let Some(o) = get("f1", k * d + l) {
                    terms.push(format!("{o} * dphi[j][{l}]"));
                }
            }
            if !terms.is_empty() {
                let _ = writeln!(s, "out[j][{k}] += {};", terms.join(" + "));
            }
        }
        s.push_str("}\n");
        s
    }

    /// out[i][k][j][m] += a[k][m]·φ_j + Σ_n b[k][m][n]·∂_n φ_j, with
    /// a[k][m] = φ_i c00[k][m] + Σ_l ∂_l φ_i c10[k][l][m] and
    /// b[k][m][n] = φ_i c01[k][m][n] + Σ_l ∂_l φ_i c11[k][l][m][n].
    fn tangent_loop(&self, outputs: &Outputs) -> String {
        let d = self.d;
        let get = |kind: &str, flat: usize| output(outputs, kind, flat);
        let mut rows = String::new();
        let mut a_names = vec![None; d * d];
        let mut b_names = vec![None; d * d * d];
        for k in 0..d {
            for m in 0..d {
                let mut terms = Vec::new();
                if let Some(c) = get("c00", k * d + m) {
                    terms.push(format!("phi[i] * {c}"));
                }
                for l in 0..d {
                    if let Some(c) = get("c10", (k * d + l) * d + m) {
                        terms.push(format!("dphi[i][{l}] * {c}"));
                    }
                }
                if !terms.is_empty() {
                    let name = format!("a_{k}_{m}");
                    let _ = writeln!(rows, "let {name} = {};", terms.join(" + "));
                    a_names[k * d + m] = Some(name);
                }
                for n in 0..d {
                    let mut terms = Vec::new();
                    if let Some(c) = get("c01", (k * d + m) * d + n) {
                        terms.push(format!("phi[i] * {c}"));
                    }
                    for l in 0..d {
                        if let Some(c) = get("c11", ((k * d + l) * d + m) * d + n) {
                            terms.push(format!("dphi[i][{l}] * {c}"));
                        }
                    }
                    if !terms.is_empty() {
                        let name = format!("b_{k}_{m}_{n}");
                        let _ = writeln!(rows, "let {name} = {};", terms.join(" + "));
                        b_names[(k * d + m) * d + n] = Some(name);
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
