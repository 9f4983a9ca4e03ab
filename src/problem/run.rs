//! The one loop every problem runs through: bind the problem (mesh, regions, coefs) and the
//! files in use (scheme, laws, params), initialize, step with cuts and the energy watch, measure
//! every row, checkpoint, then write series.csv, stages.csv, summary.json, the figure and the
//! VTU collection. Nothing in it names a problem.

use std::cell::RefCell;
use std::time::Instant;

use super::ProblemFile;
use super::bind::coef_shapes;
pub use super::check::{check, params_in_use};
use super::dirichlet::dirichlet;
use super::expr::Exprs;
use super::observe::{Observer, State};
use super::options::Times;
pub use super::options::{Chosen, Options};
pub use super::outputs::Run;
use super::outputs::{Summary, all_params, json, write_outputs};
use super::reference::bound_reference;
use super::resolve::bound;
use super::resume::{Record, identity};
use super::summary::SummaryKeys;
use crate::checkpoint::Control;
use crate::driver::FilesInUse;
use crate::error::CaseError;
use crate::runtime::fem::assembly::{Assembler, Quadrature};
use crate::runtime::library::Binding;
use crate::runtime::linalg::pattern::Owners;
use crate::simulation::{Problem, Simulation, Snapshots};

pub fn run(opts: &Options) -> Result<Run, CaseError> {
    if let Some(options) = &opts.petsc_options {
        crate::runtime::linalg::set_petsc_options(options).map_err(|e| CaseError::Option(e.to_string()))?;
    }
    bound(opts, |pf, params, ex, in_use| {
        if pf.problem().run_static.is_some() {
            if opts.dt.is_some() || opts.t_end.is_some() || opts.t_start.is_some() {
                return Err(CaseError::Option(format!(
                    "{} is static (`run static`): it takes no --dt, --t-end or --t-start",
                    pf.file
                )));
            }
            let times = Times { dt: f64::NAN, t_start: 0.0, t_end: 0.0 };
            return simulate(opts, pf, params, ex, in_use, &times);
        }
        let given = super::bind::settings(pf, ex, &pf.problem().run)?;
        let setting = |name: &str, over: Option<f64>, default: f64| {
            over.or_else(|| given.iter().find(|(n, _)| n == name).map(|(_, v)| *v)).unwrap_or(default)
        };
        let times = Times {
            dt: setting("dt", opts.dt, f64::NAN),
            t_start: setting("t_start", opts.t_start, 0.0),
            t_end: setting("t_end", opts.t_end, f64::NAN),
        };
        let positive = |x: f64| x > 0.0 && x.is_finite();
        if !positive(times.dt) || !positive(times.t_end) || times.t_end / times.dt > 1e7 {
            return Err(CaseError::Option(
                "--dt and --t-end (or the problem's `run dt = ..., t_end = ...`) must be positive, with at most 10⁷ steps"
                    .into(),
            ));
        }
        if !(times.t_start >= 0.0 && times.t_start < times.t_end) {
            return Err(CaseError::Option(format!("--t-start must be in [0, t_end), not {}", times.t_start)));
        }
        simulate(opts, pf, params, ex, in_use, &times)
    })
}

