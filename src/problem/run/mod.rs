//! The one loop every problem runs through: bind the problem (mesh, regions, coefs) and the
//! files in use (scheme, laws, params), initialize, step with cuts and the energy watch, measure
//! every row, checkpoint, then write series.csv, stages.csv, summary.json, the figure and the
//! VTU collection. Nothing in it names a problem.

mod statics;
mod summarize;
mod time;

use std::path::PathBuf;
use std::time::Instant;

use super::ProblemFile;
use super::bind::coef_shapes;
pub use super::check::{check, params_in_use};
use super::dirichlet::{Held, dirichlet};
use super::expr::{Exprs, PointFn};
use super::observe::{Observer, Sources, State};
use super::options::Times;
pub use super::options::{Chosen, Options, StepOptions};
use super::outputs::write_outputs;
pub use super::outputs::{Fields, Run};
use super::reference::bound_reference;
use super::resolve::bound;
use super::resume::identity;
use super::summary::SummaryKeys;
use crate::checkpoint::Control;
use crate::driver::FilesInUse;
use crate::error::CaseError;
use crate::runtime::fem::assembly::{Assembler, Quadrature};
use crate::runtime::fem::kernel::Coef;
use crate::runtime::fem::mesh::Mesh;
use crate::runtime::library::Binding;
use crate::runtime::linalg::Counters;
use crate::runtime::linalg::pattern::Owners;
use crate::runtime::nonlinear::statics::Constraints;
use crate::simulation::statics::StaticProblem;
use crate::simulation::{Operators, Outcome, Problem, Simulation, Snapshots};

pub fn run(opts: &Options) -> Result<Run, CaseError> {
    run_watched(opts, None).map_err(|s| s.error)
}

/// A run that stopped before its end (an interrupt, a step that failed, an energy that grew):
/// why, and the rows it measured up to there.
pub struct Stopped {
    pub error: CaseError,
    pub run: Option<Box<Run>>,
}

impl From<CaseError> for Stopped {
    fn from(error: CaseError) -> Stopped {
        Stopped { error, run: None }
    }
}

/// A row as a run measures it, shown to a [`Watcher`] as the run goes.
pub struct Seen<'a> {
    pub t: f64,
    /// Every column's name, in the order of `values`.
    pub columns: &'a [String],
    pub values: &'a [f64],
    /// The run's end time.
    pub t_end: f64,
}

/// Sees each row of a time run as it is measured; `false` stops the run after that step, as
/// SIGINT does (its results up to there written, [`CaseError::Interrupted`]).
pub type Watcher<'w> = dyn Fn(&Seen) -> bool + 'w;

