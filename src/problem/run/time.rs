//! A time run: the settled or given start, the rows a checkpoint kept, then the steps, each
//! measured (and each intermediate stage of a multi-stage scheme) and written as it is taken.

use std::cell::RefCell;

use super::{Bound, Request, Rows, Stepped, row};
use crate::checkpoint::Control;
use crate::error::CaseError;
use crate::problem::observe::{Observer, State};
use crate::problem::resume::Record;
use crate::runtime::fem::mesh::Mesh;
use crate::runtime::time::scheme::StageView;
use crate::simulation::adaptive::Interval;
use crate::simulation::{Operators, Simulation, Snapshots, Span, Step, Watch};

/// The initial fields a time run starts from.
pub(super) struct Start<'a> {
    pub u0: Vec<f64>,
    pub v0: Vec<f64>,
    pub mesh: &'a Mesh,
}

pub(super) fn run(
    req: &Request,
    sim: &mut Simulation,
    bound: &Bound,
    observer: &Observer,
    snapshots: &mut Snapshots,
    control: &mut Control,
    start: Start,
) -> Result<Stepped, CaseError> {
    let columns: Vec<String> = observer.names().map(str::to_string).collect();
    let watch = req.watcher.map(|w| (w, columns.as_slice()));
    let (t0, dt) = (req.times.t_start, req.times.dt);
    let u0 = settle(req, sim, bound, &start)?;
    sim.initialize_at(t0, u0, start.v0)?;
    let mut rows = Rows::default();
    let stages = RefCell::new(Vec::new());
    match control.observer() {
        Some(records) => resume(records, sim, observer, snapshots, &mut rows, &stages)?,
        None => {
            let u0 = &sim.states[0];
            let first = State { v: sim.velocity(), ..State::new(t0, u0, u0) };
            let (values, switches) = row(observer, &sim.ops, first);
            show(watch, &values, req.times.t_end);
            rows = Rows { series: vec![values], switches: vec![switches], iterations: vec![0], ..Rows::default() };
            let v = velocity(&sim.states, sim.v_index, &sim.states[0], dt);
            snapshots.write(&sim.ops, 0, t0, &sim.states[0], &v)?;
        }
    }
    let steps = ((req.times.t_end - t0) / dt).round() as usize;
    let names = sim.stepper.desc().states.clone();
    let v_index = sim.v_index;
    let mut on_stage = |ops: &Operators, stage: &StageView, v_index: Option<usize>, start: &[f64]| {
        if let Some(u) = stage.value_of(&names[0]) {
            let v = v_index.and_then(|i| stage.value_of(&names[i]));
            let state = State { v, stage: true, ..State::new(stage.time, u, start) };
            let ((t, values), _) = row(observer, ops, state);
            stages.borrow_mut().push((stage.name.to_string(), t, values));
        }
    };
    // A fresh run's first record holds its initial row and snapshot; a resumed run's, what
    // came after the checkpoint.
    let mut saved = match control.observer() {
        Some(_) => Saved::of(&rows, &stages.borrow(), snapshots),
        None => Saved { rows: 0, stages: 0, snapshots: 0 },
    };
    let mut on_step = |ops: &Operators, step: &Step, record: Option<&mut Vec<u8>>| {
        let state = State {
            t: step.t,
            u: &step.states[0],
            v: v_index.map(|i| step.states[i].as_slice()),
            newton: step.report.iterations(),
            before: Some((step.before, step.dt)),
            before_previous: step.previous,
            previous: step.before,
            stage: false,
        };
        let (values, active) = row(observer, ops, state);
        show(watch, &values, req.times.t_end);
        rows.series.push(values);
        rows.switches.push(active);
        rows.iterations.push(step.report.iterations());
        rows.newton.push(step.report.clone());
        let v = velocity(step.states, v_index, step.before, step.dt);
        snapshots.write(ops, step.k, step.t, &step.states[0], &v)?;
        if let Some(record) = record {
            *record = saved.record(&rows, &stages.borrow(), snapshots)?;
        }
        Ok(())
    };
    let watch = Watch { stage: &mut on_stage, step: &mut on_step };
    let progress = req.opts.progress && req.writes;
    let outcome = match req.times.adaptive {
        Some(adaptive) => {
            let span = Interval { t0, t_end: req.times.t_end, dt };
            sim.run_adaptive(span, adaptive, progress, control, watch)?
        }
        None => sim.run(Span { t0, dt, steps }, progress, control, watch)?,
    };
    let steps = outcome.adaptive.as_ref().map_or(steps, |s| s.accepted);
    rows.stages = stages.into_inner();
    let last = (rows.series.last().map_or(t0, |r| r.0), sim.states[0].clone(), sim.velocity().map(<[f64]>::to_vec));
    let search = sim.stepper.search_cost();
    Ok(Stepped { rows, outcome, counters: sim.stepper.counters(), steps, last, search })
}