fn simulate(
    opts: &Options,
    pf: &ProblemFile,
    params: &[super::ProblemParam],
    ex: &mut Exprs,
    in_use: &FilesInUse,
    times: &Times,
) -> Result<Run, CaseError> {
    let start = Instant::now();
    let p = pf.problem();
    let (mesh, mesh_label) = super::bind::mesh(pf, ex, opts.mesh.as_deref(), opts.cell_size)?;
    // Under mpirun each process assembles the cells around the nodes it owns, where it can.
    let ownership = match split(opts, pf, in_use)? {
        true => crate::runtime::linalg::ownership::Ownership::of(&mesh).map_err(mpi)?,
        false => None,
    };
    // Every process integrates over the problem's regions whole (the contact law's among them).
    let whole: Vec<&str> =
        pf.problem().regions.iter().map(|r| r.name.name.as_str()).chain(contact_region(pf)).collect();
    let part = ownership.as_ref().map(|o| mesh.part(o.owners(), o.rank() as u32, &whole));
    let asm = match (&part, &ownership) {
        (Some((local, owned)), Some(o)) => {
            let (cells, rank) = (local.num_cells(), o.rank());
            tracing::info!(rank, owned, cells, whole = mesh.num_cells(), "this process's part of the mesh");
            Assembler::split(local, o.clone(), *owned)
        }
        _ => Assembler::new(&mesh),
    };
    let n = asm.size();
    // Collective in a split run: counted now, while every process runs the same code (rank 0
    // alone may stop early, on a failed write).
    let matrix_nnz = matrix_nnz(&asm)?;
    let quad = super::bind::settings(pf, ex, &p.quadrature)?;
    let max = crate::compiler::ir::MAX_DEGREE as f64;
    let degree = |name: &str| -> Result<Option<u32>, CaseError> {
        match quad.iter().find(|(n, _)| n == name) {
            None => Ok(None),
            Some((_, v)) if (1.0..=max).contains(v) && v.fract() == 0.0 => Ok(Some(*v as u32)),
            Some((_, v)) => Err(CaseError::Option(format!(
                "{}: quadrature {name} = {v}: a degree is a whole number in [1, {max}]",
                pf.file
            ))),
        }
    };
    let quadrature = Quadrature { cell: degree("cell")?, facet: degree("facet")? };
    let coef_fns = super::bind::coefs(pf, ex)?;
    coef_shapes(pf, in_use, &coef_fns, mesh.dim())?;
    let lookup = super::bind::coef_lookup(&coef_fns);
    // Without contact, the coefs only the contact law reads are zero (it integrates over no facet).
    let zeros: Vec<(String, usize)> = if super::bind::contact_free(pf) {
        let law = &in_use.forms.units[in_use.forms.contact];
        law.coefs().into_iter().map(|(name, rank)| (name, mesh.dim().pow(rank))).collect()
    } else {
        Vec::new()
    };
    let coefs = |name: &str| {
        lookup(name).or_else(|| {
            let (_, len) = zeros.iter().find(|(n, _)| n == name)?;
            Some(crate::runtime::fem::kernel::Coef::constant(vec![0.0; *len]))
        })
    };
    let contact = super::bind::CONTACT;
    let contact_region = contact_region(pf);
    let others: Vec<String> = p.regions.iter().map(|r| r.name.name.clone()).filter(|r| r != contact).collect();
    let (constraints, held) = dirichlet(pf, ex, &mesh)?;
    let problem = Problem {
        coefs: &coefs,
        quadrature,
        contact: contact_region,
        regions: &others,
        constraints: constraints.clone(),
        prescribed: held.as_ref().map(|h| h.prescribed(&mesh)),
        mass: opts.mass,
        newton: opts.newton,
    };
    // In a run of several processes each holds the whole state and takes the same steps; rank 0
    // writes the results, and the checkpoints with the others' parts in a split run (any
    // number of processes resumes them). Collective.
    let shared = shared_dir(opts.out.as_ref())?;
    let mut control = Control::new(
        opts.checkpoint_every,
        shared.clone(),
        identity(opts, pf, params, in_use, &mesh, times),
        opts.resume,
        ownership.clone(),
    )?;
    let writes = crate::runtime::linalg::ranks::writes();
    let out = if writes { opts.out.clone() } else { None };
    // A static problem is one equilibrium, from u₀ (no initial acceleration to solve for): it
    // binds the operators, and no stepper.
    let statics = p.run_static.is_some();
    if statics && held.is_some() {
        return Err(CaseError::Option(format!(
            "{}: a static problem holds its Dirichlet values at zero (a nonzero held value needs a time run)",
            pf.file
        )));
    }
    let mut runner = if statics {
        Runner::Static(Box::new(crate::simulation::Operators::bind(&asm, problem, in_use)?))
    } else {
        Runner::Time(Box::new(Simulation::new(&asm, problem, in_use)?))
    };
    let t0 = times.t_start;
    // The initial fields take the held values on the held dofs.
    let mut u0 = super::bind::initial(pf, ex, &mesh, "u", t0)?;
    let mut v0 = super::bind::initial(pf, ex, &mesh, "v", t0)?;
    constraints.impose(&mut u0);
    constraints.zero(&mut v0);
    if let Some(h) = &held {
        h.initial(&mesh, t0, &mut u0, &mut v0);
    }
    let mut regions = vec![(contact.to_string(), runner.ops().contact_facets)];
    for name in &others {
        regions.push((name.clone(), asm.region(name)?));
    }
    let binding = Binding { quadrature, regions, dim: mesh.dim() };
    let coef_vals = super::bind::coef_vals(pf, ex)?;
    let reference = bound_reference(pf, ex, in_use, asm.mesh(), runner.ops().contact_facets, t0)?;
    let mut observer = Observer::new(
        pf,
        ex,
        runner.ops(),
        &in_use.forms,
        &coefs,
        &binding,
        &coef_vals,
        quadrature.facet.unwrap_or(7),
        reference,
    )?;
    let columns: Vec<String> = observer.names().map(str::to_string).collect();
    let shown = observer.shown();
    let applies = super::summary::applies(pf, ex, &in_use.forms.params)?;
    let absent: Vec<String> = observer.left_out.iter().map(|(c, _)| c.clone()).collect();
    let summary_fns = SummaryKeys::new(pf, ex, &columns, applies, &absent)?;
    for (what, list) in [("series", &observer.left_out), ("summary key", &summary_fns.left_out)] {
        for (name, why) in list {
            eprintln!("note: {what} `{name}` is left out of this run: {why}");
        }
    }
    // A column only `at_max` reads (not written, plotted or read by another column or key) is
    // measured only where its maximand reaches a new maximum: the contact radius at the peak
    // force samples the pressure at those rows, not at every step.
    for (column, by) in summary_fns.at_max_columns(&columns) {
        if !p.plots.iter().flat_map(|pl| &pl.columns).any(|c| c.name == columns[column]) {
            observer.defer(column, by);
        }
    }
    let row = |ops: &crate::simulation::Operators, state: State| {
        let t = state.t;
        let (values, switches) = observer.row(ops, &state);
        ((t, values), switches)
    };
    let name = pf.name().to_string();
    // Every process of a split run writes its piece of each snapshot, into rank 0's directory.
    let pieces = match &ownership {
        Some(_) => shared.clone(),
        None => out.clone(),
    };
    let mut snapshots = Snapshots::new(pieces.as_ref(), opts.vtu_every, &name);
    let (series, switches, iterations, stage_rows, outcome, counters, steps, last) = match &mut runner {
        Runner::Static(ops) => {
            // One equilibrium by the static driver: its single row is the solution.
            let contact = contact_region.ok_or_else(|| {
                CaseError::Option(format!(
                    "{}: a static problem needs its contact (an obstacle, or `Gamma_C`)",
                    pf.file
                ))
            })?;
            let clock = Instant::now();
            let problem = crate::simulation::statics::StaticProblem {
                coefs: &coefs,
                contact,
                regions: &others,
                contact_degree: quadrature.facet,
                constraints: constraints.clone(),
                newton: opts.newton,
                t: t0,
            };
            // The level a law's `prev` reads: the state the equilibrium is sought from.
            let initial = u0.clone();
            let solution = crate::simulation::statics::solve(&asm, problem, &in_use.forms, u0)?;
            let seconds = clock.elapsed().as_secs_f64();
            let newton = solution.newton.iterations();
            let (row, switches) = row(
                ops,
                State {
                    t: t0,
                    u: &solution.u,
                    v: None,
                    newton,
                    before: None,
                    before_previous: None,
                    previous: &initial,
                    stage: false,
                },
            );
            snapshots.write(ops, 0, t0, &solution.u, &vec![0.0; n])?;
            let outcome = crate::simulation::Outcome {
                step_seconds: vec![seconds],
                cuts: 0,
                stopped: None,
                resumed: None,
                energy_growth: 0.0,
            };
            let last = (t0, solution.u);
            (vec![row], vec![switches], vec![newton], Vec::new(), outcome, solution.counters, 0, last)
        }
        Runner::Time(sim) => {
            let u0 = if super::bind::settled(pf) {
                let held_nonzero = held.as_ref().is_some_and(|h| !h.zero_at(&mesh, t0));
                let problem = crate::simulation::statics::StaticProblem {
                    coefs: &coefs,
                    contact: super::settle::contact(pf, contact_region, held_nonzero)?,
                    regions: &others,
                    contact_degree: quadrature.facet,
                    constraints: constraints.clone(),
                    newton: opts.newton,
                    t: t0,
                };
                super::settle::settle(pf, &asm, problem, in_use, u0)?
            } else {
                u0
            };
            sim.initialize_at(t0, u0, v0)?;
            let u0 = &sim.states[0];
            let first = State {
                t: t0,
                u: u0,
                v: sim.velocity(),
                newton: 0,
                before: None,
                before_previous: None,
                previous: u0,
                stage: false,
            };
            let (first, first_switches) = row(&sim.ops, first);
            let mut series = vec![first];
            let mut switches = vec![first_switches];
            // Newton iterations of each row's step (0 for the initial state).
            let mut iterations: Vec<usize> = vec![0];
            let steps = ((times.t_end - t0) / times.dt).round() as usize;
            // A scheme without a velocity state: the step's mean velocity.
            let velocity = |states: &[Vec<f64>], v_index: Option<usize>, before: &[f64], dt: f64| -> Vec<f64> {
                match v_index {
                    Some(i) => states[i].clone(),
                    None => states[0].iter().zip(before).map(|(a, b)| (a - b) / dt).collect(),
                }
            };
            let v_index = sim.v_index;
            let stage_rows: RefCell<Vec<(String, f64, Vec<f64>)>> = RefCell::new(Vec::new());
            let (mut saved_rows, mut saved_stages, mut saved_snapshots) = (0, 0, 0);
            match control.observer() {
                Some(records) => {
                    let stages = &sim.stepper.desc().stages;
                    series.clear();
                    iterations.clear();
                    switches.clear();
                    for bytes in records {
                        let record: Record = postcard::from_bytes(bytes).map_err(|e| {
                            CaseError::Option(format!("the checkpoint's record of the run is damaged ({e})"))
                        })?;
                        series.extend(record.series);
                        iterations.extend(record.iterations);
                        switches.extend(record.switches);
                        for (stage, t, values) in record.stages {
                            if !stages.iter().any(|s| s.name == stage) {
                                return Err(CaseError::Option(format!(
                                    "the checkpoint has a stage `{stage}`, which this scheme has not"
                                )));
                            }
                            stage_rows.borrow_mut().push((stage, t, values));
                        }
                        snapshots.extend_written(record.snapshots);
                    }
                    observer.resume(&series, &switches);
                    (saved_rows, saved_stages, saved_snapshots) =
                        (series.len(), stage_rows.borrow().len(), snapshots.written().len());
                }
                None => snapshots.write(
                    &sim.ops,
                    0,
                    t0,
                    &sim.states[0],
                    &velocity(&sim.states, v_index, &sim.states[0], times.dt),
                )?,
            }
            let names = sim.stepper.desc().states.clone();
            let outcome = sim.run(
                t0,
                times.dt,
                steps,
                opts.progress && writes,
                &mut control,
                &mut |ops, stage, v_index, start| {
                    if let Some(u) = stage.value_of(&names[0]) {
                        let v = v_index.and_then(|i| stage.value_of(&names[i]));
                        let state = State {
                            t: stage.time,
                            u,
                            v,
                            newton: 0,
                            before: None,
                            before_previous: None,
                            previous: start,
                            stage: true,
                        };
                        let ((t, values), _) = row(ops, state);
                        stage_rows.borrow_mut().push((stage.name.to_string(), t, values));
                    }
                },
                &mut |ops, step, record| {
                    let v = v_index.map(|i| step.states[i].as_slice());
                    let state = State {
                        t: step.t,
                        u: &step.states[0],
                        v,
                        newton: step.report.iterations(),
                        before: Some((step.before, step.dt)),
                        before_previous: step.previous,
                        previous: step.before,
                        stage: false,
                    };
                    let (values, active) = row(ops, state);
                    series.push(values);
                    switches.push(active);
                    iterations.push(step.report.iterations());
                    snapshots.write(
                        ops,
                        step.k,
                        step.t,
                        &step.states[0],
                        &velocity(step.states, v_index, step.before, step.dt),
                    )?;
                    if let Some(record) = record {
                        let stages = stage_rows.borrow();
                        *record = postcard::to_stdvec(&Record {
                            series: series[saved_rows..].to_vec(),
                            iterations: iterations[saved_rows..].to_vec(),
                            switches: switches[saved_rows..].to_vec(),
                            stages: stages[saved_stages..].to_vec(),
                            snapshots: snapshots.written()[saved_snapshots..].to_vec(),
                        })
                        .map_err(|e| CaseError::Option(format!("cannot encode the checkpoint: {e}")))?;
                        (saved_rows, saved_stages, saved_snapshots) =
                            (series.len(), stages.len(), snapshots.written().len());
                    }
                    Ok(())
                },
            )?;
            let stage_rows = stage_rows.into_inner();
            let last = (series.last().map_or(t0, |r| r.0), sim.states[0].clone());
            (series, switches, iterations, stage_rows, outcome, sim.stepper.counters(), steps, last)
        }
    };
    // Rank 0 writes the collection (every process of a split run holds the directory).
    if writes {
        snapshots.finish()?;
    }
    let wall = start.elapsed().as_secs_f64();
    let mut summary = Summary::default();
    let mut put = |k: &str, v: serde_json::Value| summary.keys.push((k.to_string(), v));
    put("case", name.clone().into());
    put("problem", pf.file.clone().into());
    put("scheme", if statics { "static".into() } else { in_use.scheme_name().into() });
    put("contact", in_use.forms.contact_name().into());
    put("interpreted", json(&in_use.interpreted()));
    put("params", json(&all_params(in_use, params, pf)));
    put("mass", json(&opts.mass));
    put("cell_size", json(&opts.cell_size));
    put("mesh", mesh_label.clone().into());
    put("cells", mesh.num_cells().into());
    put("dofs", n.into());
    put("dt", json(&times.dt));
    put("steps", steps.into());
    // The time reached (t_end, or where the run stopped).
    put("t_end", json(&series.last().map_or(t0, |r| r.0)));
    let (own, expectations) = summary_fns.values(&series);
    for (k, v) in &own {
        put(k, json(v));
    }
    if !expectations.is_empty() {
        put("expected", json(&expectations));
    }
    put("newton_total", iterations.iter().sum::<usize>().into());
    put("newton_max", iterations.iter().max().copied().unwrap_or(0).into());
    put("wall_seconds", json(&wall));
    put("seconds_per_step", json(&(wall / steps.max(1) as f64)));
    put("stepping_seconds", json(&outcome.step_seconds.iter().sum::<f64>()));
    put("step_median_seconds", json(&crate::resources::median(outcome.step_seconds.clone())));
    put("factorizations", counters.numeric.into());
    put("symbolic_factorizations", counters.symbolic.into());
    put("low_rank_updates", counters.updates.into());
    put("matrix_nnz", matrix_nnz.into());
    let factor_nnz = match &runner {
        Runner::Time(sim) => sim.stepper.factor_nnz(),
        Runner::Static(_) => None,
    };
    put("factor_nnz", json(&factor_nnz));
    // An explicit scheme's critical step, estimated at the start (docs/language.md).
    if let Runner::Time(sim) = &runner
        && let Some(stable) = sim.stable
    {
        put("stable_dt", json(&stable.dt));
        put("omega_max", json(&stable.omega_max));
    }
    put("solver", json(&opts.newton.solver));
    put("krylov_iterations", counters.iterations.into());
    put("linear_solves", counters.solves.into());
    put("peak_memory_bytes", json(&crate::resources::peak_memory()));
    put("step_cuts", outcome.cuts.into());
    // A run without inertia (static, or a scheme without `mass`) watches no energy.
    if let Runner::Time(sim) = &runner
        && sim.inertia
    {
        put("energy_growth", json(&outcome.energy_growth));
    }
    if let Some(stopped) = &outcome.stopped {
        put("stopped", stopped.to_string().into());
    }
    if let Some(resumed) = &outcome.resumed {
        put("resumed", json(resumed));
    }
    // Why a key is null: undefined on this run (0/0 or no row where `first` finds one); and
    // what this run left out.
    let mut notes: Vec<String> = own
        .iter()
        .filter(|(_, v)| !v.is_some_and(f64::is_finite))
        .map(|(k, _)| {
            let at = p.summary.iter().find(|d| d.name.name == *k).map(|d| d.span);
            let line = at.map_or(0, |s| pf.program.unit.sources.line_col(s.file, s.start).0);
            format!("{k} is undefined on this run (its expression at {}:{line} has no value)", pf.file)
        })
        .collect();
    for (name, why) in observer.left_out.iter().chain(&summary_fns.left_out) {
        notes.push(format!("{name} is left out of this run: {why}"));
    }
    if !notes.is_empty() {
        put("notes", json(&notes));
    }
    summary.own = own.into_iter().map(|(k, _)| k).collect();
    let run = Run { summary, columns, rows: series, switches, stages: stage_rows };
    if let Some(dir) = &out {
        write_outputs(dir, pf, &run, &shown)?;
        // The reference's figures of the last state (Hertz's pressure profile): rank 0 alone
        // draws them, so they read the state's facet samples, never a product (collective in a
        // split run).
        observer
            .write_reference(dir, runner.ops(), &last.1, last.0)
            .map_err(|source| CaseError::Write { path: dir.display().to_string(), source })?;
    }
    if let Some(e) = outcome.stopped {
        return Err(e);
    }
    Ok(run)
}

