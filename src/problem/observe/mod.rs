//! What a problem measures: its series columns at every row (the initial state, each step, each
//! intermediate stage) and its summary keys over the rows. A column is an expression of
//! measured values (row values such as `energy`, earlier columns, reducers such as
//! `mean(u[1])`, functionals of the files in use such as `contact_energy(u)`), each measured
//! once per row and read by the column's compiled expression.

mod compile;
mod measure;
use compile::Compiling;
use measure::{over_rows, reference_at};

use super::ProblemFile;
use super::expr::{At, Exprs, PointFn};
use crate::compiler::check::problem::RowReducer as R;
use crate::compiler::ir::lower::Val;
use crate::compiler::syntax::ast::{Expr, ExprKind, Ident};
use crate::driver::FormsInUse;
use crate::error::CaseError;
use crate::runtime::fem::bound::{BoundForm, BoundFunctional, with_previous};
use crate::runtime::fem::evaluate::{FacetSample, facet_samples};
use crate::runtime::fem::mesh::Facet;
use crate::runtime::library::Binding;
use crate::simulation::{AxisMean, Operators, resultant};

/// What `density_*` reduces a functional's sampled integrand to.
#[derive(Clone, Copy)]
enum Density {
    Min,
    Max,
    Support,
}

/// One measured value of a row.
enum Measure {
    Time,
    Energy,
    Kinetic,
    Newton,
    ActivePoints,
    StatusKept,
    /// An earlier column.
    Column(usize),
    Mean {
        field: u8,
        weights: AxisMean,
    },
    NodalMean {
        field: u8,
        axis: usize,
        /// A body's nodes (all nodes: none).
        nodes: Option<Vec<bool>>,
    },
    AtMin {
        field: u8,
        axis: usize,
        node: usize,
        /// The node carries no mass (redistributed): its velocity is the step's mean one.
        massless: bool,
    },
    /// The resultant of slot form `slot`'s residual, over the dofs listed (all without a list).
    Force {
        slot: usize,
        dofs: Option<Vec<usize>>,
    },
    /// `work(SLOT)`: ½(r(uⁿ) + r(uⁿ⁺¹))·(uⁿ⁺¹ − uⁿ), slot form `slot`'s residual at the step's
    /// two ends, each with its own previous level.
    Work {
        slot: usize,
    },
    /// `measure(REGION, EXPR)`: the weight of the region's points where EXPR ≥ 0.
    Area {
        region: usize,
        f: PointFn,
    },
    /// `peak(REGION, EXPR)`: the largest EXPR over the region's points, and 0.
    Peak {
        region: usize,
        f: PointFn,
    },
    /// A functional of the files in use, at the states its arguments name.
    Functional {
        index: usize,
        at: Vec<Level>,
    },
    /// Functional `which` of the problem's reference.
    Reference {
        which: usize,
        mid: bool,
    },
    /// `density_min(F(u))`, `density_max(F(u))` or `density_support(F(u))`: the least or
    /// largest value of functional `index`'s integrand over its region's sample points, or the
    /// measure where it is not zero.
    Density {
        index: usize,
        of: Density,
    },
    /// `inner_mass(A, B)`: aᵀ M b with the scheme's mass, A and B evaluated at the nodes.
    InnerMass {
        a: PointFn,
        b: PointFn,
    },
    /// `cumulative(COLUMN)` (`sum`) or `initial(COLUMN)`: an earlier column over the series
    /// rows so far, kept in `value` from row to row (and rebuilt from the rows on a resume).
    OverRows {
        column: usize,
        sum: bool,
        value: std::cell::Cell<f64>,
    },
}

/// A row's state: what the measures read.
pub struct State<'a> {
    pub t: f64,
    pub u: &'a [f64],
    pub v: Option<&'a [f64]>,
    pub newton: usize,
    /// The displacement at the start of the step and the step (none at the initial row and at
    /// stages).
    pub before: Option<(&'a [f64], f64)>,
    /// The level a law's `prev` read at the step's start (none when no law reads one).
    pub before_previous: Option<&'a [f64]>,
    /// The level a contact law's `prev` reads at this row: the step's start (at a stage too),
    /// the initial state at the first row and in a static problem.
    pub previous: &'a [f64],
    /// An intermediate stage's row (not a row of the series).
    pub stage: bool,
}