/// [`run`], showing each row to `watcher`; a run that stops early keeps its rows.
pub fn run_watched(opts: &Options, watcher: Option<&Watcher>) -> Result<Run, Stopped> {
    if let Some(options) = &opts.petsc_options {
        crate::runtime::linalg::set_petsc_options(options).map_err(|e| CaseError::Option(e.to_string()))?;
    }
    let ran = bound(opts, |pf, params, ex, in_use, read_mesh| {
        if pf.problem().run_static.is_some() {
            if opts.dt.is_some()
                || opts.t_end.is_some()
                || opts.t_start.is_some()
                || opts.steps != StepOptions::default()
            {
                return Err(CaseError::Option(format!(
                    "{} is static (`run static`): it takes no --dt, --t-end, --t-start or --adaptive",
                    pf.file
                )));
            }
            let times = Times { dt: f64::NAN, t_start: 0.0, t_end: 0.0, adaptive: None };
            return Ok(simulate(opts, pf, params, ex, in_use, &times, read_mesh, watcher));
        }
        let given = super::bind::settings(pf, ex, &pf.problem().run)?;
        let setting = |name: &str, over: Option<f64>, default: f64| {
            over.or_else(|| given.iter().find(|(n, _)| n == name).map(|(_, v)| *v)).unwrap_or(default)
        };
        let mut times = Times {
            dt: setting("dt", opts.dt, f64::NAN),
            t_start: setting("t_start", opts.t_start, 0.0),
            t_end: setting("t_end", opts.t_end, f64::NAN),
            adaptive: None,
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
        times.adaptive = adaptive(opts.steps, &setting, &times)?;
        Ok(simulate(opts, pf, params, ex, in_use, &times, read_mesh, watcher))
    });
    ran?
}

/// Adaptive steps, when the options or the problem's `run` line ask for them: each bound a
/// positive number (dt_min ≤ dt_max).
fn adaptive(
    steps: StepOptions,
    setting: &dyn Fn(&str, Option<f64>, f64) -> f64,
    times: &Times,
) -> Result<Option<crate::simulation::step_control::Adaptive>, CaseError> {
    // A value given on the command line counts, NaN included (refused below).
    let given = |name: &str, over: Option<f64>| over.is_some() || !setting(name, None, f64::NAN).is_nan();
    let tolerance = setting("adaptive", steps.adaptive, f64::NAN);
    if !given("adaptive", steps.adaptive) {
        if let Some(name) = [("dt_min", steps.dt_min), ("dt_max", steps.dt_max), ("event_dt", steps.event_dt)]
            .iter()
            .find(|(n, o)| given(n, *o))
            .map(|(n, _)| n)
        {
            return Err(CaseError::Option(format!(
                "`{name}` bounds adaptive steps: give --adaptive TOL (or the problem's `run adaptive = TOL`) too"
            )));
        }
        return Ok(None);
    }
    let positive = |name: &str, x: f64| match x > 0.0 && x.is_finite() {
        true => Ok(x),
        false => Err(CaseError::Option(format!(
            "--{} (or the problem's `run {name} = ...`) must be a positive number, not {x}",
            name.replace('_', "-")
        ))),
    };
    let span = times.t_end - times.t_start;
    let a = crate::simulation::step_control::Adaptive {
        tolerance: positive("adaptive", tolerance)?,
        dt_min: positive("dt_min", setting("dt_min", steps.dt_min, times.dt * 1e-6))?,
        dt_max: positive("dt_max", setting("dt_max", steps.dt_max, span / 10.0))?,
        event: positive("event_dt", setting("event_dt", steps.event_dt, times.dt / 20.0))?,
    };
    if a.dt_min > a.dt_max {
        return Err(CaseError::Option(format!("--dt-min {} exceeds --dt-max {}", a.dt_min, a.dt_max)));
    }
    Ok(Some(a))
}

#[allow(clippy::too_many_arguments)]
fn simulate(
    opts: &Options,
    pf: &ProblemFile,
    params: &[super::ProblemParam],
    ex: &mut Exprs,
    in_use: &FilesInUse,
    times: &Times,
    read_mesh: Option<super::bind::ReadMesh>,
    watcher: Option<&Watcher>,
) -> Result<Run, Stopped> {
    let clock = Instant::now();
    let writes = crate::runtime::linalg::ranks::writes();
    let req = Request { opts, pf, params, in_use, times, writes, watcher };
    let (mesh, mesh_label) = super::bind::mesh(pf, ex, opts.mesh.as_deref(), opts.cell_size, read_mesh)?;
    // Under mpirun each process assembles the cells around the nodes it owns, where it can.
    let ownership = match split(opts, pf, in_use)? {
        true => crate::runtime::linalg::ownership::Ownership::of(&mesh).map_err(mpi)?,
        false => None,
    };
    let pairs = super::pairs::surfaces(pf, ex, &mesh)?;
    // Every process integrates over the problem's regions whole (the contact law's and the
    // pairs' among them: a pair's facing points may be anywhere on the other surface).
    let whole: Vec<&str> = pf
        .problem()
        .regions
        .iter()
        .map(|r| r.name.name.as_str())
        .chain(contact_region(pf))
        .chain(pairs.iter().flat_map(|p| [p.own.as_str(), p.facing.as_str()]))
        .collect();
    let part = ownership.as_ref().map(|o| (mesh.part(o.owners(), o.rank() as u32, &whole), o));
    let couplings = |m: &Mesh| pairs.iter().flat_map(|p| p.on(m).couplings(m)).collect::<Vec<_>>();
    let asm = match &part {
        Some(((local, owned), o)) => {
            let (cells, rank) = (local.num_cells(), o.rank());
            tracing::info!(rank, owned, cells, whole = mesh.num_cells(), "this process's part of the mesh");
            Assembler::split_with_couplings(local, (*o).clone(), *owned, &couplings(local))
        }
        None if pairs.is_empty() => Assembler::new(&mesh),
        None => Assembler::with_couplings(&mesh, &couplings(&mesh)),
    };
    // Collective in a split run: counted now, while every process runs the same code (rank 0
    // alone may stop early, on a failed write).
    let sized = Sized { mesh: mesh_label, cells: mesh.num_cells(), dofs: asm.size(), matrix_nnz: matrix_nnz(&asm)? };
    let coef_table = CoefTable::new(pf, ex, in_use, mesh.dim())?;
    let coefs = |name: &str| coef_table.get(name);
    let others: Vec<String> =
        pf.problem().regions.iter().map(|r| r.name.name.clone()).filter(|r| r != super::bind::CONTACT).collect();
    let (constraints, held) = dirichlet(pf, ex, &mesh)?;
    let bound = Bound {
        coefs: &coefs,
        quadrature: quadrature(pf, ex)?,
        contact: contact_region(pf),
        others: &others,
        constraints: &constraints,
        held: held.as_ref(),
        pairs: &pairs,
    };
    let mut runner = Runner::bind(&req, &asm, &bound)?;
    let (u0, v0) = initial_fields(pf, ex, &mesh, &bound, times.t_start)?;
    // A static problem's initial u, and the guess of `settled(GUESS)`, are Newton's first
    // iterate (a Hertz start presses the bodies into each other): the bodies as meshed must
    // not overlap. A time run starts from its initial u.
    let guess = matches!(runner, Runner::Static(_)) || super::bind::settled(pf);
    let placed = if guess { vec![0.0; u0.len()] } else { u0.clone() };
    super::pairs::check_overlap(pf, &mesh, &pairs, &placed)?;
    let observing = Observing::new(&req, ex, &runner, &asm, &bound, times.t_start)?;
    // Bound: the run starts, and only now makes its output directory.
    let out = if writes { prepared(opts)? } else { None };
    // In a run of several processes each holds the whole state and takes the same steps; rank 0
    // writes the results, and the checkpoints with the others' parts in a split run (any
    // number of processes resumes them). Collective.
    let shared = shared_dir(out.as_ref())?;
    let id = identity(opts, pf, params, in_use, &mesh, times);
    let mut control = Control::new(opts.checkpoint_every, shared.clone(), id, opts.resume, ownership.clone())?;
    // Every process of a split run writes its piece of each snapshot, into rank 0's directory.
    let pieces = if ownership.is_some() { shared.clone() } else { out.clone() };
    let mut snapshots = Snapshots::new(pieces.as_ref(), opts.vtu_every, pf.name());
    let stepped = match &mut runner {
        Runner::Static(ops) => statics::run(&req, ops, &asm, &bound, &observing.observer, &mut snapshots, u0)?,
        Runner::Time(sim) => {
            let start = time::Start { u0, v0, mesh: &mesh };
            time::run(&req, sim, &bound, &observing.observer, &mut snapshots, &mut control, start)?
        }
    };
    // Rank 0 writes the collection (every process of a split run holds the directory).
    if writes {
        snapshots.finish()?;
    }
    let ran = Ran { stepped, sized, runner: &runner, wall: clock.elapsed().as_secs_f64() };
    finish(&req, ran, observing, out.as_ref(), &mesh)
}

/// The run's summary and rows, written to `out` with the reference's figures; the run's error
/// after them if it stopped early.
fn finish(req: &Request, ran: Ran, observing: Observing, out: Option<&PathBuf>, mesh: &Mesh) -> Result<Run, Stopped> {
    let summary = summarize::summary(req, &ran, &observing);
    let Stepped { rows, outcome, last, .. } = ran.stepped;
    let mut run = Run {
        summary,
        columns: observing.columns,
        rows: rows.series,
        switches: rows.switches,
        stages: rows.stages,
        newton: rows.newton,
        fields: None,
    };
    if let Some(dir) = out {
        write_outputs(dir, req.pf, &run, &observing.shown)?;
        // The reference's figures of the last state (Hertz's pressure profile): rank 0 alone
        // draws them, so they read the state's facet samples, never a product (collective in a
        // split run).
        observing
            .observer
            .write_reference(dir, ran.runner.ops(), &last.1, last.0)
            .map_err(|source| CaseError::Write { path: dir.display().to_string(), source })?;
    }
    if req.opts.keep_fields {
        let (t, u, v) = last;
        run.fields = Some(Box::new(Fields { t, u, v, mesh: mesh.clone() }));
    }
    match outcome.stopped {
        Some(error) => Err(Stopped { error, run: Some(Box::new(run)) }),
        None => Ok(run),
    }
}

/// What a run asked for: its options, the problem file, the files in use and the times.
pub(super) struct Request<'a> {
    pub opts: &'a Options,
    pub pf: &'a ProblemFile,
    pub params: &'a [super::ProblemParam],
    pub in_use: &'a FilesInUse,
    pub times: &'a Times,
    /// This process writes the results (rank 0, or the only one).
    pub writes: bool,
    /// Sees each row as it is measured.
    pub watcher: Option<&'a Watcher<'a>>,
}

