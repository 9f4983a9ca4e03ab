//! Intermediate representation: per space dimension, each form's integrands reduced to the
//! pointwise coefficients of the test function and of its gradient, and the tangent as the
//! derivatives of those coefficients with respect to each field's value and gradient.
//!
//! For a residual r(u; v) = ∫ f0(u)·v + f1(u):∇v, the kernels need f0 (d values) and f1 (d×d);
//! the tangent with respect to u needs ∂f0/∂u, ∂f0/∂∇u, ∂f1/∂u, ∂f1/∂∇u. Everything is a
//! node of one hash-consed graph, so common subexpressions are shared.

pub mod derive;
pub mod eval;
pub mod graph;
pub mod lower;
pub mod pair;
pub mod plan;
pub mod print;

use std::collections::BTreeSet;

use derive::Derivative;
use graph::{Func, Graph, Node, NodeId, Sym};

use crate::check::{CELL_REGION, Unit};
use crate::diagnostic::Diagnostic;

/// Highest polynomial degree a form may need to be integrated exactly. The runtime has rules
/// of every degree (runtime/src/fem/quadrature.rs: collapsed Gauss products past its symmetric
/// rules), but their point counts grow as degree^dim and only degrees up to 10 are tested
/// there; an estimate past this is a mistake (`u^40`) rather than an integrand.
pub const MAX_DEGREE: u32 = 20;

/// Space dimensions the kernels are generated for.
pub const DIMS: [usize; 3] = [1, 2, 3];

pub struct DimIr {
    pub dim: usize,
    pub graph: Graph,
    pub forms: Vec<FormIr>,
}

pub struct FormIr {
    pub name: String,
    pub fields: Vec<String>,
    /// `None` for a functional (no test function: one value per integral).
    pub test: Option<String>,
    pub integrals: Vec<IntegralIr>,
    /// The tangent does not depend on the fields, nor the form on the previous time level:
    /// assemble once.
    pub linear: bool,
    /// The form reads the previous time level's displacement (`prev`), as field argument
    /// `fields.len()`, which the driver supplies and no tangent differentiates (forms only).
    pub previous: bool,
    /// In a contact pair's law: its facet integrals are evaluated at facing points
    /// ([`IntegralIr::pair`]).
    pub pair: bool,
    /// A pair law integrated over each surface of its pair in turn (`int(REGION, both_sides)`):
    /// the runtime binds it a second time with the surfaces' roles swapped.
    pub both_sides: bool,
}

pub struct IntegralIr {
    pub region: String,
    /// Integral over cells (`Omega`); otherwise over facets of a boundary region.
    pub cell: bool,
    /// Coefficient of v_k: `f0[k]`.
    pub f0: Vec<NodeId>,
    /// Coefficient of ∂_l v_k: `f1[k*d + l]`.
    pub f1: Vec<NodeId>,
    /// Derivatives with respect to each field argument.
    pub tangents: Vec<TangentIr>,
    /// The integrand of a functional.
    pub value: Option<NodeId>,
    /// The quadrature degree for P1 and P2 elements: the one the file sets
    /// (`int(REGION, degree = k)`), else the estimate.
    pub degree: [u32; 2],
    /// The estimated degree (exact on affine cells when the integrand is polynomial), which
    /// `check` reports.
    pub estimated: [u32; 2],
    /// In a contact pair's law (a file that reads `opposite`): the facing side's part.
    pub pair: Option<PairIr>,
}

/// The facing side of a facet integral of a contact pair's law: the coefficients of the facing
/// test function, and the tangent blocks that couple the two sides.
pub struct PairIr {
    /// Coefficient of opposite(v)_k: `h0[k]`.
    pub h0: Vec<NodeId>,
    /// Coefficient of ∂_l opposite(v)_k: `h1[k*d + l]`.
    pub h1: Vec<NodeId>,
    /// Per field argument: the blocks (own test, facing trial), (facing test, own trial) and
    /// (facing test, facing trial), in [`TangentIr`]'s conventions; the own block is the
    /// integral's `tangents`.
    pub tangents: Vec<[TangentIr; 3]>,
    /// The derivative of each of f0, f1, h0, h1 (in that order, entry c) as the facing point
    /// slides, y → y + s e_r, in the reference configuration of the facing body: at
    /// `[c*d + r]`. The facing side's values move along their gradients there, their gradients
    /// along their second derivatives, and its normal along the surface's curvature (both zero
    /// on P1 facets).
    pub sliding: Vec<NodeId>,
}

