//! What a problem measures: its series columns at every row (the initial state, each step, each
//! intermediate stage) and its summary keys over the rows. A column is an expression of
//! measured values (row values such as `energy`, earlier columns, reducers such as
//! `mean(u[1])`, functionals of the files in use such as `contact_energy(u)`), each measured
//! once per row and read by the column's compiled expression.

mod compile;

use super::ProblemFile;
use super::expr::{At, Exprs, PointFn};
use crate::compiler::check::problem::RowReducer as R;
use crate::compiler::ir::lower::Val;
use crate::compiler::syntax::ast::{Expr, ExprKind, Ident};
use crate::driver::FormsInUse;
use crate::error::CaseError;
use crate::runtime::fem::assembly::Assembler;
use crate::runtime::fem::bound::{BoundForm, BoundFunctional, with_previous};
use crate::runtime::fem::evaluate::{FacetSample, facet_samples};
use crate::runtime::fem::mesh::Facet;
use crate::runtime::library::Binding;
use crate::simulation::{AxisMean, Operators, resultant};

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
    /// `density_min(F(u))` (`min`) or `density_support(F(u))`: the least value of functional
    /// `index`'s integrand over its region's sample points, or the measure where it is not zero.
    Density {
        index: usize,
        min: bool,
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

/// The placeholder name of measured value `id` in a rewritten expression.
pub(super) fn placeholder(id: usize) -> String {
    format!("#{id}")
}

impl<'m> Observer<'m> {
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        pf: &ProblemFile,
        ex: &mut Exprs,
        ops: &Operators<'m>,
        forms: &FormsInUse,
        coefs: &dyn Fn(&str) -> Option<crate::runtime::fem::kernel::Coef>,
        binding: &Binding<'m>,
        coef_vals: &[(String, Val)],
        degree: u32,
        reference: Option<crate::references::Bound>,
    ) -> Result<Observer<'m>, CaseError> {
        let p = pf.problem();
        let mut inst = forms.instantiate(coefs, binding)?;
        let slots = inst.take_form("contact").map(|f| ("contact".to_string(), f)).into_iter().collect();
        let mut o = Observer {
            measures: Vec::new(),
            columns: Vec::new(),
            regions: Vec::new(),
            degree,
            slots,
            owner: Vec::new(),
            reference,
            functionals: Vec::new(),
            reuse: Default::default(),
            deferred: Vec::new(),
            last_switches: Default::default(),
            left_out: Vec::new(),
        };
        let mut region_names: Vec<String> = Vec::new();
        let u = ex.field(0);
        let v = ex.field(1);
        let mut pointwise: Vec<(String, Val)> = vec![("u".into(), u), ("v".into(), v)];
        pointwise.extend(coef_vals.iter().cloned());
        for (d, written) in &p.series {
            let required = p.required.iter().any(|r| r.name == d.name.name);
            // A required column goes on, to the located error of the functional it lacks.
            if let Some(why) = o.unavailable(&d.value, &inst).filter(|_| !required) {
                o.left_out.push((d.name.name.clone(), why));
                continue;
            }
            let mut leaves: Vec<(usize, usize)> = Vec::new();
            let rewritten =
                o.rewrite(pf, ex, ops, &mut inst, &d.value, &mut leaves, &pointwise, &mut region_names, binding)?;
            let scope: Vec<(String, Val)> =
                leaves.iter().map(|&(id, comps)| (placeholder(id), ex.measured(id, comps))).collect();
            let val = ex.lower(&rewritten, &scope).map_err(|e| pf.render(*e))?;
            let f = ex.function(&val, &d.value).map_err(|e| pf.render(*e))?;
            if f.len() != 1 {
                return Err(pf.render(crate::compiler::Diagnostic::error(
                    "E0301",
                    "shape mismatch",
                    d.value.span,
                    "a column is a number: take a component",
                )));
            }
            let c = o.columns.len();
            o.owner.resize(o.measures.len(), c);
            o.columns.push((d.name.name.clone(), *written, f));
        }
        Ok(o)
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

    /// The row at a state: one value per column, and the `contact` slot's switch at each of
    /// its quadrature points (the active set; empty without the slot).
    pub fn row(&self, ops: &Operators, s: &State) -> (Vec<f64>, Vec<bool>) {
        let asm: &Assembler = ops.asm;
        let mesh = asm.mesh();
        let d = mesh.dim();
        let n = asm.size();
        let mut reuse = self.reuse.borrow_mut();
        let Reuse { measured, spare, scratch } = &mut *reuse;
        spare.append(measured);
        let mut one = |x: f64| {
            let mut v = spare.pop().unwrap_or_default();
            v.clear();
            v.push(x);
            v
        };
        let mut columns: Vec<f64> = Vec::with_capacity(self.columns.len());
        let mut samples: Vec<Option<Vec<FacetSample>>> = self.regions.iter().map(|_| None).collect();
        let mut samples_v: Vec<Option<Vec<FacetSample>>> = self.regions.iter().map(|_| None).collect();
        // The values of each sampled expression, by region and expression.
        let mut sampled: Vec<(usize, Vec<crate::compiler::ir::graph::NodeId>, Vec<f64>)> = Vec::new();
        let field = |f: u8| if f == 0 { Some(s.u) } else { s.v };
        let mut kinetic = None;
        let mut switches = Vec::new();
        // The step's midpoint, for the functionals at `u_mid` (none without a step).
        let mut mid: Option<Option<(Vec<f64>, f64)>> = None;
        let mut midpoint = || -> Option<(Vec<f64>, f64)> {
            let (before, dt) = s.before?;
            Some((before.iter().zip(s.u).map(|(a, b)| 0.5 * (a + b)).collect(), s.t - 0.5 * dt))
        };
        if ops.probe.is_some() {
            // The run's contact slot (the energy guard asked the same step's already).
            switches = ops.contact_switches(s.u, s.previous, s.t);
        } else if let Some((_, probe)) = self.slots.iter().find(|(n, _)| n == "contact") {
            probe.switches(asm, &with_previous(probe.previous(), &[s.u], s.previous), 0, s.t, &mut switches);
        }
        let mut next = 0;
        for (c, (_, _, f)) in self.columns.iter().enumerate() {
            if let Some((_, by, best)) = self.deferred.iter().find(|(d, _, _)| *d == c)
                && !s.stage
            {
                let w = columns[*by];
                if w > best.get() {
                    best.set(w);
                } else {
                    // Not a new maximum of `by`: its measures are left out (nothing else reads them).
                    while next < self.measures.len() && !self.belongs_after(next, c) {
                        measured.push(one(f64::NAN));
                        next += 1;
                    }
                    columns.push(f64::NAN);
                    continue;
                }
            }
            // The measures of this column (in the order they were added).
            while next < self.measures.len() && !self.belongs_after(next, c) {
                let value: Vec<f64> = match &self.measures[next] {
                    Measure::Time => one(s.t),
                    Measure::Energy => {
                        let k = *kinetic.get_or_insert_with(|| ops.kinetic(s.v));
                        one(ops.energy_with_kinetic(s.u, k))
                    }
                    Measure::Kinetic => one(*kinetic.get_or_insert_with(|| ops.kinetic(s.v))),
                    Measure::Newton => one(s.newton as f64),
                    Measure::ActivePoints => one(switches.iter().filter(|b| **b).count() as f64),
                    Measure::StatusKept => {
                        one(f64::from(u8::from(self.last_switches.borrow().as_ref() == Some(&switches))))
                    }
                    Measure::Column(i) => one(columns[*i]),
                    Measure::Mean { field: fi, weights, .. } => one(field(*fi).map_or(f64::NAN, |x| weights.of(x))),
                    Measure::NodalMean { field: fi, axis } => {
                        one(field(*fi)
                            .map_or(f64::NAN, |x| x.iter().skip(*axis).step_by(d).sum::<f64>() / (n / d) as f64))
                    }
                    Measure::AtMin { field: 1, axis, node, massless: true } if s.before.is_some() => {
                        let (before, dt) = s.before.expect("a step");
                        let i = d * node + axis;
                        one((s.u[i] - before[i]) / dt)
                    }
                    Measure::AtMin { field: fi, axis, node, .. } => {
                        one(field(*fi).map_or(f64::NAN, |x| x[d * node + axis]))
                    }
                    Measure::Force { slot, dofs } => {
                        let mut r = vec![0.0; n];
                        let form = &self.slots[*slot].1;
                        form.residual(asm, &with_previous(form.previous(), &[s.u], s.previous), s.t, &mut r);
                        match dofs {
                            None => resultant(&r, d),
                            Some(dofs) => (0..d)
                                .map(|k| -dofs.iter().filter(|&&i| i % d == k).map(|&i| r[i]).sum::<f64>())
                                .collect(),
                        }
                    }
                    Measure::Work { slot } => {
                        let form = &self.slots[*slot].1;
                        let value = s.before.map_or(f64::NAN, |(before, dt)| {
                            // Both ends' residuals summed, then applied to the step's motion.
                            let mut r = vec![0.0; n];
                            let start = s.before_previous.unwrap_or(before);
                            form.residual(asm, &with_previous(form.previous(), &[before], start), s.t - dt, &mut r);
                            form.residual(asm, &with_previous(form.previous(), &[s.u], s.previous), s.t, &mut r);
                            0.5 * r.iter().zip(s.u.iter().zip(before)).map(|(r, (a, b))| r * (a - b)).sum::<f64>()
                        });
                        one(value)
                    }
                    Measure::Area { region, f } | Measure::Peak { region, f } => {
                        // `measure` and `peak` of one expression share its values.
                        let cached = sampled.iter().find(|(r, k, _)| *r == *region && *k == f.key);
                        if let Some((_, _, values)) = cached {
                            let us = samples[*region].as_ref().expect("sampled with the values");
                            let value = if matches!(self.measures[next], Measure::Area { .. }) {
                                us.iter().zip(values).filter(|(_, e)| **e >= 0.0).map(|(p, _)| p.weight).sum()
                            } else {
                                values.iter().fold(0.0f64, |m, e| m.max(*e))
                            };
                            measured.push(one(value));
                            next += 1;
                            continue;
                        }
                        let us = samples[*region]
                            .get_or_insert_with(|| facet_samples(mesh, self.regions[*region], self.degree, s.u));
                        let vs = match (f.reads_v(), s.v) {
                            (true, Some(v)) => Some(
                                &*samples_v[*region]
                                    .get_or_insert_with(|| facet_samples(mesh, self.regions[*region], self.degree, v)),
                            ),
                            _ => None,
                        };
                        let mut out = [0.0];
                        let values: Vec<f64> = us
                            .iter()
                            .enumerate()
                            .map(|(i, p)| {
                                let v = vs.map_or(&[][..], |vs| vs[i].value.as_slice());
                                f.eval(
                                    &At { x: &p.x, t: s.t, u: &p.value, v, ..At::default() },
                                    &mut *scratch,
                                    &mut out,
                                );
                                out[0]
                            })
                            .collect();
                        let value = if matches!(self.measures[next], Measure::Area { .. }) {
                            one(us.iter().zip(&values).filter(|(_, e)| **e >= 0.0).map(|(p, _)| p.weight).sum())
                        } else {
                            one(values.iter().fold(0.0f64, |m, e| m.max(*e)))
                        };
                        sampled.push((*region, f.key.clone(), values));
                        value
                    }
                    Measure::Functional { index, at } => {
                        let f = &self.functionals[*index].1;
                        let m = if at.contains(&Level::Mid) {
                            mid.get_or_insert_with(&mut midpoint).as_ref()
                        } else {
                            None
                        };
                        let t = m.map_or(s.t, |(_, t)| *t);
                        let states: Option<Vec<&[f64]>> = at
                            .iter()
                            .map(|a| match a {
                                Level::Now => Some(s.u),
                                Level::Mid => m.map(|(u, _)| u.as_slice()),
                                Level::Start => s.before.map(|(b, _)| b),
                            })
                            .collect();
                        one(states.map_or(f64::NAN, |x| f.value(asm, &x, t)))
                    }
                    Measure::Reference { which, mid: false } => one(self
                        .reference
                        .as_ref()
                        .map_or(f64::NAN, |(_, r)| r.value(*which, &reference_at(ops, s.u, s.t)))),
                    Measure::Reference { which, mid: true } => one(mid
                        .get_or_insert_with(&mut midpoint)
                        .as_ref()
                        .zip(self.reference.as_ref().map(|(_, r)| r))
                        .map_or(f64::NAN, |((u, t), r)| r.value(*which, &reference_at(ops, u, *t)))),
                    Measure::Density { index, min } => {
                        let rule = crate::runtime::fem::quadrature::sampling_rule(d - 1, if d == 3 { 8 } else { 16 });
                        let points = self.functionals[*index].1.facet_point_values(asm, &rule, &[s.u], s.t);
                        one(if *min {
                            points.iter().map(|p| p.value).fold(f64::INFINITY, f64::min)
                        } else {
                            points.iter().filter(|p| p.value != 0.0).map(|p| p.weight).sum()
                        })
                    }
                    Measure::OverRows { column, sum, value } => {
                        // A stage is not a row of the series: it reads the value at its step's start.
                        if !s.stage {
                            value.set(over_rows(*sum, value.get(), columns[*column]));
                        }
                        one(value.get())
                    }
                    Measure::InnerMass { a, b } => {
                        let nodal = |f: &PointFn, scratch: &mut Vec<f64>| {
                            let mut out = vec![0.0; n];
                            for (i, o) in out.chunks_mut(d).enumerate() {
                                let u = &s.u[d * i..d * i + d];
                                let v = s.v.map_or(&[][..], |v| &v[d * i..d * i + d]);
                                f.eval(&At { x: mesh.node(i), t: s.t, u, v, ..At::default() }, scratch, o);
                            }
                            out
                        };
                        let (a, b) = (nodal(a, &mut *scratch), nodal(b, &mut *scratch));
                        one(Operators::quad(ops.scheme_mass(), &a, &b))
                    }
                };
                measured.push(value);
                next += 1;
            }
            let mut out = [0.0];
            f.eval(&At { measured, ..At::default() }, &mut *scratch, &mut out);
            columns.push(out[0]);
        }
        if !s.stage {
            *self.last_switches.borrow_mut() = Some(switches.clone());
        }
        (columns, switches)
    }

    /// Whether measure `m` was added for a column after column `c` (measures are added in
    /// column order, so a column's are measured just before it).
    fn belongs_after(&self, m: usize, c: usize) -> bool {
        self.owner.get(m).is_some_and(|&o| o > c)
    }
}

/// The running value of `cumulative` (`sum`) or `initial` after a row whose column reads `x`:
/// a sum leaves NaN out, `initial` keeps the first value.
fn over_rows(sum: bool, running: f64, x: f64) -> f64 {
    match (sum, x.is_nan(), running.is_nan()) {
        (true, false, _) => running + x,
        (false, _, true) => x,
        _ => running,
    }
}

/// A state as a reference measures it.
fn reference_at<'a>(ops: &'a Operators<'_>, u: &'a [f64], t: f64) -> crate::references::At<'a> {
    crate::references::At { asm: ops.asm, mass: ops.scheme_mass(), pressure: ops.contact_pressure.as_deref(), u, t }
}
