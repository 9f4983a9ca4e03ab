//! `signorini run disc` and `run sphere`: an elastic body bouncing on a rigid plane
//! (docs/mathematics.md §6). The disc of radius 10 centred at (0, 12) falls from rest under
//! f = (0, −0.1) onto {y = 0}: plane strain with λ = μ = 20 (E = 50, ν = 1/4), ρ = 1, curved P2
//! triangles, no Dirichlet condition. The sphere is the same in 3D: the ball of radius 10
//! centred at (0, 0, 12), f = (0, 0, −0.1), the plane {z = 0}, curved P2 tetrahedra. The
//! series' vertical columns (the fields `uy_*`, `vy_mean`, `fy_contact` of [`Row`], which
//! hold the vertical component in both) are named after the axis (`uy_mean`, `fy_contact` for the disc;
//! `uz_mean`, `fz_contact` for the sphere).

use std::cell::RefCell;
use std::path::PathBuf;
use std::time::Instant;

use serde::{Deserialize, Serialize};

use super::CaseError;
use super::bar::MassChoice;
use crate::checkpoint::{Control, Identity};
use crate::driver::{Active, ParamValue, Setup};
use crate::runtime::assembly::{Assembler, Quadrature};
use crate::runtime::evaluate::facet_samples;
use crate::runtime::mesh::{CellSize, Mesh, ball::ball, disc::disc};
use crate::runtime::newton::NewtonOptions;
use crate::runtime::problem::Constraints;
use crate::simulation::{Problem, Simulation, Snapshots, Tools};

/// Gravity of the benchmark.
pub const GRAVITY: f64 = 0.1;
/// The body: the 2D disc or the 3D sphere.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Body {
    Disc,
    Sphere,
}

impl Body {
    pub fn name(self) -> &'static str {
        match self {
            Body::Disc => "disc",
            Body::Sphere => "sphere",
        }
    }

    pub fn dim(self) -> usize {
        match self {
            Body::Disc => 2,
            Body::Sphere => 3,
        }
    }

    /// What the built-in mesh is called.
    pub fn mesh_name(self) -> &'static str {
        match self {
            Body::Disc => "disc",
            Body::Sphere => "ball",
        }
    }

    /// The vertical axis's letter, for column names.
    pub fn axis(self) -> char {
        match self {
            Body::Disc => 'y',
            Body::Sphere => 'z',
        }
    }

    /// Cell and contact-facet quadrature degrees. Disc: the 12-point triangle rule and 4 Gauss
    /// points per edge (GetFEM's IM_TRIANGLE(6)). Sphere: degree 4 in the cells (the P2 mass on
    /// straight cells), 5 on the contact faces.
    fn quadrature(self) -> Quadrature {
        match self {
            Body::Disc => Quadrature { cell: Some(6), facet: Some(7) },
            Body::Sphere => Quadrature { cell: Some(4), facet: Some(5) },
        }
    }
}
/// The disc's material (λ = μ = 20) and its Nitsche/penalty parameter, over the files' defaults.
pub const OVERRIDES: &[(&str, f64)] = &[("E", 50.0), ("nu", 0.25), ("rho", 1.0), ("gamma0", 1000.0)];

#[derive(Clone, Debug, PartialEq)]
pub struct Options {
    pub body: Body,
    /// Scheme, contact law, extra forms and params.
    pub setup: Setup,
    pub mass: MassChoice,
    /// What `h` means in γ = γ0/h.
    pub cell_size: CellSize,
    /// A Gmsh file; the built-in curved disc generator otherwise.
    pub mesh: Option<PathBuf>,
    /// Mesh size of the built-in generator.
    pub h: f64,
    pub dt: f64,
    /// Start from the exact free fall at this time (u = −g t²/2, v = −g t, vertically) instead
    /// of rest at t = 0: the first contact at √40 is reached in few steps.
    pub t_start: f64,
    pub t_end: f64,
    pub newton: NewtonOptions,
    pub out: Option<PathBuf>,
    /// Write a VTU snapshot every this many steps (0: none) into `out`/vtu, with disc.pvd.
    pub vtu_every: usize,
    /// Show a progress bar on long runs (when stdout is a terminal).
    pub progress: bool,
    /// Write `out`/checkpoint.bin after every this many steps (0: only on an interrupt).
    pub checkpoint_every: usize,
    /// Continue from `out`/checkpoint.bin.
    pub resume: bool,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            body: Body::Disc,
            setup: Setup::default(),
            mass: MassChoice::Consistent,
            cell_size: CellSize::Diameter,
            mesh: None,
            h: 1.0,
            dt: 0.02,
            t_start: 0.0,
            t_end: 20.0,
            newton: NewtonOptions::default(),
            out: None,
            vtu_every: 0,
            progress: false,
            checkpoint_every: 0,
            resume: false,
        }
    }
}

