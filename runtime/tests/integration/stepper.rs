//! The stepper through the runtime alone: Crank–Nicolson (Newmark β = ¼, γ = ½) written as the
//! data a compiled scheme provides (its description and coefficients, transcribed from
//! `signorini emit forms/schemes/newmark.wf`), stepping the oscillator ü + u = 0 built from a
//! hand-written form (one P1 element, ρ = 3, k = 1: M = K = 1 on the free dof). The scheme
//! conserves ½(v² + u²) to round-off and is second order against cos t. On 400 cells, the
//! steps after the first allocate no vector of the problem's size (issue 12), counted by an
//! allocator that records, per thread, allocations of at least a given size. With a penalty
//! obstacle that counts its evaluations: a steady form's active set is evaluated once a step,
//! a moving one's twice (the stage reuses the last set for the same arguments).

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use crate::common::MassStiffness;
use signorini_runtime::descriptors::{
    Borrowed, Combination, InitialDesc, Level, List, SchemeDesc, SlotUse, StageDesc, TermDesc, Text,
};
use signorini_runtime::fem::assembly::{Assembler, Quadrature};
use signorini_runtime::fem::bound::{Bound, BoundForm};
use signorini_runtime::fem::mesh::structured::interval;
use signorini_runtime::linalg::{Matrix, Structure};
use signorini_runtime::nonlinear::newton::NewtonOptions;
use signorini_runtime::nonlinear::statics::Constraints;
use signorini_runtime::time::scheme::TimeScheme;
use signorini_runtime::time::stepper::Stepper;

thread_local! {
    /// Allocations of at least `THRESHOLD` bytes on this thread since it was last reset.
    static LARGE: Cell<usize> = const { Cell::new(0) };
    static THRESHOLD: Cell<usize> = const { Cell::new(usize::MAX) };
}

struct Counting;

