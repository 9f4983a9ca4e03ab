//! The kernel plan of a form in one dimension: for each integral and mode (residual, tangent,
//! switches, value), which outputs of the IR a kernel computes and in which order, where each
//! leaf comes from, what is set once per call, and how the weighted outputs contract with the
//! basis functions. The code generator writes a plan out as Rust (codegen/kernel.rs) and the
//! interpreter runs it (the main crate's `interpret`), so the two agree by construction.

use super::eval::Program;
use super::graph::{Graph, Node, NodeId, Sym};
use super::lower::components;
use super::{DimIr, FormIr, IntegralIr, TangentIr};
use crate::check::Unit;

/// The IR list a root is an entry of (index conventions of [`IntegralIr`] and [`TangentIr`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Array {
    F0,
    F1,
    C00,
    C01,
    C10,
    C11,
    /// `TangentIr::switches`.
    Switch,
    /// `TangentIr::gates`.
    Gate,
    Value,
}

/// One output of a body: entry `at` (the flat index) of `array`, the value of `node`.
#[derive(Clone, Copy, Debug)]
pub struct Root {
    pub array: Array,
    pub at: usize,
    pub node: NodeId,
}

/// Where the value of one leaf comes from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Leaf {
    Param(u16),
    /// Component `comp` of field argument `arg` at the point.
    Value {
        arg: u8,
        comp: u8,
    },
    Grad {
        arg: u8,
        comp: u8,
        dir: u8,
    },
    Normal(u8),
    CellDiameter,
    Coord(u8),
    Time,
    /// Component `comp` of coef `id`, at index `at` of the per-point buffer of coef values.
    Coef {
        id: u16,
        comp: u8,
        at: u32,
    },
    /// A leaf no kernel reads (the test function in f0/f1, the time step, the cell diameter
    /// of a volume integral, which the checker rejects): 0.
    Zero,
}

impl Leaf {
    /// Set once per kernel call: what depends only on these leaves is computed before the
    /// quadrature loop.
    pub fn hoisted(self) -> bool {
        matches!(self, Leaf::Param(_) | Leaf::CellDiameter | Leaf::Time | Leaf::Zero)
    }

    fn of(s: Sym, cell: bool, coefs: &[CoefSlot]) -> Leaf {
        match s {
            Sym::Param(i) => Leaf::Param(i),
            Sym::Field { arg, comp } => Leaf::Value { arg, comp },
            Sym::FieldGrad { arg, comp, dir } => Leaf::Grad { arg, comp, dir },
            Sym::Normal(k) => Leaf::Normal(k),
            Sym::CellDiameter if !cell => Leaf::CellDiameter,
            Sym::Coord(k) => Leaf::Coord(k),
            Sym::Time => Leaf::Time,
            Sym::Coef { id, comp } => {
                let slot = coefs.iter().find(|c| c.id == id).expect("laid out from the same leaves");
                Leaf::Coef { id, comp, at: (slot.at + comp as usize) as u32 }
            }
            Sym::CellDiameter | Sym::Dt | Sym::Test { .. } | Sym::TestGrad { .. } => Leaf::Zero,
        }
    }
}

/// A coef evaluated at each point: its `len` components at `at..at + len` of the buffer.
#[derive(Clone, Copy, Debug)]
pub struct CoefSlot {
    pub id: u16,
    pub at: usize,
    pub len: usize,
}

/// The basis factor of a term: φ or ∂_l φ of a node.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Basis {
    Phi,
    Dphi(u8),
}

/// `Σ basis·root` over the terms (root indices into [`Body::roots`]), summed left to right.
pub type Terms = Vec<(Basis, u32)>;

/// How the weighted roots become kernel output.
#[derive(Debug)]
pub enum Contract {
    /// `out[j][k] += Σ rows[k]`, with the test basis functions at node j.
    Residual { rows: Vec<Terms> },
    /// `a[k][m] = Σ a[k*d + m]` and `b[k][m][n] = Σ b[(k*d + m)*d + n]` at test node i;
    /// `out[i][k][j][m] += a[k][m]·φ_j + Σ_n b[k][m][n]·∂_n φ_j` over the present ones.
    Tangent { a: Vec<Terms>, b: Vec<Terms> },
    /// The signs of the (unweighted) roots: the first `count` are the switches, the rest the
    /// gates (see [`Decided::Gated`]).
    Switches { count: usize },
    /// The integral of the only root.
    Value,
}

impl Contract {
    /// Whether the contraction reads basis values φ.
    pub fn reads_phi(&self) -> bool {
        match self {
            Contract::Residual { rows } => rows.iter().flatten().any(|t| t.0 == Basis::Phi),
            // A present a[k][m] multiplies φ_j.
            Contract::Tangent { a, b } => {
                a.iter().any(|t| !t.is_empty()) || b.iter().flatten().any(|t| t.0 == Basis::Phi)
            }
            Contract::Switches { .. } | Contract::Value => false,
        }
    }

