//! Every library scheme's derived energy identity against the scheme's own stepping. The
//! compiled stages are stepped on M ü + K u + C(u) = F(t) (3 dofs, M and K random symmetric
//! positive definite, C a nonlinear contact-like force, F(t) = f cos t), each stage solved by
//! Newton to round-off, at random params in their ranges and a random dt; then on every step
//! the kept energy computed from the stepped states changes by the identity's work less its
//! dissipation: |Ẽ' − Ẽ − W + D| at round-off, and D ≥ 0 where its coefficients are.

use std::path::Path;

use proptest::prelude::*;
use signorini_compiler::scheme::energy::classify::Identity;
use signorini_compiler::scheme::energy::evaluate::Operators;
use signorini_compiler::scheme::energy::window::Free;
use signorini_compiler::scheme::{Affine, Quantity, SchemeIr, Term, eval_all};

const N: usize = 3;
type V = [f64; N];
type Mat = [[f64; N]; N];

struct System {
    m: Mat,
    k: Mat,
    f: V,
}

fn mul(a: &Mat, x: &V) -> V {
    std::array::from_fn(|i| (0..N).map(|j| a[i][j] * x[j]).sum())
}

fn dot(x: &V, y: &V) -> f64 {
    x.iter().zip(y).map(|(a, b)| a * b).sum()
}

fn add(x: &V, y: &V, c: f64) -> V {
    std::array::from_fn(|i| x[i] + c * y[i])
}

/// A contact-like force: stiff where a dof passes −0.1, plus a hardening cubic.
fn contact(x: &V) -> V {
    std::array::from_fn(|i| 50.0 * (-x[i] - 0.1).max(0.0).powi(2) + 0.5 * x[i].powi(3))
}

impl System {
    fn random(r: &mut impl FnMut() -> f64) -> System {
        let spd = |r: &mut dyn FnMut() -> f64, shift: f64| -> Mat {
            let b: Mat = std::array::from_fn(|_| std::array::from_fn(|_| r() - 0.5));
            std::array::from_fn(|i| {
                std::array::from_fn(|j| {
                    (0..N).map(|l| b[i][l] * b[j][l]).sum::<f64>() + if i == j { shift } else { 0.0 }
                })
            })
        };
        let m = spd(r, 0.5);
        let k = spd(r, 1.0);
        let f = std::array::from_fn(|_| r() - 0.5);
        System { m, k, f }
    }

    /// A slot applied to its arguments at time `t`.
    fn apply(&self, slot: &str, args: &[V], t: f64) -> V {
        match (slot, args) {
            ("mass", [x]) => mul(&self.m, x),
            ("stiffness", [x]) => mul(&self.k, x),
            ("contact", [x]) => contact(x),
            ("load", []) => self.f.map(|f| f * t.cos()),
            ("hybrid_contact", [x, y]) => add(&contact(x), &contact(y), 1.0).map(|c| 0.5 * c),
            // The discrete gradient of ½u·K·u.
            ("stiffness_dg", [x, y]) => mul(&self.k, &add(x, y, 1.0)).map(|c| 0.5 * c),
            _ => panic!("no slot {slot} of {} arguments here", args.len()),
        }
    }
}

/// The value of an affine level combination: `w` for the unknown, the known quantities from
/// the states and the stages' values so far.
fn level(s: &SchemeIr, a: &Affine, w: &V, states: &[V], values: &[Vec<V>], c: &[f64], at: usize) -> (V, usize) {
    let mut x = w.map(|w| c[at] * w);
    let mut k = at + 1;
    for (q, _) in &a.known {
        let of = match *q {
            Quantity::State(i) => states[i],
            Quantity::Stage { stage, index } => values[stage][index],
        };
        x = add(&x, &of, c[k]);
        k += 1;
    }
    let _ = s;
    (x, k)
}

/// The coefficient nodes of `terms`, in the order [`residual`] reads them.
fn roots(terms: &[Term]) -> Vec<signorini_compiler::ir::graph::NodeId> {
    let mut r = Vec::new();
    for t in terms {
        r.push(t.coef);
        r.push(t.time);
        for a in &t.args {
            r.push(a.unknown);
            r.extend(a.known.iter().map(|(_, c)| *c));
        }
    }
    r
}

/// Σ coef·slot(args(w)) at `w`.
fn residual(s: &SchemeIr, sys: &System, terms: &[Term], c: &[f64], w: &V, states: &[V], values: &[Vec<V>]) -> V {
    let mut out = [0.0; N];
    let mut k = 0;
    for t in terms {
        let (coef, time) = (c[k], c[k + 1]);
        k += 2;
        let mut args = Vec::new();
        for a in &t.args {
            let (x, next) = level(s, a, w, states, values, c, k);
            args.push(x);
            k = next;
        }
        out = add(&out, &sys.apply(&t.form, &args, time), coef);
    }
    out
}

