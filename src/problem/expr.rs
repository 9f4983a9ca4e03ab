//! A problem's expressions, evaluated: lowered into the compiler's expression DAG for the
//! problem's dimension (params as constants, `let`s in order), and compiled to the one IR
//! evaluator ([`Program`]) as functions of the position `x`, the time `t`, the facet normal `n`,
//! the fields `u` and `v` and values measured elsewhere (a series column's reducers).

use crate::compiler::Diagnostic;
use crate::compiler::check::Unit;
use crate::compiler::ir::eval::Program;
use crate::compiler::ir::graph::{NodeId, Sym};
use crate::compiler::ir::lower::{Jet, Lowerer, Val};
use crate::compiler::syntax::ast::{Defined, Expr, Shape};

type Res<T> = Result<T, Box<Diagnostic>>;

/// The lowering context of one problem in one dimension.
pub struct Exprs<'u> {
    pub low: Lowerer<'u>,
    scope: Vec<(String, Val)>,
    d: usize,
}

impl<'u> Exprs<'u> {
    /// The problem's params (by name, with their values) and its `let`s, in order.
    pub fn new(unit: &'u Unit, d: usize, params: &[(String, f64)], lets: &[Defined]) -> Res<Exprs<'u>> {
        let mut low = Lowerer::new(unit, d);
        let mut scope: Vec<(String, Val)> = params.iter().map(|(n, v)| (n.clone(), low.constant_val(*v))).collect();
        for l in lets {
            let v = low.problem_expr(&l.value, scope.clone())?;
            scope.push((l.name.name.clone(), v));
        }
        Ok(Exprs { low, scope, d })
    }

    pub fn dim(&self) -> usize {
        self.d
    }

    /// A param's or a constant `let`'s value, by name.
    pub fn constant(&self, name: &str) -> Option<f64> {
        let (_, v) = self.scope.iter().rev().find(|(n, _)| n == name)?;
        if v.c.len() != 1 {
            return None;
        }
        self.low.g.as_const(v.c[0].v)
    }

    /// Lowers `e` with `extra` names visible (fields, coefs, measured values) besides the params
    /// and `let`s.
    pub fn lower(&mut self, e: &Expr, extra: &[(String, Val)]) -> Res<Val> {
        let mut scope = self.scope.clone();
        scope.extend(extra.iter().cloned());
        self.low.problem_expr(e, scope)
    }

    /// A constant scalar (params and numbers only).
    pub fn scalar(&mut self, e: &Expr) -> Res<f64> {
        let v = self.lower(e, &[])?;
        self.low.g.as_const(v.c[0].v).ok_or_else(|| not_constant(e))
    }

    /// A constant scalar of the params, `let`s and the `extra` names.
    pub fn scalar_with(&mut self, e: &Expr, extra: &[(String, Val)]) -> Res<f64> {
        let v = self.lower(e, extra)?;
        self.low.g.as_const(v.c[0].v).ok_or_else(|| not_constant(e))
    }

    /// A constant vector of the problem's dimension.
    pub fn vector(&mut self, e: &Expr) -> Res<Vec<f64>> {
        let v = self.lower(e, &[])?;
        v.c.iter().map(|j| self.low.g.as_const(j.v).ok_or_else(|| not_constant(e))).collect()
    }

    /// A field argument (`u` is 0, `v` is 1) as a value of the problem's dimension.
    pub fn field(&mut self, arg: u8) -> Val {
        let c = (0..self.d).map(|k| Jet { v: self.low.g.sym(Sym::Field { arg, comp: k as u8 }), g: None }).collect();
        Val { shape: Shape::Vector, c }
    }

    /// A measured value (`id`) of `components` components, as a leaf.
    pub fn measured(&mut self, id: usize, components: usize) -> Val {
        let c = (0..components)
            .map(|k| Jet { v: self.low.g.sym(Sym::Coef { id: id as u16, comp: k as u8 }), g: None })
            .collect();
        Val { shape: if components == 1 { Shape::Scalar } else { Shape::Vector }, c }
    }

    /// As [`Exprs::function`], with the first and second derivatives with respect to `x` (a coef
    /// that a contact law may read at the displaced point, `g(x + u)`, and differentiate there).
    pub fn coef_function(&mut self, v: &Val, e: &Expr) -> Res<PointFn> {
        use crate::compiler::ir::derive::Derivative;
        let mut f = self.function(v, e)?;
        if f.constant().is_some() {
            return Ok(f);
        }
        let d = self.d;
        let roots: Vec<NodeId> = v.c.iter().map(|j| j.v).collect();
        let by = |g: &mut crate::compiler::ir::graph::Graph, nodes: &[NodeId]| -> Vec<NodeId> {
            let mut out = Vec::with_capacity(nodes.len() * d);
            for &n in nodes {
                for k in 0..d {
                    out.push(Derivative::new(Sym::Coord(k as u8)).of(g, n));
                }
            }
            out
        };
        let first = by(&mut self.low.g, &roots);
        let second = by(&mut self.low.g, &first);
        let mut derivatives = Vec::new();
        for nodes in [first, second] {
            let program = Program::new(&self.low.g, &nodes);
            derivatives.push(PointFn::new(program, nodes).map_err(|what| {
                Box::new(Diagnostic::error(
                    "E0501",
                    format!("{what} means nothing here"),
                    e.span,
                    "not known at a point",
                ))
            })?);
        }
        f.derivatives = derivatives;
        Ok(f)
    }

    /// Compiles the components of `v` (at `e`, for errors).
    pub fn function(&self, v: &Val, e: &Expr) -> Res<PointFn> {
        let roots: Vec<NodeId> = v.c.iter().map(|j| j.v).collect();
        PointFn::new(Program::new(&self.low.g, &roots), roots.clone()).map_err(|what| {
            Box::new(Diagnostic::error("E0501", format!("{what} means nothing here"), e.span, "not known at a point"))
        })
    }
}

fn not_constant(e: &Expr) -> Box<Diagnostic> {
    Box::new(
        Diagnostic::error("E0603", "not a constant", e.span, "depends on x, t or a field")
            .with_help("mesh arguments, run and quadrature settings are numbers and params"),
    )
}

/// What a leaf of a point function reads.
#[derive(Clone, Copy, Debug)]
enum Leaf {
    X(usize),
    T,
    N(usize),
    U(usize),
    V(usize),
    Measured(usize, usize),
}

/// Where a point function is evaluated.
#[derive(Clone, Copy, Default)]
pub struct At<'a> {
    pub x: &'a [f64],
    pub t: f64,
    pub n: &'a [f64],
    pub u: &'a [f64],
    pub v: &'a [f64],
    pub measured: &'a [Vec<f64>],
}