/// The size of the run's discrete problem, for its summary.
pub(super) struct Sized {
    pub mesh: String,
    pub cells: usize,
    pub dofs: usize,
    pub matrix_nnz: u64,
}

/// What the problem binds on the mesh, which every stage after reads.
pub(super) struct Bound<'a> {
    pub coefs: &'a dyn Fn(&str) -> Option<Coef>,
    pub quadrature: Quadrature,
    /// The contact law's `Gamma_C` (`contact_region`).
    pub contact: Option<&'a str>,
    /// The problem's other regions, bound by their names.
    pub others: &'a [String],
    pub constraints: &'a Constraints,
    pub held: Option<&'a Held>,
    /// The contact pairs.
    pub pairs: &'a [crate::runtime::fem::pair::PairRegions],
}

impl Bound<'_> {
    fn problem(&self, opts: &Options, mesh: &Mesh) -> Problem<'_> {
        Problem {
            coefs: self.coefs,
            quadrature: self.quadrature,
            contact: self.contact,
            regions: self.others,
            pairs: self.pairs,
            constraints: self.constraints.clone(),
            prescribed: self.held.map(|h| h.prescribed(mesh)),
            mass: opts.mass,
            newton: opts.newton,
        }
    }

    /// The equilibrium with the contact on `contact` at time `t` (a static problem's, or the
    /// settled start's).
    pub(super) fn statics<'p>(&'p self, contact: Option<&'p str>, opts: &Options, t: f64) -> StaticProblem<'p> {
        StaticProblem {
            coefs: self.coefs,
            contact,
            regions: self.others,
            pairs: self.pairs,
            contact_degree: self.quadrature.facet,
            constraints: self.constraints.clone(),
            newton: opts.newton,
            t,
        }
    }
}