fn solve(a: &Mat, b: &V) -> V {
    let (mut a, mut b) = (*a, *b);
    for col in 0..N {
        let p = (col..N).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs())).unwrap();
        a.swap(col, p);
        b.swap(col, p);
        for row in col + 1..N {
            let f = a[row][col] / a[col][col];
            for j in col..N {
                a[row][j] -= f * a[col][j];
            }
            b[row] -= f * b[col];
        }
    }
    let mut x = [0.0; N];
    for i in (0..N).rev() {
        x[i] = (b[i] - (i + 1..N).map(|j| a[i][j] * x[j]).sum::<f64>()) / a[i][i];
    }
    x
}

/// Newton on r(w) = 0 from `w`, the Jacobian by central differences, to round-off; none if it
/// does not converge.
fn newton(r: &dyn Fn(&V) -> V, mut w: V) -> Option<V> {
    for _ in 0..60 {
        let f = r(&w);
        let scale = w.iter().fold(1.0f64, |m, x| m.max(x.abs()));
        let h = 1e-6 * scale;
        let mut j: Mat = [[0.0; N]; N];
        for col in 0..N {
            let (mut p, mut m) = (w, w);
            p[col] += h;
            m[col] -= h;
            let (fp, fm) = (r(&p), r(&m));
            for row in 0..N {
                j[row][col] = (fp[row] - fm[row]) / (2.0 * h);
            }
        }
        let d = solve(&j, &f);
        w = add(&w, &d, -1.0);
        if !w.iter().all(|x| x.is_finite() && x.abs() < 1e6) {
            return None;
        }
        if d.iter().all(|d| d.abs() <= 1e-15 * scale) {
            return Some(w);
        }
    }
    None
}

/// One step's record: the states at its start and each stage's unknown.
struct Step {
    start: Vec<V>,
    unknowns: Vec<V>,
}

/// `steps` steps of `s` from u = u0, v = v0 (other states 0, the initial line solved); none if
/// a Newton solve fails.
fn run(s: &SchemeIr, sys: &System, params: &[f64], dt: f64, u0: V, v0: V, steps: usize) -> Option<Vec<Step>> {
    let mut states: Vec<V> = s.states.iter().map(|_| [0.0; N]).collect();
    states[0] = u0;
    if let Some(v) = s.states.iter().position(|n| n == "v") {
        states[v] = v0;
    }
    if let Some(init) = &s.initial {
        let c = eval_all(&s.graph, &roots(&init.terms), params, 1.0, 0.0);
        // The solved state is the initial residual's unknown.
        let r = |x: &V| residual(s, sys, &init.terms, &c, x, &states, &[]);
        states[init.state] = newton(&r, [0.0; N])?;
    }
    let mut out = Vec::new();
    for n in 0..=steps {
        let t = n as f64 * dt;
        let mut values: Vec<Vec<V>> = Vec::new();
        let mut unknowns = Vec::new();
        for stage in &s.stages {
            let c = eval_all(&s.graph, &roots(&stage.terms), params, dt, t);
            let r = |w: &V| residual(s, sys, &stage.terms, &c, w, &states, &values);
            let w = newton(&r, states[0])?;
            let mut mine = Vec::new();
            for a in &stage.values {
                let mut nodes = vec![a.unknown];
                nodes.extend(a.known.iter().map(|(_, c)| *c));
                let cv = eval_all(&s.graph, &nodes, params, dt, t);
                mine.push(level(s, a, &w, &states, &values, &cv, 0).0);
            }
            values.push(mine);
            unknowns.push(w);
        }
        out.push(Step { start: states.clone(), unknowns });
        states = s
            .updates
            .iter()
            .map(|q| match *q {
                Quantity::State(i) => states[i],
                Quantity::Stage { stage, index } => values[stage][index],
            })
            .collect();
    }
    Some(out)
}

/// The kept energy at a step boundary from the states there and one step before.
fn kept(s: &SchemeIr, id: &Identity, sys: &System, params: &[f64], dt: f64, now: &[V], then: &[V]) -> f64 {
    let theta = id.weight.as_ref().map_or(0.0, |w| w.eval(params, dt, 0.0));
    let hat = |i: usize| add(&now[i].map(|x| (1.0 - theta) * x), &then[i], theta);
    let v = s.states.iter().position(|n| n == "v").unwrap();
    let mut e = 0.5 * dot(&hat(v), &mul(&sys.m, &hat(v)));
    if id.elastic {
        e += 0.5 * dot(&hat(0), &mul(&sys.k, &hat(0)));
    }
    if let (Some(q), Some(init)) = (&id.acceleration, &s.initial) {
        let a = hat(init.state);
        e += q.eval(params, dt, 0.0) * 0.5 * dt * dt * dot(&a, &mul(&sys.m, &a));
    }
    if let Some(q) = &id.step_before {
        let d = add(&now[0], &then[0], -1.0);
        e += q.eval(params, dt, 0.0) * 0.5 * dot(&d, &mul(&sys.k, &d));
    }
    e
}

