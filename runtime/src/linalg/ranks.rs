//! The processes of a run that Open MPI's `mpirun` launched (feature `petsc`): every process
//! holds the whole problem and takes the same steps; PETSc solves each linear system across
//! them, each process giving its own rows and receiving the whole solution. Without the feature,
//! or outside `mpirun`, there is one process.

use crate::linalg::LinalgError;

/// The processes `mpirun` launched, from its environment (1 outside `mpirun`).
fn launched() -> usize {
    std::env::var("OMPI_COMM_WORLD_SIZE").ok().and_then(|s| s.parse().ok()).unwrap_or(1)
}

/// Starts MPI when `mpirun` launched several processes, and returns (rank, size). Every
/// process calls it first thing.
pub fn start() -> Result<(usize, usize), LinalgError> {
    if launched() <= 1 {
        return Ok((0, 1));
    }
    #[cfg(feature = "petsc")]
    return crate::linalg::petsc::ranks::start();
    #[cfg(not(feature = "petsc"))]
    Err(LinalgError::Other(format!(
        "mpirun launched {} processes, but this signorini was built without MPI: build it with `--features petsc` (README: Large runs)",
        launched()
    )))
}

/// (rank, size): (0, 1) in a run of one process.
pub fn world() -> (usize, usize) {
    #[cfg(feature = "petsc")]
    return crate::linalg::petsc::ranks::world();
    #[cfg(not(feature = "petsc"))]
    (0, 1)
}

/// Whether this is the process that writes the run's results (rank 0).
pub fn writes() -> bool {
    world().0 == 0
}

/// Whether `flag` holds on any process: collective, every process calls it at the same point
/// of the run (a decision that one process may see alone, an interrupt, becomes everyone's).
pub fn any(flag: bool) -> Result<bool, LinalgError> {
    #[cfg(feature = "petsc")]
    return crate::linalg::petsc::ranks::any(flag);
    #[cfg(not(feature = "petsc"))]
    Ok(flag)
}

/// Ends this process and, in a run of several, every other one with `code` (a process that
/// fails alone must not leave the others waiting for it).
pub fn abort(code: i32) -> ! {
    #[cfg(feature = "petsc")]
    crate::linalg::petsc::ranks::abort(code);
    #[cfg(not(feature = "petsc"))]
    std::process::exit(code)
}
