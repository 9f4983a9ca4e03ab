//! A row's measures at a state, each column after its own: row values, reducers over the
//! mesh, slot forms' resultants and work, sampled regions, functionals and the reference.

use super::*;

/// What one row's measures share: its state, the columns measured so far, the active set, and
/// what several measures read but is computed once (the kinetic energy, a region's samples
/// and an expression's values on them, the step's midpoint).
struct RowState<'r, 'o> {
    s: &'r State<'r>,
    ops: &'r Operators<'o>,
    columns: Vec<f64>,
    switches: Vec<bool>,
    kinetic: Option<f64>,
    samples: Vec<Option<Vec<FacetSample>>>,
    samples_v: Vec<Option<Vec<FacetSample>>>,
    /// The values of each sampled expression, by region and expression.
    sampled: Vec<(usize, Vec<crate::compiler::ir::graph::NodeId>, Vec<f64>)>,
    /// The step's midpoint and its time, for `u_mid` (none without a step).
    mid: Option<Option<(Vec<f64>, f64)>>,
}

impl RowState<'_, '_> {
    fn kinetic(&mut self) -> f64 {
        *self.kinetic.get_or_insert_with(|| self.ops.kinetic(self.s.v))
    }

    fn field(&self, f: u8) -> Option<&[f64]> {
        if f == 0 { Some(self.s.u) } else { self.s.v }
    }

    fn midpoint(&mut self) -> Option<&(Vec<f64>, f64)> {
        let s = self.s;
        self.mid
            .get_or_insert_with(|| {
                let (before, dt) = s.before?;
                Some((before.iter().zip(s.u).map(|(a, b)| 0.5 * (a + b)).collect(), s.t - 0.5 * dt))
            })
            .as_ref()
    }
}

/// A measure's value, in a vector a row reuses (a row's measures are small vectors:
/// allocating them took a tenth of a 1D run).
fn one(spare: &mut Vec<Vec<f64>>, x: f64) -> Vec<f64> {
    let mut v = spare.pop().unwrap_or_default();
    v.clear();
    v.push(x);
    v
}

