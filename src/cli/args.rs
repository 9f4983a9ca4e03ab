//! The clap types of the command line: every subcommand with its options and their value
//! parsers, and what the options of a run make of the files, params and step guard
//! ([`MethodArgs::to_methods`]).

use std::path::PathBuf;

use clap::{Subcommand, ValueEnum};

use crate::driver::{Methods, Setting};
use crate::guard::Guard;
use crate::runtime::fem::mesh::CellSize;
use crate::runtime::linalg::Solver;
use crate::simulation::MassChoice;

#[derive(Subcommand)]
pub enum Command {
    /// Check .wf files; print every diagnostic; exit 1 if any has an error.
    Check {
        #[arg(required = true)]
        files: Vec<PathBuf>,
    },
    /// Benchmarks (medians of repeated runs).
    Bench {
        #[command(subcommand)]
        what: BenchCommand,
    },
    /// Run the comparisons of Huang, Chouly, Drouet and Pignet's talk (CANUM 2022) and the
    /// validation cases, and write DIR/report.md with tables, figures and references.
    Report {
        #[arg(long, default_value = "results/report")]
        out: PathBuf,
        /// Only the bar and disc comparisons (sections 1 and 2): skip the verification and the
        /// Δt sweeps, which take most of the run's few minutes.
        #[arg(long)]
        quick: bool,
    },
    /// Mesh utilities.
    Mesh {
        #[command(subcommand)]
        command: MeshCommand,
    },
    /// Run a problem of the library by name (`disc`, `sphere`; `signorini list` shows them), a
    /// problem file (`my_problem.wf`), or a case file (`case.toml`).
    Run {
        /// A problem by name or .wf file, or a TOML case file (`case = "bar"` or `"disc"`, and
        /// the options as keys).
        file: Option<PathBuf>,
        #[command(flatten)]
        args: Box<ProblemArgs>,
    },
    /// Print every scheme and contact law of the library with its params (defaults, ranges,
    /// docs), and the other form files with their slots.
    List,
    /// Measure what the mathematics claims: every scheme's time orders and spectral radius,
    /// P1/P2 space orders in 1D/2D/3D, the energy laws with and without contact, and the
    /// disc's convergence under Δt and h refinement; writes DIR/verify.md, verify.json and
    /// figures in DIR/verify/. With --scheme NAME|FILE.wf (and --param): that scheme alone, in
    /// seconds: orders, spectral radius and period error over ωΔt, energy balance, the bar and
    /// the disc beside the library's schemes, and its file's claims checked (exit 1 if one is
    /// contradicted); writes DIR/verify_NAME.md, .json and .png.
    Verify {
        #[arg(long, default_value = "results")]
        out: PathBuf,
        #[command(flatten)]
        methods: MethodArgs,
    },
    /// Compare two runs' series.csv (or their output directories) column by column.
    Compare {
        a: PathBuf,
        b: PathBuf,
        /// Fail (exit 1) when a column's relative difference exceeds this.
        #[arg(long, value_parser = non_negative)]
        tol: Option<f64>,
    },
    /// Print a compilation stage of a .wf file.
    Emit {
        file: PathBuf,
        #[arg(long, value_enum, default_value_t = Stage::Rust)]
        stage: Stage,
        /// Space dimension of the IR to print.
        #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u8).range(1..=3))]
        dim: u8,
    },
}

