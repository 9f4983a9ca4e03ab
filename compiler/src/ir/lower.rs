//! Checked AST → scalar DAG for one space dimension. Values are tensors of scalar nodes; each
//! scalar carries its spatial gradient (forward mode), so `grad` of any smooth expression of
//! the fields and of `x` is available. User functions and lets are inlined.

use std::collections::HashMap;

mod coef_at;
mod derivative;
mod jets;
mod levels;
mod tensor;

use super::graph::{Func, Graph, NodeId, Sym};
use crate::check::{CELL_REGION, Global, Unit};
use crate::diagnostic::Diagnostic;
use crate::source::Span;
use crate::syntax::ast::{BinOp, Expr, ExprKind, Shape};

/// Most graph nodes one form's integrands may add in one dimension (before differentiation).
/// Functions are inlined, and calls with distinct arguments can expand exponentially.
pub const MAX_FORM_NODES: usize = 100_000;

type Res<T> = Result<T, Box<Diagnostic>>;

/// A scalar with its spatial gradient (`None` where no gradient exists: normal, case data,
/// gradients themselves).
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Jet {
    pub v: NodeId,
    pub g: Option<Vec<NodeId>>,
}

/// A lowered value: components in row-major order (1, d or d·d of them).
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Val {
    pub shape: Shape,
    pub c: Vec<Jet>,
}

/// One form's integrand over one region, as the coefficients of the test function.
#[derive(Clone, Debug)]
pub struct Integrand {
    pub region: String,
    /// The quadrature degree the file sets (`int(REGION, degree = k)`), the largest of the
    /// region's integrals that set one.
    pub degree: Option<u32>,
    /// The integrand itself (scalar, linear in the test function).
    pub value: NodeId,
}

#[derive(Clone, Debug)]
pub struct LoweredForm {
    pub name: String,
    pub fields: Vec<String>,
    /// `None` for a functional.
    pub test: Option<String>,
    /// One per region, in order of first appearance; integrals over one region are summed.
    pub integrands: Vec<Integrand>,
}

pub struct Lowerer<'p> {
    pub g: Graph,
    prog: &'p Unit,
    d: usize,
    scope: Vec<(String, Val)>,
    lets: HashMap<String, Val>,
    /// Inlined calls by function and argument values: each distinct call is expanded once.
    calls: HashMap<(String, Vec<Val>), Val>,
    /// Graph size when the current form began, for [`MAX_FORM_NODES`], and its name.
    form_start: usize,
    form_name: String,
    /// `derivative` calls being lowered: the level of the next one's seed.
    seeds: u8,
    /// In a form of n field arguments, n: `prev(u)` reads the previous time level's
    /// displacement as an n+1-th field, which no tangent differentiates. None outside forms
    /// (functionals, a problem's expressions).
    previous: Option<u8>,
    /// Lowering a facet integral of a form or functional, where `opposite(e)` reads the facing
    /// surface of a contact pair.
    facing: bool,
}

impl<'p> Lowerer<'p> {
    pub fn new(prog: &'p Unit, d: usize) -> Self {
        Lowerer {
            g: Graph::default(),
            prog,
            d,
            scope: Vec::new(),
            lets: HashMap::new(),
            calls: HashMap::new(),
            form_start: 0,
            form_name: String::new(),
            seeds: 0,
            previous: None,
            facing: false,
        }
    }

    pub fn dim(&self) -> usize {
        self.d
    }

    /// Lowers an expression of a problem, with `scope` (its params as constants, its fields)
    /// visible before the unit's names.
    pub fn problem_expr(&mut self, e: &Expr, scope: Vec<(String, Val)>) -> Res<Val> {
        self.form_start = self.g.len();
        self.scope = scope;
        let v = self.expr(e);
        self.scope.clear();
        v
    }

    /// A constant value with a zero gradient.
    pub fn constant_val(&mut self, v: f64) -> Val {
        Self::scalar(self.constant(v))
    }

