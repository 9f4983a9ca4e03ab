//! The `signorini` command line: [`Cli`] and the dispatch of its subcommands to the modules
//! that carry them out. The clap types of the subcommands are in [`args`]; a problem's params as
//! options of `run` in [`problem_params`]; running problems and case files in [`run`], and the
//! lines that summarize a run in [`summary`]; `check`, `emit` and `mesh info` in [`files`];
//! `verify` in [`verify`], `bench` in [`bench`], `compare` in [`compare`], `list` in [`list`].

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Parser;

pub mod args;
mod bench;
mod compare;
mod files;
pub mod list;
mod problem_params;
mod run;
mod summary;
mod verify;

pub use args::{BenchCommand, Command, MeshCommand, Stage};
pub use files::stage_text;

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
    /// The command line, where every option's value may be negative: `--t-start -1` then gets
    /// the option's own range error instead of clap's "unexpected argument '-1'".
    pub fn parse_args() -> Self {
        use clap::{CommandFactory, FromArgMatches};
        let matches = negative_values(Self::command())
            .get_matches_from(problem_params::as_options(std::env::args_os().collect()));
        Self::from_arg_matches(&matches).unwrap_or_else(|e| e.exit())
    }
}

/// One run as `signorini run ARGS...` asks for it, read as the command line reads it (its
/// checks and messages, a problem's params as options), for a host other than the shell (the
/// Python API): a problem or a case file. `--all` runs many and is refused.
pub fn run_options(args: &[String]) -> Result<crate::problem::run::Options, String> {
    let cli = parse("run", args)?;
    let Command::Run { file: Some(file), args } = cli.command else {
        return Err("name a problem, a problem file or a case file".into());
    };
    if args.all {
        return Err("`--all` runs every scheme and contact law and prints a table: run them one by one".into());
    }
    if file.extension().is_some_and(|e| e == "toml") {
        return run::case_options(&file, cli.force).map_err(|e| e.to_string());
    }
    run::options(&file.to_string_lossy(), *args, cli.force)
}

/// The scheme and files `signorini verify --scheme ... ARGS` names (`--scheme`, `--contact`,
/// `--param`, ...), read as the command line reads them.
pub fn verify_methods(args: &[String]) -> Result<crate::driver::Methods, String> {
    match parse("verify", args)?.command {
        Command::Verify { methods, .. } if methods.scheme.is_some() => methods.to_methods(),
        _ => Err("name the scheme to verify".into()),
    }
}

/// `signorini SUBCOMMAND ARGS...` read as [`Cli::parse_args`] reads a command line; an error is
/// clap's message without its usage lines and `error: ` (a host shows its own call).
fn parse(subcommand: &str, args: &[String]) -> Result<Cli, String> {
    use clap::{CommandFactory, FromArgMatches};
    let message = |e: clap::Error| {
        let text = e.render().to_string();
        text.split("\n\nUsage:").next().unwrap_or_default().trim_end().trim_start_matches("error: ").to_string()
    };
    let argv = ["signorini", subcommand].iter().map(|s| s.into()).chain(args.iter().map(|a| a.into())).collect();
    let matches =
        negative_values(Cli::command()).try_get_matches_from(problem_params::as_options(argv)).map_err(message)?;
    Cli::from_arg_matches(&matches).map_err(message)
}

/// An option of `signorini run`: its long name, whether it takes a value and may be repeated,
/// and its help (a host that maps its own arguments onto them checks names against these).
pub struct RunOption {
    pub name: String,
    pub takes_value: bool,
    pub repeated: bool,
    pub help: String,
}

/// The options of `signorini run`, `--force` among them.
pub fn run_option_list() -> Vec<RunOption> {
    use clap::CommandFactory;
    let cmd = Cli::command();
    let force = cmd.get_arguments().filter(|a| a.get_id() == "force");
    let run = cmd.find_subcommand("run").map(|r| r.get_arguments().cloned().collect::<Vec<_>>()).unwrap_or_default();
    force
        .cloned()
        .chain(run)
        .filter_map(|a| {
            let name = a.get_long()?.to_string();
            let action = a.get_action();
            Some(RunOption {
                name,
                takes_value: action.takes_values(),
                repeated: matches!(action, clap::ArgAction::Append),
                help: a.get_help().map(ToString::to_string).unwrap_or_default(),
            })
        })
        .collect()
}

fn negative_values(cmd: clap::Command) -> clap::Command {
    cmd.mut_args(|a| if a.get_action().takes_values() { a.allow_negative_numbers(true) } else { a })
        .mut_subcommands(negative_values)
}

/// `--force`, for the output directories of every command.
static FORCE: std::sync::OnceLock<bool> = std::sync::OnceLock::new();

/// `--force`, as given.
pub(super) fn force() -> bool {
    FORCE.get().copied().unwrap_or(false)
}

/// The directory a run writes to (see `output::prepare`), announced when it is not `--out`.
pub(super) fn out_dir(out: Option<PathBuf>) -> Result<Option<PathBuf>, String> {
    let Some(dir) = out else { return Ok(None) };
    // In a run of several processes, rank 0 writes the results (and alone prepares their
    // directory).
    if !crate::runtime::linalg::ranks::writes() {
        return Ok(None);
    }
    let (dir, note) = crate::output::prepare(&dir, FORCE.get().copied().unwrap_or(false))?;
    if let Some(note) = note {
        eprintln!("note: {note}");
    }
    Ok(Some(dir))
}