/// Index conventions: k = test component, l = test derivative direction, m = trial component,
/// n = trial derivative direction.
pub struct TangentIr {
    /// ∂f0[k]/∂u_m at `[k*d + m]`.
    pub c00: Vec<NodeId>,
    /// ∂f0[k]/∂(∂_n u_m) at `[(k*d + m)*d + n]`.
    pub c01: Vec<NodeId>,
    /// ∂f1[k,l]/∂u_m at `[(k*d + l)*d + m]`.
    pub c10: Vec<NodeId>,
    /// ∂f1[k,l]/∂(∂_n u_m) at `[((k*d + l)*d + m)*d + n]`.
    pub c11: Vec<NodeId>,
    /// Arguments `a` of the Heaviside nodes H(a) in the tangent that depend on this field: the
    /// active set. Their signs at the quadrature points decide the tangent when `piecewise`.
    pub switches: Vec<NodeId>,
    /// The tangent depends on this field only through the switches (true for Nitsche and
    /// penalty contact, and for linear forms): an unchanged active set means an unchanged
    /// matrix.
    pub piecewise: bool,
    /// Where it is not `piecewise`: arguments `a` of steps H(a) (switches or a built-in's inner
    /// steps) that multiply every field dependence outside the switches, so that at a point
    /// where all of them are off (a ≤ 0) the tangent depends on the fields only through the
    /// switches there. A Coulomb law's are its friction radius (`proj_ball`'s r): out of
    /// contact, or everywhere at F = 0, the active set decides its tangent. `None` where no such
    /// steps exist (or where the tangent is `piecewise`).
    pub gates: Option<Vec<NodeId>>,
}

impl TangentIr {
    pub fn nodes(&self) -> impl Iterator<Item = NodeId> + '_ {
        self.c00.iter().chain(&self.c01).chain(&self.c10).chain(&self.c11).copied()
    }
}