    /// Lowers form `index`; refuses non-finite constant arithmetic and expansions past
    /// [`MAX_FORM_NODES`], at the user's tokens.
    pub fn form(&mut self, index: usize) -> Res<LoweredForm> {
        let form = &self.prog.forms[index];
        self.form_start = self.g.len();
        self.form_name.clone_from(&form.name);
        // A functional is evaluated at levels the driver names (`contact_work(u, w)`): the
        // previous one is an argument there, not `prev`.
        self.previous = form.test.is_some().then_some(form.fields.len() as u8);
        let d = self.d;
        let mut scope = Vec::new();
        for (a, f) in form.fields.iter().enumerate() {
            let c = (0..d)
                .map(|k| Jet {
                    v: self.g.sym(Sym::Field { arg: a as u8, comp: k as u8 }),
                    g: Some(
                        (0..d)
                            .map(|l| self.g.sym(Sym::FieldGrad { arg: a as u8, comp: k as u8, dir: l as u8 }))
                            .collect(),
                    ),
                })
                .collect();
            scope.push((f.name.clone(), Val { shape: Shape::Vector, c }));
        }
        let c = (0..d)
            .map(|k| Jet {
                v: self.g.sym(Sym::Test { comp: k as u8 }),
                g: Some((0..d).map(|l| self.g.sym(Sym::TestGrad { comp: k as u8, dir: l as u8 })).collect()),
            })
            .collect();
        if let Some(test) = &form.test {
            scope.push((test.name.clone(), Val { shape: Shape::Vector, c }));
        }
        self.scope = scope;
        let mut integrands: Vec<Integrand> = Vec::new();
        for integral in &form.integrals {
            self.facing = integral.region.name != crate::check::CELL_REGION;
            let v = self.expr(&integral.integrand);
            self.facing = false;
            let v = match v {
                Ok(v) => v.c[0].v,
                Err(d) => {
                    self.scope.clear();
                    return Err(d);
                }
            };
            let v = if integral.sign < 0.0 { self.g.neg(v) } else { v };
            let degree = match integral.degree {
                None => None,
                Some((k, _)) if k.fract() == 0.0 && (0.0..=super::MAX_DEGREE as f64).contains(&k) => Some(k as u32),
                Some((k, span)) => {
                    self.scope.clear();
                    return Err(Box::new(
                        Diagnostic::error(
                            "E0504",
                            format!("quadrature degree {k} is not an integer from 0 to {}", super::MAX_DEGREE),
                            span,
                            "not a quadrature degree",
                        )
                        .with_help(
                            "`int(REGION, degree = K)` takes the degree of polynomial the rule integrates exactly",
                        ),
                    ));
                }
            };
            match integrands.iter_mut().find(|i| i.region == integral.region.name) {
                Some(i) => {
                    i.value = self.g.add(i.value, v);
                    i.degree = i.degree.max(degree);
                }
                None => integrands.push(Integrand { region: integral.region.name.clone(), degree, value: v }),
            }
        }
        // Volume integral first: kernels are emitted in this order.
        integrands.sort_by_key(|i| i.region != CELL_REGION);
        self.scope.clear();
        Ok(LoweredForm {
            name: form.name.clone(),
            fields: form.fields.iter().map(|f| f.name.clone()).collect(),
            test: form.test.as_ref().map(|t| t.name.clone()),
            integrands,
        })
    }

    fn zero_grad(&mut self) -> Option<Vec<NodeId>> {
        let z = self.g.zero();
        Some(vec![z; self.d])
    }

    fn constant(&mut self, v: f64) -> Jet {
        let v = self.g.constant(v);
        Jet { v, g: self.zero_grad() }
    }

    fn scalar(j: Jet) -> Val {
        Val { shape: Shape::Scalar, c: vec![j] }
    }