/// How an error line starts: `error`, and which process saw it in a run of several.
fn error_prefix() -> String {
    match crate::runtime::linalg::ranks::world() {
        (_, 1) => "error".into(),
        (rank, size) => format!("error (rank {rank} of {size})"),
    }
}

/// Prints an error line (see [`error_prefix`]) in one write: the processes of an MPI run share
/// stderr, and their lines must not interleave.
pub fn print_error(message: impl std::fmt::Display) {
    use std::io::Write;
    let text = message.to_string();
    // A rendered diagnostic (`error[E0001]: ...`) says "error" itself: one prefix, not two.
    let line = match (text.starts_with("error[") || text.starts_with("error:"), crate::runtime::linalg::ranks::world())
    {
        (true, (_, 1)) => format!("{text}\n"),
        (true, (rank, size)) => format!("(rank {rank} of {size}) {text}\n"),
        (false, _) => format!("{}: {text}\n", error_prefix()),
    };
    let _ = std::io::stderr().lock().write_all(line.as_bytes());
}

/// Under mpirun, the threads of each process: the cores shared among the node's processes
/// (`--threads` chooses otherwise).
fn threads_per_rank() -> Option<usize> {
    let local: usize = std::env::var("OMPI_COMM_WORLD_LOCAL_SIZE").ok()?.parse().ok()?;
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    (local > 1).then(|| (cores / local).max(1))
}

/// Prints an error and fails.
pub(super) fn fail(e: impl std::fmt::Display) -> ExitCode {
    print_error(e);
    ExitCode::FAILURE
}

pub fn run(cli: Cli) -> ExitCode {
    let _ = FORCE.set(cli.force);
    let code = dispatch(cli);
    if crate::interrupt::requested() { ExitCode::from(crate::interrupt::EXIT_CODE) } else { code }
}

fn dispatch(cli: Cli) -> ExitCode {
    if let Some(n) = cli.threads.map(|n| n as usize).or_else(threads_per_rank)
        && let Err(e) = rayon::ThreadPoolBuilder::new().num_threads(n).build_global()
    {
        print_error(format_args!("cannot start {n} threads: {e}"));
        return ExitCode::FAILURE;
    }
    // The commands that run many cases and write their own files (verify, report, bench,
    // compare) run as one process; under mpirun they would repeat each other's work.
    let alone = match &cli.command {
        Command::Verify { .. } => Some("verify"),
        Command::Report { .. } => Some("report"),
        Command::Bench { .. } => Some("bench"),
        Command::Compare { .. } => Some("compare"),
        _ => None,
    };
    if let Some(name) = alone
        && crate::runtime::linalg::ranks::world().1 > 1
    {
        return fail(format!(
            "`{name}` runs as one process: under mpirun only `run` is shared among the processes (`bench sphere --ranks` launches mpirun itself)"
        ));
    }
    match cli.command {
        Command::Check { files } => files::check(&files),
        Command::Emit { file, stage, dim } => files::emit(&file, stage, dim as usize),
        Command::List => {
            print!("{}", list::text());
            ExitCode::SUCCESS
        }
        Command::Verify { out, methods } if methods.scheme.is_some() => verify::scheme(&out, &methods),
        Command::Verify { methods, .. } if methods.given() => {
            fail("--contact, --material, --forms, --param and --line-search apply to `verify --scheme` only")
        }
        Command::Verify { out, .. } => verify::library(&out),
        Command::Compare { a, b, tol } => compare::command(&a, &b, tol),
        Command::Report { out, quick } => report(out, quick),
        Command::Run { file: Some(file), .. } if file.extension().is_some_and(|e| e == "toml") => run::case_file(&file),
        Command::Run { file: Some(problem), args } => run::problem(&problem.to_string_lossy(), *args),
        Command::Run { file: None, .. } => {
            let names = crate::problem::library_names().join(", ");
            print_error(format_args!("name a problem ({names}), a problem file or a case file"));
            ExitCode::FAILURE
        }
        Command::Mesh { command: MeshCommand::Info { file } } => files::mesh_info(&file),
        Command::Bench { what: BenchCommand::Assemble { sizes, factor, repeats, out } } => {
            bench::assemble(&sizes, factor, repeats, &out)
        }
        Command::Bench { what: BenchCommand::Disc { meshes, repeats, out } } => bench::disc(&meshes, repeats, &out),
        Command::Bench { what: BenchCommand::Sphere { max_dofs, solvers, ranks, out } } => {
            bench::sphere(max_dofs, &solvers, &ranks.iter().map(|&r| r as usize).collect::<Vec<_>>(), &out)
        }
        Command::Bench { what: BenchCommand::Search { repeats, out } } => bench::search(repeats, &out),
        Command::Bench { what: BenchCommand::Balls { max_dofs, out } } => bench::balls(max_dofs, &out),
        Command::Bench { what: BenchCommand::Adaptive { out } } => bench::adaptive(&out),
    }
}

/// `report`: the talk's comparisons run and written up in `out`.
fn report(out: PathBuf, quick: bool) -> ExitCode {
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
            print_error(e);
            ExitCode::FAILURE
        }
    }
}
