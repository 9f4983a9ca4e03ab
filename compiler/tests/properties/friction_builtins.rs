//! The frictional built-ins `norm`, `proj_ball` and `tangential`, lowered into a contact-like
//! form: in 2D and 3D, at random points of each regime of the projection (separation: radius
//! ≤ 0; stick: |a| < r; slip: |a| > r, with a = tangential(u − w, nc), r = F (u·nc − g)), and
//! at the points where a = 0 exactly, the form's value is the projection's definition and its
//! automatic tangent matches central finite differences. Every regime is asserted present.
//! Where the radius is ≤ 0 (its gate off) a Coulomb-like tangent is its frictionless law's.

use std::path::Path;

use signorini_compiler::ir::eval::evaluate;
use signorini_compiler::ir::graph::Sym;
use signorini_compiler::{MemLoader, compile_text};

const SOURCE: &str = "
param F = 0.4 in [0, inf)
coef nc: vector
coef w: vector
coef g
form law(u; v) = int(Gamma_C, degree = 4)
    dot(proj_ball(tangential(u - w, nc), F*(dot(u, nc) - g)), v) + norm(u - w) * dot(u, v)
";

/// Deterministic numbers in [−1, 1] (xorshift).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }
}

/// One point: the field u, the coefs nc (unit), w and g, and the param F.
#[derive(Clone)]
struct Point {
    u: Vec<f64>,
    nc: Vec<f64>,
    w: Vec<f64>,
    g: f64,
    f: f64,
}

impl Point {
    fn leaf(&self, s: Sym) -> f64 {
        match s {
            Sym::Field { arg: 0, comp } => self.u[comp as usize],
            Sym::Coef { id: 0, comp } => self.nc[comp as usize],
            Sym::Coef { id: 1, comp } => self.w[comp as usize],
            Sym::Coef { id: 2, comp: 0 } => self.g,
            Sym::Param(0) => self.f,
            other => panic!("the law reads no {other:?}"),
        }
    }

    fn dot(a: &[f64], b: &[f64]) -> f64 {
        a.iter().zip(b).map(|(x, y)| x * y).sum()
    }

    /// a = (u − w) − ((u − w)·nc) nc and r = F (u·nc − g).
    fn slip_and_radius(&self) -> (Vec<f64>, f64) {
        let d: Vec<f64> = self.u.iter().zip(&self.w).map(|(u, w)| u - w).collect();
        let dn = Point::dot(&d, &self.nc);
        let a = d.iter().zip(&self.nc).map(|(x, n)| x - dn * n).collect();
        (a, self.f * (Point::dot(&self.u, &self.nc) - self.g))
    }

    /// The law by its definition: the projection of a onto the ball of radius r (zero for
    /// r ≤ 0), plus |u − w| u.
    fn expected(&self) -> Vec<f64> {
        let (a, r) = self.slip_and_radius();
        let size = Point::dot(&a, &a).sqrt();
        let scale = if r <= 0.0 {
            0.0
        } else if size <= r {
            1.0
        } else {
            r / size
        };
        let d: Vec<f64> = self.u.iter().zip(&self.w).map(|(u, w)| u - w).collect();
        let m = Point::dot(&d, &d).sqrt();
        a.iter().zip(&self.u).map(|(a, u)| scale * a + m * u).collect()
    }
}

#[derive(Debug, PartialEq, Eq, Clone, Copy)]
enum Regime {
    Separation,
    Stick,
    Slip,
}

fn regime(p: &Point) -> Regime {
    let (a, r) = p.slip_and_radius();
    let size = Point::dot(&a, &a).sqrt();
    if r <= 0.0 {
        Regime::Separation
    } else if size < r {
        Regime::Stick
    } else {
        Regime::Slip
    }
}

/// The distance of a point from the regimes' boundaries (r = 0, |a| = r), relative to its
/// scale: finite differences across a boundary measure a jump, not a derivative.
fn margin(p: &Point) -> f64 {
    let (a, r) = p.slip_and_radius();
    let size = Point::dot(&a, &a).sqrt();
    r.abs().min((size - r).abs())
}

