use clap::Parser;

fn main() -> std::process::ExitCode {
    signorini::cli::run(signorini::cli::Cli::parse())
}