/// Lowers every form of the program for dimension `d`, with tangents. Refuses non-finite
/// constant arithmetic, forms that expand too far and quadrature degrees past [`MAX_DEGREE`].
pub fn build(prog: &Unit, d: usize) -> Result<DimIr, Vec<Diagnostic>> {
    let mut lowerer = lower::Lowerer::new(prog, d);
    let mut diags = Vec::new();
    let mut lowered = Vec::new();
    for i in 0..prog.forms.len() {
        match lowerer.form(i) {
            Ok(f) => lowered.push(f),
            Err(e) => diags.push(*e),
        }
    }
    if !diags.is_empty() {
        return Err(diags);
    }
    let mut g = lowerer.g;
    // A file that reads the facing side anywhere is a contact pair's law: each of its facet
    // integrals is evaluated at facing points, and it has no volume integral.
    let reads_facing =
        |g: &Graph, n: NodeId| g.reachable([n]).into_iter().any(|m| matches!(g.node(m), Node::Sym(Sym::Opposite(_))));
    // The file's own forms (an imported material's are as they are in their file).
    let own: Vec<bool> = prog.forms.iter().map(|f| f.span.file == prog.root).collect();
    let pair_law =
        lowered.iter().zip(&own).any(|(lf, own)| *own && lf.integrands.iter().any(|i| reads_facing(&g, i.value)));
    let own_forms: Vec<&lower::LoweredForm> = lowered.iter().zip(&own).filter(|(_, o)| **o).map(|(lf, _)| lf).collect();
    if pair_law && let Some(e) = pair_volume_error(prog, &own_forms) {
        return Err(vec![e]);
    }
    let both_sides = match sides(prog, pair_law) {
        Ok(both) => both,
        Err(e) => return Err(vec![*e]),
    };
    let mut forms = Vec::new();
    for (lf, own) in lowered.into_iter().zip(own) {
        let pair_form = pair_law && own;
        let mut integrals = Vec::new();
        for integrand in &lf.integrands {
            if lf.test.is_none() {
                let roots = [integrand.value];
                let estimated = [1, 2].map(|p| node_degrees(&g, p, roots)[&integrand.value]);
                let degree = integrand.degree.map_or(estimated, |k| [k, k]);
                integrals.push(IntegralIr {
                    region: integrand.region.clone(),
                    cell: integrand.region == CELL_REGION,
                    f0: Vec::new(),
                    f1: Vec::new(),
                    tangents: Vec::new(),
                    value: Some(integrand.value),
                    degree,
                    estimated,
                    pair: None,
                });
                continue;
            }
            let f0: Vec<NodeId> =
                (0..d).map(|k| Derivative::new(Sym::Test { comp: k as u8 }).of(&mut g, integrand.value)).collect();
            let f1: Vec<NodeId> = (0..d * d)
                .map(|kl| {
                    Derivative::new(Sym::TestGrad { comp: (kl / d) as u8, dir: (kl % d) as u8 })
                        .of(&mut g, integrand.value)
                })
                .collect();
            let previous = lf.fields.len() as u8;
            let tangents = (0..lf.fields.len())
                .map(|a| tangent(&mut g, d, a as u8, previous, (&f0, &f1), Side::Own))
                .collect::<Vec<_>>();
            let pair = pair_form.then(|| pair(&mut g, d, lf.fields.len(), integrand.value, (&f0, &f1)));
            let estimated = [1, 2].map(|p| integral_degree(&g, p, &f0, &f1, &tangents));
            let degree = integrand.degree.map_or(estimated, |k| [k, k]);
            integrals.push(IntegralIr {
                region: integrand.region.clone(),
                cell: integrand.region == CELL_REGION,
                f0,
                f1,
                tangents,
                value: None,
                degree,
                estimated,
                pair,
            });
        }
        let tangent_nodes = integrals.iter().flat_map(|i| i.tangents.iter().flat_map(TangentIr::nodes));
        let constant_tangent = !g
            .reachable(tangent_nodes)
            .into_iter()
            .any(|n| matches!(g.node(n), Node::Sym(Sym::Field { .. } | Sym::FieldGrad { .. })));
        let prev = lf.fields.len() as u8;
        let is_previous = |n: NodeId| matches!(g.node(n), Node::Sym(Sym::Field { arg, .. } | Sym::FieldGrad { arg, .. }) if arg == prev);
        let values = integrals.iter().flat_map(|i| i.f0.iter().chain(&i.f1).chain(&i.value)).copied();
        let previous = g.reachable(values).into_iter().any(is_previous);
        // A pair's tangent moves with the facing points even where its coefficients are constant.
        let linear = constant_tangent && !previous && !pair_form;
        if let Some(e) = degree_error(prog, &lf.name, &integrals) {
            diags.push(e);
        }
        forms.push(FormIr {
            name: lf.name,
            fields: lf.fields,
            test: lf.test,
            integrals,
            linear,
            previous,
            pair: pair_form,
            both_sides: pair_form && both_sides,
        });
    }
    if !diags.is_empty() {
        return Err(diags);
    }
    if pair_law {
        one_rule(&mut forms);
    }
    Ok(DimIr { dim: d, graph: g, forms })
}