/// The problem's coefs by name; without contact, the coefs only the contact law reads are zero
/// (it integrates over no facet).
struct CoefTable {
    fns: Vec<(String, PointFn)>,
    zeros: Vec<(String, usize)>,
}

impl CoefTable {
    fn new(pf: &ProblemFile, ex: &mut Exprs, in_use: &FilesInUse, dim: usize) -> Result<CoefTable, CaseError> {
        let fns = super::bind::coefs(pf, ex)?;
        coef_shapes(pf, in_use, &fns, dim)?;
        let zeros = match super::bind::contact_free(pf) {
            true => (in_use.forms.contact_units().into_iter())
                .flat_map(|i| in_use.forms.units[i].coefs())
                .map(|(n, rank)| (n, dim.pow(rank)))
                .collect(),
            false => Vec::new(),
        };
        Ok(CoefTable { fns, zeros })
    }

    fn get(&self, name: &str) -> Option<Coef> {
        super::bind::coef_lookup(&self.fns)(name).or_else(|| {
            let (_, len) = self.zeros.iter().find(|(n, _)| n == name)?;
            Some(Coef::constant(vec![0.0; *len]))
        })
    }
}

/// The problem's `quadrature cell = ..., facet = ...` degrees.
fn quadrature(pf: &ProblemFile, ex: &mut Exprs) -> Result<Quadrature, CaseError> {
    let quad = super::bind::settings(pf, ex, &pf.problem().quadrature)?;
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
    Ok(Quadrature { cell: degree("cell")?, facet: degree("facet")? })
}