/// Shows a row to the watcher, if any; one that says stop asks the run to stop after the step.
fn show(watch: Option<(&super::Watcher, &[String])>, (t, values): &(f64, Vec<f64>), t_end: f64) {
    if let Some((watcher, columns)) = watch
        && !watcher(&super::Seen { t: *t, columns, values, t_end })
    {
        crate::interrupt::request();
    }
}

/// The displacement the run starts from: u₀, or with `initial u = settled(GUESS)` the static
/// equilibrium from it.
fn settle(req: &Request, sim: &Simulation, bound: &Bound, start: &Start) -> Result<Vec<f64>, CaseError> {
    let (pf, t0) = (req.pf, req.times.t_start);
    if !crate::problem::bind::settled(pf) {
        return Ok(start.u0.clone());
    }
    let held_nonzero = bound.held.is_some_and(|h| !h.zero_at(start.mesh, t0));
    let contact = crate::problem::settle::contact(pf, bound.contact, !bound.pairs.is_empty(), held_nonzero)?;
    let problem = bound.statics(contact, req.opts, t0);
    crate::problem::settle::settle(pf, sim.ops.asm, problem, req.in_use, start.u0.clone())
}

/// A scheme without a velocity state: the step's mean velocity.
fn velocity(states: &[Vec<f64>], v_index: Option<usize>, before: &[f64], dt: f64) -> Vec<f64> {
    match v_index {
        Some(i) => states[i].clone(),
        None => states[0].iter().zip(before).map(|(a, b)| (a - b) / dt).collect(),
    }
}

/// Takes up the rows, stages and snapshots the checkpoint's records kept.
fn resume(
    records: &[Vec<u8>],
    sim: &Simulation,
    observer: &Observer,
    snapshots: &mut Snapshots,
    rows: &mut Rows,
    stages: &RefCell<Vec<(String, f64, Vec<f64>)>>,
) -> Result<(), CaseError> {
    let known = &sim.stepper.desc().stages;
    for bytes in records {
        let record: Record = postcard::from_bytes(bytes)
            .map_err(|e| CaseError::Option(format!("the checkpoint's record of the run is damaged ({e})")))?;
        rows.series.extend(record.series);
        rows.iterations.extend(record.iterations);
        rows.switches.extend(record.switches);
        for (stage, t, values) in record.stages {
            if !known.iter().any(|s| s.name == stage) {
                return Err(CaseError::Option(format!(
                    "the checkpoint has a stage `{stage}`, which this scheme has not"
                )));
            }
            stages.borrow_mut().push((stage, t, values));
        }
        snapshots.extend_written(record.snapshots);
    }
    observer.resume(&rows.series, &rows.switches);
    Ok(())
}

/// How much of the rows, stages and snapshots the checkpoints so far hold: each checkpoint
/// records what came after the one before.
struct Saved {
    rows: usize,
    stages: usize,
    snapshots: usize,
}

impl Saved {
    fn of(rows: &Rows, stages: &[(String, f64, Vec<f64>)], snapshots: &Snapshots) -> Saved {
        Saved { rows: rows.series.len(), stages: stages.len(), snapshots: snapshots.written().len() }
    }

    /// The record of what came since the last checkpoint, which it then holds.
    fn record(
        &mut self,
        rows: &Rows,
        stages: &[(String, f64, Vec<f64>)],
        snapshots: &Snapshots,
    ) -> Result<Vec<u8>, CaseError> {
        let bytes = postcard::to_stdvec(&Record {
            series: rows.series[self.rows..].to_vec(),
            iterations: rows.iterations[self.rows..].to_vec(),
            switches: rows.switches[self.rows..].to_vec(),
            stages: stages[self.stages..].to_vec(),
            snapshots: snapshots.written()[self.snapshots..].to_vec(),
        })
        .map_err(|e| CaseError::Option(format!("cannot encode the checkpoint: {e}")))?;
        *self = Saved::of(rows, stages, snapshots);
        Ok(bytes)
    }
}