/// One row of `series.csv`.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Row {
    pub t: f64,
    pub energy: f64,
    /// ½vᵀMv (with the mass the scheme uses).
    pub kinetic: f64,
    pub energy_aug: f64,
    /// Mass-weighted mean of u_y (the centre of mass).
    pub uy_mean: f64,
    /// Plain mean of the nodal u_y (GetFEM's benchmark reports this one).
    pub uy_mean_nodal: f64,
    /// Mass-weighted mean of v_y: the centre of mass's velocity (NaN for a scheme without `v`).
    pub vy_mean: f64,
    pub uy_lowest: f64,
    pub fy_contact: f64,
    /// The measure of the contact zone's points where the gap is closed (u_N ≥ g): a length
    /// for the disc, an area for the sphere.
    pub contact_area: f64,
    pub active_points: usize,
    /// The contact switches at every contact quadrature point (the active set).
    #[serde(skip)]
    pub switches: Vec<bool>,
    pub penetration: f64,
    pub newton: usize,
}

#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    pub case: &'static str,
    pub scheme: String,
    /// The contact law (its file stem).
    pub contact: String,
    /// Files of the run compiled at run time (given by path, not in the library).
    pub interpreted: Vec<String>,
    /// Every param of the scheme and form files, with its value and where it comes from.
    pub params: std::collections::BTreeMap<String, ParamValue>,
    pub mass: MassChoice,
    pub cell_size: CellSize,
    pub mesh: String,
    pub cells: usize,
    pub dofs: usize,
    pub dt: f64,
    pub steps: usize,
    /// Time of the first step that ends with an active contact point.
    pub first_contact: Option<f64>,
    pub max_penetration: f64,
    pub min_uy_mean: f64,
    pub energy_aug_initial: f64,
    pub energy_aug_final: f64,
    /// The largest kinetic energy ½vᵀMv over the run (at impact): the disc's energy scale, as
    /// E_aug(0) = 0.
    pub kinetic_energy_max: f64,
    pub newton_total: usize,
    pub newton_max: usize,
    pub wall_seconds: f64,
    pub seconds_per_step: f64,
    /// Time inside the time stepper alone (no setup, measurements or output), in total and
    /// the median over steps.
    pub stepping_seconds: f64,
    pub step_median_seconds: f64,
    /// Numeric factorizations of the stage Jacobians (the rest of the Newton iterations reuse one;
    /// with the iterative solver: preconditioner setups).
    pub factorizations: usize,
    /// Changes of the active set solved by a low-rank correction of the last factorization
    /// instead of a new one.
    pub low_rank_updates: usize,
    /// Stored entries of the step matrix and of its Cholesky factor (direct solver).
    pub matrix_nnz: usize,
    pub factor_nnz: Option<usize>,
    /// The linear solver asked for, and the Krylov iterations over the run (0: direct).
    pub solver: crate::runtime::linalg::Solver,
    pub krylov_iterations: usize,
    /// The process's peak resident memory at the end of the run (Linux), in bytes.
    pub peak_memory_bytes: Option<u64>,
    /// Halvings of Δt after a failed Newton (the series has the actual time levels).
    pub step_cuts: usize,
    /// Why the run ended before t_end, if it did (the series stops at the last good step).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stopped: Option<String>,
    /// The checkpoint this run resumed from (its counters and wall time cover the rest only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub resumed: Option<crate::simulation::Resumed>,
}