impl Counting {
    fn record(size: usize) {
        if size >= THRESHOLD.with(Cell::get) {
            LARGE.with(|c| c.set(c.get() + 1));
        }
    }
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        Self::record(layout.size());
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        Self::record(layout.size());
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        Self::record(new_size);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

struct CrankNicolson;

const U_NEW: Combination = Combination { unknown: Some(0), known: Borrowed(&[]) };
const A_NEW: Combination = Combination {
    unknown: Some(8),
    known: Borrowed(&[(Level::State(0), 9), (Level::State(1), 10), (Level::State(2), 11)]),
};

const MASS: SlotUse = SlotUse { name: Borrowed("mass"), fields: 1, declared: Borrowed("test:1:1") };
const STIFFNESS: SlotUse = SlotUse { name: Borrowed("stiffness"), fields: 1, declared: Borrowed("test:1:6") };

// The stage's parts the obstacle's scheme shares.
const STAGE_NAME: Text = Borrowed("stage1");
const QUANTITIES: List<Text> = Borrowed(&[Borrowed("u'"), Borrowed("v'"), Borrowed("a'")]);
const VALUES: List<Combination> = Borrowed(&[
    U_NEW,
    Combination {
        unknown: Some(4),
        known: Borrowed(&[(Level::State(0), 5), (Level::State(1), 6), (Level::State(2), 7)]),
    },
    A_NEW,
]);

const DESC: SchemeDesc = SchemeDesc {
    name: Borrowed("crank_nicolson"),
    uses: Borrowed(&[MASS, STIFFNESS]),
    states: Borrowed(&[Borrowed("u"), Borrowed("v"), Borrowed("a")]),
    initial: Some(InitialDesc {
        state: 2,
        terms: Borrowed(&[
            TermDesc { coef: 0, form: Borrowed("mass"), args: Borrowed(&[U_NEW]), time: 1 },
            TermDesc {
                coef: 0,
                form: Borrowed("stiffness"),
                args: Borrowed(&[Combination { unknown: None, known: Borrowed(&[(Level::State(0), 0)]) }]),
                time: 1,
            },
        ]),
    }),
    stages: Borrowed(&[StageDesc {
        name: STAGE_NAME,
        time: 3,
        quantities: QUANTITIES,
        values: VALUES,
        terms: Borrowed(&[
            TermDesc { coef: 0, form: Borrowed("mass"), args: Borrowed(&[A_NEW]), time: 3 },
            TermDesc { coef: 0, form: Borrowed("stiffness"), args: Borrowed(&[U_NEW]), time: 3 },
        ]),
    }]),
    updates: Borrowed(&[Level::Stage(0, 0), Level::Stage(0, 1), Level::Stage(0, 2)]),
    estimate: None,
    coefficients: 12,
};

impl TimeScheme for CrankNicolson {
    fn desc(&self) -> &SchemeDesc {
        &DESC
    }
    /// a' = (u' − u − Δt v − Δt²/4 a)·4/Δt², v' = v + Δt/2 (a + a'), as coefficients of u', u, v, a.
    fn coefficients(&self, dt: f64, t: f64, out: &mut [f64]) {
        let c = 4.0 / (dt * dt);
        out[..4].copy_from_slice(&[1.0, t, -1.0, t + dt]);
        // v' = 2/Δt u' − 2/Δt u − v + 0·a.
        out[4..8].copy_from_slice(&[0.5 * dt * c, -0.5 * dt * c, -1.0, 0.0]);
        out[8..12].copy_from_slice(&[c, -c, -dt * c, -1.0]);
    }
}

/// Crank–Nicolson on the oscillator's forms over `asm`'s mesh, its last dof fixed.
fn stepper<'a>(asm: &'a Assembler<'a>) -> Stepper<'a> {
    stepper_with(asm, Box::new(CrankNicolson), Vec::new())
}

/// `scheme` on the oscillator's forms and `more` over `asm`'s mesh, its last dof fixed.
fn stepper_with<'a>(
    asm: &'a Assembler<'a>,
    scheme: Box<dyn TimeScheme>,
    more: Vec<(&'static str, Box<dyn BoundForm>)>,
) -> Stepper<'a> {
    let bound = |rho, k| -> Box<dyn BoundForm> {
        Box::new(Bound {
            kernel: MassStiffness { rho, k },
            quadrature: Quadrature::default(),
            regions: Vec::new(),
            cells: None,
        })
    };
    let mut forms = vec![("mass", bound(3.0, 0.0)), ("stiffness", bound(0.0, 1.0))];
    forms.extend(more);
    let n = asm.size();
    let mut constraints = Constraints::none(n);
    constraints.fix(n - 1);
    Stepper::new(scheme, asm, forms, constraints, Structure::SymmetricPositiveDefinite, NewtonOptions::default())
        .unwrap()
}

/// A quarter cosine at rest on `cells` cells: u, v and a.
fn at_rest(cells: usize) -> Vec<Vec<f64>> {
    let n = cells + 1;
    let u0 = (0..n).map(|i| (std::f64::consts::FRAC_PI_2 * i as f64 / cells as f64).cos()).collect();
    vec![u0, vec![0.0; n], vec![0.0; n]]
}

fn run(dt: f64, t_end: f64) -> (f64, f64) {
    let mesh = interval(1, 0.0, 1.0);
    let asm = Assembler::new(&mesh);
    let mut stepper = stepper(&asm);
    let mut states = vec![vec![1.0, 0.0], vec![0.0; 2], vec![0.0; 2]];
    stepper.initialize(&mut states, 0.0).unwrap();
    assert!((states[2][0] + 1.0).abs() < 1e-14, "a(0) = −u(0)");
    let energy = |s: &[Vec<f64>]| 0.5 * (s[0][0] * s[0][0] + s[1][0] * s[1][0]);
    let steps = (t_end / dt).round() as usize;
    let mut drift = 0.0f64;
    for k in 0..steps {
        stepper.step(&mut states, k as f64 * dt, dt).unwrap();
        drift = drift.max((energy(&states) - 0.5).abs());
    }
    ((states[0][0] - t_end.cos()).abs(), drift)
}