/// W0006: a form whose tangent divides by (or takes a negative power of) an expression of the
/// fields that a `pos`/`neg` clips to zero on a whole part of its region: the derivative of
/// `d*d^(1/3)` with d = pos(u_N − g) is 0/0 wherever the body is out of contact, and the first
/// Jacobian is NaN. One warning per integral.
pub fn vanishing_denominators(prog: &Unit, ir: &DimIr) -> Vec<Diagnostic> {
    let g = &ir.graph;
    let clipped = |den: NodeId| vanishes_with_a_clip(g, den);
    let mut out = Vec::new();
    for form in ir.forms.iter().filter(|f| f.test.is_some()) {
        let Some(def) = prog.forms.iter().find(|f| f.name == form.name) else { continue };
        for integral in &form.integrals {
            let nodes = g.reachable(integral.tangents.iter().flat_map(TangentIr::nodes));
            let power = "write the power directly: `d^(4/3)` rather than `d*d^(1/3)` differentiates to (4/3) d^(1/3), which is 0 at d = 0";
            let log = "keep the logarithm's argument away from 0: `ln(c + pos(d))` with c > 0";
            // A logarithm's derivative da/a divides by its argument.
            let logarithm_of = |a: NodeId| (0..g.len() as NodeId).any(|m| g.node(m) == Node::Func(Func::Ln, a));
            let divides = nodes.iter().find_map(|&n| match g.node(n) {
                Node::Div(_, den) if clipped(den) => Some(("divides by", if logarithm_of(den) { log } else { power })),
                Node::Powi(a, k) if k < 0 && clipped(a) => Some(("takes a negative power of", power)),
                Node::Powf(a, p) if f64::from_bits(p) < 0.0 && clipped(a) => Some(("takes a negative power of", power)),
                // ln's derivative is da/a: a logarithm of a clipped value is a negative power.
                Node::Func(Func::Ln, a) if clipped(a) => Some(("takes the logarithm of", log)),
                _ => None,
            });
            let (Some((what, help)), Some(at)) =
                (divides, def.integrals.iter().find(|i| i.region.name == integral.region))
            else {
                continue;
            };
            out.push(
                Diagnostic::warning(
                    "W0006",
                    format!("the tangent of `{}` {what} an expression that is zero where `pos`/`neg` clips it", form.name),
                    at.integrand.span,
                    "its derivative is 0/0 (NaN) there",
                )
                .with_note("Newton's first Jacobian is then NaN wherever the clip is active (out of contact), and the solve fails as singular")
                .with_help(help),
            );
        }
    }
    out
}

/// A form whose estimated quadrature degree (on P1 or P2 elements) passes [`MAX_DEGREE`].
fn degree_error(prog: &Unit, name: &str, integrals: &[IntegralIr]) -> Option<Diagnostic> {
    // A degree the file sets is the author's (checked when lowered).
    let (i, degree) = integrals
        .iter()
        .enumerate()
        .filter(|(_, x)| x.degree == x.estimated)
        .map(|(i, x)| (i, x.degree[0].max(x.degree[1])))
        .max_by_key(|x| x.1)?;
    if degree <= MAX_DEGREE {
        return None;
    }
    let form = prog.forms.iter().find(|f| f.name == name)?;
    let region = &integrals[i].region;
    let integral = form.integrals.iter().find(|x| x.region.name == *region)?;
    Some(
        Diagnostic::error(
            "E0503",
            format!("form `{name}` needs quadrature of degree {degree}"),
            integral.integrand.span,
            format!("a polynomial of degree {degree} on P2 elements, above the cap of {MAX_DEGREE}"),
        )
        .with_help(format!(
            "lower the powers or the nesting of products, or set the degree: `int({region}, degree = {MAX_DEGREE})`"
        )),
    )
}

/// Which side of a contact pair a trial function is read on.
#[derive(Clone, Copy, PartialEq)]
enum Side {
    Own,
    Facing,
}

impl Side {
    fn of(self, s: Sym) -> Sym {
        match (self, s.facing()) {
            (Side::Facing, Some(f)) => Sym::Opposite(f),
            _ => s,
        }
    }
}

/// The facing side of a pair law's integrand `value`, whose own test coefficients are `own`.
fn pair(g: &mut Graph, d: usize, fields: usize, value: NodeId, own: (&[NodeId], &[NodeId])) -> PairIr {
    use graph::Facing;
    let h0: Vec<NodeId> =
        (0..d).map(|k| Derivative::new(Sym::Opposite(Facing::Test { comp: k as u8 })).of(g, value)).collect();
    let h1: Vec<NodeId> = (0..d * d)
        .map(|kl| {
            let s = Sym::Opposite(Facing::TestGrad { comp: (kl / d) as u8, dir: (kl % d) as u8 });
            Derivative::new(s).of(g, value)
        })
        .collect();
    let previous = fields as u8;
    let tangents = (0..fields as u8)
        .map(|a| {
            [
                tangent(g, d, a, previous, own, Side::Facing),
                tangent(g, d, a, previous, (&h0, &h1), Side::Own),
                tangent(g, d, a, previous, (&h0, &h1), Side::Facing),
            ]
        })
        .collect();
    let coefficients: Vec<NodeId> = own.0.iter().chain(own.1).chain(&h0).chain(&h1).copied().collect();
    let sliding = sliding(g, d, &coefficients);
    PairIr { h0, h1, tangents, sliding }
}