pub struct Run {
    pub summary: Summary,
    pub series: Vec<Row>,
    /// Multi-stage schemes: the measures at every intermediate stage (`stages.csv`); the
    /// Newton column is 0 there (the step's count is in `series`).
    pub stages: Vec<StageRow>,
}

/// The measures at an intermediate stage's time.
#[derive(Clone, Debug)]
pub struct StageRow {
    /// The stage's name in the scheme's file.
    pub stage: &'static str,
    pub row: Row,
}

/// The mesh: read or generated, validated, with its `contact` region (the Gmsh group of that
/// name, else the facets whose outward normal points down).
pub fn mesh(opts: &Options) -> Result<Mesh, CaseError> {
    let d = opts.body.dim();
    let mut mesh = match &opts.mesh {
        Some(path) => super::read_mesh(path)?,
        None => {
            // The sphere's P2 dofs grow like (20/h)³: h = 0.3 is about 3 million.
            let smallest = if d == 2 { 0.05 } else { 0.3 };
            if !(opts.h >= smallest && opts.h <= 10.0) {
                return Err(CaseError::Option(format!("--h must be in [{smallest}, 10], not {}", opts.h)));
            }
            // P2 nodes: the disc's rings (3m² vertices), the ball's (2n+1)³ lattice.
            let dofs = match opts.body {
                Body::Disc => 2.0 * 4.0 * 3.0 * (10.0 / opts.h).ceil().powi(2),
                Body::Sphere => 3.0 * (4.0 * (10.0 / opts.h).round() + 1.0).powi(3),
            };
            crate::resources::check(opts.body.name(), dofs, d, Some(opts.h))?;
            match opts.body {
                Body::Disc => disc(10.0, [0.0, 12.0], opts.h),
                Body::Sphere => ball(10.0, [0.0, 0.0, 12.0], opts.h),
            }
        }
    };
    if opts.mesh.is_some() {
        crate::resources::check(opts.body.name(), (mesh.num_nodes() * mesh.dim()) as f64, mesh.dim(), None)?;
    }
    if mesh.dim() != d {
        return Err(CaseError::Option(format!("the {} case needs a {d}D mesh, not {}D", opts.body.name(), mesh.dim())));
    }
    if !mesh.has_region("contact") {
        mesh.add_region_where("contact", |n, _| n[d - 1] < 0.0);
    }
    mesh.set_cell_size(opts.cell_size);
    mesh.validate()?;
    Ok(mesh)
}

pub fn run(opts: &Options) -> Result<Run, CaseError> {
    let positive = |x: f64| x > 0.0 && x.is_finite();
    if !positive(opts.dt) || !positive(opts.t_end) || opts.t_end / opts.dt > 1e7 {
        return Err(CaseError::Option("--dt and --t-end must be positive, with at most 10⁷ steps".into()));
    }
    if !(opts.t_start >= 0.0 && opts.t_start < opts.t_end) {
        return Err(CaseError::Option(format!("--t-start must be in [0, t_end), not {}", opts.t_start)));
    }
    let active = Active::resolve(&opts.setup, OVERRIDES)?;
    simulate(opts, &active)
}

