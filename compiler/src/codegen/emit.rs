//! Straight-line Rust for the nodes of an expression graph: the one emitter of the kernels and
//! of the schemes' coefficients.
//!
//! A node gets a `let` when the source named it (a `let` or a `fn` of the file: the local has
//! the user's name), when more than one node or output reads it, or when it is constant over
//! the quadrature loop that reads it (it is computed once, before the loop). Every other node
//! is written inline where it is read. Each node is one floating-point operation, written as
//! the IR evaluator computes it and parenthesised by precedence, so inlining changes no bit of
//! the result: the order of the operations is the graph's.

use std::collections::{HashMap, HashSet};

use super::names::Namer;
use crate::ir::graph::{Graph, Node, NodeId, Sym};

/// Precedences of the Rust written for a node: an atom (a name, a literal, a method call), a
/// unary minus, a product, a sum.
pub const ATOM: u8 = 4;
pub const UNARY: u8 = 3;
pub const MUL: u8 = 2;
pub const ADD: u8 = 1;

/// The `let`s of the nodes some outputs need.
pub struct Lines {
    /// `let`s of the nodes that do not vary inside the loop (or of every node, without one).
    pub invariant: String,
    /// `let`s of the nodes that vary inside the loop.
    pub varying: String,
    /// The local of each bound node.
    bound: HashMap<NodeId, String>,
}

/// Writes nodes of `g` with the leaves named by `leaf`.
pub struct Emitter<'a> {
    g: &'a Graph,
    leaf: &'a HashMap<Sym, String>,
    /// The field of `self.coefs` of each coef, by id: where a kernel evaluates one at a point.
    coefs: &'a [String],
}

impl<'a> Emitter<'a> {
    pub fn new(g: &'a Graph, leaf: &'a HashMap<Sym, String>) -> Self {
        Emitter { g, leaf, coefs: &[] }
    }

    /// With the coefs' names, for a kernel that evaluates coefs at points (`Node::CoefAt`).
    pub fn with_coefs(self, coefs: &'a [String]) -> Self {
        Emitter { coefs, ..self }
    }

    /// The `let`s the nodes `outputs` need, named by `namer`. `varies(s)`: whether leaf `s`
    /// changes from one pass of the loop to the next; `in_loop`: whether the outputs are read
    /// inside the loop (a kernel's) or after every `let` (a scheme's coefficients).
    pub fn bind(&self, outputs: &[NodeId], varies: impl Fn(Sym) -> bool, in_loop: bool, namer: &mut Namer) -> Lines {
        let g = self.g;
        let nodes = g.reachable(outputs.iter().copied());
        // Which nodes vary in the loop, how often each is read, and which invariant ones are read
        // inside the loop (by a varying node, or as an output).
        let mut varying: HashMap<NodeId, bool> = HashMap::new();
        let mut reads: HashMap<NodeId, usize> = HashMap::new();
        let mut read_in_loop: HashSet<NodeId> =
            if in_loop { outputs.iter().copied().collect() } else { HashSet::new() };
        for &n in &nodes {
            let v = match g.node(n) {
                Node::Const(_) => false,
                Node::Sym(s) => varies(s),
                _ => g.children(n).any(|c| varying[&c]),
            };
            varying.insert(n, v);
            for c in g.children(n) {
                *reads.entry(c).or_default() += 1;
                if v {
                    read_in_loop.insert(c);
                }
            }
        }
        for r in outputs {
            *reads.entry(*r).or_default() += 1;
        }
        let bound: Vec<NodeId> = nodes
            .iter()
            .copied()
            .filter(|&n| {
                let hoisted = !varying[&n] && read_in_loop.contains(&n);
                !matches!(g.node(n), Node::Const(_) | Node::Sym(_))
                    && (g.names.contains_key(&n) || reads.get(&n).copied().unwrap_or(0) > 1 || hoisted)
            })
            .collect();
        // The invariant lets first, then the varying ones: temporaries are numbered as they read.
        let mut lines = Lines { invariant: String::new(), varying: String::new(), bound: HashMap::new() };
        for pass in [false, true] {
            for &n in bound.iter().filter(|&&n| varying[&n] == pass) {
                let (text, _) = self.expr(n, &lines);
                let local = match g.names.get(&n) {
                    Some(name) => namer.fresh(name),
                    None => namer.temporary(),
                };
                let line = format!("let {local} = {text};\n");
                if pass {
                    lines.varying.push_str(&line);
                } else {
                    lines.invariant.push_str(&line);
                }
                lines.bound.insert(n, local);
            }
        }
        lines
    }