/// The contact law's `Gamma_C`: the obstacle's region (`on REGION`, or `Gamma_C`); none without
/// an obstacle or a region `Gamma_C`.
fn contact_region(pf: &ProblemFile) -> Option<&str> {
    let (p, contact) = (pf.problem(), super::bind::CONTACT);
    match p.obstacles.first() {
        Some(o) => Some(o.region.as_ref().map_or(contact, |r| r.name.as_str())),
        None => p.regions.iter().any(|r| r.name.name == contact).then_some(contact),
    }
}

/// Whether a run under mpirun is split across its processes (each assembling the cells around
/// the nodes it owns, `Mesh::part`), rather than repeated whole by each: a time run with PETSc's
/// solvers (`--solver petsc`, or the default) and the material's mass. A static problem, another solver (which factors or iterates
/// on the whole matrix), the redistributed or lumped mass and a scheme that estimates its
/// critical step (both factor the whole mass) are repeated whole by every process.
fn split(opts: &Options, pf: &ProblemFile, in_use: &FilesInUse) -> Result<bool, CaseError> {
    use crate::runtime::linalg::ranks;
    if ranks::world().1 == 1
        || pf.problem().run_static.is_some()
        || !opts.newton.solver.petsc()
        || opts.mass != crate::simulation::MassChoice::Consistent
    {
        return Ok(false);
    }
    let (claims, _) = in_use.scheme_claims_and_law()?;
    Ok(!claims.iter().any(|(c, _)| c == "cfl"))
}