fn simulate(opts: &Options, active: &Active) -> Result<Run, CaseError> {
    let start = Instant::now();
    let mesh = mesh(opts)?;
    let asm = Assembler::new(&mesh);
    let n = asm.size();
    let (d, vert) = (opts.body.dim(), opts.body.dim() - 1);
    let quadrature = opts.body.quadrature();
    let coefs = super::above_plane(d, 0.0, GRAVITY);
    let problem = Problem {
        coefs: &coefs,
        quadrature,
        contact: "contact",
        constraints: Constraints::none(n),
        mass: opts.mass,
        newton: opts.newton,
    };
    let mut control =
        Control::new(opts.checkpoint_every, opts.out.clone(), identity(opts, active, &mesh), opts.resume)?;
    let mut sim = Simulation::new(&asm, problem, active)?;
    if sim.tools.probe.is_none() {
        return Err(CaseError::Option(
            "the disc measures `contact`, which the form files in use do not provide".into(),
        ));
    }
    // At rest at t = 0, or in exact free fall at t_start.
    let t0 = opts.t_start;
    let fall = |size: f64| (0..n).map(|i| if i % d == d - 1 && size != 0.0 { size } else { 0.0 }).collect::<Vec<f64>>();
    sim.initialize_at(t0, fall(-0.5 * GRAVITY * t0 * t0), fall(-GRAVITY * t0))?;
    let vertical_mean = sim.tools.axis_mean(vert);
    let lowest =
        (0..mesh.num_nodes()).min_by(|&a, &b| mesh.node(a)[vert].total_cmp(&mesh.node(b)[vert])).expect("nodes");
    let measure = |tools: &Tools, u: &[f64], v: Option<&[f64]>, newton: usize, t: f64| -> Row {
        let kinetic = tools.kinetic(v);
        let energy = tools.energy_with_kinetic(u, kinetic);
        let switches = tools.contact_switches(u, t);
        let samples = facet_samples(&mesh, tools.contact_facets, quadrature.facet.unwrap_or(7), u);
        // The gap u_N − g at each point: −u_d − x_d.
        let gaps: Vec<f64> = samples.iter().map(|s| -s.value[vert] - s.x[vert]).collect();
        let penetration = gaps.iter().fold(0.0f64, |m, g| m.max(*g));
        Row {
            t,
            energy,
            kinetic,
            energy_aug: energy + tools.value(&tools.contact_energy, u),
            // Area-weighted mean of u_y: e_yᵀ M u / e_yᵀ M e_y.
            uy_mean: vertical_mean.of(u),
            uy_mean_nodal: u.iter().skip(vert).step_by(d).sum::<f64>() / (n / d) as f64,
            vy_mean: v.map_or(f64::NAN, |v| vertical_mean.of(v)),
            uy_lowest: u[d * lowest + vert],
            // Where the body touches or penetrates the plane: the gap closed.
            contact_area: samples.iter().zip(&gaps).filter(|(_, g)| **g >= 0.0).map(|(s, _)| s.weight).sum(),
            fy_contact: tools.contact_force(u, t)[vert],
            active_points: switches.iter().filter(|b| **b).count(),
            switches,
            penetration,
            newton,
        }
    };
    let mut series = vec![measure(&sim.tools, &sim.states[0], sim.velocity(), 0, t0)];
    let steps = ((opts.t_end - t0) / opts.dt).round() as usize;
    let mut snapshots = Snapshots::new(opts.out.as_ref(), opts.vtu_every, opts.body.name());
    // A scheme without a velocity state: the step's mean velocity.
    let velocity = |states: &[Vec<f64>], v_index: Option<usize>, before: &[f64], dt: f64| -> Vec<f64> {
        match v_index {
            Some(i) => states[i].clone(),
            None => states[0].iter().zip(before).map(|(a, b)| (a - b) / dt).collect(),
        }
    };
    let v_index = sim.v_index;
    // Multi-stage schemes: the state at each intermediate stage's time (stages.csv).
    let stage_rows: RefCell<Vec<StageRow>> = RefCell::new(Vec::new());
    // What the checkpoints so far hold (each records what is new since the one before).
    let (mut saved_rows, mut saved_stages, mut saved_snapshots) = (0, 0, 0);
    match control.observer() {
        Some(records) => {
            let stages = sim.stepper.desc().stages;
            series.clear();
            for bytes in records {
                let record: Record = postcard::from_bytes(bytes)
                    .map_err(|e| CaseError::Option(format!("the checkpoint's record of the run is damaged ({e})")))?;
                series.extend(record.series.into_iter().map(Saved::into_row));
                for (name, row) in record.stages {
                    let stage = stages.iter().find(|s| s.name == name).ok_or_else(|| {
                        CaseError::Option(format!("the checkpoint has a stage `{name}`, which this scheme has not"))
                    })?;
                    stage_rows.borrow_mut().push(StageRow { stage: stage.name, row: row.into_row() });
                }
                snapshots.extend_written(record.snapshots);
            }
            (saved_rows, saved_stages, saved_snapshots) =
                (series.len(), stage_rows.borrow().len(), snapshots.written().len());
        }
        None => snapshots.write(
            &sim.tools,
            0,
            t0,
            &sim.states[0],
            &velocity(&sim.states, v_index, &sim.states[0], opts.dt),
        )?,
    }
    let names = sim.stepper.desc().states;
    let outcome = sim.run(
        t0,
        opts.dt,
        steps,
        opts.progress,
        &mut control,
        &mut |tools, stage, v_index| {
            if let Some(u) = stage.value_of(names[0]) {
                let v = v_index.and_then(|i| stage.value_of(names[i]));
                stage_rows.borrow_mut().push(StageRow { stage: stage.name, row: measure(tools, u, v, 0, stage.time) });
            }
        },
        &mut |tools, step, record| {
            let v = v_index.map(|i| step.states[i].as_slice());
            series.push(measure(tools, &step.states[0], v, step.report.iterations(), step.t));
            snapshots.write(
                tools,
                step.k,
                step.t,
                &step.states[0],
                &velocity(step.states, v_index, step.before, step.dt),
            )?;
            if let Some(record) = record {
                let stages = stage_rows.borrow();
                *record = postcard::to_stdvec(&Record {
                    series: series[saved_rows..].iter().map(Saved::of).collect(),
                    stages: stages[saved_stages..].iter().map(|s| (s.stage.to_string(), Saved::of(&s.row))).collect(),
                    snapshots: snapshots.written()[saved_snapshots..].to_vec(),
                })
                .map_err(|e| CaseError::Option(format!("cannot encode the checkpoint: {e}")))?;
                (saved_rows, saved_stages, saved_snapshots) = (series.len(), stages.len(), snapshots.written().len());
            }
            Ok(())
        },
    )?;
    let stage_rows = stage_rows.into_inner();
    snapshots.finish()?;
    let wall = start.elapsed().as_secs_f64();
    let last = series.last().expect("initial row");
    let summary = Summary {
        case: opts.body.name(),
        scheme: active.scheme_name().to_string(),
        contact: active.forms.contact_name().to_string(),
        interpreted: active.interpreted(),
        params: active.forms.params.values(),
        mass: opts.mass,
        cell_size: opts.cell_size,
        mesh: opts
            .mesh
            .as_ref()
            .map_or_else(|| format!("built-in {}, h = {}", opts.body.mesh_name(), opts.h), |p| p.display().to_string()),
        cells: mesh.num_cells(),
        dofs: n,
        dt: opts.dt,
        steps,
        first_contact: series.iter().find(|r| r.active_points > 0).map(|r| r.t),
        max_penetration: series.iter().map(|r| r.penetration).fold(0.0, f64::max),
        min_uy_mean: series.iter().map(|r| r.uy_mean).fold(f64::INFINITY, f64::min),
        energy_aug_initial: series[0].energy_aug,
        energy_aug_final: last.energy_aug,
        kinetic_energy_max: series.iter().map(|r| r.kinetic).fold(0.0, f64::max),
        newton_total: series.iter().map(|r| r.newton).sum(),
        newton_max: series.iter().map(|r| r.newton).max().unwrap_or(0),
        wall_seconds: wall,
        seconds_per_step: wall / steps.max(1) as f64,
        stepping_seconds: outcome.step_seconds.iter().sum(),
        step_median_seconds: crate::bench::median(outcome.step_seconds),
        factorizations: sim.stepper.counters().numeric,
        low_rank_updates: sim.stepper.counters().updates,
        matrix_nnz: sim.tools.asm.pattern().nnz(),
        factor_nnz: sim.stepper.factor_nnz(),
        solver: opts.newton.solver,
        krylov_iterations: sim.stepper.counters().iterations,
        peak_memory_bytes: crate::bench::peak_memory(),
        step_cuts: outcome.cuts,
        stopped: outcome.stopped.as_ref().map(ToString::to_string),
        resumed: outcome.resumed,
    };
    if let Some(dir) = &opts.out {
        write_outputs(dir, opts.body, &summary, &series, &stage_rows)?;
    }
    if let Some(e) = outcome.stopped {
        return Err(e);
    }
    Ok(Run { summary, series, stages: stage_rows })
}

