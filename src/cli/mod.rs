//! The `signorini` command line: the clap types of every subcommand (run, check, emit, list,
//! verify, report, bench, compare, mesh) and their dispatch.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand, ValueEnum};

mod compare;
mod list;

use crate::compiler;
use crate::driver::{Setting, Setup};
use crate::runtime::fem::mesh::CellSize;
use crate::runtime::linalg::Solver;
use crate::simulation::MassChoice;

#[derive(Parser)]
#[command(
    name = "signorini",
    version,
    about = "Dynamic contact mechanics: weak-form compiler and finite-element runtime"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
    /// Threads for assembly and the iterative solvers (default: all cores). Results have the
    /// same bits for any number.
    #[arg(long, global = true, value_parser = clap::value_parser!(u16).range(1..))]
    pub threads: Option<u16>,
    /// Replace an earlier run's output directory (without it, a non-empty --out gets a fresh
    /// run-N subdirectory; a directory signorini did not write is never removed).
    #[arg(long, global = true)]
    pub force: bool,
}

impl Cli {
    /// The command line, where every option's value may be negative: `--alpha -0.1` then gets
    /// the option's own range error instead of clap's "unexpected argument '-0'".
    pub fn parse_args() -> Self {
        use clap::{CommandFactory, FromArgMatches};
        let matches = negative_values(Self::command()).get_matches_from(problem_flags(std::env::args_os().collect()));
        Self::from_arg_matches(&matches).unwrap_or_else(|e| e.exit())
    }
}

/// `run PROBLEM --NAME VALUE` for a param NAME of the problem (`--ne 40`, `--h 0.5`): as
/// `--param NAME=VALUE`. The problem's file declares its params; an option of `run` of the same
/// name keeps its meaning.
fn problem_flags(mut args: Vec<std::ffi::OsString>) -> Vec<std::ffi::OsString> {
    let text = |a: &std::ffi::OsString| a.to_str().map(str::to_string);
    let Some(run) = args.iter().position(|a| a == "run") else { return args };
    let cmd = <Cli as clap::CommandFactory>::command();
    // The options of `run`, and whether each takes a value.
    let known: Vec<(String, bool)> = cmd
        .find_subcommand("run")
        .map(|r| {
            r.get_arguments()
                .filter_map(|a| a.get_long().map(|l| (l.to_string(), a.get_action().takes_values())))
                .collect()
        })
        .unwrap_or_default();
    let takes_value = |flag: &str| known.iter().find(|(l, _)| l == flag).map(|(_, v)| *v);
    // The problem: the first word after `run` that is no option's (an unknown option, maybe a
    // param of the problem, takes the word after it).
    let mut i = run + 1;
    let problem = loop {
        let Some(arg) = args.get(i).and_then(text) else { return args };
        match arg.strip_prefix("--") {
            Some("") => return args,
            Some(flag) if flag.contains('=') => i += 1,
            Some(flag) => i += if takes_value(flag) == Some(false) { 1 } else { 2 },
            None if arg.starts_with('-') => i += 1,
            None => break arg,
        }
    };
    if problem.ends_with(".toml") {
        return args;
    }
    let Ok(pf) = crate::problem::load(&problem) else { return args };
    let params: Vec<String> = pf.problem().params.iter().map(|q| q.name.name.clone()).collect();
    let mut i = run + 1;
    while i < args.len() {
        let Some(arg) = text(&args[i]) else {
            i += 1;
            continue;
        };
        if arg == "--" {
            break;
        }
        let Some(flag) = arg.strip_prefix("--") else {
            i += 1;
            continue;
        };
        let (name, inline) = match flag.split_once('=') {
            Some((n, v)) => (n.to_string(), Some(v.to_string())),
            None => (flag.to_string(), None),
        };
        let param = name.replace('-', "_");
        if takes_value(&name).is_some() || !params.contains(&param) {
            i += 1;
            continue;
        }
        let value = match inline {
            Some(v) => v,
            None if i + 1 < args.len() => text(&args.remove(i + 1)).unwrap_or_default(),
            None => {
                i += 1;
                continue;
            }
        };
        args[i] = "--param".into();
        args.insert(i + 1, format!("{param}={value}").into());
        i += 2;
    }
    args
}

