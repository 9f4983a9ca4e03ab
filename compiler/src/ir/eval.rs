//! Numeric evaluation of the expression DAG: the one evaluator for everything that computes
//! with IR instead of generating code for it (interpreted forms, scheme coefficients, tests).
//!
//! A [`Program`] is compiled once for a set of roots: the reachable nodes become instructions
//! over a flat array of slots, leaves (the [`Sym`]s) first, then constants, then one slot per
//! operation in topological order. Running it per point allocates nothing once the scratch
//! buffer has grown. Each node is one floating-point operation written exactly as the
//! generated kernels write it (`a + b`, `a * b`, `a / b`, `-a`, `powi`, `sqrt`, `sin`, ...,
//! `atan2`, H(a) = 1 if a > 0 else 0), so interpreted and compiled results agree bit for bit
//! up to the order in which the kernels sum over basis functions.

use std::collections::HashMap;

use super::graph::{Dirs, Func, Graph, Node, NodeId, Sym};

/// Slot index.
type Slot = u32;

#[derive(Clone, Copy, Debug)]
enum Op {
    Add(Slot, Slot),
    Mul(Slot, Slot),
    Div(Slot, Slot),
    Neg(Slot),
    Powi(Slot, i32),
    Powf(Slot, f64),
    Sqrt(Slot),
    Heaviside(Slot),
    Func(Func, Slot),
    Atan2(Slot, Slot),
    /// Component `comp` of coef `id` (or a derivative) at a point: the slots of its
    /// components, `len` of them.
    CoefAt {
        id: u16,
        comp: u8,
        dirs: Dirs,
        point: [Slot; 3],
        len: u8,
    },
}

/// The values of case data at points other than the quadrature point ([`Node::CoefAt`]):
/// component `comp` of coef `id` at `point`, differentiated along `dirs`.
pub trait CoefsAt {
    fn at(&self, id: u16, comp: u8, dirs: &[u8], point: &[f64]) -> f64;
}

/// For programs that read no coef at a point: NaN if one does.
struct NoCoefs;

impl CoefsAt for NoCoefs {
    fn at(&self, _: u16, _: u8, _: &[u8], _: &[f64]) -> f64 {
        f64::NAN
    }
}

/// Straight-line code computing some roots of a graph from the values of its leaves.
#[derive(Clone, Debug, Default)]
pub struct Program {
    syms: Vec<Sym>,
    consts: Vec<f64>,
    ops: Vec<Op>,
    /// Operations `..invariant` depend only on leaves accepted as invariant (see
    /// [`Program::staged`]); they may run once for many runs of the rest.
    invariant: usize,
    roots: Vec<Slot>,
}

impl Program {
    /// Compiles the nodes reachable from `roots`. Leaves are ordered as in [`Sym`]'s `Ord`.
    pub fn new(g: &Graph, roots: &[NodeId]) -> Program {
        Program::staged(g, roots, |_| false)
    }