/// Compiled components of an expression: `eval` writes one value per component.
#[derive(Clone, Debug)]
pub struct PointFn {
    program: Program,
    leaves: Vec<Leaf>,
    /// When every component is a leaf or a constant: which, so that `eval` copies them.
    trivial: Option<Vec<Result<usize, f64>>>,
    /// The roots in the problem's graph: equal keys, equal functions (the graph is hash-consed).
    pub key: Vec<NodeId>,
    /// The first and second derivatives with respect to `x`, component-major (a coef's; see
    /// [`Exprs::coef_function`]), or none.
    derivatives: Vec<PointFn>,
}

impl PointFn {
    fn new(program: Program, key: Vec<NodeId>) -> Result<PointFn, &'static str> {
        let leaves = program
            .syms()
            .iter()
            .map(|s| {
                Ok(match *s {
                    Sym::Coord(k) => Leaf::X(k as usize),
                    Sym::Time => Leaf::T,
                    Sym::Normal(k) => Leaf::N(k as usize),
                    Sym::Field { arg: 0, comp } => Leaf::U(comp as usize),
                    Sym::Field { comp, .. } => Leaf::V(comp as usize),
                    Sym::Coef { id, comp } => Leaf::Measured(id as usize, comp as usize),
                    Sym::CellDiameter => return Err("`h`, the cell size,"),
                    _ => return Err("a derivative"),
                })
            })
            .collect::<Result<_, _>>()?;
        let trivial = program.trivial_roots();
        Ok(PointFn { program, leaves, trivial, key, derivatives: Vec::new() })
    }

    /// Number of components.
    pub fn len(&self) -> usize {
        self.program.outputs()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The values, when they depend on nothing.
    pub fn constant(&self) -> Option<Vec<f64>> {
        self.leaves.is_empty().then(|| {
            let mut out = vec![0.0; self.len()];
            self.eval(&At::default(), &mut Vec::new(), &mut out);
            out
        })
    }

    /// Whether the values depend on the time.
    pub fn reads_time(&self) -> bool {
        self.leaves.iter().any(|l| matches!(l, Leaf::T))
    }

    /// Whether the values depend on the velocity.
    pub fn reads_v(&self) -> bool {
        self.leaves.iter().any(|l| matches!(l, Leaf::V(_)))
    }

    /// Writes the values at `at` into `out` (`scratch` is reused between calls).
    pub fn eval(&self, at: &At, scratch: &mut Vec<f64>, out: &mut [f64]) {
        let nan = f64::NAN;
        let get = |s: &[f64], k: usize| s.get(k).copied().unwrap_or(nan);
        let leaf = |l: Leaf| match l {
            Leaf::X(k) => get(at.x, k),
            Leaf::T => at.t,
            Leaf::N(k) => get(at.n, k),
            Leaf::U(k) => get(at.u, k),
            Leaf::V(k) => get(at.v, k),
            Leaf::Measured(i, k) => at.measured.get(i).map_or(nan, |m| get(m, k)),
        };
        if let Some(roots) = &self.trivial {
            for (o, r) in out.iter_mut().zip(roots) {
                *o = match r {
                    Ok(i) => leaf(self.leaves[*i]),
                    Err(c) => *c,
                };
            }
            return;
        }
        self.program.prepare(scratch);
        for (slot, l) in scratch.iter_mut().zip(&self.leaves) {
            *slot = leaf(*l);
        }
        self.program.exec(scratch);
        for (i, o) in out.iter_mut().enumerate().take(self.len()) {
            *o = self.program.root(scratch, i);
        }
    }

    /// As a coef of the forms: a constant, a function of x, or of x and t. Values have no
    /// negative zeros (`−0` and `0` are one value of a coef; the kernels then do the same
    /// arithmetic whichever was written).
    pub fn coef(mut self) -> crate::runtime::fem::kernel::Coef {
        use crate::runtime::fem::kernel::Coef;
        if let Some(values) = self.constant() {
            return Coef::constant(values.into_iter().map(|v| v + 0.0).collect::<Vec<_>>());
        }
        // Assembly calls coefs from every thread: each has its scratch.
        thread_local!(static SCRATCH: std::cell::RefCell<Vec<f64>> = const { std::cell::RefCell::new(Vec::new()) });
        let derivatives = std::mem::take(&mut self.derivatives);
        let coef = self.values();
        if derivatives.is_empty() {
            return coef;
        }
        coef.with_derivatives(move |x, t, order, out| match derivatives.get(order.wrapping_sub(1)) {
            Some(d) => SCRATCH.with(|s| d.eval(&At { x, t, ..At::default() }, &mut s.borrow_mut(), out)),
            None => out.fill(f64::NAN),
        })
    }

    /// The values as a coef (not constant), without derivatives.
    fn values(self) -> crate::runtime::fem::kernel::Coef {
        use crate::runtime::fem::kernel::Coef;
        let n = self.len();
        let steady = !self.reads_time();
        // Components that are coordinates or constants (a plane's gap `x[1]`): copied, with no
        // program to run at each quadrature point.
        let copies: Option<Vec<Result<usize, f64>>> = self.trivial.as_ref().and_then(|roots| {
            roots
                .iter()
                .map(|r| match r {
                    Ok(i) => match self.leaves[*i] {
                        Leaf::X(k) => Some(Ok(k)),
                        _ => None,
                    },
                    Err(c) => Some(Err(*c + 0.0)),
                })
                .collect()
        });
        if let Some(copies) = copies {
            return Coef::of_position(n, move |x, out| {
                for (o, c) in out.iter_mut().zip(&copies) {
                    *o = match c {
                        Ok(k) => x.get(*k).copied().unwrap_or(f64::NAN),
                        Err(v) => *v,
                    };
                }
            });
        }
        thread_local!(static SCRATCH: std::cell::RefCell<Vec<f64>> = const { std::cell::RefCell::new(Vec::new()) });
        let f = move |x: &[f64], t: f64, out: &mut [f64]| {
            SCRATCH.with(|s| self.eval(&At { x, t, ..At::default() }, &mut s.borrow_mut(), out));
        };
        if steady { Coef::of_position(n, move |x, out| f(x, 0.0, out)) } else { Coef::function(n, f) }
    }
}
