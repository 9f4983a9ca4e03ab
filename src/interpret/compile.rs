//! Lowering of one form's IR in one dimension to what the interpreted kernels run: per
//! integral and mode, an `ir::eval::Program` of its pointwise coefficients, where each leaf
//! comes from, and how the weighted coefficients contract with the basis functions (the
//! loops the generated kernels write out, with the same terms in the same order).

use signorini_compiler::Program as Checked;
use signorini_compiler::ir::eval::Program;
use signorini_compiler::ir::graph::{Graph, NodeId, Sym};
use signorini_compiler::ir::lower::components;
use signorini_compiler::ir::{DimIr, FormIr, IntegralIr};

/// Where the value of one leaf of a program comes from.
#[derive(Clone, Copy)]
pub(super) enum Leaf {
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
    /// Index into the per-point buffer of coef values.
    Coef(u32),
    /// A leaf no form reads (the test function in f0/f1, the time step): the generated code
    /// writes 0.0 or nothing.
    Zero,
}

/// The basis factor of a term: φ or ∂_l φ of a node.
#[derive(Clone, Copy)]
pub(super) enum Basis {
    Phi,
    Dphi(u8),
}

/// `Σ basis·root` over the terms, summed left to right.
pub(super) type Terms = Vec<(Basis, u32)>;

/// How the weighted roots become kernel output.
pub(super) enum Contract {
    /// `out[j][k] += Σ rows[k]`, with test basis functions at node j.
    Residual { rows: Vec<Terms> },
    /// a[k][m] = Σ a_terms[k*d+m] and b[k][m][n] = Σ b_terms[(k*d+m)*d+n] at test node i;
    /// `out[i][k][j][m] += a[k][m]·φ_j + Σ_n b[k][m][n]·∂_n φ_j` over the present ones.
    Tangent { a: Vec<Terms>, b: Vec<Terms> },
    /// The sign of each (unweighted) root.
    Switches,
    /// The integral of the only root.
    Value,
}

/// One kernel body: what the generated code writes for one (integral, mode).
pub(super) struct Body {
    pub prog: Program,
    /// Source of each leaf of `prog`, in slot order.
    pub leaves: Vec<Leaf>,
    /// Coefs evaluated at each point: (coef index, offset in the buffer, components).
    pub coefs: Vec<(usize, usize, usize)>,
    pub coef_len: usize,
    /// Physical coordinates of the point are needed (for `x` or for a coef).
    pub uses_x: bool,
    /// Physical basis gradients are needed.
    pub uses_dphi: bool,
    pub contract: Contract,
}

/// The kernels of one integral.
pub(super) struct Integral {
    /// `None` where the generated body is empty (every output is zero).
    pub residual: Option<Body>,
    pub tangents: Vec<Option<Body>>,
    pub switches: Vec<Option<Body>>,
    /// Per field argument, where its tangent depends on the fields only through the switches.
    pub decided: Vec<Decided>,
    pub value: Option<Body>,
}

/// Where a tangent depends on the fields only through its switches (`TangentIr::gates`).
pub(super) enum Decided {
    Always,
    /// Where the gates are all off: the body's outputs after the switches, from this index.
    Gated(usize),
    Never,
}

/// The kernels of one form in one dimension.
pub(super) struct DimKernels {
    pub cell: Option<Integral>,
    /// In the order of the form's boundary regions (`FormMeta::facets`).
    pub facets: Vec<Integral>,
}

pub(super) fn dim_kernels(prog: &Checked, ir: &DimIr, form: &FormIr) -> DimKernels {
    let integral = |i: &IntegralIr| Integral {
        residual: (form.test.is_some()).then(|| residual(prog, ir, i)).flatten(),
        tangents: (0..i.tangents.len()).map(|a| tangent(prog, ir, i, a)).collect(),
        switches: i
            .tangents
            .iter()
            .map(|t| {
                let gates = t.gates.iter().flatten().filter(|_| !t.piecewise);
                let roots: Vec<NodeId> = t.switches.iter().chain(gates).copied().collect();
                body(prog, ir, i.cell, &roots, Contract::Switches)
            })
            .collect(),
        decided: i
            .tangents
            .iter()
            .map(|t| match (t.piecewise, &t.gates) {
                (true, _) => Decided::Always,
                (false, Some(g)) if !g.is_empty() => Decided::Gated(t.switches.len()),
                (false, _) => Decided::Never,
            })
            .collect(),
        value: i.value.and_then(|v| body(prog, ir, i.cell, &[v], Contract::Value)),
    };
    DimKernels {
        cell: form.integrals.iter().find(|i| i.cell).map(integral),
        facets: form.integrals.iter().filter(|i| !i.cell).map(integral).collect(),
    }
}

/// Roots are the non-zero outputs, in the order the generated code lists them; `index` maps a
/// list's flat index to its root.
struct Roots<'g> {
    g: &'g Graph,
    nodes: Vec<NodeId>,
}

impl Roots<'_> {
    fn add(&mut self, list: &[NodeId]) -> Vec<Option<u32>> {
        list.iter()
            .map(|&n| {
                (!self.g.is_zero(n)).then(|| {
                    self.nodes.push(n);
                    self.nodes.len() as u32 - 1
                })
            })
            .collect()
    }
}