/// The disc's record in a checkpoint: what is new since the checkpoint before.
#[derive(Serialize, Deserialize)]
struct Record {
    series: Vec<Saved>,
    stages: Vec<(String, Saved)>,
    snapshots: Vec<(f64, String)>,
}

/// A row with its switches (which series.csv leaves out).
#[derive(Serialize, Deserialize)]
struct Saved(Row, Vec<bool>);

impl Saved {
    fn of(row: &Row) -> Saved {
        Saved(row.clone(), row.switches.clone())
    }

    fn into_row(self) -> Row {
        Row { switches: self.1, ..self.0 }
    }
}

/// What a resumed run must share with its checkpoint.
fn identity(opts: &Options, active: &Active, mesh: &Mesh) -> Identity {
    crate::checkpoint::identity(
        opts.body.name(),
        active,
        mesh,
        &[
            ("mass", format!("{:?}", opts.mass)),
            ("cell size", format!("{:?}", opts.cell_size)),
            ("dt", format!("{:?}", opts.dt)),
            ("t_start", format!("{:?}", opts.t_start)),
            ("t_end", format!("{:?}", opts.t_end)),
            ("Newton options", format!("{:?}", opts.newton)),
            ("checkpoint period", opts.checkpoint_every.to_string()),
        ],
    )
}