/// The initial fields at `t0`, which take the held values on the held dofs.
fn initial_fields(
    pf: &ProblemFile,
    ex: &mut Exprs,
    mesh: &Mesh,
    bound: &Bound,
    t0: f64,
) -> Result<(Vec<f64>, Vec<f64>), CaseError> {
    let mut u0 = super::bind::initial(pf, ex, mesh, "u", t0)?;
    let mut v0 = super::bind::initial(pf, ex, mesh, "v", t0)?;
    bound.constraints.impose(&mut u0);
    bound.constraints.zero(&mut v0);
    if let Some(h) = bound.held {
        h.initial(mesh, t0, &mut u0, &mut v0);
    }
    Ok((u0, v0))
}

/// The observer of the run's rows, with its columns and summary keys.
pub(super) struct Observing<'m> {
    pub observer: Observer<'m>,
    pub columns: Vec<String>,
    pub shown: Vec<bool>,
    pub keys: SummaryKeys,
}

impl<'m> Observing<'m> {
    fn new(
        req: &Request,
        ex: &mut Exprs,
        runner: &Runner<'m>,
        asm: &'m Assembler,
        bound: &Bound,
        t0: f64,
    ) -> Result<Observing<'m>, CaseError> {
        let (pf, in_use, ops) = (req.pf, req.in_use, runner.ops());
        let mut regions = vec![(super::bind::CONTACT.to_string(), ops.contact_facets)];
        for name in bound.others {
            regions.push((name.clone(), asm.region(name)?));
        }
        let binding = Binding {
            bodies: &asm.mesh().bodies,
            pairs: bound.pairs.iter().map(|p| p.on(asm.mesh())).collect(),
            ..Binding::new(bound.quadrature, regions, asm.mesh().dim())
        };
        let reference = bound_reference(pf, ex, in_use, asm.mesh(), ops.contact_facets, t0)?;
        let sources = Sources {
            ops,
            forms: &in_use.forms,
            coefs: bound.coefs,
            binding: &binding,
            coef_vals: &super::bind::coef_vals(pf, ex)?,
            degree: bound.quadrature.facet.unwrap_or(7),
        };
        let mut observer = Observer::new(pf, ex, &sources, reference)?;
        let columns: Vec<String> = observer.names().map(str::to_string).collect();
        let applies = super::summary::applies(pf, ex, &in_use.forms.params)?;
        let absent: Vec<String> = observer.left_out.iter().map(|(c, _)| c.clone()).collect();
        let keys = SummaryKeys::new(pf, ex, &columns, applies, &absent)?;
        for (what, list) in [("series", &observer.left_out), ("summary key", &keys.left_out)] {
            for (name, why) in list {
                eprintln!("note: {what} `{name}` is left out of this run: {why}");
            }
        }
        // A column only `at_max` reads (not written, plotted or read by another column or key)
        // is measured only where its maximand reaches a new maximum: the contact radius at the
        // peak force samples the pressure at those rows, not at every step.
        for (column, by) in keys.at_max_columns(&columns) {
            if !pf.problem().plots.iter().flat_map(|pl| &pl.columns).any(|c| c.name == columns[column]) {
                observer.defer(column, by);
            }
        }
        Ok(Observing { shown: observer.shown(), observer, columns, keys })
    }
}