    fn expr(&mut self, e: &Expr) -> Res<Val> {
        let v = match &e.kind {
            ExprKind::Number(v) => Self::scalar(self.constant(*v)),
            ExprKind::Name(id) => self.name(&id.name)?,
            ExprKind::Neg(a) => {
                let a = self.expr(a)?;
                self.map(&a, |s, j| s.jneg(j))
            }
            ExprKind::Binary(op, a, b) => {
                let (a, b) = (self.expr(a)?, self.expr(b)?);
                if *op == BinOp::Div && self.g.is_zero(b.c[0].v) {
                    return Err(Box::new(not_finite(e.span, "divides by zero")));
                }
                // A real power: of a number, folded; of a value that varies, a^p with p a^(p−1)
                // as its derivative.
                if let (BinOp::Pow, Some(k)) = (op, b_const(e).filter(|k| k.fract() != 0.0)) {
                    if let Some(x) = self.g.as_const(a.c[0].v) {
                        return Ok(self.constant_val(x.powf(k)));
                    }
                    let base = a.c[0].clone();
                    return Ok(Self::scalar(self.jpowf(&base, k)));
                }
                self.binary(*op, a, b, b_const(e))
            }
            ExprKind::Call(f, args) if f.name == "derivative" => self.derivative(args)?,
            ExprKind::Call(f, args) => {
                let args: Vec<Val> = args.iter().map(|a| self.expr(a)).collect::<Res<_>>()?;
                self.call(&f.name, args, e.span)?
            }
            ExprKind::Vector(items) => {
                if items.len() != self.d {
                    let d = Diagnostic::error(
                        "E0302",
                        "wrong dimension",
                        e.span,
                        format!("a vector of {} components in a {}D problem", items.len(), self.d),
                    );
                    return Err(Box::new(d));
                }
                let c = items.iter().map(|a| Ok(self.expr(a)?.c[0].clone())).collect::<Res<Vec<Jet>>>()?;
                Val { shape: Shape::Vector, c }
            }
            ExprKind::Index(a, i) => {
                let a = self.expr(a)?;
                let k = crate::check::const_value(i).unwrap_or(-1.0);
                if !(k >= 0.0 && (k as usize) < self.d) {
                    let d = Diagnostic::error(
                        "E0302",
                        "wrong dimension",
                        i.span,
                        format!("component {k} of a vector in a {}D problem (components count from 0)", self.d),
                    );
                    return Err(Box::new(d));
                }
                Self::scalar(a.c[k as usize].clone())
            }
        };
        // Operands are finite (checked below them), so a non-finite constant was made here.
        if let Some(x) = v.c.iter().find_map(|j| self.g.as_const(j.v).filter(|x| !x.is_finite())) {
            return Err(Box::new(not_finite(e.span, &format!("evaluates to {x}"))));
        }
        Ok(v)
    }

    fn name(&mut self, name: &str) -> Res<Val> {
        if let Some((_, v)) = self.scope.iter().rev().find(|(n, _)| n == name) {
            return Ok(v.clone());
        }
        let d = self.d;
        Ok(match self.prog.globals.get(name) {
            Some(Global::Param(i)) => {
                let v = self.g.sym(Sym::Param(*i as u16));
                Self::scalar(Jet { v, g: self.zero_grad() })
            }
            Some(Global::Coef(i)) => {
                let shape = self.prog.coefs[*i].shape;
                let n = components(shape, d);
                let c = (0..n)
                    .map(|k| Jet { v: self.g.sym(Sym::Coef { id: *i as u16, comp: k as u8 }), g: None })
                    .collect();
                Val { shape, c }
            }
            Some(Global::Let { value, .. }) => {
                if let Some(v) = self.lets.get(name) {
                    return Ok(v.clone());
                }
                let saved = std::mem::take(&mut self.scope);
                let v = self.expr(&value.clone());
                self.scope = saved;
                let v = v?;
                self.name_val(&v, name);
                self.lets.insert(name.to_string(), v.clone());
                v
            }
            _ => match name {
                "I" => {
                    let c = (0..d * d).map(|k| self.constant(if k / d == k % d { 1.0 } else { 0.0 })).collect();
                    Val { shape: Shape::Tensor, c }
                }
                "x" => {
                    let c = (0..d)
                        .map(|k| {
                            let v = self.g.sym(Sym::Coord(k as u8));
                            let g = (0..d).map(|l| self.g.constant(if k == l { 1.0 } else { 0.0 })).collect();
                            Jet { v, g: Some(g) }
                        })
                        .collect();
                    Val { shape: Shape::Vector, c }
                }
                "t" => {
                    let v = self.g.sym(Sym::Time);
                    Self::scalar(Jet { v, g: self.zero_grad() })
                }
                "h" => {
                    let v = self.g.sym(Sym::CellDiameter);
                    Self::scalar(Jet { v, g: self.zero_grad() })
                }
                "n" => {
                    let c = (0..d).map(|k| Jet { v: self.g.sym(Sym::Normal(k as u8)), g: None }).collect();
                    Val { shape: Shape::Vector, c }
                }
                "pi" => Self::scalar(self.constant(std::f64::consts::PI)),
                _ => unreachable!("checked name `{name}`"),
            },
        })
    }

    fn name_val(&mut self, v: &Val, name: &str) {
        let single = v.c.len() == 1;
        let d = self.d;
        for (k, j) in v.c.iter().enumerate() {
            let n = if single {
                name.to_string()
            } else if v.shape == Shape::Vector {
                format!("{name}_{k}")
            } else {
                format!("{name}_{}{}", k / d, k % d)
            };
            self.g.name(j.v, &n);
        }
    }