    /// The Rust of a node and its precedence: its local if it has one, else its expression.
    pub fn value(&self, id: NodeId, lines: &Lines) -> (String, u8) {
        match lines.bound.get(&id) {
            Some(local) => (local.clone(), ATOM),
            None => self.expr(id, lines),
        }
    }

    /// The expression of a node (not its own local), its operands by [`Emitter::value`].
    fn expr(&self, id: NodeId, lines: &Lines) -> (String, u8) {
        let g = self.g;
        let sub = |x: NodeId| self.value(x, lines);
        let wrap = |(t, p): (String, u8), min: u8| if p < min { format!("({t})") } else { t };
        match g.node(id) {
            Node::Const(b) => literal(f64::from_bits(b)),
            Node::Sym(s) => (self.leaf[&s].clone(), ATOM),
            Node::Add(a, b) => {
                let l = wrap(sub(a), ADD);
                // a + (−x) is a − x, bit for bit.
                match g.node(b) {
                    Node::Neg(x) if !lines.bound.contains_key(&b) => (format!("{l} - {}", wrap(sub(x), MUL)), ADD),
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
            Node::Powf(a, p) => (format!("{}.powf({})", wrap(sub(a), ATOM), literal(f64::from_bits(p)).0), ATOM),
            Node::Sqrt(a) => (format!("{}.sqrt()", wrap(sub(a), ATOM)), ATOM),
            Node::Heaviside(a) | Node::Step(a) => (format!("heaviside({})", sub(a).0), ATOM),
            // `f64`'s methods, as the IR evaluator calls them (`Func::apply`).
            Node::Func(f, a) => (format!("{}.{}()", wrap(sub(a), ATOM), f.name()), ATOM),
            Node::Atan2(y, x) => (format!("{}.atan2({})", wrap(sub(y), ATOM), sub(x).0), ATOM),
            // `Coef::at`, as the IR evaluator calls it through `CoefsAt`.
            Node::CoefAt { id: c, comp, dirs, point } => {
                let at: Vec<String> = g.point(point).iter().map(|&p| sub(p).0).collect();
                let name = self.coefs.get(c as usize).map_or("coef", String::as_str);
                (format!("self.coefs.{name}.at(&[{}], t, {comp}, &{:?})", at.join(", "), dirs.as_slice()), ATOM)
            }
        }
    }
}

/// The constants of `std::f64::consts` a literal is written as (clippy refuses their digits).
const NAMED_CONSTANTS: &[(f64, &str)] = &[
    (std::f64::consts::PI, "PI"),
    (std::f64::consts::TAU, "TAU"),
    (std::f64::consts::E, "E"),
    (std::f64::consts::FRAC_PI_2, "FRAC_PI_2"),
    (std::f64::consts::FRAC_PI_3, "FRAC_PI_3"),
    (std::f64::consts::FRAC_PI_4, "FRAC_PI_4"),
    (std::f64::consts::FRAC_PI_6, "FRAC_PI_6"),
    (std::f64::consts::FRAC_PI_8, "FRAC_PI_8"),
    (std::f64::consts::FRAC_1_PI, "FRAC_1_PI"),
    (std::f64::consts::FRAC_2_PI, "FRAC_2_PI"),
    (std::f64::consts::FRAC_2_SQRT_PI, "FRAC_2_SQRT_PI"),
    (std::f64::consts::SQRT_2, "SQRT_2"),
    (std::f64::consts::FRAC_1_SQRT_2, "FRAC_1_SQRT_2"),
    (std::f64::consts::LN_2, "LN_2"),
    (std::f64::consts::LN_10, "LN_10"),
    (std::f64::consts::LOG2_E, "LOG2_E"),
    (std::f64::consts::LOG10_E, "LOG10_E"),
    (std::f64::consts::LOG2_10, "LOG2_10"),
    (std::f64::consts::LOG10_2, "LOG10_2"),
];

/// An f64 literal and its precedence (a negative one is a unary minus): the shortest digits
/// that read back as the value, or the name of a constant of `std::f64::consts`.
pub fn literal(v: f64) -> (String, u8) {
    if v.is_nan() {
        return ("f64::NAN".into(), ATOM);
    }
    if v.is_infinite() {
        return if v > 0.0 { ("f64::INFINITY".into(), ATOM) } else { ("-f64::INFINITY".into(), UNARY) };
    }
    let magnitude = match NAMED_CONSTANTS.iter().find(|(c, _)| c.to_bits() == v.abs().to_bits()) {
        Some((_, name)) => format!("std::f64::consts::{name}"),
        None => {
            let s = format!("{:?}", v.abs());
            if s.contains(['.', 'e', 'E']) { s } else { format!("{s}.0") }
        }
    };
    if v.is_sign_negative() { (format!("-{magnitude}"), UNARY) } else { (magnitude, ATOM) }
}