fn write_outputs(
    dir: &std::path::Path,
    body: Body,
    summary: &Summary,
    series: &[Row],
    stages: &[StageRow],
) -> Result<(), CaseError> {
    let a = body.axis();
    let header = format!(
        "t,energy,energy_aug,u{a}_mean,u{a}_mean_nodal,v{a}_mean,u{a}_lowest,f{a}_contact,contact_area,active_points,penetration,newton"
    );
    let line = |r: &Row| {
        format!(
            "{},{},{},{},{},{},{},{},{},{},{},{}\n",
            r.t,
            r.energy,
            r.energy_aug,
            r.uy_mean,
            r.uy_mean_nodal,
            r.vy_mean,
            r.uy_lowest,
            r.fy_contact,
            r.contact_area,
            r.active_points,
            r.penetration,
            r.newton
        )
    };
    let mut csv = format!("{header}\n");
    series.iter().for_each(|r| csv.push_str(&line(r)));
    let err = |path: std::path::PathBuf| move |source| CaseError::Write { path: path.display().to_string(), source };
    crate::output::write_atomic(&dir.join("series.csv"), csv.as_bytes()).map_err(err(dir.join("series.csv")))?;
    crate::output::write_json(&dir.join("summary.json"), summary).map_err(err(dir.join("summary.json")))?;
    if !stages.is_empty() {
        // The series' columns, after the stage's name (Newton: 0, counted per step).
        let mut csv = format!("stage,{header}\n");
        for StageRow { stage, row } in stages {
            csv.push_str(&format!("{stage},{}", line(row)));
        }
        crate::output::write_atomic(&dir.join("stages.csv"), csv.as_bytes()).map_err(err(dir.join("stages.csv")))?;
    }
    use crate::plot::Curve;
    let pts = |f: &dyn Fn(&Row) -> f64| series.iter().map(|r| (r.t, f(r))).collect::<Vec<_>>();
    let plot_err = |e: String| CaseError::Write { path: dir.display().to_string(), source: std::io::Error::other(e) };
    let aug = "E + contact energy";
    crate::plot::panels(
        &dir.join(format!("{}.png", body.name())),
        "t",
        &[
            (
                "energies",
                "energy",
                vec![
                    Curve { label: "E", points: pts(&|r| r.energy), dashed: false },
                    Curve { label: aug, points: pts(&|r| r.energy_aug), dashed: false },
                ],
            ),
            (
                "vertical displacement",
                &format!("u_{a}"),
                vec![
                    Curve { label: "mean", points: pts(&|r| r.uy_mean), dashed: false },
                    Curve { label: "lowest point", points: pts(&|r| r.uy_lowest), dashed: false },
                ],
            ),
            (
                "contact force",
                &format!("F_{a}"),
                vec![Curve { label: "vertical", points: pts(&|r| r.fy_contact), dashed: false }],
            ),
            (
                "Newton iterations",
                "iterations",
                vec![Curve { label: "per step", points: pts(&|r| r.newton as f64), dashed: false }],
            ),
        ],
    )
    .map_err(plot_err)
}