    /// As [`Program::new`], with the operations that depend only on constants and on leaves
    /// for which `invariant` holds placed first, so that [`Program::exec_invariant`] runs them
    /// once (per cell, say) and [`Program::exec_varying`] the rest (per quadrature point).
    pub fn staged(g: &Graph, roots: &[NodeId], invariant: impl Fn(Sym) -> bool) -> Program {
        let nodes = g.reachable(roots.iter().copied());
        let mut syms: Vec<Sym> =
            nodes.iter().filter_map(|&n| if let Node::Sym(s) = g.node(n) { Some(s) } else { None }).collect();
        syms.sort_unstable();
        let mut slot: HashMap<NodeId, Slot> = HashMap::new();
        let mut consts = Vec::new();
        let mut varies: HashMap<NodeId, bool> = HashMap::new();
        for &n in &nodes {
            match g.node(n) {
                Node::Const(b) => {
                    consts.push(f64::from_bits(b));
                    varies.insert(n, false);
                }
                Node::Sym(s) => {
                    varies.insert(n, !invariant(s));
                }
                _ => {
                    let v = g.children(n).any(|c| varies[&c]);
                    varies.insert(n, v);
                }
            }
        }
        for &n in &nodes {
            if let Node::Sym(s) = g.node(n) {
                slot.insert(n, syms.binary_search(&s).unwrap_or_default() as Slot);
            }
        }
        let mut next = syms.len() as Slot;
        for &n in &nodes {
            if matches!(g.node(n), Node::Const(_)) {
                slot.insert(n, next);
                next += 1;
            }
        }
        // Invariant operations first; within each stage ids keep children before parents.
        let (nodes, varies) = (&nodes, &varies);
        let ops_in = |stage_varies: bool| {
            nodes
                .iter()
                .copied()
                .filter(move |&n| !matches!(g.node(n), Node::Const(_) | Node::Sym(_)) && varies[&n] == stage_varies)
        };
        let order: Vec<NodeId> = ops_in(false).chain(ops_in(true)).collect();
        let invariant = ops_in(false).count();
        let mut ops = Vec::with_capacity(order.len());
        for n in order {
            let s = |c: NodeId| slot[&c];
            ops.push(match g.node(n) {
                Node::Add(a, b) => Op::Add(s(a), s(b)),
                Node::Mul(a, b) => Op::Mul(s(a), s(b)),
                Node::Div(a, b) => Op::Div(s(a), s(b)),
                Node::Neg(a) => Op::Neg(s(a)),
                Node::Powi(a, k) => Op::Powi(s(a), k),
                Node::Powf(a, p) => Op::Powf(s(a), f64::from_bits(p)),
                Node::Sqrt(a) => Op::Sqrt(s(a)),
                Node::Heaviside(a) | Node::Step(a) => Op::Heaviside(s(a)),
                Node::Func(f, a) => Op::Func(f, s(a)),
                Node::Atan2(y, x) => Op::Atan2(s(y), s(x)),
                Node::CoefAt { id, comp, dirs, point } => {
                    let at = g.point(point);
                    let mut slots = [0; 3];
                    for (o, &p) in slots.iter_mut().zip(at) {
                        *o = s(p);
                    }
                    Op::CoefAt { id, comp, dirs, point: slots, len: at.len() as u8 }
                }
                Node::Const(_) | Node::Sym(_) => continue,
            });
            slot.insert(n, next);
            next += 1;
        }
        let roots = roots.iter().map(|r| slot[r]).collect();
        Program { syms, consts, ops, invariant, roots }
    }

    /// The leaves the program reads, in slot order: `slots[i]` holds the value of `syms()[i]`.
    pub fn syms(&self) -> &[Sym] {
        &self.syms
    }

    /// When the program computes nothing (each root is a leaf or a constant): per root, the
    /// index of its leaf in [`Program::syms`] or its constant value. Callers then copy instead of
    /// running it (a gap `g = x[1]` at every quadrature point).
    pub fn trivial_roots(&self) -> Option<Vec<Result<usize, f64>>> {
        if !self.ops.is_empty() {
            return None;
        }
        let leaves = self.syms.len();
        Some(
            self.roots
                .iter()
                .map(|&r| match (r as usize).checked_sub(leaves) {
                    None => Ok(r as usize),
                    Some(c) => Err(self.consts[c]),
                })
                .collect(),
        )
    }

    /// Number of roots (outputs).
    pub fn outputs(&self) -> usize {
        self.roots.len()
    }

    /// Number of slots [`Program::exec`] needs.
    pub fn slots(&self) -> usize {
        self.syms.len() + self.consts.len() + self.ops.len()
    }

    /// Resizes `slots` for this program and writes the constants; the caller then writes the
    /// leaves into `slots[..syms().len()]`.
    pub fn prepare(&self, slots: &mut Vec<f64>) {
        slots.resize(self.slots(), 0.0);
        let c0 = self.syms.len();
        slots[c0..c0 + self.consts.len()].copy_from_slice(&self.consts);
    }

    /// Runs every operation on `slots` (prepared, with the leaves written).
    pub fn exec(&self, slots: &mut [f64]) {
        self.exec_ops(slots, 0, self.ops.len(), &NoCoefs);
    }

    /// Runs the operations that depend only on invariant leaves.
    pub fn exec_invariant(&self, slots: &mut [f64]) {
        self.exec_ops(slots, 0, self.invariant, &NoCoefs);
    }

    /// Runs the operations that depend on varying leaves (after [`Program::exec_invariant`]).
    pub fn exec_varying(&self, slots: &mut [f64]) {
        self.exec_ops(slots, self.invariant, self.ops.len(), &NoCoefs);
    }

    /// [`Program::exec_invariant`] for a program that reads coefs at points.
    pub fn exec_invariant_with(&self, slots: &mut [f64], coefs: &dyn CoefsAt) {
        self.exec_ops(slots, 0, self.invariant, coefs);
    }

    /// [`Program::exec_varying`] for a program that reads coefs at points.
    pub fn exec_varying_with(&self, slots: &mut [f64], coefs: &dyn CoefsAt) {
        self.exec_ops(slots, self.invariant, self.ops.len(), coefs);
    }

    /// The value of root `i` after a run.
    #[inline]
    pub fn root(&self, slots: &[f64], i: usize) -> f64 {
        slots[self.roots[i] as usize]
    }