impl Operators for System {
    fn mass(&self, x: &[f64]) -> Vec<f64> {
        mul(&self.m, &vector(x)).to_vec()
    }
    fn stiffness(&self, x: &[f64]) -> Vec<f64> {
        mul(&self.k, &vector(x)).to_vec()
    }
    fn apply(&self, slot: &str, args: &[Vec<f64>], t: f64) -> Vec<f64> {
        let args: Vec<V> = args.iter().map(|a| vector(a)).collect();
        System::apply(self, slot, &args, t).to_vec()
    }
}

fn vector(x: &[f64]) -> V {
    std::array::from_fn(|i| x[i])
}

/// The identity's closure |Ẽ' − Ẽ − W + D| on step `n` of `steps`, its scale, and D: the kept
/// energies from the stepped states themselves, the work and the dissipation from the identity
/// (whose own kept energies must agree).
fn closure(
    s: &SchemeIr,
    id: &Identity,
    sys: &System,
    params: &[f64],
    dt: f64,
    steps: &[Step],
    n: usize,
) -> (f64, f64, f64) {
    let x: Vec<Vec<f64>> = id
        .free()
        .iter()
        .map(|f| match *f {
            Free::State(i) => steps[n].start[i],
            Free::Unknown(k) => steps[n].unknowns[k],
            Free::Previous(i) => steps[n - 1].start[i],
            Free::PreviousUnknown(k) => steps[n - 1].unknowns[k],
        })
        .map(|v| v.to_vec())
        .collect();
    let b = id.balance(s, sys, params, dt, n as f64 * dt, &x);
    let (e1, e0) = (
        kept(s, id, sys, params, dt, &steps[n + 1].start, &steps[n].start),
        kept(s, id, sys, params, dt, &steps[n].start, &steps[n - 1].start),
    );
    let scale = e0.abs() + e1.abs() + b.work.abs() + b.dissipation.abs();
    assert!(
        (b.kept_after - e1).abs() + (b.kept_before - e0).abs() <= 1e-10 * (1.0 + scale),
        "{}: the identity's kept energies {} → {} against the states' {e0} → {e1}",
        s.name,
        b.kept_before,
        b.kept_after
    );
    ((e1 - e0 - b.work + b.dissipation).abs(), scale, b.dissipation)
}

fn library() -> Vec<SchemeIr> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../forms/schemes");
    let mut files: Vec<_> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().path()).collect();
    files.sort();
    files
        .iter()
        .map(|f| {
            let (prog, _) = signorini_compiler::check_path(f, &signorini_compiler::FsLoader).unwrap();
            prog.schemes.into_iter().next().unwrap()
        })
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(12))]

    #[test]
    fn every_library_identity_closes_on_the_schemes_own_steps(
        seed in any::<u64>(),
        along in prop::collection::vec(0.0f64..1.0, 3),
        log_dt in -2.0f64..0.0,
    ) {
        let mut state = seed | 1;
        let mut r = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let sys = System::random(&mut r);
        let dt = 10f64.powf(log_dt);
        let u0: V = std::array::from_fn(|_| r() - 0.5);
        let v0: V = std::array::from_fn(|_| r() - 0.5);
        for s in library() {
            let id = Identity::derive(&s).unwrap_or_else(|e| panic!("{}: {e:?}", s.name));
            // Params inside their ranges (open ends kept out).
            let params: Vec<f64> = s
                .params
                .iter()
                .zip(&along)
                .map(|(p, f)| match p.range {
                    Some(r) if r.lo.is_finite() && r.hi.is_finite() => r.lo + (r.hi - r.lo) * (0.02 + 0.96 * f),
                    _ => p.default,
                })
                .collect();
            // An explicit scheme (one that claims a stability limit) well inside it.
            let mut dt = if s.claims.iter().any(|(c, _)| c == "cfl") { dt.min(0.02) } else { dt };
            // A step Newton cannot solve (the contact's branches) is made smaller.
            let steps = loop {
                match run(&s, &sys, &params, dt, u0, v0, 6) {
                    Some(steps) => break steps,
                    None if dt > 1e-3 => dt /= 4.0,
                    None => panic!("{}: Newton fails at dt = {dt}", s.name),
                }
            };
            let d_nonnegative = id.dissipation.squares.iter().all(|q| q.coef.eval(&params, 1.0, 0.0) >= 0.0);
            for n in 1..5 {
                let (gap, scale, d) = closure(&s, &id, &sys, &params, dt, &steps, n);
                prop_assert!(gap <= 1e-10 * (1.0 + scale), "{} at {params:?}, dt = {dt}: step {n} misses by {gap:e} (scale {scale:e})", s.name);
                if d_nonnegative {
                    prop_assert!(d >= -1e-12 * (1.0 + scale), "{}: D = {d:e} < 0", s.name);
                }
            }
        }
    }
}