impl Observer<'_> {
    /// The row at a state: one value per column, and the `contact` slot's switch at each of
    /// its quadrature points (the active set; empty without the slot).
    pub fn row(&self, ops: &Operators, s: &State) -> (Vec<f64>, Vec<bool>) {
        let mut reuse = self.reuse.borrow_mut();
        let Reuse { measured, spare, scratch } = &mut *reuse;
        spare.append(measured);
        let none = || self.regions.iter().map(|_| None).collect();
        let mut r = RowState {
            s,
            ops,
            columns: Vec::with_capacity(self.columns.len()),
            switches: self.switches(ops, s),
            kinetic: None,
            samples: none(),
            samples_v: none(),
            sampled: Vec::new(),
            mid: None,
        };
        let mut next = 0;
        for (c, (_, _, f)) in self.columns.iter().enumerate() {
            let end = (next..self.measures.len()).find(|&m| self.belongs_after(m, c)).unwrap_or(self.measures.len());
            if self.passed_over(c, &r) {
                // Not a new maximum of `by`: its measures are left out (nothing else reads them).
                measured.extend((next..end).map(|_| one(spare, f64::NAN)));
                r.columns.push(f64::NAN);
            } else {
                for m in next..end {
                    let value = self.measure(&self.measures[m], &mut r, spare, scratch);
                    measured.push(value);
                }
                let mut out = [0.0];
                f.eval(&At { measured, ..At::default() }, &mut *scratch, &mut out);
                r.columns.push(out[0]);
            }
            next = end;
        }
        if !s.stage {
            *self.last_switches.borrow_mut() = Some(r.switches.clone());
        }
        (r.columns, r.switches)
    }

    /// The active set at the row's state.
    fn switches(&self, ops: &Operators, s: &State) -> Vec<bool> {
        let mut switches = Vec::new();
        if ops.probe.is_some() {
            // The run's contact slot (the energy guard asked the same step's already).
            switches = ops.contact_switches(s.u, s.previous, s.t);
        } else if let Some((_, probe)) = self.slots.iter().find(|(n, _)| n == "contact") {
            probe.switches(ops.asm, &with_previous(probe.previous(), &[s.u], s.previous), 0, s.t, &mut switches);
        }
        switches
    }

    /// Whether deferred column `c` is passed over at this row: its maximand is no new maximum.
    fn passed_over(&self, c: usize, r: &RowState) -> bool {
        let Some((_, by, best)) = self.deferred.iter().find(|(d, _, _)| *d == c) else { return false };
        if r.s.stage {
            return false;
        }
        let w = r.columns[*by];
        if w > best.get() {
            best.set(w);
            return false;
        }
        true
    }

    fn measure(&self, m: &Measure, r: &mut RowState, spare: &mut Vec<Vec<f64>>, scratch: &mut Vec<f64>) -> Vec<f64> {
        let (s, ops) = (r.s, r.ops);
        let mesh = ops.asm.mesh();
        let (d, n) = (mesh.dim(), ops.asm.size());
        let value = match m {
            Measure::Time => s.t,
            Measure::Energy => {
                let k = r.kinetic();
                ops.energy_with_kinetic(s.u, k)
            }
            Measure::Kinetic => r.kinetic(),
            Measure::Newton => s.newton as f64,
            Measure::ActivePoints => r.switches.iter().filter(|b| **b).count() as f64,
            Measure::StatusKept => f64::from(u8::from(self.last_switches.borrow().as_ref() == Some(&r.switches))),
            Measure::Column(i) => r.columns[*i],
            Measure::Mean { field, weights, .. } => r.field(*field).map_or(f64::NAN, |x| weights.of(x)),
            Measure::NodalMean { field, axis, nodes: None } => {
                r.field(*field).map_or(f64::NAN, |x| x.iter().skip(*axis).step_by(d).sum::<f64>() / (n / d) as f64)
            }
            Measure::NodalMean { field, axis, nodes: Some(nodes) } => r.field(*field).map_or(f64::NAN, |x| {
                let mine = x.iter().skip(*axis).step_by(d).zip(nodes).filter(|(_, m)| **m);
                let (sum, count) = mine.fold((0.0, 0usize), |(s, k), (v, _)| (s + v, k + 1));
                sum / count as f64
            }),
            Measure::AtMin { field: 1, axis, node, massless: true } if s.before.is_some() => {
                let (before, dt) = s.before.expect("a step");
                let i = d * node + axis;
                (s.u[i] - before[i]) / dt
            }
            Measure::AtMin { field, axis, node, .. } => r.field(*field).map_or(f64::NAN, |x| x[d * node + axis]),
            Measure::Force { slot, dofs } => return self.force(*slot, dofs.as_deref(), s, ops),
            Measure::Work { slot } => self.work(*slot, s, ops),
            Measure::Area { region, f } => self.sampled(*region, f, r, scratch, true),
            Measure::Peak { region, f } => self.sampled(*region, f, r, scratch, false),
            Measure::Functional { index, at } => self.functional_value(*index, at, r),
            Measure::Reference { which, mid } => self.reference_value(*which, *mid, r),
            Measure::Density { index, of } => {
                let rule = crate::runtime::fem::quadrature::sampling_rule(d - 1, if d == 3 { 8 } else { 16 });
                let points = self.functionals[*index].1.facet_point_values(ops.asm, &rule, &[s.u], s.t);
                match of {
                    Density::Min => points.iter().map(|p| p.value).fold(f64::INFINITY, f64::min),
                    Density::Max => points.iter().map(|p| p.value).fold(f64::NEG_INFINITY, f64::max),
                    Density::Support => points.iter().filter(|p| p.value != 0.0).map(|p| p.weight).sum(),
                }
            }
            Measure::OverRows { column, sum, value } => {
                // A stage is not a row of the series: it reads the value at its step's start.
                if !s.stage {
                    value.set(over_rows(*sum, value.get(), r.columns[*column]));
                }
                value.get()
            }
            Measure::InnerMass { a, b } => {
                let (a, b) = (nodal(a, s, ops, scratch), nodal(b, s, ops, scratch));
                Operators::quad(ops.scheme_mass(), &a, &b)
            }
        };
        one(spare, value)
    }

    /// The resultant of a slot form's residual over `dofs` (all without).
    fn force(&self, slot: usize, dofs: Option<&[usize]>, s: &State, ops: &Operators) -> Vec<f64> {
        let (asm, d) = (ops.asm, ops.asm.mesh().dim());
        let mut r = vec![0.0; asm.size()];
        let form = &self.slots[slot].1;
        form.residual(asm, &with_previous(form.previous(), &[s.u], s.previous), s.t, &mut r);
        match dofs {
            None => resultant(&r, d),
            Some(dofs) => (0..d).map(|k| -dofs.iter().filter(|&&i| i % d == k).map(|&i| r[i]).sum::<f64>()).collect(),
        }
    }

    /// A slot's work over the step: both ends' residuals summed, then applied to its motion.
    fn work(&self, slot: usize, s: &State, ops: &Operators) -> f64 {
        let asm = ops.asm;
        let form = &self.slots[slot].1;
        s.before.map_or(f64::NAN, |(before, dt)| {
            let mut r = vec![0.0; asm.size()];
            let start = s.before_previous.unwrap_or(before);
            form.residual(asm, &with_previous(form.previous(), &[before], start), s.t - dt, &mut r);
            form.residual(asm, &with_previous(form.previous(), &[s.u], s.previous), s.t, &mut r);
            0.5 * r.iter().zip(s.u.iter().zip(before)).map(|(r, (a, b))| r * (a - b)).sum::<f64>()
        })
    }

    /// `measure` (`area`) or `peak` of an expression over a region's sample points; the two
    /// share the expression's values.
    fn sampled(&self, region: usize, f: &PointFn, r: &mut RowState, scratch: &mut Vec<f64>, area: bool) -> f64 {
        let s = r.s;
        let mesh = r.ops.asm.mesh();
        let known = r.sampled.iter().position(|(g, k, _)| *g == region && *k == f.key);
        let at = match known {
            Some(i) => i,
            None => {
                let (facets, degree) = (self.regions[region], self.degree);
                let us = r.samples[region].get_or_insert_with(|| facet_samples(mesh, facets, degree, s.u));
                let vs = match (f.reads_v(), s.v) {
                    (true, Some(v)) => {
                        Some(&*r.samples_v[region].get_or_insert_with(|| facet_samples(mesh, facets, degree, v)))
                    }
                    _ => None,
                };
                let mut out = [0.0];
                let values: Vec<f64> = us
                    .iter()
                    .enumerate()
                    .map(|(i, p)| {
                        let v = vs.map_or(&[][..], |vs| vs[i].value.as_slice());
                        f.eval(&At { x: &p.x, t: s.t, u: &p.value, v, ..At::default() }, &mut *scratch, &mut out);
                        out[0]
                    })
                    .collect();
                r.sampled.push((region, f.key.clone(), values));
                r.sampled.len() - 1
            }
        };
        let values = &r.sampled[at].2;
        let us = r.samples[region].as_ref().expect("sampled with the values");
        match area {
            true => us.iter().zip(values).filter(|(_, e)| **e >= 0.0).map(|(p, _)| p.weight).sum(),
            false => values.iter().fold(0.0f64, |m, e| m.max(*e)),
        }
    }

    /// Functional `index` at the states `at` names (NaN where one is not defined on this row).
    fn functional_value(&self, index: usize, at: &[Level], r: &mut RowState) -> f64 {
        let (s, asm) = (r.s, r.ops.asm);
        let f = &self.functionals[index].1;
        let m = if at.contains(&Level::Mid) { r.midpoint() } else { None };
        let t = m.map_or(s.t, |(_, t)| *t);
        let states: Option<Vec<&[f64]>> = at
            .iter()
            .map(|a| match a {
                Level::Now => Some(s.u),
                Level::Mid => m.map(|(u, _)| u.as_slice()),
                Level::Start => s.before.map(|(b, _)| b),
            })
            .collect();
        states.map_or(f64::NAN, |x| f.value(asm, &x, t))
    }

    /// Functional `which` of the reference, at the row's state or the step's midpoint.
    fn reference_value(&self, which: usize, mid: bool, r: &mut RowState) -> f64 {
        let Some((_, reference)) = &self.reference else { return f64::NAN };
        let (ops, s) = (r.ops, r.s);
        match mid {
            false => reference.value(which, &reference_at(ops, s.u, s.t)),
            true => r.midpoint().map_or(f64::NAN, |(u, t)| reference.value(which, &reference_at(ops, u, *t))),
        }
    }
}