    /// Evaluates the roots for the given leaf values (`leaves[i]` is the value of `syms()[i]`).
    /// `scratch` is reused across calls; `out` has one entry per root.
    pub fn run(&self, leaves: &[f64], scratch: &mut Vec<f64>, out: &mut [f64]) {
        self.prepare(scratch);
        let n = self.syms.len().min(leaves.len());
        scratch[..n].copy_from_slice(&leaves[..n]);
        self.exec(scratch);
        for (o, &r) in out.iter_mut().zip(&self.roots) {
            *o = scratch[r as usize];
        }
    }

    fn exec_ops(&self, slots: &mut [f64], from: usize, to: usize, coefs: &dyn CoefsAt) {
        let base = self.syms.len() + self.consts.len();
        for i in from..to {
            let v = |s: Slot| slots[s as usize];
            // The generated code's spelling of each node (codegen/emit.rs `Emitter::expr`).
            slots[base + i] = match self.ops[i] {
                Op::Add(a, b) => v(a) + v(b),
                Op::Mul(a, b) => v(a) * v(b),
                Op::Div(a, b) => v(a) / v(b),
                Op::Neg(a) => -v(a),
                Op::Powi(a, k) => v(a).powi(k),
                Op::Powf(a, p) => v(a).powf(p),
                Op::Sqrt(a) => v(a).sqrt(),
                Op::Heaviside(a) => heaviside(v(a)),
                Op::Func(f, a) => f.apply(v(a)),
                Op::Atan2(y, x) => v(y).atan2(v(x)),
                Op::CoefAt { id, comp, dirs, point, len } => {
                    let mut at = [0.0; 3];
                    for (o, &p) in at.iter_mut().zip(&point[..len as usize]) {
                        *o = v(p);
                    }
                    coefs.at(id, comp, dirs.as_slice(), &at[..len as usize])
                }
            };
        }
    }
}

/// H(a) = 1 if a > 0, else 0 (as `runtime::fem::kernel::heaviside`).
#[inline(always)]
pub fn heaviside(a: f64) -> f64 {
    if a > 0.0 { 1.0 } else { 0.0 }
}

/// One-shot evaluation of `roots` with the value of each leaf given by `leaf` (for code that
/// evaluates rarely; compile a [`Program`] to evaluate often).
pub fn evaluate(g: &Graph, roots: &[NodeId], leaf: impl Fn(Sym) -> f64) -> Vec<f64> {
    let p = Program::new(g, roots);
    let leaves: Vec<f64> = p.syms().iter().map(|&s| leaf(s)).collect();
    let mut out = vec![0.0; roots.len()];
    p.run(&leaves, &mut Vec::new(), &mut out);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn evaluates_every_node_kind() {
        let mut g = Graph::default();
        let (x, y) = (g.sym(Sym::Time), g.sym(Sym::Dt));
        let two = g.constant(2.0);
        let sum = g.add(x, y);
        let neg = g.neg(y);
        let prod = g.mul(sum, neg);
        let q = g.div(prod, two);
        let p3 = g.powi(q, 3);
        let r = g.sqrt(x);
        let h = g.heaviside(q);
        let roots = [q, p3, r, h, two];
        let (tx, ty) = (2.5, 0.5);
        let got = evaluate(&g, &roots, |s| if s == Sym::Time { tx } else { ty });
        let qv = (tx + ty) * -ty / 2.0;
        assert_eq!(got, vec![qv, qv.powi(3), tx.sqrt(), 0.0, 2.0]);
    }

    #[test]
    fn staged_runs_agree_with_one_run() {
        let mut g = Graph::default();
        let (p, x) = (g.sym(Sym::Param(0)), g.sym(Sym::Coord(0)));
        let one = g.one();
        let pp = g.add(p, one);
        let c = g.div(one, pp);
        let root = g.mul(c, x);
        let staged = Program::staged(&g, &[root, c], |s| matches!(s, Sym::Param(_)));
        let plain = Program::new(&g, &[root, c]);
        assert_eq!(staged.syms(), plain.syms());
        let mut slots = Vec::new();
        staged.prepare(&mut slots);
        // Leaves in `Sym` order: Param(0), then Coord(0).
        slots[0] = 0.7;
        staged.exec_invariant(&mut slots);
        let mut out = [0.0; 2];
        for xv in [0.1, -4.0] {
            slots[1] = xv;
            staged.exec_varying(&mut slots);
            let leaves: Vec<f64> = plain.syms().iter().map(|s| if *s == Sym::Coord(0) { xv } else { 0.7 }).collect();
            plain.run(&leaves, &mut Vec::new(), &mut out);
            assert_eq!([staged.root(&slots, 0), staged.root(&slots, 1)], out);
        }
    }
}
