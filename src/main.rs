fn main() -> std::process::ExitCode {
    use signorini::runtime::linalg::ranks;
    // Behave like other command-line tools when the reader of stdout goes away
    // (`signorini run bar --all | head`): end quietly instead of panicking in println!.
    #[cfg(unix)]
    // SAFETY: restoring the default disposition of SIGPIPE before any thread starts.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    signorini::interrupt::install();
    // Under mpirun every process runs the same command; rank 0 speaks for them (its stdout and
    // logs), the others only report their errors.
    let (rank, size) = match ranks::start() {
        Ok(world) => world,
        Err(e) => {
            eprintln!("error: {e}");
            return std::process::ExitCode::FAILURE;
        }
    };
    if rank > 0 {
        quiet_stdout();
    } else {
        // Logs (Newton iterations, ...) with RUST_LOG=signorini_runtime=debug.
        tracing_subscriber::fmt()
            .with_env_filter(tracing_subscriber::EnvFilter::from_default_env())
            .with_writer(std::io::stderr)
            .init();
    }
    let code = signorini::cli::run(signorini::cli::Cli::parse_args());
    if size > 1 && code != std::process::ExitCode::SUCCESS && !signorini::interrupt::requested() {
        // A process that failed, alone or with the others: none may wait for it.
        ranks::abort(1);
    }
    if let Err(e) = signorini::runtime::linalg::finalize_petsc() {
        signorini::cli::print_error(e);
        return std::process::ExitCode::FAILURE;
    }
    code
}

/// Sends this process's stdout to /dev/null (the other ranks of an MPI run print nothing).
fn quiet_stdout() {
    #[cfg(unix)]
    if let Ok(null) = std::fs::OpenOptions::new().write(true).open("/dev/null") {
        use std::os::fd::AsRawFd;
        // SAFETY: duplicating an open descriptor over stdout's, before anything is printed.
        unsafe {
            libc::dup2(null.as_raw_fd(), libc::STDOUT_FILENO);
        }
    }
}