/// The derivative of each of `roots` as the facing point slides along each axis r (see
/// [`PairIr::sliding`]): its leaves read at y + s e_r to first order in s, differentiated in
/// s at 0.
fn sliding(g: &mut Graph, d: usize, roots: &[NodeId]) -> Vec<NodeId> {
    use graph::Facing;
    let s = Sym::Seed(u8::MAX);
    let mut out = vec![0; roots.len() * d];
    for r in 0..d as u8 {
        let shifted = |g: &mut Graph, x: Sym| -> Option<NodeId> {
            let Sym::Opposite(f) = x else { return None };
            let along = match f {
                Facing::Coord(k) if k == r => g.one(),
                Facing::Field { arg, comp } => g.sym(Sym::Opposite(Facing::FieldGrad { arg, comp, dir: r })),
                Facing::FieldGrad { arg, comp, dir } => {
                    g.sym(Sym::Opposite(Facing::FieldHess { arg, comp, dir, along: r }))
                }
                Facing::Normal(comp) => g.sym(Sym::Opposite(Facing::NormalRate { comp, along: r })),
                _ => return None,
            };
            let (at, seed) = (g.sym(x), g.sym(s));
            let step = g.mul(seed, along);
            Some(g.add(at, step))
        };
        let mut ds = Derivative::new(s);
        for (c, &root) in roots.iter().enumerate() {
            let moved = g.replace(root, &shifted);
            let rate = ds.of(g, moved);
            out[c * d + r as usize] = g.replace(rate, &|g: &mut Graph, x: Sym| (x == s).then(|| g.zero()));
        }
    }
    out
}

/// A pair law integrates every form with one rule, the largest of their estimates, so that its
/// functionals (the force it measures) sum what its forms impose, point by point. A degree the
/// file sets stays.
fn one_rule(forms: &mut [FormIr]) {
    let estimated = |i: &&mut IntegralIr| i.degree == i.estimated;
    let mut largest = [0, 0];
    for i in forms.iter_mut().filter(|f| f.pair).flat_map(|f| f.integrals.iter_mut()).filter(estimated) {
        largest = [largest[0].max(i.degree[0]), largest[1].max(i.degree[1])];
    }
    for i in forms.iter_mut().filter(|f| f.pair).flat_map(|f| f.integrals.iter_mut()).filter(estimated) {
        (i.degree, i.estimated) = (largest, largest);
    }
}

/// Whether a pair law's integrals are taken over both surfaces (`int(REGION, both_sides)`): all
/// of its own integrals say so or none (E0411), and only a pair law's (E0410).
fn sides(prog: &Unit, pair_law: bool) -> Result<bool, Box<Diagnostic>> {
    let integrals = || prog.forms.iter().filter(|f| f.span.file == prog.root).flat_map(|f| &f.integrals);
    let first = integrals().find_map(|i| i.both_sides);
    let Some(first) = first else { return Ok(false) };
    if !pair_law {
        return Err(Box::new(
            Diagnostic::error(
                "E0410",
                "`both_sides` in a law that reads no facing side",
                first,
                "only a contact pair's law has two sides",
            )
            .with_help("a pair's law reads the other surface with `opposite(e)`; elsewhere drop `both_sides`"),
        ));
    }
    match integrals().find(|i| i.both_sides.is_none()) {
        None => Ok(true),
        Some(one) => Err(Box::new(
            Diagnostic::error(
                "E0411",
                "a pair law over both surfaces in some integrals and over its own surface in others",
                one.span,
                "over the own surface only",
            )
            .with_label(first, "over both surfaces")
            .with_note("the law is bound once for each direction of its pair, all its forms together")
            .with_help("write `both_sides` in every integral of the file, or in none"),
        )),
    }
}

