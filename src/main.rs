fn main() -> std::process::ExitCode {
    // Behave like other command-line tools when the reader of stdout goes away
    // (`signorini run bar --all | head`): end quietly instead of panicking in println!.
    #[cfg(unix)]
    // SAFETY: restoring the default disposition of SIGPIPE before any thread starts.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    signorini::interrupt::install();
    // Logs (Newton iterations, ...) with RUST_LOG=signorini_runtime=debug.
    tracing_subscriber::fmt()
        .with_env_filter(tracing_subscriber::EnvFilter::from_default_env())
        .with_writer(std::io::stderr)
        .init();
    let code = signorini::cli::run(signorini::cli::Cli::parse_args());
    if let Err(e) = signorini::runtime::linalg::finalize_petsc() {
        eprintln!("error: {e}");
        return std::process::ExitCode::FAILURE;
    }
    code
}