#[derive(Subcommand)]
pub enum BenchCommand {
    /// P2 plane-strain stiffness and mass assembly on N×N unit squares, and the factorization
    /// of M/(β dt²) + K.
    Assemble {
        /// Mesh sizes N.
        #[arg(long, value_delimiter = ',', default_values_t = vec![64, 256, 512])]
        sizes: Vec<usize>,
        /// N of the factorization benchmark (0: skip it).
        #[arg(long, default_value_t = 256)]
        factor: usize,
        #[arg(long, default_value_t = 5)]
        repeats: usize,
        /// Directory for bench_assemble.json.
        #[arg(long, default_value = "results")]
        out: PathBuf,
    },
    /// Time per step of the bouncing disc (the library's default scheme and contact law, the
    /// disc's own Δt and end time), stepper alone, on each Gmsh mesh.
    Disc {
        #[arg(long = "mesh", required = true, num_args = 1..)]
        meshes: Vec<PathBuf>,
        #[arg(long, default_value_t = 5)]
        repeats: usize,
        /// Directory for bench_disc.json.
        #[arg(long, default_value = "results")]
        out: PathBuf,
    },
    /// Time per step and peak memory of the bouncing sphere against its size (built-in balls
    /// of 15k, 47k, 108k, 274k, 556k and 986k unknowns up to --max-dofs; 50 steps through the
    /// first contact), each solver in its own process. Up to 120k: a few minutes; the 986k
    /// ball alone takes about half an hour and 10 GB.
    Sphere {
        #[arg(long, default_value_t = 120_000)]
        max_dofs: usize,
        /// The solvers timed, side by side at each size (the direct one up to 60 000
        /// unknowns); default: direct, iterative, and petsc in a build with PETSc.
        #[arg(long, value_delimiter = ',', value_parser = Solver::parse)]
        solvers: Vec<Solver>,
        /// The numbers of MPI processes PETSc's runs are timed on, each under `mpirun -n N`
        /// (Open MPI's; a build with PETSc).
        #[arg(long, value_delimiter = ',', default_value = "1", value_parser = clap::value_parser!(u32).range(1..=1024))]
        ranks: Vec<u32>,
        /// Directory for bench_sphere.json, bench_sphere.png and the runs.
        #[arg(long, default_value = "results")]
        out: PathBuf,
    },
    /// Two balls colliding (the problem of two bodies in forms/library.toml's `[bench]`) at
    /// 4.4k, 29k, 94k and 146k unknowns up to --max-dofs, each in its own process: the contact
    /// pairs' search and assembly against the impact steps' time. Up to 100k: about 10 minutes.
    Balls {
        #[arg(long, default_value_t = 100_000)]
        max_dofs: usize,
        /// Directory for bench_balls.json and the runs.
        #[arg(long, default_value = "results")]
        out: PathBuf,
    },
    /// Each problem of forms/library.toml's `[[bench.adaptive]]` with its fixed steps and with
    /// adaptive ones side by side (steps, factorizations, the compared summary keys against a
    /// fine fixed-step reference run, or the fixed run at as many steps): a few minutes.
    Adaptive {
        /// Directory for bench_adaptive.json, bench_adaptive.md and the runs.
        #[arg(long, default_value = "results")]
        out: PathBuf,
    },
    /// The facing-point search of contact between bodies against the number of facets (about
    /// 10³, 10⁴, 10⁵ in 2D and 3D): building its R-tree and the queries, per n log n.
    Search {
        #[arg(long, default_value_t = 5)]
        repeats: usize,
        /// Directory for bench_search.json.
        #[arg(long, default_value = "results")]
        out: PathBuf,
    },
}

#[derive(Subcommand)]
pub enum MeshCommand {
    /// Print a JSON summary of a Gmsh file: nodes, cells by type, boundary facets, regions,
    /// total measure.
    Info { file: PathBuf },
}

/// The scheme, the form files and their params (`signorini list` shows what there is).
#[derive(clap::Args, Clone)]
pub struct MethodArgs {
    /// A scheme of the library by name, or a .wf file (run interpreted); default: forms/library.toml.
    #[arg(long)]
    pub(super) scheme: Option<String>,
    /// A contact law of the library by name (see `signorini list`), or a .wf file; default: forms/library.toml.
    #[arg(long)]
    pub(super) contact: Option<String>,
    /// The material's form file, by name or path; default: forms/library.toml.
    #[arg(long)]
    pub(super) material: Option<String>,
    /// Extra form files whose slots the scheme applies (repeatable).
    #[arg(long = "forms", value_name = "FILE.wf")]
    pub(super) forms: Vec<PathBuf>,
    /// A param of the scheme or form files: NAME=VALUE, or OWNER.NAME=VALUE (repeatable).
    #[arg(long = "param", value_name = "NAME=VALUE", allow_hyphen_values = true)]
    pub(super) params: Vec<String>,
    /// What h means in γ = γ0/h: diameter (largest vertex distance) or getfem (GetFEM's
    /// element_size: √d · max over the cell's nodes of σ_min of the reference Jacobian).
    #[arg(long, value_parser = CellSize::parse, default_value = name_of(CellSize::default()))]
    pub(super) cell_size: CellSize,
    /// Halvings of Δt allowed when a step's Newton fails (Δt doubles back after two good steps).
    #[arg(long, default_value_t = Guard::default().max_step_cuts, value_parser = step_cuts)]
    pub(super) max_step_cuts: usize,
    /// Stop when E_aug (elastic + kinetic + contact energy) exceeds E_aug(0) + the loads' work
    /// by this fraction of the problem's energy scale (0: never).
    #[arg(long, default_value_t = Guard::default().energy_tolerance, value_parser = non_negative)]
    pub(super) energy_tolerance: f64,
    /// Run an explicit scheme (one that claims `cfl`) above its estimated critical step Δt_c.
    #[arg(long)]
    pub(super) allow_unstable_dt: bool,
    /// Backtracking line search in Newton (halving the step while ‖R‖ does not decrease).
    #[arg(long)]
    pub(super) line_search: bool,
    /// Chord Newton for a tangent that is not piecewise (a finite-strain material): the
    /// factored tangent is kept, across steps, while each iteration contracts the residual at
    /// least tenfold. Fewer factorizations; each stage ends at Newton's tolerance, where
    /// Newton's last step usually overshoots it to round-off (docs/mathematics.md §8)
    #[arg(long)]
    pub(super) chord: bool,
}

