//! What the built-ins' property tests share: a random point of the field (its value and
//! gradient, two vector coefs, x, the params) and the check of a form's four tangent blocks
//! against central differences of its coefficients.

use proptest::prelude::*;
use signorini_compiler::Compiled;
use signorini_compiler::ir::DimIr;
use signorini_compiler::ir::eval::evaluate;
use signorini_compiler::ir::graph::Sym;

/// A point: the field's value and gradient (`gu[k*d + l]` = ∂_l u_k), the coefs `a` and `b`,
/// x, and the values of the params in declaration order.
#[derive(Clone, Debug)]
pub struct Point {
    pub d: usize,
    pub u: Vec<f64>,
    pub gu: Vec<f64>,
    pub a: Vec<f64>,
    pub b: Vec<f64>,
    pub x: Vec<f64>,
    pub params: &'static [f64],
}

impl Point {
    pub fn dot(p: &[f64], q: &[f64]) -> f64 {
        p.iter().zip(q).map(|(x, y)| x * y).sum()
    }

    /// ∇u as a matrix.
    pub fn at(&self, i: usize, j: usize) -> f64 {
        self.gu[i * self.d + j]
    }

    pub fn leaf(&self, s: Sym) -> f64 {
        match s {
            Sym::Field { arg: 0, comp } => self.u[comp as usize],
            Sym::FieldGrad { arg: 0, comp, dir } => self.at(comp as usize, dir as usize),
            Sym::Coef { id: 0, comp } => self.a[comp as usize],
            Sym::Coef { id: 1, comp } => self.b[comp as usize],
            Sym::Coord(k) => self.x[k as usize],
            Sym::Param(i) => self.params[i as usize],
            other => panic!("the forms read no {other:?}"),
        }
    }
}

/// Points in 1D, 2D and 3D: u and x in (−½, ½), the gradient's entries in (−g, g), the coefs'
/// in (−1, 1).
pub fn points(g: f64, params: &'static [f64]) -> impl Strategy<Value = Point> {
    let v = |lo: f64, hi: f64, n: usize| proptest::collection::vec(lo..hi, n);
    (1usize..=3, v(-0.5, 0.5, 3), v(-g, g, 9), v(-1.0, 1.0, 3), v(-1.0, 1.0, 3), v(-0.5, 0.5, 3)).prop_map(
        move |(d, u, gu, a, b, x)| Point {
            d,
            u: u[..d].to_vec(),
            gu: gu[..d * d].to_vec(),
            a: a[..d].to_vec(),
            b: b[..d].to_vec(),
            x: x[..d].to_vec(),
            params,
        },
    )
}

pub fn close(got: f64, want: f64, tol: f64) -> bool {
    got.is_finite() && (got - want).abs() <= tol * (1.0 + want.abs())
}

/// The form's coefficients: f0 (of v, d of them) then f1 (of ∇v, d·d).
pub fn coefficients(ir: &DimIr, form: &str, p: &Point) -> Vec<f64> {
    let integral = &ir.forms.iter().find(|f| f.name == form).expect("the form is lowered").integrals[0];
    let mut out = evaluate(&ir.graph, &integral.f0, |s| p.leaf(s));
    out.extend(evaluate(&ir.graph, &integral.f1, |s| p.leaf(s)));
    out
}

/// Central differences of `f` in each of the values that `bump` perturbs (`count` of them).
pub fn differences(
    p: &Point,
    count: usize,
    bump: fn(&mut Point, usize, f64),
    f: impl Fn(&Point) -> Vec<f64>,
) -> Vec<Vec<f64>> {
    let e = 1e-6;
    (0..count)
        .map(|j| {
            let (mut plus, mut minus) = (p.clone(), p.clone());
            bump(&mut plus, j, e);
            bump(&mut minus, j, -e);
            f(&plus).iter().zip(f(&minus)).map(|(x, y)| (x - y) / (2.0 * e)).collect()
        })
        .collect()
}

/// The four blocks of the form's tangent against central differences of its coefficients, in
/// u's value (c00, c10) and in its gradient (c01, c11).
pub fn check_tangent(compiled: &Compiled, form: &str, p: &Point) -> Result<(), TestCaseError> {
    let d = p.d;
    let ir = compiled.ir(d);
    let t = &ir.forms.iter().find(|f| f.name == form).expect("the form is lowered").integrals[0].tangents[0];
    let at = |nodes: &[_]| evaluate(&ir.graph, nodes, |s| p.leaf(s));
    let (c00, c01, c10, c11) = (at(&t.c00), at(&t.c01), at(&t.c10), at(&t.c11));
    let (n0, n1) = (d, d * d);
    let by_value = differences(p, d, |q, m, e| q.u[m] += e, |q| coefficients(ir, form, q));
    let by_grad = differences(p, n1, |q, mn, e| q.gu[mn] += e, |q| coefficients(ir, form, q));
    for i in 0..n0 + n1 {
        for (m, fd) in by_value.iter().enumerate() {
            let auto = if i < n0 { c00[i * d + m] } else { c10[(i - n0) * d + m] };
            prop_assert!(close(auto, fd[i], 1e-6), "{form} {d}D: ∂coef[{i}]/∂u{m} {auto} against {} at {p:?}", fd[i]);
        }
        for (mn, fd) in by_grad.iter().enumerate() {
            let auto = if i < n0 { c01[i * n1 + mn] } else { c11[(i - n0) * n1 + mn] };
            prop_assert!(
                close(auto, fd[i], 1e-6),
                "{form} {d}D: ∂coef[{i}]/∂∇u[{mn}] {auto} against {} at {p:?}",
                fd[i]
            );
        }
    }
    Ok(())
}
