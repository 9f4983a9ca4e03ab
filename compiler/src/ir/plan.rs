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
            Sym::FieldHess { .. } | Sym::NormalRate { .. } => unreachable!("read on a pair's facing side only"),
            Sym::Seed(_) => unreachable!("a derivative's seed is set to 0 where the derivative is lowered"),
            Sym::Opposite(_) => unreachable!("a pair law's integrals are planned by `ir::pair`"),
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
    /// Some coef is evaluated at a point of the body's own (`g(x + u)`: `Node::CoefAt`).
    pub coefs_at: bool,
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

/// The plan of `form`, lowered in `ir`: empty for a contact pair's law, whose integrals are
/// evaluated pointwise at facing points (`ir::pair`).
pub fn form(unit: &Unit, ir: &DimIr, form: &FormIr) -> FormPlan {
    if form.pair {
        return FormPlan { cell: None, facets: Vec::new() };
    }
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
    let reachable = g.reachable(nodes.iter().copied());
    let coefs_at = reachable.iter().any(|&n| matches!(g.node(n), Node::CoefAt { .. }));
    // In slot order: `Program` sorts its leaves as `Sym` does.
    let mut syms: Vec<Sym> =
        reachable.into_iter().filter_map(|n| if let Node::Sym(s) = g.node(n) { Some(s) } else { None }).collect();
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
    Some(Body { roots, prog, leaves, coefs, coef_len, uses_x, coefs_at, uses_dphi, contract })
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::*;
    use crate::{MemLoader, check_path};

    /// The 2D plan of form `name` of the file `text`.
    fn plan(text: &str, name: &str) -> FormPlan {
        let loader = MemLoader::default().with("t.wf", text);
        let (prog, _) = check_path(Path::new("t.wf"), &loader).unwrap_or_else(|f| panic!("{}", f.rendered));
        let ir = &prog.irs[1];
        let fi = ir.forms.iter().position(|f| f.name == name).expect("declared");
        form(&prog, ir, &ir.forms[fi])
    }

    #[test]
    fn a_residual_sums_its_non_zero_coefficients_by_basis() {
        let p =
            plan("param k = 2.0 in (0, inf)\nform f(u; v) = int(Omega) k * dot(u, v) + inner(grad(u), grad(v))\n", "f");
        let cell = p.cell.expect("a volume integral");
        let r = cell.residual.as_ref().expect("non-zero");
        let roots: Vec<(Array, usize)> = r.roots.iter().map(|r| (r.array, r.at)).collect();
        let f1 = (0..4).map(|at| (Array::F1, at));
        assert_eq!(roots, [(Array::F0, 0), (Array::F0, 1)].into_iter().chain(f1).collect::<Vec<_>>());
        let Contract::Residual { rows } = &r.contract else { panic!("a residual") };
        assert_eq!(rows[0], [(Basis::Phi, 0), (Basis::Dphi(0), 2), (Basis::Dphi(1), 3)]);
        assert_eq!(rows[1], [(Basis::Phi, 1), (Basis::Dphi(0), 4), (Basis::Dphi(1), 5)]);
        assert!(r.leaf(Sym::Param(0)).is_some_and(Leaf::hoisted));
        assert_eq!(r.leaf(Sym::FieldGrad { arg: 0, comp: 1, dir: 0 }), Some(Leaf::Grad { arg: 0, comp: 1, dir: 0 }));
        assert!(r.uses_dphi && !r.uses_x && r.weighted());
        // Linear: the tangent is constant, so the (absent) switches decide it.
        assert_eq!(cell.decided, [Decided::Always]);
        assert!(cell.switches[0].is_none());
        let Some(Body { contract: Contract::Tangent { a, b }, .. }) = &cell.tangents[0] else { panic!("a tangent") };
        assert_eq!(a[1], []); // ∂f0[0]/∂u_1 = 0, and f1 reads no u.
        assert_eq!(b.iter().filter(|t| !t.is_empty()).count(), 4); // ∂_n u_m with m = k
    }

    #[test]
    fn a_facet_body_lays_out_its_coefs_and_hoists_the_cell_diameter() {
        let text = "param gamma0 = 5.0 in (0, inf)\ncoef g\ncoef nc: vector\n\
                    form c(u; v) = int(Gamma_C) gamma0 / h * pos(dot(u, nc) - g) * dot(v, nc)\n";
        let p = plan(text, "c");
        assert!(p.cell.is_none());
        let facet = &p.facets[0];
        let r = facet.residual.as_ref().expect("non-zero");
        let layout: Vec<(u16, usize, usize)> = r.coefs.iter().map(|c| (c.id, c.at, c.len)).collect();
        assert_eq!((layout, r.coef_len), (vec![(0, 0, 1), (1, 1, 2)], 3));
        assert_eq!(r.leaf(Sym::Coef { id: 1, comp: 1 }), Some(Leaf::Coef { id: 1, comp: 1, at: 2 }));
        assert!(r.leaf(Sym::CellDiameter).is_some_and(Leaf::hoisted));
        assert!(r.uses_x && !r.uses_dphi);
        // Penalty contact: the active set decides the tangent; its switch is a sign, unweighted.
        assert_eq!(facet.decided, [Decided::Always]);
        let s = facet.switches[0].as_ref().expect("a switch");
        assert!(matches!(s.contract, Contract::Switches { count: 1 }) && !s.weighted());
        assert_eq!(s.roots.iter().map(|r| r.array).collect::<Vec<_>>(), [Array::Switch]);
    }
}