fn negative_values(cmd: clap::Command) -> clap::Command {
    cmd.mut_args(|a| if a.get_action().takes_values() { a.allow_negative_numbers(true) } else { a })
        .mut_subcommands(negative_values)
}

/// `--force`, for the output directories of every command.
static FORCE: std::sync::OnceLock<bool> = std::sync::OnceLock::new();

/// The directory a run writes to (see `output::prepare`), announced when it is not `--out`.
fn out_dir(out: Option<PathBuf>) -> Result<Option<PathBuf>, String> {
    let Some(dir) = out else { return Ok(None) };
    let (dir, note) = crate::output::prepare(&dir, FORCE.get().copied().unwrap_or(false))?;
    if let Some(note) = note {
        eprintln!("note: {note}");
    }
    Ok(Some(dir))
}

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
    /// Run the talk's comparisons and write DIR/report.md with tables and figures.
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
    /// Time per step of the bouncing disc (Newmark, Nitsche θ = 1, Δt = 0.02, 1000 steps),
    /// stepper alone, on each Gmsh mesh.
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
    /// first contact), direct and iterative solvers, each run in its own process. Up to 120k:
    /// a few minutes; the 986k ball alone takes about half an hour and 10 GB.
    Sphere {
        #[arg(long, default_value_t = 120_000)]
        max_dofs: usize,
        /// Directory for bench_sphere.json, bench_sphere.png and the runs.
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
    scheme: Option<String>,
    /// A contact law of the library by name (see `signorini list`), or a .wf file; default: forms/library.toml.
    #[arg(long)]
    contact: Option<String>,
    /// The material's form file, by name or path; default: forms/library.toml.
    #[arg(long)]
    material: Option<String>,
    /// Extra form files whose slots the scheme applies (repeatable).
    #[arg(long = "forms", value_name = "FILE.wf")]
    forms: Vec<PathBuf>,
    /// A param of the scheme or form files: NAME=VALUE, or OWNER.NAME=VALUE (repeatable).
    #[arg(long = "param", value_name = "NAME=VALUE", allow_hyphen_values = true)]
    params: Vec<String>,
    /// Shorthand for --param alpha=VALUE.
    #[arg(long, allow_hyphen_values = true)]
    alpha: Option<f64>,
    /// Shorthand for --param theta=VALUE.
    #[arg(long, allow_hyphen_values = true)]
    theta: Option<f64>,
    /// Shorthand for --param gamma0=VALUE.
    #[arg(long, allow_hyphen_values = true)]
    gamma0: Option<f64>,
    /// What h means in γ = γ0/h: diameter (largest vertex distance) or getfem (GetFEM's
    /// element_size: √d · max over the cell's nodes of σ_min of the reference Jacobian).
    #[arg(long, value_parser = CellSize::parse, default_value = "diameter")]
    cell_size: CellSize,
    /// Halvings of Δt allowed when a step's Newton fails (Δt doubles back after two good steps).
    #[arg(long, default_value_t = 6, value_parser = step_cuts)]
    max_step_cuts: usize,
    /// Stop when E_aug (elastic + kinetic + contact energy) exceeds E_aug(0) + the loads' work
    /// by this fraction of the problem's energy scale (0: never).
    #[arg(long, default_value_t = crate::guard::ENERGY_TOLERANCE, value_parser = non_negative)]
    energy_tolerance: f64,
    /// Run an explicit scheme (one that claims `cfl`) above its estimated critical step Δt_c.
    #[arg(long)]
    allow_unstable_dt: bool,
    /// Backtracking line search in Newton (halving the step while ‖R‖ does not decrease).
    #[arg(long)]
    line_search: bool,
}

/// `--max-step-cuts`: the range the case files accept too.
fn step_cuts(s: &str) -> Result<usize, String> {
    use crate::guard::MAX_STEP_CUTS;
    match s.trim().parse::<i64>() {
        Ok(n) if (0..=MAX_STEP_CUTS as i64).contains(&n) => Ok(n as usize),
        Ok(n) => Err(format!("{n} is not in 0..={MAX_STEP_CUTS}")),
        Err(_) => Err(format!("`{s}` is not a whole number")),
    }
}