/// `--max-step-cuts`: a whole number in the range the case files accept too.
fn step_cuts(s: &str) -> Result<usize, String> {
    let n = s.trim().parse::<i64>().map_err(|_| format!("`{s}` is not a whole number"))?;
    crate::guard::step_cuts(n)
}

/// The command-line name of a runtime type's value (its serde name: `diameter`, `auto`), for
/// clap's `[default: ...]` of the runtime's own default.
fn name_of(value: impl serde::Serialize) -> String {
    let name = serde_json::to_value(value).ok().and_then(|v| v.as_str().map(str::to_string));
    name.unwrap_or_default()
}

/// `--energy-tolerance` (0: off) and `--tol`: a number ≥ 0.
pub(super) fn non_negative(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(x) if x >= 0.0 && x.is_finite() => Ok(x),
        Ok(x) => Err(format!("{x} is not 0 or a positive number")),
        Err(_) => Err(format!("`{s}` is not a number")),
    }
}

impl MethodArgs {
    /// Whether any choice of files or params was given.
    pub(super) fn given(&self) -> bool {
        self.scheme.is_some()
            || self.contact.is_some()
            || self.material.is_some()
            || !self.forms.is_empty()
            || !self.params.is_empty()
            || self.line_search
            || self.chord
    }

    pub(super) fn to_methods(&self) -> Result<Methods, String> {
        let mut params = Vec::new();
        for p in &self.params {
            let (name, value) = p.split_once('=').ok_or_else(|| format!("--param {p}: expected NAME=VALUE"))?;
            let value: f64 =
                value.trim().parse().map_err(|_| format!("--param {p}: `{}` is not a number", value.trim()))?;
            params.push(Setting { name: name.trim().into(), value, origin: format!("--param {p}") });
        }
        let d = Methods::default();
        Ok(Methods {
            scheme: self.scheme.clone().unwrap_or(d.scheme),
            contact: self.contact.clone().unwrap_or(d.contact),
            material: self.material.clone().unwrap_or(d.material),
            forms: self.forms.clone(),
            generated: Vec::new(),
            compiled: Vec::new(),
            params,
            pairs: Vec::new(),
            guard: Guard {
                max_step_cuts: self.max_step_cuts,
                energy_tolerance: self.energy_tolerance,
                allow_unstable_dt: self.allow_unstable_dt,
            },
        })
    }
}

/// The options of a problem's run; the problem's file gives the defaults of `--dt`, `--t-end`,
/// `--t-start` and of its params (`--param NAME=VALUE`).
#[derive(clap::Args)]
pub struct ProblemArgs {
    #[command(flatten)]
    pub(super) methods: MethodArgs,
    #[arg(long, value_enum, default_value_t = MassChoice::default())]
    pub(super) mass: MassChoice,
    /// A Gmsh mesh (MSH 2.2 or 4.1) instead of the problem's.
    #[arg(long)]
    pub(super) mesh: Option<PathBuf>,
    /// The time step (default: the problem's `run dt = ...`).
    #[arg(long, allow_hyphen_values = true)]
    pub(super) dt: Option<f64>,
    /// The end time (default: the problem's).
    #[arg(long, allow_hyphen_values = true)]
    pub(super) t_end: Option<f64>,
    /// The start time, where the initial fields are evaluated (default: the problem's; the
    /// disc and the sphere start in exact free fall there).
    #[arg(long, allow_hyphen_values = true)]
    pub(super) t_start: Option<f64>,
    #[command(flatten)]
    pub(super) steps: StepArgs,
    /// Directory for series.csv, summary.json and the problem's figure (NAME.png).
    #[arg(long)]
    pub(super) out: Option<PathBuf>,
    /// Write a VTU snapshot every K steps into DIR/vtu, and DIR/NAME.pvd for ParaView.
    #[arg(long, default_value_t = 0)]
    pub(super) vtu_every: usize,
    #[command(flatten)]
    pub(super) checkpoint: CheckpointArgs,
    /// Linear solver of each step: direct (sparse Cholesky/LU), iterative (Jacobi-preconditioned
    /// CG, or BiCGStab for unsymmetric tangents; memory of the matrix only), auto (iterative
    /// above 10 000 unknowns in 3D, 100 000 in 2D), or petsc (CG or GMRES with block Jacobi, or
    /// algebraic multigrid where that does not serve; a build with `--features petsc`).
    #[arg(long, value_parser = Solver::parse, default_value = name_of(Solver::default()))]
    pub(super) solver: Solver,
    /// Options for PETSc's solvers, over the defaults of --solver petsc (`PETSC_OPTIONS` is
    /// read too): e.g. "-ksp_type preonly -pc_type lu -pc_factor_mat_solver_type mumps".
    #[arg(long, value_name = "OPTIONS", allow_hyphen_values = true)]
    pub(super) petsc_options: Option<String>,
    /// Run every scheme × every contact law × {consistent, redistributed} (with the --param
    /// settings that apply) and print one table of the problem's summary (with --out: one
    /// subdirectory per run).
    #[arg(long)]
    pub(super) all: bool,
}