    /// Whether the contraction reads basis gradients ∂φ.
    pub fn reads_dphi(&self) -> bool {
        let dphi = |t: &(Basis, u32)| matches!(t.0, Basis::Dphi(_));
        match self {
            Contract::Residual { rows } => rows.iter().flatten().any(dphi),
            // A present b[k][m][n] multiplies ∂_n φ_j.
            Contract::Tangent { a, b } => a.iter().flatten().any(dphi) || b.iter().any(|t| !t.is_empty()),
            Contract::Switches { .. } | Contract::Value => false,
        }
    }
}

/// One kernel body: what runs at the quadrature points of one (integral, mode).
#[derive(Debug)]
pub struct Body {
    /// The non-zero outputs, in the order they are computed.
    pub roots: Vec<Root>,
    /// The roots' evaluation, staged: operations on hoisted leaves only come first.
    pub prog: Program,
    /// Source of each leaf of `prog`, in slot order (`prog.syms()`).
    pub leaves: Vec<Leaf>,
    /// The coefs evaluated at each point, by id, and the length of their buffer.
    pub coefs: Vec<CoefSlot>,
    pub coef_len: usize,
    /// Physical coordinates of the point are needed (for `x` or for a coef).
    pub uses_x: bool,
    /// Physical basis gradients are needed (by a field gradient or the contraction).
    pub uses_dphi: bool,
    pub contract: Contract,
}

impl Body {
    /// Switches are signs: they take no quadrature weight.
    pub fn weighted(&self) -> bool {
        !matches!(self.contract, Contract::Switches { .. })
    }

    /// The source of leaf `s`, if the body reads it.
    pub fn leaf(&self, s: Sym) -> Option<Leaf> {
        self.prog.syms().binary_search(&s).ok().map(|i| self.leaves[i])
    }
}

/// Where a tangent depends on the fields only through its switches (`TangentIr::gates`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Decided {
    /// Everywhere (`piecewise`).
    Always,
    /// Where the gates (the switches body's roots after the switches) are all off.
    Gated,
    Never,
}

/// The kernels of one integral.
#[derive(Debug)]
pub struct Integral {
    /// Over cells; otherwise over the facets of a boundary region.
    pub cell: bool,
    /// `None` where there is nothing to compute (every output is zero).
    pub residual: Option<Body>,
    /// Per field argument.
    pub tangents: Vec<Option<Body>>,
    pub switches: Vec<Option<Body>>,
    pub decided: Vec<Decided>,
    pub value: Option<Body>,
}

/// The kernels of one form in one dimension.
#[derive(Debug)]
pub struct FormPlan {
    pub cell: Option<Integral>,
    /// In the order of the form's boundary regions.
    pub facets: Vec<Integral>,
}

/// The plan of `form`, lowered in `ir`.
pub fn form(unit: &Unit, ir: &DimIr, form: &FormIr) -> FormPlan {
    let integral = |i: &IntegralIr| Integral {
        cell: i.cell,
        // A functional has no test function, so no residual.
        residual: form.test.is_some().then(|| residual(unit, ir, i)).flatten(),
        tangents: i.tangents.iter().map(|t| tangent(unit, ir, i.cell, t)).collect(),
        switches: i.tangents.iter().map(|t| switches(unit, ir, i.cell, t)).collect(),
        decided: i
            .tangents
            .iter()
            .map(|t| match (t.piecewise, &t.gates) {
                (true, _) => Decided::Always,
                (false, Some(g)) if !g.is_empty() => Decided::Gated,
                (false, _) => Decided::Never,
            })
            .collect(),
        value: i.value.and_then(|v| {
            let mut roots = Roots { g: &ir.graph, list: Vec::new() };
            roots.add(Array::Value, &[v]);
            body(unit, ir, i.cell, roots.list, Contract::Value)
        }),
    };
    FormPlan {
        cell: form.integrals.iter().find(|i| i.cell).map(integral),
        facets: form.integrals.iter().filter(|i| !i.cell).map(integral).collect(),
    }
}

/// The roots of a body as they are listed; `add` gives, per entry of a list, its root index
/// (`None` for a zero entry, which no kernel computes).
struct Roots<'g> {
    g: &'g Graph,
    list: Vec<Root>,
}

impl Roots<'_> {
    fn add(&mut self, array: Array, nodes: &[NodeId]) -> Vec<Option<u32>> {
        self.add_if(array, nodes, |g, n| !g.is_zero(n))
    }

    fn add_if(&mut self, array: Array, nodes: &[NodeId], keep: fn(&Graph, NodeId) -> bool) -> Vec<Option<u32>> {
        let list = &mut self.list;
        let g = self.g;
        nodes
            .iter()
            .enumerate()
            .map(|(at, &node)| {
                keep(g, node).then(|| {
                    list.push(Root { array, at, node });
                    list.len() as u32 - 1
                })
            })
            .collect()
    }
}

