//! The `signorini` command line: `check` and `emit` for .wf files.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand, ValueEnum};

use crate::compiler::{self, FsLoader};

#[derive(Parser)]
#[command(
    name = "signorini",
    version,
    about = "Dynamic contact mechanics: weak-form compiler and finite-element runtime"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand)]
pub enum Command {
    /// Check .wf files; print every diagnostic; exit 1 if any has an error.
    Check {
        #[arg(required = true)]
        files: Vec<PathBuf>,
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

#[derive(Clone, Copy, ValueEnum)]
pub enum Stage {
    Ast,
    Ir,
    Rust,
}

pub fn run(cli: Cli) -> ExitCode {
    match cli.command {
        Command::Check { files } => check(&files),
        Command::Emit { file, stage, dim } => emit(&file, stage, dim as usize),
    }
}

fn check(files: &[PathBuf]) -> ExitCode {
    let mut failed = false;
    for f in files {
        match compiler::check_path(f, &FsLoader) {
            Ok((_, warnings)) => eprint!("{warnings}"),
            Err(e) => {
                eprint!("{e}");
                failed = true;
            }
        }
    }
    if failed { ExitCode::FAILURE } else { ExitCode::SUCCESS }
}

fn emit(file: &Path, stage: Stage, dim: usize) -> ExitCode {
    let (prog, warnings) = match compiler::check_path(file, &FsLoader) {
        Ok(p) => p,
        Err(e) => {
            eprint!("{e}");
            return ExitCode::FAILURE;
        }
    };
    eprint!("{warnings}");
    let out = match stage {
        Stage::Ast => {
            let (ast, _) = compiler::syntax::parse(prog.root, prog.sources.text(prog.root));
            Ok(compiler::syntax::print::print_file(&ast, &prog.sources))
        }
        Stage::Ir => {
            let ir = compiler::ir::build(&prog, dim);
            let params: Vec<String> = prog.params.iter().map(|p| p.name.clone()).collect();
            let coefs: Vec<String> = prog.coefs.iter().map(|c| c.name.clone()).collect();
            Ok(compiler::ir::print::print(&ir, &params, &coefs))
        }
        Stage::Rust => {
            let opts = compiler::codegen::Options {
                runtime: compiler::codegen::DEFAULT_RUNTIME.to_string(),
                module: compiler::module_name(file),
                source_name: compiler::display_name(file),
            };
            compiler::codegen::generate_pretty(&prog, &opts)
        }
    };
    match out {
        Ok(text) => {
            print!("{text}");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
