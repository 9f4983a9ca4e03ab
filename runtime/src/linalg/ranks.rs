//! The processes of a run that Open MPI's `mpirun` launched (feature `petsc`): every process
//! holds the whole state and takes the same steps, assembling the rows of the nodes it owns
//! (`linalg::ownership`); PETSc solves each linear system across them, each process giving its
//! own rows and receiving the whole solution. Without the feature, or outside `mpirun`, there
//! is one process.

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
    if world().1 == 1 {
        return Ok(flag);
    }
    #[cfg(feature = "petsc")]
    return crate::linalg::petsc::ranks::any(flag);
    #[cfg(not(feature = "petsc"))]
    Ok(flag)
}

/// The sum of each process's `x`, added in rank order from rank 0's: the same bits on every
/// process and in every run on as many processes (MPI's own sum may add in any order).
/// Collective.
pub fn sum(x: f64) -> Result<f64, LinalgError> {
    if world().1 == 1 {
        return Ok(x);
    }
    #[cfg(feature = "petsc")]
    return Ok(crate::linalg::petsc::ranks::gather(x)?.into_iter().reduce(|a, b| a + b).unwrap_or(x));
    #[cfg(not(feature = "petsc"))]
    Ok(x)
}

/// The largest of each process's `x` (exact: the same bits on every process). Collective.
pub fn max(x: f64) -> Result<f64, LinalgError> {
    if world().1 == 1 {
        return Ok(x);
    }
    #[cfg(feature = "petsc")]
    return Ok(crate::linalg::petsc::ranks::gather(x)?.into_iter().fold(x, f64::max));
    #[cfg(not(feature = "petsc"))]
    Ok(x)
}

/// The sum of each process's `count` (exact). Collective.
pub fn total(count: u64) -> Result<u64, LinalgError> {
    if world().1 == 1 {
        return Ok(count);
    }
    #[cfg(feature = "petsc")]
    return crate::linalg::petsc::ranks::total(count);
    #[cfg(not(feature = "petsc"))]
    Ok(count)
}

/// Rank 0's `bytes` on every process. Collective.
pub fn broadcast(bytes: &mut Vec<u8>) -> Result<(), LinalgError> {
    if world().1 == 1 {
        return Ok(());
    }
    #[cfg(feature = "petsc")]
    return crate::linalg::petsc::ranks::broadcast(bytes);
    #[cfg(not(feature = "petsc"))]
    {
        let _ = bytes;
        Ok(())
    }
}

/// Every process's part into `all`, process p's `offsets[p]..offsets[p + 1]`; this process's is
/// `mine`. Collective.
pub fn gather_parts(mine: &[f64], offsets: &[usize], all: &mut [f64]) -> Result<(), LinalgError> {
    if world().1 == 1 {
        all.copy_from_slice(mine);
        return Ok(());
    }
    #[cfg(feature = "petsc")]
    return crate::linalg::petsc::ranks::gather_parts(mine, offsets, all);
    #[cfg(not(feature = "petsc"))]
    {
        let _ = offsets;
        Ok(())
    }
}

/// Ends this process and, in a run of several, every other one with `code` (a process that
/// fails alone must not leave the others waiting for it).
pub fn abort(code: i32) -> ! {
    #[cfg(feature = "petsc")]
    crate::linalg::petsc::ranks::abort(code);
    #[cfg(not(feature = "petsc"))]
    std::process::exit(code)
}