/// The rows a run measured.
#[derive(Default)]
pub(super) struct Rows {
    /// (time, values) per row.
    pub series: Vec<(f64, Vec<f64>)>,
    /// The active set per row.
    pub switches: Vec<Vec<bool>>,
    /// Newton iterations of each row's step (0 for the initial state).
    pub iterations: Vec<usize>,
    /// (stage, time, values) at every intermediate stage.
    pub stages: Vec<(String, f64, Vec<f64>)>,
    /// Newton's report of each step this process took (not kept by checkpoints).
    pub newton: Vec<crate::runtime::time::stepper::StepReport>,
}

/// What stepping (or the static solve) gave.
pub(super) struct Stepped {
    pub rows: Rows,
    pub outcome: Outcome,
    pub counters: Counters,
    pub steps: usize,
    /// The time, displacement and velocity (if the scheme has one) of the last state (the
    /// reference's figures read it).
    pub last: (f64, Vec<f64>, Option<Vec<f64>>),
    /// What the contact pairs' search and assembly cost the solves.
    pub search: crate::runtime::fem::search_cost::SearchCost,
}

/// A finished run, before its summary.
pub(super) struct Ran<'r, 'm> {
    pub stepped: Stepped,
    pub sized: Sized,
    pub runner: &'r Runner<'m>,
    pub wall: f64,
}

/// A row of the observer at a state: ((time, values), active set).
pub(super) fn row(observer: &Observer, ops: &Operators, state: State) -> RowValues {
    let t = state.t;
    let (values, switches) = observer.row(ops, &state);
    ((t, values), switches)
}

pub(super) type RowValues = ((f64, Vec<f64>), Vec<bool>);

/// The run's output directory: `--out` prepared now when the command line asked for a fresh
/// one (`output::prepare`: a new, emptied or `run-N` directory), else as given.
fn prepared(opts: &Options) -> Result<Option<PathBuf>, CaseError> {
    let (Some(dir), Some(force)) = (&opts.out, opts.out_fresh) else { return Ok(opts.out.clone()) };
    let (dir, note) = crate::output::prepare(dir, force).map_err(CaseError::Option)?;
    if let Some(note) = note {
        eprintln!("note: {note}");
    }
    Ok(Some(dir))
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
    Ok(!in_use.scheme_energy()?.claims.iter().any(|(c, _)| c == "cfl"))
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
pub(super) enum Runner<'m> {
    Time(Box<Simulation<'m>>),
    Static(Box<Operators<'m>>),
}

impl<'m> Runner<'m> {
    /// A static problem is one equilibrium, from u₀ (no initial acceleration to solve for), with
    /// the held values at the start time: it binds the operators, and no stepper.
    fn bind(req: &Request, asm: &'m Assembler, bound: &Bound) -> Result<Runner<'m>, CaseError> {
        let problem = bound.problem(req.opts, asm.mesh());
        if req.pf.problem().run_static.is_none() {
            return Ok(Runner::Time(Box::new(Simulation::new(asm, problem, req.in_use)?)));
        }
        Ok(Runner::Static(Box::new(Operators::bind(asm, problem, req.in_use)?)))
    }

    pub(super) fn ops(&self) -> &Operators<'m> {
        match self {
            Runner::Time(sim) => &sim.ops,
            Runner::Static(ops) => ops,
        }
    }
}