/// `--energy-tolerance` (0: off) and `--tol`: a number ≥ 0.
fn non_negative(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(x) if x >= 0.0 && x.is_finite() => Ok(x),
        Ok(x) => Err(format!("{x} is not 0 or a positive number")),
        Err(_) => Err(format!("`{s}` is not a number")),
    }
}

impl MethodArgs {
    /// Whether any choice of files or params was given.
    fn given(&self) -> bool {
        self.scheme.is_some()
            || self.contact.is_some()
            || self.material.is_some()
            || !self.forms.is_empty()
            || !self.params.is_empty()
            || self.alpha.is_some()
            || self.theta.is_some()
            || self.gamma0.is_some()
            || self.line_search
    }

    fn setup(&self) -> Result<Setup, String> {
        let mut params = Vec::new();
        for (name, v) in [("alpha", self.alpha), ("theta", self.theta), ("gamma0", self.gamma0)] {
            if let Some(value) = v {
                params.push(Setting { name: name.into(), value, origin: format!("--{name}") });
            }
        }
        for p in &self.params {
            let (name, value) = p.split_once('=').ok_or_else(|| format!("--param {p}: expected NAME=VALUE"))?;
            let value: f64 =
                value.trim().parse().map_err(|_| format!("--param {p}: `{}` is not a number", value.trim()))?;
            params.push(Setting { name: name.trim().into(), value, origin: format!("--param {p}") });
        }
        let d = Setup::default();
        Ok(Setup {
            scheme: self.scheme.clone().unwrap_or(d.scheme),
            contact: self.contact.clone().unwrap_or(d.contact),
            material: self.material.clone().unwrap_or(d.material),
            forms: self.forms.clone(),
            compiled: Vec::new(),
            params,
            guard: crate::guard::Guard {
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
    methods: MethodArgs,
    #[arg(long, value_enum, default_value_t = MassChoice::Consistent)]
    mass: MassChoice,
    /// A Gmsh mesh (MSH 2.2 or 4.1) instead of the problem's.
    #[arg(long)]
    mesh: Option<PathBuf>,
    /// The time step (default: the problem's `run dt = ...`).
    #[arg(long, allow_hyphen_values = true)]
    dt: Option<f64>,
    /// The end time (default: the problem's).
    #[arg(long, allow_hyphen_values = true)]
    t_end: Option<f64>,
    /// The start time, where the initial fields are evaluated (default: the problem's; the
    /// disc and the sphere start in exact free fall there).
    #[arg(long, allow_hyphen_values = true)]
    t_start: Option<f64>,
    /// Directory for series.csv, summary.json and the problem's figure (NAME.png).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Write a VTU snapshot every K steps into DIR/vtu, and DIR/NAME.pvd for ParaView.
    #[arg(long, default_value_t = 0)]
    vtu_every: usize,
    #[command(flatten)]
    checkpoint: CheckpointArgs,
    /// Linear solver of each step: direct (sparse Cholesky/LU), iterative (Jacobi-preconditioned
    /// CG, or BiCGStab for unsymmetric tangents; memory of the matrix only), or auto (iterative
    /// above 10 000 unknowns in 3D, 100 000 in 2D).
    #[arg(long, value_parser = Solver::parse, default_value = "auto")]
    solver: Solver,
    /// Run every scheme × every contact law × {consistent, redistributed} (with the --param
    /// settings that apply) and print one table of the problem's summary (with --out: one
    /// subdirectory per run).
    #[arg(long)]
    all: bool,
}

/// Checkpoint and restart of a time-stepping case.
#[derive(clap::Args)]
pub struct CheckpointArgs {
    /// Write DIR/checkpoint.bin after every N steps (0: only when interrupted); --resume DIR
    /// then continues the run with the same bits as an uninterrupted one.
    #[arg(long, default_value_t = 0, value_name = "N")]
    checkpoint_every: usize,
    /// Continue the run of output directory DIR from its checkpoint.bin, writing there. The
    /// options must be the run's own (a checkpoint of other options is refused).
    #[arg(long, value_name = "DIR", conflicts_with = "out")]
    resume: Option<PathBuf>,
}

impl CheckpointArgs {
    /// The output directory: the resumed run's, or `--out` prepared (see `output::prepare`).
    fn out(&self, out: Option<PathBuf>) -> Result<Option<PathBuf>, String> {
        match &self.resume {
            Some(dir) => Ok(Some(dir.clone())),
            None if self.checkpoint_every > 0 && out.is_none() => {
                Err("--checkpoint-every needs --out DIR: the checkpoints go there".into())
            }
            None => out_dir(out),
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
}

pub fn run(cli: Cli) -> ExitCode {
    let _ = FORCE.set(cli.force);
    let code = dispatch(cli);
    if crate::interrupt::requested() { ExitCode::from(crate::interrupt::EXIT_CODE) } else { code }
}

fn dispatch(cli: Cli) -> ExitCode {
    if let Some(n) = cli.threads
        && let Err(e) = rayon::ThreadPoolBuilder::new().num_threads(n as usize).build_global()
    {
        eprintln!("error: cannot start {n} threads: {e}");
        return ExitCode::FAILURE;
    }
    match cli.command {
        Command::Check { files } => check(&files),
        Command::Emit { file, stage, dim } => emit(&file, stage, dim as usize),
        Command::List => {
            print!("{}", list::text());
            ExitCode::SUCCESS
        }
        Command::Verify { out, methods } if methods.scheme.is_some() => verify_scheme(&out, &methods),
        Command::Verify { methods, .. } if methods.given() => fail(
            "--contact, --material, --forms, --param, --alpha, --theta, --gamma0 and --line-search apply to `verify --scheme` only",
        ),
        Command::Verify { out, .. } => match crate::verify::run(&mut |what| eprintln!("running {what}")) {
            Ok(v) => match v.write(&out) {
                Ok(()) => {
                    print!("{}", v.markdown());
                    println!("wrote {}", out.join("verify.md").display());
                    ExitCode::SUCCESS
                }
                Err(e) => fail(e),
            },
            Err(e) => fail(e),
        },
        Command::Compare { a, b, tol } => match compare::compare(&a, &b) {
            Ok((text, worst)) => {
                print!("{text}");
                match tol {
                    Some(t) if worst > t => fail(format!("the runs differ by {worst:e} > {t:e}")),
                    _ => ExitCode::SUCCESS,
                }
            }
            Err(e) => fail(e),
        },
        Command::Report { out, quick } => {
            let out = match out_dir(Some(out)) {
                Ok(dir) => dir.expect("given"),
                Err(e) => return fail(e),
            };
            match crate::report::write(&out, quick, &mut |what| eprintln!("running {what}")) {
                Ok(()) => {
                    println!("wrote {}", out.join("report.md").display());
                    ExitCode::SUCCESS
                }
                Err(e) => {
                    eprintln!("error: {e}");
                    ExitCode::FAILURE
                }
            }
        }
        Command::Run { file: Some(file), .. } if file.extension().is_some_and(|e| e == "toml") => run_file(&file),
        Command::Run { file: Some(problem), args } => run_problem(&problem.to_string_lossy(), *args),
        Command::Run { file: None, .. } => {
            let names = crate::problem::library_names().join(", ");
            eprintln!("error: name a problem ({names}), a problem file or a case file");
            ExitCode::FAILURE
        }
        Command::Mesh { command: MeshCommand::Info { file } } => mesh_info(&file),
        Command::Bench { what: BenchCommand::Assemble { sizes, factor, repeats, out } } => {
            bench_assemble(&sizes, factor, repeats, &out)
        }
        Command::Bench { what: BenchCommand::Disc { meshes, repeats, out } } => bench_disc(&meshes, repeats, &out),
        Command::Bench { what: BenchCommand::Sphere { max_dofs, out } } => bench_sphere(max_dofs, &out),
    }
}

fn check(files: &[PathBuf]) -> ExitCode {
    let mut failed = false;
    for f in files {
        match compiler::compile(f, &crate::driver::sources::LibraryLoader) {
            Ok(compiled) => {
                eprint!("{}", compiled.warnings);
                print!("{}", quadrature_degrees(f, &compiled));
                // A problem is also bound: its mesh and regions, the coefs of the files in use.
                if !compiled.program.unit.problems.is_empty()
                    && let Err(e) = crate::problem::run::check(&f.to_string_lossy())
                {
                    eprintln!("{e}");
                    failed = true;
                }
            }
            Err(e) => {
                eprint!("{e}");
                failed = true;
            }
        }
    }
    if failed { ExitCode::FAILURE } else { ExitCode::SUCCESS }
}

/// Each integral's quadrature degree on P1 and P2 elements (2D): the estimate, or the one the
/// file sets with `int(REGION, degree = K)`.
fn quadrature_degrees(file: &Path, compiled: &compiler::Compiled) -> String {
    let mut out = String::new();
    let unit = &compiled.program.unit;
    // The file's own forms (an imported file's are in its own report).
    let own = |name: &str| unit.forms.iter().any(|f| f.name == name && f.span.file == unit.root);
    for form in compiled.ir(2).forms.iter().filter(|f| own(&f.name)) {
        for i in &form.integrals {
            let how = if i.degree == i.estimated {
                format!("estimated; `int({}, degree = K)` sets it", i.region)
            } else {
                format!("set in the file; estimated {} and {}", i.estimated[0], i.estimated[1])
            };
            out.push_str(&format!(
                "{}: {} over {}: quadrature degree {} on P1, {} on P2 ({how})\n",
                file.display(),
                form.name,
                i.region,
                i.degree[0],
                i.degree[1]
            ));
        }
    }
    out
}

fn emit(file: &Path, stage: Stage, dim: usize) -> ExitCode {
    let compiled = match compiler::compile(file, &crate::driver::sources::LibraryLoader) {
        Ok(c) => c,
        Err(e) => {
            eprint!("{e}");
            return ExitCode::FAILURE;
        }
    };
    eprint!("{}", compiled.warnings);
    let prog = &compiled.program;
    let out = match stage {
        Stage::Ast => Ok(compiler::syntax::print::print_file(&compiled.ast, &prog.sources)),
        Stage::Ir => {
            let params: Vec<String> = prog.params.iter().map(|p| p.name.clone()).collect();
            let coefs: Vec<String> = prog.coefs.iter().map(|c| c.name.clone()).collect();
            Ok(compiler::ir::print::print(compiled.ir(dim), &params, &coefs))
        }
        Stage::Scheme => {
            Ok(compiled.schemes().iter().map(compiler::scheme::print::print).collect::<Vec<_>>().join("\n"))
        }
        Stage::Rust => {
            let opts = compiler::codegen::Options {
                runtime: compiler::codegen::DEFAULT_RUNTIME.to_string(),
                module: compiler::module_name(file),
                source_name: compiler::display_name(file),
            };
            compiled.rust_pretty(&opts)
        }
    };
    match out {
        Ok(text) => {
            print!("{text}");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprint!("{e}");
            ExitCode::FAILURE
        }
    }
}

/// Prints an error and fails.
fn fail(e: impl std::fmt::Display) -> ExitCode {
    eprintln!("error: {e}");
    ExitCode::FAILURE
}

fn mesh_info(file: &Path) -> ExitCode {
    match crate::runtime::fem::mesh::gmsh::read(file) {
        Ok(mesh) => {
            let regions: serde_json::Map<String, serde_json::Value> = mesh
                .regions
                .iter()
                .map(|r| (r.name.clone(), serde_json::json!({ "facets": r.facets.len() })))
                .collect();
            let groups: serde_json::Map<String, serde_json::Value> =
                mesh.cell_groups.iter().map(|(n, c)| (n.clone(), serde_json::json!({ "cells": c.len() }))).collect();
            let info = serde_json::json!({
                "file": file.display().to_string(),
                "dimension": mesh.dim(),
                "nodes": mesh.num_nodes(),
                "cells": { mesh.kind.name(): mesh.num_cells() },
                "boundary_facets": mesh.boundary_facets().len(),
                "regions": regions,
                "cell_groups": groups,
                "measure": mesh.measure(),
                "max_cell_diameter": mesh.max_diameter(),
                "warnings": mesh.warnings,
            });
            println!("{}", serde_json::to_string_pretty(&info).expect("JSON of plain values"));
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn bench_assemble(sizes: &[usize], factor: usize, repeats: usize, out: &Path) -> ExitCode {
    if sizes.iter().any(|&n| n == 0 || n > 2048) {
        eprintln!("error: --sizes must lie in 1..=2048");
        return ExitCode::FAILURE;
    }
    // The P2 plane-strain unknowns of the N×N mesh, 2 (2N + 1)², against the memory there is,
    // before anything is allocated.
    for (what, n) in sizes.iter().map(|&n| ("--sizes", n)).chain((factor > 0).then_some(("--factor", factor))) {
        let dofs = 2.0 * (2.0 * n as f64 + 1.0).powi(2);
        if let Err(e) = crate::resources::check(&format!("bench assemble {what} {n}"), dofs, 2, None) {
            return fail(e);
        }
    }
    let report = crate::bench::assemble(sizes, (factor > 0).then_some(factor), repeats, &mut |line| println!("{line}"));
    write_bench(&out.join("bench_assemble.json"), &report)
}

fn bench_sphere(max_dofs: usize, out: &Path) -> ExitCode {
    use crate::bench::sphere;
    let report = match sphere::sphere(max_dofs, out, &mut |line| println!("{line}")) {
        Ok(r) => r,
        Err(e) => return fail(e),
    };
    if let Err(e) = sphere::figure(&report, out) {
        return fail(e);
    }
    write_bench(&out.join("bench_sphere.json"), &report)
}

fn bench_disc(meshes: &[PathBuf], repeats: usize, out: &Path) -> ExitCode {
    let report = match crate::bench::disc::disc(meshes, repeats, &mut |line| println!("{line}")) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::FAILURE;
        }
    };
    write_bench(&out.join("bench_disc.json"), &report)
}

/// Writes a benchmark's JSON and says where.
fn write_bench(path: &Path, report: &impl serde::Serialize) -> ExitCode {
    match crate::output::write_json(path, report) {
        Ok(()) => {
            println!("wrote {}", path.display());
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: cannot write {}: {e}", path.display());
            ExitCode::FAILURE
        }
    }
}

fn verify_scheme(out: &Path, methods: &MethodArgs) -> ExitCode {
    let setup = match methods.setup() {
        Ok(s) => s,
        Err(e) => return fail(e),
    };
    let v = match crate::verify::scheme::run(&setup, &mut |what| eprintln!("running {what}")) {
        Ok(v) => v,
        Err(e) => return fail(e),
    };
    if let Err(e) = v.write(out) {
        return fail(e);
    }
    print!("{}", v.markdown());
    println!("wrote {}", out.join(format!("verify_{}.md", v.scheme)).display());
    let contradicted: Vec<String> = v
        .verdicts
        .iter()
        .filter(|c| !c.holds)
        .map(|c| format!("{} = {} (measured {:.4})", c.claim, c.claimed, c.measured))
        .collect();
    if contradicted.is_empty() {
        ExitCode::SUCCESS
    } else {
        fail(format!("the measurements contradict what {}'s file claims: {}", v.scheme, contradicted.join(", ")))
    }
}

fn run_problem(problem: &str, a: ProblemArgs) -> ExitCode {
    let setup = match a.methods.setup() {
        Ok(s) => s,
        Err(e) => return fail(e),
    };
    if a.all {
        if a.checkpoint.checkpoint_every > 0 || a.checkpoint.resume.is_some() {
            return fail("--all runs many cases: it takes no --checkpoint-every or --resume");
        }
        let mut opts = crate::problem::run::Options::new(problem);
        opts.mesh = a.mesh;
        opts.dt = a.dt;
        opts.t_start = a.t_start;
        opts.t_end = a.t_end;
        opts.cell_size = a.methods.cell_size;
        opts.newton.solver = a.solver;
        opts.newton.line_search = a.methods.line_search;
        opts.vtu_every = a.vtu_every;
        opts.chosen.material = a.methods.material.is_some();
        opts.out = match out_dir(a.out) {
            Ok(dir) => dir,
            Err(e) => return fail(e),
        };
        return run_problem_all(opts, setup);
    }
    let opts = crate::problem::run::Options {
        problem: problem.to_string(),
        setup,
        mass: a.mass,
        cell_size: a.methods.cell_size,
        mesh: a.mesh,
        dt: a.dt,
        t_start: a.t_start,
        t_end: a.t_end,
        newton: crate::runtime::nonlinear::newton::NewtonOptions {
            solver: a.solver,
            line_search: a.methods.line_search,
            ..Default::default()
        },
        out: match a.checkpoint.out(a.out) {
            Ok(dir) => dir,
            Err(e) => return fail(e),
        },
        vtu_every: a.vtu_every,
        progress: true,
        checkpoint_every: a.checkpoint.checkpoint_every,
        resume: a.checkpoint.resume.is_some(),
        chosen: crate::problem::run::Chosen {
            scheme: a.methods.scheme.is_some(),
            contact: a.methods.contact.is_some(),
            material: a.methods.material.is_some(),
        },
    };
    finish_problem(crate::problem::run::run(&opts))
}

/// `run PROBLEM --all`: every scheme × contact law × mass matrix, one line each with the
/// problem's own summary keys.
fn run_problem_all(base: crate::problem::run::Options, setup: Setup) -> ExitCode {
    // The masses of the implicit schemes' comparison (lumped is for explicit ones).
    let masses = [MassChoice::Consistent, MassChoice::Redistributed].map(|m| (m, m.name()));
    // The problem's own params (`ne`, or `bar.ne`) apply to every run: checked once.
    let rest = match crate::problem::load(&base.problem).and_then(|pf| crate::problem::params(&pf, &setup.params)) {
        Ok((_, rest)) => rest,
        Err(e) => return fail(e),
    };
    // A file's param applies to the runs whose files declare it (alpha to hht, not newmark);
    // one that no run takes is misspelt or out of range everywhere: an error, not a silent drop.
    let combinations: Vec<(&str, &str)> = crate::driver::all_schemes()
        .into_iter()
        .flat_map(|s| crate::driver::contact_names().into_iter().map(move |c| (s, c)))
        .collect();
    let takes = |scheme: &str, contact: &str, p: &Setting| {
        let probe = Setup { scheme: scheme.into(), contact: contact.into(), params: vec![p.clone()], ..setup.clone() };
        crate::driver::Active::resolve(&probe, &[])
    };
    for p in &rest {
        let results: Vec<_> = combinations.iter().map(|(s, c)| takes(s, c, p)).collect();
        if results.iter().all(Result::is_err) {
            // Out of range where it is declared says more than unknown where it is not.
            let errors: Vec<String> = results.into_iter().filter_map(Result::err).map(|e| e.to_string()).collect();
            let why = errors.iter().find(|e| !e.contains("unknown param")).or(errors.last());
            return fail(format!("{} applies to none of the runs: {}", p.origin, why.map_or("", |e| e.as_str())));
        }
    }
    let mut header: Option<Vec<String>> = None;
    let mut failed = false;
    for (scheme, contact) in combinations.iter().copied() {
        for (mass, mass_name) in masses {
            let params: Vec<Setting> = setup
                .params
                .iter()
                .filter(|p| !rest.contains(p) || takes(scheme, contact, p).is_ok())
                .cloned()
                .collect();
            let label = format!("{scheme}_{contact}_{mass_name}");
            let opts = crate::problem::run::Options {
                setup: Setup { scheme: scheme.into(), contact: contact.into(), params, ..setup.clone() },
                mass,
                out: base.out.as_ref().map(|d| d.join(&label)),
                chosen: crate::problem::run::Chosen { scheme: true, contact: true, ..base.chosen },
                ..base.clone()
            };
            match crate::problem::run::run(&opts) {
                Ok(r) => {
                    let s = &r.summary;
                    let keys = header.get_or_insert_with(|| {
                        let keys = s.own.clone();
                        let names: Vec<String> = keys.iter().map(|k| format!("{k:>w$}", w = k.len().max(11))).collect();
                        println!(
                            "{:<15} {:<16} {:<13} {} {:>7} {:>4}",
                            "scheme",
                            "contact",
                            "mass",
                            names.join(" "),
                            "Newton",
                            "max"
                        );
                        keys
                    });
                    let values: Vec<String> = keys
                        .iter()
                        .map(|k| {
                            let w = k.len().max(11);
                            s.number(k).map_or(format!("{:>w$}", "—"), |v| format!("{v:>w$.4e}"))
                        })
                        .collect();
                    let count = |k: &str| s.get(k).and_then(|v| v.as_u64()).unwrap_or(0);
                    println!(
                        "{scheme:<15} {contact:<16} {mass_name:<13} {} {:>7} {:>4}",
                        values.join(" "),
                        count("newton_total"),
                        count("newton_max")
                    );
                }
                Err(e) => {
                    println!("{scheme:<15} {contact:<16} {mass_name:<13} failed: {e}");
                    failed = true;
                }
            }
        }
    }
    if failed { ExitCode::FAILURE } else { ExitCode::SUCCESS }
}

fn finish_problem(result: Result<crate::problem::run::Run, crate::error::CaseError>) -> ExitCode {
    match result {
        Ok(r) => {
            let s = &r.summary;
            if let Some(files) = s.get("interpreted").and_then(|v| v.as_array()) {
                let files: Vec<String> = files.iter().filter_map(|f| f.as_str().map(str::to_string)).collect();
                interpreted_note(&files);
            }
            let text =
                |k: &str| s.get(k).map_or(String::new(), |v| v.as_str().map_or_else(|| v.to_string(), str::to_string));
            // The problem's own summary keys; null where a reducer found nothing.
            let own: Vec<String> = s
                .own
                .iter()
                .map(|k| format!("{k} {}", s.number(k).map_or("none".to_string(), |x| format!("{x:.6}"))))
                .collect();
            let set: Vec<String> = s
                .get("params")
                .and_then(|p| p.as_object())
                .map(|p| {
                    p.iter()
                        .filter(|(_, v)| v.get("source").and_then(|x| x.as_str()) != Some("file"))
                        .map(|(n, v)| format!("{n} = {}", v.get("value").map_or(String::new(), ToString::to_string)))
                        .collect()
                })
                .unwrap_or_default();
            let set = if set.is_empty() { String::new() } else { format!(" ({})", set.join(", ")) };
            println!(
                "{}: {} {}{set}, {} dofs, {} steps: {}; Newton {} (max {}), {:.2} s ({:.3} ms/step){}",
                text("case"),
                text("scheme"),
                text("contact"),
                text("dofs"),
                text("steps"),
                own.join(", "),
                text("newton_total"),
                text("newton_max"),
                s.number("wall_seconds").unwrap_or(f64::NAN),
                1e3 * s.number("seconds_per_step").unwrap_or(f64::NAN),
                s.number("peak_memory_bytes").map_or(String::new(), |b| format!(", peak memory {:.0} MB", b / 1e6))
            );
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run_file(file: &Path) -> ExitCode {
    use crate::cases::file;
    let out = |opts_out: &mut Option<PathBuf>| -> Result<(), String> {
        *opts_out = out_dir(Some(opts_out.take().unwrap_or_else(|| file::default_out(file))))?;
        Ok(())
    };
    match file::read(file) {
        Ok(mut opts) => {
            if let Err(e) = out(&mut opts.out) {
                return fail(e);
            }
            opts.progress = true;
            finish_problem(crate::problem::run::run(&opts))
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

/// Says which files ran interpreted, and how to compile them.
fn interpreted_note(files: &[String]) {
    for f in files {
        eprintln!(
            "note: {f} ran interpreted (compiled at run time, same results as compiled); to compile it, copy it into forms/ (a scheme: forms/schemes/) and rebuild"
        );
    }
}