/// E0409: a volume integral in a contact pair's law.
fn pair_volume_error(prog: &Unit, lowered: &[&lower::LoweredForm]) -> Option<Diagnostic> {
    let lf = lowered.iter().find(|lf| lf.integrands.iter().any(|i| i.region == CELL_REGION))?;
    let form = prog.forms.iter().find(|f| f.name == lf.name)?;
    let integral = form.integrals.iter().find(|i| i.region.name == CELL_REGION)?;
    Some(
        Diagnostic::error(
            "E0409",
            format!("volume integral in `{}`, in a contact pair's law", lf.name),
            integral.integrand.span,
            "a pair's law integrates over the pair's surfaces",
        )
        .with_note(
            "the file reads `opposite`, so its integrals are evaluated at the points facing each other on two surfaces",
        )
        .with_help("move the volume terms to the material's file"),
    )
}

/// The tangent of the test coefficients `test` (f0, f1) with respect to field argument `arg`
/// read on `side`; the switches and the piecewise test count the previous level (field
/// `previous`, never differentiated) and both sides' fields as state, so that a changed
/// previous level or facing side is never taken for an unchanged tangent.
fn tangent(g: &mut Graph, d: usize, arg: u8, previous: u8, test: (&[NodeId], &[NodeId]), side: Side) -> TangentIr {
    let (f0, f1) = test;
    let val: Vec<Sym> = (0..d).map(|m| side.of(Sym::Field { arg, comp: m as u8 })).collect();
    let grad: Vec<Sym> =
        (0..d * d).map(|mn| side.of(Sym::FieldGrad { arg, comp: (mn / d) as u8, dir: (mn % d) as u8 })).collect();
    let mut dval: Vec<Derivative> = val.iter().map(|s| Derivative::new(*s)).collect();
    let mut dgrad: Vec<Derivative> = grad.iter().map(|s| Derivative::new(*s)).collect();
    let mut c00 = Vec::new();
    let mut c01 = Vec::new();
    for &f in f0 {
        for dv in dval.iter_mut() {
            c00.push(dv.of(g, f));
        }
        for dg in dgrad.iter_mut() {
            c01.push(dg.of(g, f));
        }
    }
    let mut c10 = Vec::new();
    let mut c11 = Vec::new();
    for &f in f1 {
        for dv in dval.iter_mut() {
            c10.push(dv.of(g, f));
        }
        for dg in dgrad.iter_mut() {
            c11.push(dg.of(g, f));
        }
    }
    let mut t = TangentIr { c00, c01, c10, c11, switches: Vec::new(), piecewise: true, gates: None };
    let is_field = |s: Sym| {
        let own = match s {
            Sym::Opposite(f) => f.own(),
            s => s,
        };
        matches!(own, Sym::Field { arg: x, .. } | Sym::FieldGrad { arg: x, .. } if x == arg || x == previous)
    };
    let roots: Vec<NodeId> = t.nodes().collect();
    for n in g.reachable(roots.iter().copied()) {
        if let Node::Heaviside(a) = g.node(n)
            && g.depends_on(a, is_field)
        {
            t.switches.push(a);
        }
    }
    // Field dependence outside the switches: walk the tangent without entering H nodes.
    let mut seen = std::collections::HashSet::new();
    let mut stack = roots;
    while let Some(n) = stack.pop() {
        if !seen.insert(n) {
            continue;
        }
        match g.node(n) {
            Node::Heaviside(_) => {}
            Node::Sym(s) if is_field(s) => t.piecewise = false,
            _ => stack.extend(g.children(n)),
        }
    }
    if !t.piecewise {
        let roots: Vec<NodeId> = t.nodes().collect();
        t.gates = gates(g, &roots, is_field).map(|set| set.into_iter().collect());
    }
    t
}