    fn call(&mut self, f: &str, args: Vec<Val>, span: Span) -> Res<Val> {
        if let Some(Global::Coef(i)) = self.prog.globals.get(f) {
            return Ok(self.coef_at(*i as u16, &args[0]));
        }
        if let Some(Global::Fn { params, body, .. }) = self.prog.globals.get(f) {
            let key = (f.to_string(), args);
            if let Some(v) = self.calls.get(&key) {
                return Ok(v.clone());
            }
            if self.g.len() - self.form_start > MAX_FORM_NODES {
                return Err(Box::new(
                    Diagnostic::error(
                        "E0002",
                        format!("`{f}` expands too far"),
                        span,
                        format!("the form grows past {MAX_FORM_NODES} operations by this call"),
                    )
                    .with_note(format!("while inlining the functions of form `{}`", self.form_name))
                    .with_help("functions are inlined at every call with distinct arguments: compute shared values once with `let`"),
                ));
            }
            let scope = params.iter().map(|p| p.name.clone()).zip(key.1.iter().cloned()).collect();
            let saved = std::mem::replace(&mut self.scope, scope);
            let v = self.expr(&body.clone());
            self.scope = saved;
            let v = v?;
            self.name_val(&v, f);
            self.calls.insert(key, v.clone());
            return Ok(v);
        }
        if let Some(b) = crate::check::builtin(f).filter(|b| b.numbers_only) {
            // `ceil`, `floor` (problems only): of numbers.
            let Some(x) = self.g.as_const(args[0].c[0].v).and_then(|x| b.fold.apply(&[x])) else {
                return Err(Box::new(
                    Diagnostic::error(
                        "E0303",
                        format!("`{f}` of a value that varies"),
                        span,
                        "depends on x, t or the fields",
                    )
                    .with_help(format!("`{f}` takes numbers and params only")),
                ));
            };
            return Ok(self.constant_val(x));
        }
        if f == "prev" {
            let Some(previous) = self.previous else {
                return Err(Box::new(
                    Diagnostic::error("E0406", "`prev` outside a form", span, "no previous time level here")
                        .with_note("`prev(e)` is `e` at the previous time level, which the driver gives a form's kernels")
                        .with_help("a functional takes the levels it compares as arguments: `functional work(u, w) = ...`, evaluated at the step's new and old displacements"),
                ));
            };
            return Ok(self.previous_level(&args[0], previous));
        }
        if f == "opposite" {
            if !self.facing {
                return Err(Box::new(
                    Diagnostic::error("E0408", "`opposite` outside a facet integral", span, "no facing surface here")
                        .with_note("`opposite(e)` is `e` on the other surface of a contact pair, at the point facing the quadrature point: it is read in the integrals over a pair's surface, `int(Gamma_C)`")
                        .with_help("integrate over the contact surface: `form contact(u; v) = int(Gamma_C) ...`"),
                ));
            }
            return Ok(self.opposite_side(&args[0]));
        }
        Ok(self.builtin(f, args))
    }