#[test]
fn crank_nicolson_from_data_conserves_energy_and_is_second_order() {
    let (coarse, drift) = run(0.02, 10.0);
    let (fine, _) = run(0.01, 10.0);
    assert!(drift < 1e-13, "energy drift {drift:e}");
    let order = (coarse / fine).log2();
    assert!((order - 2.0).abs() < 0.05, "order {order} ({coarse:e}, {fine:e})");
}

#[test]
fn steps_after_the_first_allocate_no_vector_of_the_problems_size() {
    let cells = 400;
    let mesh = interval(cells, 0.0, 1.0);
    let asm = Assembler::new(&mesh);
    let mut stepper = stepper(&asm);
    let n = cells + 1;
    let mut states = at_rest(cells);
    stepper.initialize(&mut states, 0.0).unwrap();
    let dt = 1e-3;
    // The first steps factor the operator and fill the stepper's reusable vectors.
    for k in 0..3 {
        stepper.step(&mut states, k as f64 * dt, dt).unwrap();
    }
    // The initial problem and the stage share one symbolic analysis; each has its factor.
    let counters = stepper.counters();
    assert_eq!((counters.symbolic, counters.numeric), (1, 2));
    THRESHOLD.with(|t| t.set(8 * n));
    LARGE.with(|c| c.set(0));
    for k in 3..23 {
        stepper.step(&mut states, k as f64 * dt, dt).unwrap();
    }
    THRESHOLD.with(|t| t.set(usize::MAX));
    let large = LARGE.with(Cell::get);
    assert_eq!(large, 0, "{large} allocations of at least {} bytes in 20 steps", 8 * n);
    assert!(states[0].iter().all(|x| x.is_finite()));
}

#[test]
fn the_initial_problem_solves_again_after_the_stage_took_its_factor_storage() {
    let cells = 60;
    let mesh = interval(cells, 0.0, 1.0);
    let asm = Assembler::new(&mesh);
    let start = at_rest(cells);
    let dt = 1e-2;
    // A stepper initialized once and one initialized again after its steps (its initial problem
    // refactors, the stage keeps its factor) step alike, bit for bit.
    let (mut once, mut twice) = (stepper(&asm), stepper(&asm));
    let (mut a, mut b) = (start.clone(), start.clone());
    once.initialize(&mut a, 0.0).unwrap();
    twice.initialize(&mut b, 0.0).unwrap();
    let first = b[2].clone();
    for k in 0..3 {
        once.step(&mut a, k as f64 * dt, dt).unwrap();
        twice.step(&mut b, k as f64 * dt, dt).unwrap();
    }
    let mut again = start.clone();
    twice.initialize(&mut again, 0.0).unwrap();
    assert_eq!(again[2], first, "the initial acceleration, solved again");
    for k in 3..6 {
        once.step(&mut a, k as f64 * dt, dt).unwrap();
        twice.step(&mut b, k as f64 * dt, dt).unwrap();
    }
    assert_eq!(a, b);
    assert!(a[0] != start[0], "the states moved");
}

/// A penalty obstacle at dof 0, k·min(u₀ − g(t), 0), g(t) = −1 − t (far below the state, so
/// never active), counting its active-set evaluations; `moving` says whether it changes with
/// time (it does, through g, either way: a steady form's set must not depend on t).
struct Obstacle {
    k: f64,
    moving: bool,
    calls: std::rc::Rc<Cell<usize>>,
}

impl Obstacle {
    fn gap(&self, u: &[f64], t: f64) -> f64 {
        let g = if self.moving { -1.0 - t } else { -1.0 };
        u[0] - g
    }
}