/// Step arguments `a` such that, where every H(a) is off, `roots` depend on the fields
/// (`is_field`) only through switches: each field dependence outside the switches sits in a
/// product with a factor that such an H(a) (a switch or an inner step) zeroes. `None` if some
/// dependence is not so gated.
fn gates(g: &Graph, roots: &[NodeId], is_field: impl Fn(Sym) -> bool + Copy) -> Option<BTreeSet<NodeId>> {
    use std::collections::HashMap;
    let switch = |a: NodeId| g.depends_on(a, is_field);
    // `open[n]`: the gates under which n is free of field dependence outside switches (`None`:
    // none do). `zero[n]`: gates under which n is zero.
    let mut open: HashMap<NodeId, Option<BTreeSet<NodeId>>> = HashMap::new();
    let mut zero: HashMap<NodeId, Option<BTreeSet<NodeId>>> = HashMap::new();
    let union = |a: &Option<BTreeSet<NodeId>>, b: &Option<BTreeSet<NodeId>>| match (a, b) {
        (Some(x), Some(y)) => Some(x.union(y).copied().collect()),
        _ => None,
    };
    // The smaller of two gate sets that both suffice.
    let least = |a: Option<BTreeSet<NodeId>>, b: Option<BTreeSet<NodeId>>| match (a, b) {
        (Some(x), Some(y)) => Some(if y.len() < x.len() { y } else { x }),
        (x, y) => x.or(y),
    };
    for n in g.reachable(roots.iter().copied()) {
        let (o, z) = match g.node(n) {
            Node::Heaviside(a) if switch(a) => (Some(BTreeSet::new()), Some(BTreeSet::from([a]))),
            Node::Sym(s) if is_field(s) => (None, None),
            Node::Const(_) | Node::Sym(_) | Node::Heaviside(_) => (Some(BTreeSet::new()), None),
            Node::Mul(a, b) => {
                let z = least(zero[&a].clone(), zero[&b].clone());
                (least(union(&open[&a], &open[&b]), z.clone()), z)
            }
            Node::Add(a, b) => (union(&open[&a], &open[&b]), union(&zero[&a], &zero[&b])),
            Node::Div(a, b) => (least(union(&open[&a], &open[&b]), zero[&a].clone()), zero[&a].clone()),
            Node::Neg(a) => (open[&a].clone(), zero[&a].clone()),
            Node::Powi(a, k) => (open[&a].clone(), zero[&a].clone().filter(|_| k > 0)),
            Node::Step(a) if switch(a) => (open[&a].clone(), Some(BTreeSet::from([a]))),
            Node::Powf(a, _) | Node::Sqrt(a) | Node::Step(a) => (open[&a].clone(), None),
            // sin 0 = tan 0 = 0; cos, exp and ln are not zero where their argument is.
            Node::Func(Func::Sin | Func::Tan, a) => (open[&a].clone(), zero[&a].clone()),
            Node::Func(Func::Cos | Func::Exp | Func::Ln, a) => (open[&a].clone(), None),
            Node::Atan2(y, x) => (union(&open[&y], &open[&x]), None),
            // Not zero where its point's components are.
            Node::CoefAt { point, .. } => {
                let at = g.point(point);
                (at.iter().try_fold(BTreeSet::new(), |acc, p| union(&Some(acc), &open[p])), None)
            }
        };
        open.insert(n, o);
        zero.insert(n, z);
    }
    roots.iter().try_fold(BTreeSet::new(), |acc, r| union(&Some(acc), &open[r]))
}

/// Whether `id` is zero wherever some H(a), `a` depending on the fields, is (a clip by `pos` or
/// `neg` out of contact): H(a) itself, a product with such a factor, a sum of two such terms,
/// a positive power or root of one. A sum with a term that stays (`|a| + (1 − H(|a|))`, the
/// guard `proj_ball` and the derivative of `sqrt` write) does not vanish.
fn vanishes_with_a_clip(g: &Graph, id: NodeId) -> bool {
    let field = |s: Sym| {
        let own = if let Sym::Opposite(f) = s { f.own() } else { s };
        matches!(own, Sym::Field { .. } | Sym::FieldGrad { .. })
    };
    let mut vanishes: std::collections::HashMap<NodeId, bool> = std::collections::HashMap::new();
    for n in g.reachable([id]) {
        let v = |m: NodeId| vanishes[&m];
        let here = match g.node(n) {
            Node::Heaviside(a) | Node::Step(a) => g.depends_on(a, field),
            Node::Mul(a, b) => v(a) || v(b),
            Node::Add(a, b) => v(a) && v(b),
            Node::Neg(a) | Node::Div(a, _) | Node::Sqrt(a) => v(a),
            Node::Powi(a, k) => k > 0 && v(a),
            Node::Powf(a, p) => f64::from_bits(p) > 0.0 && v(a),
            Node::Func(Func::Sin | Func::Tan, a) => v(a),
            // atan2(0, x) is π for x < 0.
            Node::Func(Func::Cos | Func::Exp | Func::Ln, _) | Node::Atan2(..) | Node::CoefAt { .. } => false,
            Node::Const(_) | Node::Sym(_) => false,
        };
        vanishes.insert(n, here);
    }
    vanishes[&id]
}