impl<'a> State<'a> {
    /// A state at rest at `t`, on no step: no velocity, no Newton iteration.
    pub fn new(t: f64, u: &'a [f64], previous: &'a [f64]) -> State<'a> {
        State { t, u, v: None, newton: 0, before: None, before_previous: None, previous, stage: false }
    }
}

/// A state a functional argument names (the problem's `FUNCTIONAL_STATES`).
#[derive(Clone, Copy, PartialEq, Eq)]
enum Level {
    /// `u`: the row's displacement.
    Now,
    /// `u_mid`: the step's midpoint, at t − Δt/2.
    Mid,
    /// `u_prev`: the step's start.
    Start,
}

/// The problem's series, compiled for a bound run.
pub struct Observer<'m> {
    measures: Vec<Measure>,
    /// Per column: its name, whether series.csv shows it, its expression of the measures.
    columns: Vec<(String, bool, PointFn)>,
    /// The regions sampled by `measure` and `peak`, with their facets.
    regions: Vec<&'m [Facet]>,
    degree: u32,
    /// Slot forms the measures read, by name (`contact`: the active set).
    slots: Vec<(String, Box<dyn BoundForm + 'm>)>,
    /// The column each measure was added for.
    owner: Vec<usize>,
    reference: Option<crate::references::Bound>,
    /// The functionals the measures read, by name.
    functionals: Vec<(String, Box<dyn BoundFunctional + 'm>)>,
    /// Buffers a row reuses (a row's measures are small vectors: allocating them took a tenth
    /// of a 1D run).
    reuse: std::cell::RefCell<Reuse>,
    /// Columns measured only at the series rows where another column reaches a new maximum
    /// (NaN elsewhere): (the column, the other, its largest value so far).
    deferred: Vec<(usize, usize, std::cell::Cell<f64>)>,
    /// The last series row's active set (`status_kept` compares with it).
    last_switches: std::cell::RefCell<Option<Vec<bool>>>,
    /// The columns left out of this run, and why: they read a functional that no file in use
    /// provides (a user's law may have no `contact_trial`), or such a column.
    pub left_out: Vec<(String, String)>,
}

#[derive(Default)]
struct Reuse {
    measured: Vec<Vec<f64>>,
    spare: Vec<Vec<f64>>,
    scratch: Vec<f64>,
}

/// What the observer's columns are measured with: the operators, the forms and coefs in use,
/// the regions bound, the coefs' pointwise values and the facet rule's degree.
pub struct Sources<'s, 'm> {
    pub ops: &'s Operators<'m>,
    pub forms: &'s FormsInUse,
    pub coefs: &'s dyn Fn(&str) -> Option<crate::runtime::fem::kernel::Coef>,
    pub binding: &'s Binding<'m>,
    pub coef_vals: &'s [(String, Val)],
    pub degree: u32,
}

/// The placeholder name of measured value `id` in a rewritten expression.
pub(super) fn placeholder(id: usize) -> String {
    format!("#{id}")
}

impl<'m> Observer<'m> {
    pub fn new(
        pf: &ProblemFile,
        ex: &mut Exprs,
        src: &Sources<'_, 'm>,
        reference: Option<crate::references::Bound>,
    ) -> Result<Observer<'m>, CaseError> {
        let p = pf.problem();
        let mut inst = src.forms.instantiate(src.coefs, src.binding)?;
        let slots = inst.take_form("contact").map(|f| ("contact".to_string(), f)).into_iter().collect();
        let mut o = Observer {
            measures: Vec::new(),
            columns: Vec::new(),
            regions: Vec::new(),
            degree: src.degree,
            slots,
            owner: Vec::new(),
            reference,
            functionals: Vec::new(),
            reuse: Default::default(),
            deferred: Vec::new(),
            last_switches: Default::default(),
            left_out: Vec::new(),
        };
        let mut pointwise: Vec<(String, Val)> = vec![("u".into(), ex.field(0)), ("v".into(), ex.field(1))];
        pointwise.extend(src.coef_vals.iter().cloned());
        let (ops, binding) = (src.ops, src.binding);
        let mut c = Compiling { pf, ex, ops, inst, pointwise, binding, region_names: Vec::new() };
        for (d, written) in &p.series {
            let required = p.required.iter().any(|r| r.name == d.name.name);
            // A required column goes on, to the located error of the functional it lacks.
            if let Some(why) = o.unavailable(&d.value, &c.inst).filter(|_| !required) {
                o.left_out.push((d.name.name.clone(), why));
                continue;
            }
            let f = o.column(&mut c, &d.value)?;
            let column = o.columns.len();
            o.owner.resize(o.measures.len(), column);
            o.columns.push((d.name.name.clone(), *written, f));
        }
        Ok(o)
    }

    /// A column's expression as a function of its measures (which are added).
    fn column(&mut self, c: &mut Compiling<'_, '_, 'm>, e: &Expr) -> Result<PointFn, CaseError> {
        let mut leaves: Vec<(usize, usize)> = Vec::new();
        let rewritten = self.rewrite(c, e, &mut leaves)?;
        let scope: Vec<(String, Val)> =
            leaves.iter().map(|&(id, comps)| (placeholder(id), c.ex.measured(id, comps))).collect();
        let val = c.ex.lower(&rewritten, &scope).map_err(|d| c.pf.render(*d))?;
        let f = c.ex.function(&val, e).map_err(|d| c.pf.render(*d))?;
        if f.len() != 1 {
            let d = crate::compiler::Diagnostic::error(
                "E0301",
                "shape mismatch",
                e.span,
                "a column is a number: take a component",
            );
            return Err(c.pf.render(d));
        }
        Ok(f)
    }

    /// Every column's name (shown or not), in the order of a row's values.
    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.columns.iter().map(|c| c.0.as_str())
    }

    /// Which of a row's values series.csv shows.
    pub fn shown(&self) -> Vec<bool> {
        self.columns.iter().map(|c| c.1).collect()
    }

    /// Measures `column` only at the series rows where column `by` exceeds its values at every
    /// row before (NaN at the others): all `at_max(column, by)` reads of it, when nothing else
    /// reads it. Refused (false) when `column` is written, comes before `by`, or another column
    /// reads it.
    pub fn defer(&mut self, column: usize, by: usize) -> bool {
        let read = self.measures.iter().any(|m| matches!(m, Measure::Column(i) if *i == column));
        let ok = by < column && !self.columns.get(column).is_none_or(|c| c.1) && !read;
        if ok {
            self.deferred.push((column, by, std::cell::Cell::new(f64::NEG_INFINITY)));
        }
        ok
    }

    /// Takes up the rows a checkpoint kept, as though they had been measured here: the running
    /// values of `cumulative` and `initial`, the maxima `defer` compares with, and the last
    /// row's active set (`switches`, per row).
    pub fn resume(&self, rows: &[(f64, Vec<f64>)], switches: &[Vec<bool>]) {
        *self.last_switches.borrow_mut() = switches.last().cloned();
        for m in &self.measures {
            if let Measure::OverRows { column, sum, value } = m {
                let start = if *sum { 0.0 } else { f64::NAN };
                value.set(rows.iter().fold(start, |x, (_, row)| over_rows(*sum, x, row[*column])));
            }
        }
        for (_, by, best) in &self.deferred {
            best.set(rows.iter().map(|(_, r)| r[*by]).fold(f64::NEG_INFINITY, f64::max));
        }
    }

    /// The reference's figures of a state into `dir`, if the problem names one.
    pub fn write_reference(&self, dir: &std::path::Path, ops: &Operators, u: &[f64], t: f64) -> std::io::Result<()> {
        match &self.reference {
            Some((_, r)) => r.write(dir, &reference_at(ops, u, t)),
            None => Ok(()),
        }
    }

    /// Whether measure `m` was added for a column after column `c` (measures are added in
    /// column order, so a column's are measured just before it).
    fn belongs_after(&self, m: usize, c: usize) -> bool {
        self.owner.get(m).is_some_and(|&o| o > c)
    }
}