    fn builtin(&mut self, f: &str, args: Vec<Val>) -> Val {
        let d = self.d;
        let mut args = args.into_iter();
        let mut next = || args.next().expect("checked arity");
        match f {
            "grad" => {
                let a = next();
                let c: Vec<Jet> =
                    a.c.iter()
                        .flat_map(|j| j.g.clone().expect("checked smooth").into_iter().map(|v| Jet { v, g: None }))
                        .collect();
                let shape = if a.shape == Shape::Scalar { Shape::Vector } else { Shape::Tensor };
                Val { shape, c }
            }
            "div" => {
                let a = next();
                let rows = if a.shape == Shape::Vector { 1 } else { d };
                let c = (0..rows)
                    .map(|i| {
                        let mut acc = self.g.zero();
                        for j in 0..d {
                            let comp = if rows == 1 { j } else { i * d + j };
                            let dj = a.c[comp].g.as_ref().expect("checked smooth")[j];
                            acc = self.g.add(acc, dj);
                        }
                        Jet { v: acc, g: None }
                    })
                    .collect();
                Val { shape: if rows == 1 { Shape::Scalar } else { Shape::Vector }, c }
            }
            "sym" => {
                let a = next();
                let half = self.constant(0.5);
                let c = (0..d * d)
                    .map(|k| {
                        let (i, j) = (k / d, k % d);
                        let s = self.jadd(&a.c[i * d + j], &a.c[j * d + i]);
                        self.jmul(&half, &s)
                    })
                    .collect();
                Val { shape: Shape::Tensor, c }
            }
            "transpose" => {
                let a = next();
                let c = (0..d * d).map(|k| a.c[(k % d) * d + k / d].clone()).collect();
                Val { shape: Shape::Tensor, c }
            }
            "tr" => {
                let a = next();
                let mut acc = self.constant(0.0);
                for i in 0..d {
                    acc = self.jadd(&acc, &a.c[i * d + i]);
                }
                Self::scalar(acc)
            }
            "dot" => {
                let (a, b) = (next(), next());
                self.product(a, b)
            }
            "inner" => {
                let (a, b) = (next(), next());
                Self::scalar(self.jinner(&a, &b))
            }
            "outer" => {
                let (a, b) = (next(), next());
                let c = (0..d * d).map(|k| self.jmul(&a.c[k / d], &b.c[k % d])).collect();
                Val { shape: Shape::Tensor, c }
            }
            "det" | "inv" | "cofac" | "dev" | "skew" => {
                let a = next();
                self.tensor_fn(f, &a)
            }
            "H" => {
                let a = next();
                Self::scalar(self.jheaviside(&a.c[0]))
            }
            "pos" => {
                // [a]_+ = a·H(a)
                let a = next().c.remove(0);
                let h = self.jheaviside(&a);
                Self::scalar(self.jmul(&a, &h))
            }
            "neg" => {
                // [a]_- = min(a, 0) = a·H(-a)
                let a = next().c.remove(0);
                let m = self.jneg(&a);
                let h = self.jheaviside(&m);
                Self::scalar(self.jmul(&a, &h))
            }
            "abs" => {
                // |a| = a·(H(a) − H(−a))
                let a = next().c.remove(0);
                let hp = self.jheaviside(&a);
                let m = self.jneg(&a);
                let hm = self.jheaviside(&m);
                let s = self.jsub(&hp, &hm);
                Self::scalar(self.jmul(&a, &s))
            }
            "max" | "min" => {
                // max(a, b) = b + (a − b)·H(a − b); min(a, b) = b + (a − b)·H(b − a)
                let (a, b) = (next().c.remove(0), next().c.remove(0));
                let diff = self.jsub(&a, &b);
                let arg = if f == "max" { diff.clone() } else { self.jneg(&diff) };
                let h = self.jheaviside(&arg);
                let p = self.jmul(&diff, &h);
                Self::scalar(self.jadd(&b, &p))
            }
            "sqrt" => {
                let a = next().c.remove(0);
                Self::scalar(self.jsqrt(&a))
            }
            "norm" => {
                let a = next();
                Self::scalar(self.jnorm(&a))
            }
            "atan2" => {
                let (y, x) = (next().c.remove(0), next().c.remove(0));
                Self::scalar(self.jatan2(&y, &x))
            }
            _ if let Some(func) = Func::named(f) => {
                let a = next().c.remove(0);
                Self::scalar(self.jfunc(func, &a))
            }
            "tangential" => {
                // a − (a·nc) nc
                let (a, nc) = (next(), next());
                let an = self.jinner(&a, &nc);
                let c =
                    a.c.iter()
                        .zip(&nc.c)
                        .map(|(x, y)| {
                            let p = self.jmul(&an, y);
                            self.jsub(x, &p)
                        })
                        .collect();
                Val { shape: Shape::Vector, c }
            }
            "proj_ball" => {
                // With ρ = [r]_+, |a| and the stick indicator k = H(ρ − |a|):
                // k·a + (1 − k)·ρ·a/D, D = |a| + (1 − H(|a|)). D is |a| where a ≠ 0 and 1 at
                // a = 0, so that neither branch divides by zero, nor does their tangent (see the
                // derivative of sqrt): the value is a inside the ball, ρ·a/|a| outside, 0 for
                // ρ = 0; the tangent I inside, ρ/|a| (I − â âᵀ) outside, 0 for ρ = 0. Its steps
                // are not switches of the law's active set (`Node::Step`). The whole is
                // H(r)·(...), so that where the radius is zero (out of contact, or a zero
                // friction coefficient) the tangent is zero by that step: a gate
                // (`TangentIr::gates`) where the active set decides the tangent.
                let (a, r) = (next(), next().c.remove(0));
                let hr = self.jstep(&r);
                let rho = self.jmul(&r, &hr);
                let size = self.jnorm(&a);
                let gap = self.jsub(&rho, &size);
                let k = self.jstep(&gap);
                let one = self.constant(1.0);
                let slip = self.jsub(&one, &k);
                let nonzero = self.jstep(&size);
                let guard = self.jsub(&one, &nonzero);
                let den = self.jadd(&size, &guard);
                let scale = self.jdiv(&rho, &den);
                let outer = self.jmul(&slip, &scale);
                let c =
                    a.c.iter()
                        .map(|x| {
                            let inside = self.jmul(&k, x);
                            let outside = self.jmul(&outer, x);
                            let value = self.jadd(&inside, &outside);
                            self.jmul(&hr, &value)
                        })
                        .collect();
                Val { shape: a.shape, c }
            }
            _ => unreachable!("checked built-in `{f}`"),
        }
    }