/// Adaptive time steps (default: the problem's `run adaptive = ...`, else fixed steps).
#[derive(clap::Args, Clone, Copy)]
pub struct StepArgs {
    /// Adaptive steps: each step's local error (the scheme's `estimate`) at most TOL times the
    /// largest displacement; --dt is then the first step.
    #[arg(long, value_name = "TOL", allow_hyphen_values = true)]
    pub(super) adaptive: Option<f64>,
    /// The smallest adaptive step (default: --dt × 1e-6); below it the run stops.
    #[arg(long, value_name = "DT", allow_hyphen_values = true)]
    pub(super) dt_min: Option<f64>,
    /// The largest adaptive step (default: a tenth of the run).
    #[arg(long, value_name = "DT", allow_hyphen_values = true)]
    pub(super) dt_max: Option<f64>,
    /// A first contact or release is landed on to within this (default: --dt / 20).
    #[arg(long, value_name = "DT", allow_hyphen_values = true)]
    pub(super) event_dt: Option<f64>,
}

impl StepArgs {
    pub(super) fn options(self) -> crate::problem::run::StepOptions {
        let StepArgs { adaptive, dt_min, dt_max, event_dt } = self;
        crate::problem::run::StepOptions { adaptive, dt_min, dt_max, event_dt }
    }
}

/// Checkpoint and restart of a time-stepping case.
#[derive(clap::Args)]
pub struct CheckpointArgs {
    /// Write DIR/checkpoint.bin after every N steps (0: only when interrupted); --resume DIR
    /// then continues the run with the same bits as an uninterrupted one.
    #[arg(long, default_value_t = 0, value_name = "N")]
    pub(super) checkpoint_every: usize,
    /// Continue the run of output directory DIR from its checkpoint.bin, writing there. The
    /// options must be the run's own (a checkpoint of other options is refused).
    #[arg(long, value_name = "DIR", conflicts_with = "out")]
    pub(super) resume: Option<PathBuf>,
}

impl CheckpointArgs {
    /// The output directory: the resumed run's, or `--out` prepared (see `output::prepare`).
    /// The run's directory, and whether the run prepares it as a fresh one when it starts
    /// (not a resumed run's, which holds its checkpoint).
    pub(super) fn out(&self, out: Option<PathBuf>) -> Result<(Option<PathBuf>, bool), String> {
        match &self.resume {
            Some(dir) => Ok((Some(dir.clone()), false)),
            None if self.checkpoint_every > 0 && out.is_none() => {
                Err("--checkpoint-every needs --out DIR: the checkpoints go there".into())
            }
            None => Ok((out, true)),
        }
    }
}

#[derive(Clone, Copy, ValueEnum)]
pub enum Stage {
    Ast,
    Ir,
    /// The schemes of the file, their relations solved.
    Scheme,
    Rust,
    /// Each scheme's discrete energy identity (kept energy, work, dissipation) and what it
    /// proves over the params' ranges and at the defaults.
    Energy,
}

impl Stage {
    /// The stage `--stage NAME` names, or why none does.
    pub fn named(name: &str) -> Result<Stage, String> {
        Stage::from_str(name, false).map_err(|_| {
            let names: Vec<String> = Stage::value_variants()
                .iter()
                .filter_map(|s| s.to_possible_value())
                .map(|v| v.get_name().to_string())
                .collect();
            format!("`{name}` is not a stage ({})", names.join(", "))
        })
    }
}