fn mpi(e: crate::runtime::linalg::LinalgError) -> CaseError {
    CaseError::Option(format!("MPI: {e}"))
}

/// Rank 0's output directory, on every process (collective).
fn shared_dir(out: Option<&std::path::PathBuf>) -> Result<Option<std::path::PathBuf>, CaseError> {
    let mut bytes = out.map(|d| d.to_string_lossy().into_owned().into_bytes()).unwrap_or_default();
    crate::runtime::linalg::ranks::broadcast(&mut bytes).map_err(mpi)?;
    let dir = String::from_utf8(bytes).map_err(|e| CaseError::Option(format!("rank 0's output directory: {e}")))?;
    Ok((!dir.is_empty()).then(|| dir.into()))
}

/// The stored entries of the run's matrices: in a split run, every process's own rows (each
/// holds those whole).
fn matrix_nnz(asm: &Assembler) -> Result<u64, CaseError> {
    let p = asm.pattern();
    let Some(o) = p.ownership() else { return Ok(p.nnz() as u64) };
    let d = p.dim() as u64;
    let mine: u64 = (0..p.num_nodes()).filter(|&i| o.owns(i)).map(|i| p.neighbours(i).len() as u64 * d * d).sum();
    crate::runtime::linalg::ranks::total(mine).map_err(mpi)
}

/// What runs a problem: the stepper (a time run), or a static problem's operators alone (its one
/// equilibrium is the static driver's).
enum Runner<'m> {
    Time(Box<Simulation<'m>>),
    Static(Box<crate::simulation::Operators<'m>>),
}

impl<'m> Runner<'m> {
    fn ops(&self) -> &crate::simulation::Operators<'m> {
        match self {
            Runner::Time(sim) => &sim.ops,
            Runner::Static(ops) => ops,
        }
    }
}