fn residual(prog: &Checked, ir: &DimIr, i: &IntegralIr) -> Option<Body> {
    let d = ir.dim;
    let mut roots = Roots { g: &ir.graph, nodes: Vec::new() };
    let f0 = roots.add(&i.f0);
    let f1 = roots.add(&i.f1);
    let rows = (0..d)
        .map(|k| {
            let mut terms: Terms = f0[k].map(|r| (Basis::Phi, r)).into_iter().collect();
            terms.extend((0..d).filter_map(|l| f1[k * d + l].map(|r| (Basis::Dphi(l as u8), r))));
            terms
        })
        .collect();
    body(prog, ir, i.cell, &roots.nodes, Contract::Residual { rows })
}

fn tangent(prog: &Checked, ir: &DimIr, i: &IntegralIr, arg: usize) -> Option<Body> {
    let d = ir.dim;
    let t = &i.tangents[arg];
    let mut roots = Roots { g: &ir.graph, nodes: Vec::new() };
    let (c00, c01, c10, c11) = (roots.add(&t.c00), roots.add(&t.c01), roots.add(&t.c10), roots.add(&t.c11));
    let mut a = Vec::with_capacity(d * d);
    let mut b = Vec::with_capacity(d * d * d);
    for k in 0..d {
        for m in 0..d {
            let mut terms: Terms = c00[k * d + m].map(|r| (Basis::Phi, r)).into_iter().collect();
            terms.extend((0..d).filter_map(|l| c10[(k * d + l) * d + m].map(|r| (Basis::Dphi(l as u8), r))));
            a.push(terms);
            for n in 0..d {
                let mut terms: Terms = c01[(k * d + m) * d + n].map(|r| (Basis::Phi, r)).into_iter().collect();
                terms.extend(
                    (0..d).filter_map(|l| c11[((k * d + l) * d + m) * d + n].map(|r| (Basis::Dphi(l as u8), r))),
                );
                b.push(terms);
            }
        }
    }
    body(prog, ir, i.cell, &roots.nodes, Contract::Tangent { a, b })
}

/// The body computing `roots`, or `None` if there are none (the generated body is empty).
fn body(prog: &Checked, ir: &DimIr, cell: bool, roots: &[NodeId], contract: Contract) -> Option<Body> {
    if roots.is_empty() {
        return None;
    }
    // The leaves set once per kernel call (`Leaf::{Param, CellDiameter, Time, Zero}`), as
    // the generated code hoists what depends only on them out of the quadrature loop.
    let p = Program::staged(&ir.graph, roots, |s| {
        matches!(s, Sym::Param(_) | Sym::CellDiameter | Sym::Time | Sym::Dt | Sym::Test { .. } | Sym::TestGrad { .. })
    });
    let mut coefs: Vec<(usize, usize, usize)> = Vec::new();
    let mut coef_len = 0;
    let mut coef_ids: Vec<u16> =
        p.syms().iter().filter_map(|s| if let Sym::Coef { id, .. } = s { Some(*id) } else { None }).collect();
    coef_ids.dedup(); // sorted: syms are in `Sym` order
    for id in coef_ids {
        let len = components(prog.coefs[id as usize].shape, ir.dim);
        coefs.push((id as usize, coef_len, len));
        coef_len += len;
    }
    let leaves: Vec<Leaf> = p
        .syms()
        .iter()
        .map(|&s| match s {
            Sym::Param(i) => Leaf::Param(i),
            Sym::Field { arg, comp } => Leaf::Value { arg, comp },
            Sym::FieldGrad { arg, comp, dir } => Leaf::Grad { arg, comp, dir },
            Sym::Normal(k) => Leaf::Normal(k),
            // The checker rejects geometry in volume integrals.
            Sym::CellDiameter if !cell => Leaf::CellDiameter,
            Sym::Coord(k) => Leaf::Coord(k),
            Sym::Time => Leaf::Time,
            Sym::Coef { id, comp } => {
                let off = coefs.iter().find(|c| c.0 == id as usize).map_or(0, |c| c.1);
                Leaf::Coef((off + comp as usize) as u32)
            }
            Sym::CellDiameter | Sym::Dt | Sym::Test { .. } | Sym::TestGrad { .. } => Leaf::Zero,
        })
        .collect();
    let uses_x = !coefs.is_empty() || leaves.iter().any(|l| matches!(l, Leaf::Coord(_)));
    let basis_grads = match &contract {
        Contract::Residual { rows } => rows.iter().flatten().any(|t| matches!(t.0, Basis::Dphi(_))),
        Contract::Tangent { a, b } => {
            a.iter().flatten().any(|t| matches!(t.0, Basis::Dphi(_))) || b.iter().any(|t| !t.is_empty())
        }
        Contract::Switches | Contract::Value => false,
    };
    let uses_dphi = basis_grads || leaves.iter().any(|l| matches!(l, Leaf::Grad { .. }));
    Some(Body { prog: p, leaves, coefs, coef_len, uses_x, uses_dphi, contract })
}
