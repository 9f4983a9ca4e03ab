use clap::Parser;

fn main() -> std::process::ExitCode {
    // Logs (Newton iterations, ...) with RUST_LOG=signorini_runtime=debug.
    tracing_subscriber::fmt()
        .with_env_filter(tracing_subscriber::EnvFilter::from_default_env())
        .with_writer(std::io::stderr)
        .init();
    signorini::cli::run(signorini::cli::Cli::parse())
}