impl BoundForm for Obstacle {
    fn name(&self) -> &str {
        "obstacle"
    }
    fn fields(&self) -> usize {
        1
    }
    fn linear(&self) -> bool {
        false
    }
    fn piecewise(&self) -> bool {
        true
    }
    fn residual(&self, _asm: &Assembler, fields: &[&[f64]], t: f64, out: &mut [f64]) {
        out[0] += self.k * self.gap(fields[0], t).min(0.0);
    }
    fn tangent(&self, _asm: &Assembler, fields: &[&[f64]], _wrt: usize, t: f64, m: &mut Matrix) {
        if self.gap(fields[0], t) < 0.0 {
            let p = &m.pattern;
            let at = p.col_ptr[0] + p.row_idx[p.col_ptr[0]..p.col_ptr[1]].binary_search(&0).unwrap();
            m.values[at] += self.k;
        }
    }
    fn switches(&self, _asm: &Assembler, fields: &[&[f64]], _wrt: usize, t: f64, out: &mut Vec<bool>) -> bool {
        self.calls.set(self.calls.get() + 1);
        out.push(self.gap(fields[0], t) < 0.0);
        true
    }
    fn support(&self) -> Option<Vec<u32>> {
        Some(vec![0])
    }
    fn time_dependent(&self) -> bool {
        self.moving
    }
}

const OBSTACLE_DESC: SchemeDesc = SchemeDesc {
    name: Borrowed("crank_nicolson_obstacle"),
    uses: Borrowed(&[
        MASS,
        STIFFNESS,
        SlotUse { name: Borrowed("obstacle"), fields: 1, declared: Borrowed("test:1:17") },
    ]),
    stages: Borrowed(&[StageDesc {
        name: STAGE_NAME,
        time: 3,
        quantities: QUANTITIES,
        values: VALUES,
        terms: Borrowed(&[
            TermDesc { coef: 0, form: Borrowed("mass"), args: Borrowed(&[A_NEW]), time: 3 },
            TermDesc { coef: 0, form: Borrowed("stiffness"), args: Borrowed(&[U_NEW]), time: 3 },
            TermDesc { coef: 0, form: Borrowed("obstacle"), args: Borrowed(&[U_NEW]), time: 3 },
        ]),
    }]),
    ..DESC
};

struct WithObstacle;

impl TimeScheme for WithObstacle {
    fn desc(&self) -> &SchemeDesc {
        &OBSTACLE_DESC
    }
    fn coefficients(&self, dt: f64, t: f64, out: &mut [f64]) {
        CrankNicolson.coefficients(dt, t, out);
    }
}

#[test]
fn a_steady_forms_active_set_is_evaluated_once_a_step_and_a_moving_ones_twice() {
    let cells = 20;
    let mesh = interval(cells, 0.0, 1.0);
    let asm = Assembler::new(&mesh);
    for moving in [false, true] {
        let calls = std::rc::Rc::new(Cell::new(0));
        let obstacle = Obstacle { k: 1e3, moving, calls: calls.clone() };
        let mut stepper = stepper_with(&asm, Box::new(WithObstacle), vec![("obstacle", Box::new(obstacle))]);
        let mut states = at_rest(cells);
        stepper.initialize(&mut states, 0.0).unwrap();
        let dt = 1e-2;
        stepper.step(&mut states, 0.0, dt).unwrap();
        let before = calls.get();
        let mut iterations = 0;
        for k in 1..11 {
            iterations += stepper.step(&mut states, k as f64 * dt, dt).unwrap().iterations();
        }
        assert_eq!(iterations, 10, "one Newton iteration a step (the obstacle is never reached)");
        // After each step's solve; and at its start only if the set may have moved with time
        // (the step starts at the last iterate, the same arguments).
        let per_step = if moving { 2 } else { 1 };
        assert_eq!(calls.get() - before, 10 * per_step, "moving {moving}");
    }
}