    fn binary(&mut self, op: BinOp, a: Val, b: Val, exponent: Option<f64>) -> Val {
        match op {
            BinOp::Add => self.zip(&a, &b, |s, x, y| s.jadd(x, y)),
            BinOp::Sub => self.zip(&a, &b, |s, x, y| s.jsub(x, y)),
            BinOp::Mul => self.product(a, b),
            BinOp::Div => {
                let den = b.c[0].clone();
                self.map(&a, |s, x| s.jdiv(x, &den))
            }
            BinOp::Pow => {
                let k = exponent.expect("checked constant exponent") as i32;
                let base = a.c[0].clone();
                Self::scalar(self.jpowi(&base, k))
            }
        }
    }

    /// `*` and `dot`: scalar scaling, matrix–vector, vector–matrix, matrix–matrix, scalar product.
    fn product(&mut self, a: Val, b: Val) -> Val {
        use Shape::*;
        let d = self.d;
        match (a.shape, b.shape) {
            (Scalar, _) => {
                let s = a.c[0].clone();
                self.map(&b, |t, x| t.jmul(&s, x))
            }
            (_, Scalar) => {
                let s = b.c[0].clone();
                self.map(&a, |t, x| t.jmul(x, &s))
            }
            (Vector, Vector) => {
                let c = self.sum_of_products((0..d).map(|k| (k, k)).collect(), &a, &b);
                Self::scalar(c)
            }
            (Tensor, Vector) => {
                let c =
                    (0..d).map(|i| self.sum_of_products((0..d).map(|j| (i * d + j, j)).collect(), &a, &b)).collect();
                Val { shape: Vector, c }
            }
            (Vector, Tensor) => {
                let c =
                    (0..d).map(|j| self.sum_of_products((0..d).map(|i| (i, i * d + j)).collect(), &a, &b)).collect();
                Val { shape: Vector, c }
            }
            (Tensor, Tensor) => {
                let c = (0..d * d)
                    .map(|k| {
                        let (i, j) = (k / d, k % d);
                        self.sum_of_products((0..d).map(|m| (i * d + m, m * d + j)).collect(), &a, &b)
                    })
                    .collect();
                Val { shape: Tensor, c }
            }
        }
    }

    fn sum_of_products(&mut self, pairs: Vec<(usize, usize)>, a: &Val, b: &Val) -> Jet {
        let mut acc = self.constant(0.0);
        for (i, j) in pairs {
            let p = self.jmul(&a.c[i], &b.c[j]);
            acc = self.jadd(&acc, &p);
        }
        acc
    }

    fn map(&mut self, a: &Val, mut f: impl FnMut(&mut Self, &Jet) -> Jet) -> Val {
        let c = a.c.iter().map(|x| f(self, x)).collect();
        Val { shape: a.shape, c }
    }

    fn zip(&mut self, a: &Val, b: &Val, mut f: impl FnMut(&mut Self, &Jet, &Jet) -> Jet) -> Val {
        let c = a.c.iter().zip(&b.c).map(|(x, y)| f(self, x, y)).collect();
        Val { shape: a.shape, c }
    }
}

fn not_finite(span: Span, label: &str) -> Diagnostic {
    Diagnostic::error("E0004", "constant arithmetic is not finite", span, label)
        .with_note("a division by zero or an overflow of double precision, after simplification")
}

/// Number of scalar components of a shape in dimension d.
pub fn components(shape: Shape, d: usize) -> usize {
    match shape {
        Shape::Scalar => 1,
        Shape::Vector => d,
        Shape::Tensor => d * d,
    }
}

/// The constant exponent of a `^` expression (checked to be a constant integer).
fn b_const(e: &Expr) -> Option<f64> {
    match &e.kind {
        ExprKind::Binary(BinOp::Pow, _, b) => crate::check::const_value(b),
        _ => None,
    }
}