/// An expression's values at the nodes.
fn nodal(f: &PointFn, s: &State, ops: &Operators, scratch: &mut Vec<f64>) -> Vec<f64> {
    let mesh = ops.asm.mesh();
    let d = mesh.dim();
    let mut out = vec![0.0; ops.asm.size()];
    for (i, o) in out.chunks_mut(d).enumerate() {
        let u = &s.u[d * i..d * i + d];
        let v = s.v.map_or(&[][..], |v| &v[d * i..d * i + d]);
        f.eval(&At { x: mesh.node(i), t: s.t, u, v, ..At::default() }, scratch, o);
    }
    out
}

/// The running value of `cumulative` (`sum`) or `initial` after a row whose column reads `x`:
/// a sum leaves NaN out, `initial` keeps the first value.
pub(super) fn over_rows(sum: bool, running: f64, x: f64) -> f64 {
    match (sum, x.is_nan(), running.is_nan()) {
        (true, false, _) => running + x,
        (false, _, true) => x,
        _ => running,
    }
}

/// A state as a reference measures it.
pub(super) fn reference_at<'a>(ops: &'a Operators<'_>, u: &'a [f64], t: f64) -> crate::references::At<'a> {
    crate::references::At { asm: ops.asm, mass: ops.scheme_mass(), pressure: ops.contact_pressure.as_deref(), u, t }
}
