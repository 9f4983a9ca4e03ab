//! Element kernels of one form in one dimension: for each integral, the residual and the
//! tangent with respect to each field argument, as loops over quadrature points and local
//! nodes with the pointwise coefficients written out as straight-line code.

use std::collections::{HashMap, HashSet};
use std::fmt::Write;

use super::names::{Namer, ident};
use crate::ir::graph::{Graph, Node, NodeId, Sym};
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
];

/// `impl<const N: usize> FormKernel<D, N> for Struct { ... }`.
pub fn form_impl(prog: &Program, ir: &DimIr, form: &FormIr, struct_name: &str) -> String {
    let d = ir.dim;
    let g = &ir.graph;
    let body = |integral: &IntegralIr, mode: Mode| Body { prog, g, d, form, integral, mode }.emit();
    // One `match wrt` arm per field argument with something to do; `None` if none has.
    let per_field = |integral: &IntegralIr, mode: fn(usize) -> Mode| {
        let arms: Vec<String> = (0..form.fields.len())
            .filter_map(|a| {
                let b = body(integral, mode(a));
                (!b.is_empty()).then(|| format!("{a} => {{ // d/d{}\n{b}}}\n", form.fields[a]))
            })
            .collect();
        (!arms.is_empty()).then(|| format!("match wrt {{\n{}_ => {{}}\n}}\n", arms.concat()))
    };
    let cell = form.integrals.iter().find(|i| i.cell);
    let facets: Vec<&IntegralIr> = form.integrals.iter().filter(|i| !i.cell).collect();
    // One `match region` arm per boundary region with something to do; `None` if none has.
    let per_region = |f: &dyn Fn(&IntegralIr) -> Option<String>| {
        let arms: Vec<String> = facets
            .iter()
            .enumerate()
            .filter_map(|(r, i)| f(i).map(|b| format!("{r} => {{ // int({})\n{b}}}\n", i.region)))
            .collect();
        (!arms.is_empty()).then(|| format!("match region {{\n{}_ => {{}}\n}}\n", arms.concat()))
    };
    let nonempty = |b: String| (!b.is_empty()).then_some(b);
    let (vec, mat, fields) =
        (format!("LocalVector<{d}, N>"), format!("LocalMatrix<{d}, N>"), format!("&[&LocalVector<{d}, N>]"));
    let (cctx, fctx) = (format!("&CellCtx<'_, {d}, N>"), format!("&FacetCtx<'_, {d}, N>"));
    let mut s = String::new();
    let _ = writeln!(s, "impl<const N: usize> FormKernel<{d}, N> for {struct_name} {{");
    // Methods with nothing to add keep the trait's default (which adds nothing).
    let methods = [
        (
            format!("fn cell_residual(&self, ctx: {cctx}, fields: {fields}, out: &mut {vec})"),
            cell.and_then(|i| nonempty(body(i, Mode::Residual))),
        ),
        (
            format!("fn cell_tangent(&self, ctx: {cctx}, fields: {fields}, wrt: usize, out: &mut {mat})"),
            cell.and_then(|i| per_field(i, Mode::Tangent)),
        ),
        (
            format!("fn cell_switches(&self, ctx: {cctx}, fields: {fields}, wrt: usize, out: &mut Vec<bool>)"),
            cell.and_then(|i| per_field(i, Mode::Switches)),
        ),
        (
            format!("fn facet_residual(&self, region: usize, ctx: {fctx}, fields: {fields}, out: &mut {vec})"),
            per_region(&|i| nonempty(body(i, Mode::Residual))),
        ),
        (
            format!(
                "fn facet_tangent(&self, region: usize, ctx: {fctx}, fields: {fields}, wrt: usize, out: &mut {mat})"
            ),
            per_region(&|i| per_field(i, Mode::Tangent)),
        ),
        (
            format!(
                "fn facet_switches(&self, region: usize, ctx: {fctx}, fields: {fields}, wrt: usize, out: &mut Vec<bool>)"
            ),
            per_region(&|i| per_field(i, Mode::Switches)),
        ),
    ];
    for (sig, text) in methods {
        if let Some(text) = text {
            let _ = writeln!(s, "{sig} {{\n{text}}}");
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
        let _ = writeln!(
            s,
            "fn cell_value(&self, ctx: &CellCtx<'_, {d}, N>, fields: {fields}) -> f64 {{\n{}}}",
            body(cell)
        );
    }
    let mut arms = String::new();
    for (r, i) in form.integrals.iter().filter(|i| !i.cell).enumerate() {
        let _ = writeln!(arms, "{r} => {{ // int({})\n{}}}", i.region, body(i));
    }
    if !arms.is_empty() {
        let _ = writeln!(
            s,
            "fn facet_value(&self, region: usize, ctx: &FacetCtx<'_, {d}, N>, fields: {fields}) -> f64 {{\nmatch region {{\n{arms}_ => 0.0,\n}}\n}}"
        );
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

const ATOM: u8 = 4;
const UNARY: u8 = 3;
const MUL: u8 = 2;
const ADD: u8 = 1;

impl Body<'_> {
    fn emit(&self) -> String {
        let d = self.d;
        let g = self.g;
        let idx = |v: &[usize]| v.iter().map(|x| x.to_string()).collect::<Vec<_>>().join("_");
        // The pointwise coefficients this body needs, by the index conventions of ir::TangentIr.
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
                let list = self.integral.tangents[a].switches.iter().enumerate();
                outputs.push(("s", list.map(|(k, &node)| Some(Output { name: format!("s_{k}"), node })).collect()));
            }
        }
        let roots: Vec<NodeId> = outputs.iter().flat_map(|(_, l)| l.iter().flatten()).map(|o| o.node).collect();
        if roots.is_empty() {
            return String::new();
        }
        let nodes = g.reachable(roots.iter().copied());
        let syms: HashSet<Sym> =
            nodes.iter().filter_map(|&n| if let Node::Sym(s) = g.node(n) { Some(s) } else { None }).collect();

        // Names of leaves.
        let mut namer = Namer::new(RESERVED);
        for (_, list) in &outputs {
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
        let nfields = self.form.fields.len();
        let mut field_val = vec![None; nfields];
        let mut field_grad = vec![None; nfields];
        for a in 0..nfields {
            let uses_val = syms.iter().any(|s| matches!(s, Sym::Field { arg, .. } if *arg as usize == a));
            let uses_grad = syms.iter().any(|s| matches!(s, Sym::FieldGrad { arg, .. } if *arg as usize == a));
            if uses_val || uses_grad {
                let fname = &self.form.fields[a];
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
        let coef_locals: Vec<(u16, String)> =
            coef_ids.iter().map(|&id| (id, namer.fresh(&self.prog.coefs[id as usize].name))).collect();
        for s in &syms {
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
                    format!("{}[{comp}]", coef_locals.iter().find(|(i, _)| *i == id).expect("named above").1)
                }
                Sym::Test { .. } | Sym::TestGrad { .. } => "0.0".into(), // linear forms: never reached
            };
            leaf.insert(*s, name);
        }
        let uses_t = syms.contains(&Sym::Time) || !coef_ids.is_empty();
        let uses_x = syms.iter().any(|s| matches!(s, Sym::Coord(_))) || !coef_ids.is_empty();
        let uses_h = syms.contains(&Sym::CellDiameter);
        if uses_t {
            prologue.push_str("let t = ctx.t;\n");
        }
        if uses_h {
            prologue.push_str("let h = ctx.h;\n");
        }

        // Which nodes depend on the quadrature point, and how often each is used.
        let mut pointwise: HashMap<NodeId, bool> = HashMap::new();
        let mut uses: HashMap<NodeId, usize> = HashMap::new();
        // Cell-constant nodes read inside the loop (by a pointwise node or as an output).
        let mut read_in_loop: HashSet<NodeId> = roots.iter().copied().collect();
        for &n in &nodes {
            let pw = match g.node(n) {
                // Constant over the cell: hoisted out of the quadrature loop.
                Node::Const(_) | Node::Sym(Sym::Param(_) | Sym::CellDiameter | Sym::Time) => false,
                Node::Sym(_) => true,
                _ => g.children(n).any(|c| pointwise[&c]),
            };
            pointwise.insert(n, pw);
            for c in g.children(n) {
                *uses.entry(c).or_default() += 1;
                if pw {
                    read_in_loop.insert(c);
                }
            }
        }
        for r in &roots {
            *uses.entry(*r).or_default() += 1;
        }

        // Let-bound nodes: named in the source, used more than once, or hoisted out of the loop.
        let mut bound: HashMap<NodeId, String> = HashMap::new();
        let mut hoisted = String::new();
        let mut point = String::new();
        for &n in &nodes {
            if matches!(g.node(n), Node::Const(_) | Node::Sym(_)) {
                continue;
            }
            let named = g.names.get(&n);
            let crosses = !pointwise[&n] && read_in_loop.contains(&n);
            if named.is_none() && uses.get(&n).copied().unwrap_or(0) <= 1 && !crosses {
                continue;
            }
            let (text, _) = self.expr(n, &leaf, &bound);
            let local = namer.fresh(named.map_or(&format!("t{n}"), |s| s));
            let line = format!("let {local} = {text};\n");
            if pointwise[&n] {
                point.push_str(&line)
            } else {
                hoisted.push_str(&line)
            }
            bound.insert(n, local);
        }

        // Weighted outputs (switches are signs: no weight).
        let mut weighted = String::new();
        let weight = if matches!(self.mode, Mode::Switches(_)) { "" } else { "w * " };
        for (_, list) in &outputs {
            for o in list.iter().flatten() {
                let (text, prec) = match bound.get(&o.node) {
                    Some(local) => (local.clone(), ATOM),
                    None => self.expr(o.node, &leaf, &bound),
                };
                let text = if prec < UNARY && !weight.is_empty() { format!("({text})") } else { text };
                let _ = writeln!(weighted, "let {} = {weight}{text};", o.name);
            }
        }

        // Geometry needed at the point.
        let needs = |kinds: &[&str]| outputs.iter().any(|(k, l)| kinds.contains(k) && l.iter().any(Option::is_some));
        let field_vals = field_val.iter().any(Option::is_some);
        let field_grads = field_grad.iter().any(Option::is_some);
        let need_phi = field_vals || uses_x || needs(&["f0", "c00", "c01", "c10"]);
        let need_dphi = field_grads || needs(&["f1", "c01", "c10", "c11"]);

        let mut s = String::new();
        s.push_str(&prologue);
        s.push_str(&hoisted);
        s.push_str("for q in 0..ctx.tab.len() {\n");
        if need_phi {
            s.push_str("let phi = &ctx.tab.phi[q];\n");
        }
        s.push_str("let jac = geometry::jacobian(ctx.coords, &ctx.tab.dphi[q]);\n");
        if self.integral.cell {
            s.push_str("let w = ctx.tab.weights[q] * jac.det.abs();\n");
        } else {
            s.push_str("let (n, scale) = geometry::facet_normal(&jac, ctx.ref_normal);\n");
            s.push_str("let w = ctx.tab.weights[q] * scale;\n");
        }
        if need_dphi {
            s.push_str("let dphi = geometry::physical_gradients(&jac, &ctx.tab.dphi[q]);\n");
        }
        if uses_x {
            s.push_str("let x = geometry::interpolate(ctx.coords, phi);\n");
        }
        for (id, local) in &coef_locals {
            let c = &self.prog.coefs[*id as usize];
            let len = crate::ir::lower::components(c.shape, d);
            let _ = writeln!(
                s,
                "let mut {local} = [0.0; {len}];\nself.coefs.{}.eval(&x, t, &mut {local});",
                ident(&c.name)
            );
        }
        for (dofs, val) in field_val.iter().flatten() {
            let _ = writeln!(s, "let {val} = geometry::interpolate({dofs}, phi);");
        }
        for (dofs, grad) in field_grad.iter().flatten() {
            let _ = writeln!(s, "let {grad} = geometry::gradient({dofs}, &dphi);");
        }
        s.push_str(&point);
        s.push_str(&weighted);
        match self.mode {
            Mode::Residual => s.push_str(&self.residual_loop(&outputs)),
            Mode::Tangent(_) => s.push_str(&self.tangent_loop(&outputs)),
            Mode::Switches(_) => {
                for o in outputs.iter().flat_map(|(_, l)| l.iter().flatten()) {
                    let _ = writeln!(s, "out.push({} > 0.0);", o.name);
                }
            }
            Mode::Value => s.push_str("total += value;\n"),
        }
        s.push_str("}\n");
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

    /// Rust text of a node and its precedence; let-bound nodes and leaves are names.
    fn expr(&self, id: NodeId, leaf: &HashMap<Sym, String>, bound: &HashMap<NodeId, String>) -> (String, u8) {
        let g = self.g;
        let sub = |x: NodeId| -> (String, u8) {
            if let Some(b) = bound.get(&x) {
                return (b.clone(), ATOM);
            }
            self.expr(x, leaf, bound)
        };
        let wrap = |(t, p): (String, u8), min: u8| if p < min { format!("({t})") } else { t };
        match g.node(id) {
            Node::Const(b) => literal(f64::from_bits(b)),
            Node::Sym(s) => (leaf[&s].clone(), ATOM),
            Node::Add(a, b) => {
                let l = wrap(sub(a), ADD);
                match g.node(b) {
                    Node::Neg(x) if !bound.contains_key(&b) => (format!("{l} - {}", wrap(sub(x), MUL)), ADD),
                    Node::Const(c) if f64::from_bits(c) < 0.0 => {
                        (format!("{l} - {}", literal(-f64::from_bits(c)).0), ADD)
                    }
                    _ => (format!("{l} + {}", wrap(sub(b), MUL)), ADD),
                }
            }
            Node::Mul(a, b) => (format!("{} * {}", wrap(sub(a), MUL), wrap(sub(b), UNARY)), MUL),
            Node::Div(a, b) => (format!("{} / {}", wrap(sub(a), MUL), wrap(sub(b), UNARY)), MUL),
            Node::Neg(a) => (format!("-{}", wrap(sub(a), UNARY)), UNARY),
            Node::Powi(a, k) => (format!("{}.powi({k})", wrap(sub(a), ATOM)), ATOM),
            Node::Powf(a, p) => (format!("{}.powf({:?})", wrap(sub(a), ATOM), f64::from_bits(p)), ATOM),
            Node::Sqrt(a) => (format!("{}.sqrt()", wrap(sub(a), ATOM)), ATOM),
            Node::Heaviside(a) => (format!("heaviside({})", sub(a).0), ATOM),
        }
    }
}

/// A float literal (negative ones have unary precedence).
fn literal(v: f64) -> (String, u8) {
    if v.is_nan() {
        ("f64::NAN".into(), ATOM)
    } else if v.is_infinite() {
        (if v > 0.0 { "f64::INFINITY".into() } else { "-f64::INFINITY".into() }, if v > 0.0 { ATOM } else { UNARY })
    } else {
        let s = format!("{v:?}");
        let s = if s.contains(['.', 'e', 'E']) { s } else { format!("{s}.0") };
        if v < 0.0 { (s, UNARY) } else { (s, ATOM) }
    }
}