/// Polynomial degree estimate of each node for Lagrange elements of degree p on affine cells
/// (as UFL estimates it): fields p, gradients p − 1, x 1, case data p, non-polynomial
/// functions add 2.
pub fn node_degrees(
    g: &Graph,
    p: u32,
    roots: impl IntoIterator<Item = NodeId>,
) -> std::collections::HashMap<NodeId, u32> {
    let mut deg = std::collections::HashMap::new();
    for id in g.reachable(roots) {
        let dg = |x: NodeId| deg.get(&x).copied().unwrap_or(0);
        let v = match g.node(id) {
            Node::Const(_) => 0,
            Node::Sym(s) => match s {
                Sym::Field { .. } | Sym::Test { .. } | Sym::Coef { .. } => p,
                Sym::FieldGrad { .. } | Sym::TestGrad { .. } => p - 1,
                Sym::FieldHess { .. } => p.saturating_sub(2),
                Sym::NormalRate { .. } => 0,
                Sym::Coord(_) => 1,
                Sym::Param(_) | Sym::Normal(_) | Sym::CellDiameter | Sym::Time | Sym::Dt | Sym::Seed(_) => 0,
                // The facing side's values: piecewise smooth along the own facet, across the
                // facing facets, so no rule integrates them exactly; the rule follows the own
                // side's degree (a pair law's forms share the largest, `one_rule`).
                Sym::Opposite(_) => 0,
            },
            Node::Add(a, b) => dg(a).max(dg(b)),
            // Saturating: deep products overflow u32; the cap on the degree reports them.
            Node::Mul(a, b) | Node::Div(a, b) => dg(a).saturating_add(dg(b)),
            Node::Neg(a) => dg(a),
            Node::Powi(a, k) if k >= 0 => dg(a).saturating_mul(k as u32),
            Node::Powi(a, _) | Node::Powf(a, _) | Node::Sqrt(a) | Node::Func(_, a) => dg(a).saturating_add(2),
            Node::Atan2(y, x) => dg(y).max(dg(x)).saturating_add(2),
            // Case data at a point that moves with the fields: a function of the point, as a
            // non-polynomial function of it.
            Node::CoefAt { point, .. } => g.point(point).iter().map(|&c| dg(c)).max().unwrap_or(0).saturating_add(2),
            Node::Heaviside(_) | Node::Step(_) => 0,
        };
        deg.insert(id, v);
    }
    deg
}

fn integral_degree(g: &Graph, p: u32, f0: &[NodeId], f1: &[NodeId], tangents: &[TangentIr]) -> u32 {
    let roots: Vec<NodeId> = f0.iter().chain(f1).copied().chain(tangents.iter().flat_map(TangentIr::nodes)).collect();
    let deg = node_degrees(g, p, roots);
    let d = |n: &NodeId| if g.is_zero(*n) { None } else { Some(deg[n]) };
    let mut best = 0;
    let mut take = |n: &NodeId, extra: u32| {
        if let Some(v) = d(n) {
            best = best.max(v.saturating_add(extra));
        }
    };
    f0.iter().for_each(|n| take(n, p));
    f1.iter().for_each(|n| take(n, p - 1));
    for t in tangents {
        t.c00.iter().for_each(|n| take(n, 2 * p));
        t.c01.iter().chain(&t.c10).for_each(|n| take(n, 2 * p - 1));
        t.c11.iter().for_each(|n| take(n, 2 * p - 2));
    }
    best
}