/// `Some(term)` for a present root.
fn term(basis: Basis, root: Option<u32>) -> Option<(Basis, u32)> {
    root.map(|r| (basis, r))
}

fn residual(unit: &Unit, ir: &DimIr, i: &IntegralIr) -> Option<Body> {
    let d = ir.dim;
    let mut roots = Roots { g: &ir.graph, list: Vec::new() };
    let f0 = roots.add(Array::F0, &i.f0);
    let f1 = roots.add(Array::F1, &i.f1);
    let rows = (0..d)
        .map(|k| {
            let dphi = (0..d).map(|l| term(Basis::Dphi(l as u8), f1[k * d + l]));
            term(Basis::Phi, f0[k]).into_iter().chain(dphi.flatten()).collect()
        })
        .collect();
    body(unit, ir, i.cell, roots.list, Contract::Residual { rows })
}

fn tangent(unit: &Unit, ir: &DimIr, cell: bool, t: &TangentIr) -> Option<Body> {
    let d = ir.dim;
    let mut roots = Roots { g: &ir.graph, list: Vec::new() };
    let c00 = roots.add(Array::C00, &t.c00);
    let c01 = roots.add(Array::C01, &t.c01);
    let c10 = roots.add(Array::C10, &t.c10);
    let c11 = roots.add(Array::C11, &t.c11);
    let mut a = Vec::with_capacity(d * d);
    let mut b = Vec::with_capacity(d * d * d);
    for k in 0..d {
        for m in 0..d {
            let dphi = (0..d).map(|l| term(Basis::Dphi(l as u8), c10[(k * d + l) * d + m]));
            a.push(term(Basis::Phi, c00[k * d + m]).into_iter().chain(dphi.flatten()).collect());
            for n in 0..d {
                let dphi = (0..d).map(|l| term(Basis::Dphi(l as u8), c11[((k * d + l) * d + m) * d + n]));
                b.push(term(Basis::Phi, c01[(k * d + m) * d + n]).into_iter().chain(dphi.flatten()).collect());
            }
        }
    }
    body(unit, ir, cell, roots.list, Contract::Tangent { a, b })
}

/// The switches, then (where they may decide the tangent) the gates. A zero switch stays: its
/// sign is part of the active set.
fn switches(unit: &Unit, ir: &DimIr, cell: bool, t: &TangentIr) -> Option<Body> {
    let mut roots = Roots { g: &ir.graph, list: Vec::new() };
    roots.add_if(Array::Switch, &t.switches, |_, _| true);
    if !t.piecewise {
        roots.add_if(Array::Gate, t.gates.as_deref().unwrap_or_default(), |_, _| true);
    }
    body(unit, ir, cell, roots.list, Contract::Switches { count: t.switches.len() })
}

/// The body computing `roots`, or `None` if there are none.
fn body(unit: &Unit, ir: &DimIr, cell: bool, roots: Vec<Root>, contract: Contract) -> Option<Body> {
    if roots.is_empty() {
        return None;
    }
    let g = &ir.graph;
    let nodes: Vec<NodeId> = roots.iter().map(|r| r.node).collect();
    // In slot order: `Program` sorts its leaves as `Sym` does.
    let mut syms: Vec<Sym> = g
        .reachable(nodes.iter().copied())
        .into_iter()
        .filter_map(|n| if let Node::Sym(s) = g.node(n) { Some(s) } else { None })
        .collect();
    syms.sort_unstable();
    let mut coefs: Vec<CoefSlot> = Vec::new();
    let mut coef_len = 0;
    for &s in &syms {
        if let Sym::Coef { id, .. } = s
            && coefs.last().is_none_or(|c| c.id != id)
        {
            let len = components(unit.coefs[id as usize].shape, ir.dim);
            coefs.push(CoefSlot { id, at: coef_len, len });
            coef_len += len;
        }
    }
    let leaves: Vec<Leaf> = syms.iter().map(|&s| Leaf::of(s, cell, &coefs)).collect();
    let hoisted = |s: Sym| syms.binary_search(&s).is_ok_and(|i| leaves[i].hoisted());
    let prog = Program::staged(g, &nodes, hoisted);
    debug_assert_eq!(prog.syms(), syms.as_slice());
    let uses_x = !coefs.is_empty() || leaves.iter().any(|l| matches!(l, Leaf::Coord(_)));
    let uses_dphi = contract.reads_dphi() || leaves.iter().any(|l| matches!(l, Leaf::Grad { .. }));
    Some(Body { roots, prog, leaves, coefs, coef_len, uses_x, uses_dphi, contract })
}