#[test]
fn frictional_builtins_have_their_values_and_their_tangents_in_every_regime() {
    let compiled = compile_text(Path::new("friction.wf"), SOURCE, &MemLoader::default()).expect("the law compiles");
    let mut rng = Rng(0x2545_f491_4f6c_dd1d);
    for d in [2, 3] {
        let ir = compiled.ir(d);
        let integral = &ir.forms[0].integrals[0];
        let (f0, c00) = (&integral.f0, &integral.tangents[0].c00);
        let value = |p: &Point| evaluate(&ir.graph, f0, |s| p.leaf(s));
        let tangent = |p: &Point| evaluate(&ir.graph, c00, |s| p.leaf(s));
        let mut seen = Vec::new();
        let mut check = |p: &Point, what: &str| {
            let got = value(p);
            let want = p.expected();
            for (k, (x, y)) in got.iter().zip(&want).enumerate() {
                assert!((x - y).abs() <= 1e-14 * (1.0 + y.abs()), "{d}D {what}: component {k}: {x} against {y}");
            }
            let jac = tangent(p);
            let e = 1e-7;
            for m in 0..d {
                let (mut plus, mut minus) = (p.clone(), p.clone());
                plus.u[m] += e;
                minus.u[m] -= e;
                let (fp, fm) = (value(&plus), value(&minus));
                for k in 0..d {
                    let fd = (fp[k] - fm[k]) / (2.0 * e);
                    let auto = jac[k * d + m];
                    assert!(auto.is_finite(), "{d}D {what}: ∂f{k}/∂u{m} is {auto}");
                    assert!(
                        (auto - fd).abs() <= 1e-6 * (1.0 + fd.abs()),
                        "{d}D {what}: ∂f{k}/∂u{m} {auto} against {fd}"
                    );
                }
            }
            seen.push(regime(p));
        };
        let mut checked = 0;
        while checked < 300 {
            let mut nc: Vec<f64> = (0..d).map(|_| rng.next()).collect();
            let size = Point::dot(&nc, &nc).sqrt();
            if size < 0.1 {
                continue;
            }
            nc.iter_mut().for_each(|x| *x /= size);
            let point = Point {
                u: (0..d).map(|_| rng.next()).collect(),
                w: (0..d).map(|_| rng.next()).collect(),
                g: 0.5 * rng.next(),
                f: 1.5 + rng.next(),
                nc,
            };
            if margin(&point) < 1e-3 {
                continue;
            }
            check(&point, &format!("{:?} at {:?}", regime(&point), point.u));
            checked += 1;
        }
        // a = 0 exactly (u − w along the normal, or u = w), in contact (stick) and separated.
        let nc: Vec<f64> = (0..d).map(|k| if k == d - 1 { -1.0 } else { 0.0 }).collect();
        for (g, shift) in [(-0.5, 0.3), (0.5, 0.3), (-0.5, 0.0), (0.5, 0.0)] {
            let u: Vec<f64> = (0..d).map(|k| 0.2 * k as f64 + 0.1).collect();
            let w = u.iter().zip(&nc).map(|(u, n)| u + shift * n).collect();
            let point = Point { u, w, g, f: 0.4, nc: nc.clone() };
            let what = format!("{:?} with a = 0 (g = {g}, u − w = {shift} nc)", regime(&point));
            check(&point, &what);
        }
        for r in [Regime::Separation, Regime::Stick, Regime::Slip] {
            let count = seen.iter().filter(|&&s| s == r).count();
            assert!(count >= 30, "{d}D: {count} points of {r:?}");
        }
    }
}

/// A Coulomb-like law (normal stress pos(u·nc − g), friction onto F times it), the same law
/// without friction, and a Tresca-like one (a constant radius F).
const GATED: &str = "
param F = 0.4 in [0, inf)
coef nc: vector
coef w: vector
coef g
form coulomb(u; v) = int(Gamma_C, degree = 4)
    pos(dot(u, nc) - g) * dot(v, nc) + dot(proj_ball(tangential(u - w, nc), F*pos(dot(u, nc) - g)), v)
form frictionless(u; v) = int(Gamma_C, degree = 4) pos(dot(u, nc) - g) * dot(v, nc)
form tresca(u; v) = int(Gamma_C, degree = 4) dot(proj_ball(tangential(u - w, nc), F), v)
";

/// The gates of a projection: the Coulomb-like tangent is not piecewise, but has one gate,
/// its radius; wherever that is ≤ 0 (out of contact, or F = 0) its tangent is the frictionless
/// law's, which the active set decides. A constant radius gates nothing.
#[test]
fn a_projection_s_tangent_is_gated_by_its_radius() {
    let compiled = compile_text(Path::new("gated.wf"), GATED, &MemLoader::default()).expect("the laws compile");
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    for d in [2, 3] {
        let ir = compiled.ir(d);
        let tangent = |form: usize| &ir.forms[form].integrals[0].tangents[0];
        let (coulomb, frictionless, tresca) = (tangent(0), tangent(1), tangent(2));
        assert!(!coulomb.piecewise && frictionless.piecewise && !tresca.piecewise, "{d}D");
        let gates = coulomb.gates.clone().expect("the radius gates the projection");
        assert_eq!(gates.len(), 1, "{d}D: {gates:?}");
        assert!(tresca.gates.is_none(), "{d}D: a constant radius is no gate");
        let (mut off, mut on) = (0, 0);
        for _ in 0..200 {
            let mut nc: Vec<f64> = (0..d).map(|_| rng.next()).collect();
            let size = Point::dot(&nc, &nc).sqrt().max(0.1);
            nc.iter_mut().for_each(|x| *x /= size);
            // F = 0 on one point in four.
            let f = if rng.next() < -0.5 { 0.0 } else { 1.5 + rng.next() };
            let p = Point {
                u: (0..d).map(|_| rng.next()).collect(),
                w: (0..d).map(|_| rng.next()).collect(),
                g: 0.5 * rng.next(),
                f,
                nc,
            };
            let gate = evaluate(&ir.graph, &gates, |s| p.leaf(s))[0];
            let law = evaluate(&ir.graph, &coulomb.c00, |s| p.leaf(s));
            let without = evaluate(&ir.graph, &frictionless.c00, |s| p.leaf(s));
            if gate <= 0.0 {
                off += 1;
                assert_eq!(law, without, "{d}D: gate off at {:?} (F = {f})", p.u);
            } else {
                on += 1;
            }
        }
        assert!(off > 20 && on > 20, "{d}D: {off} points with the gate off, {on} on");
    }
}
