//! The processes of a run that `mpirun` launched: MPI is started by PETSc (which then solves
//! every system across them, on `MPI_COMM_WORLD`); the few collective calls the driver makes
//! itself are here.

use std::ffi::{c_int, c_void};
use std::sync::OnceLock;

use super::{lock, sys};
use crate::linalg::LinalgError;

/// This process's rank and the number of processes.
static WORLD: OnceLock<(usize, usize)> = OnceLock::new();

pub(super) fn comm_world() -> sys::MPI_Comm {
    // Only the address of Open MPI's predefined communicator is taken (no read of the static).
    (&raw const sys::ompi_mpi_comm_world).cast_mut().cast()
}

/// Starts PETSc and MPI and returns (rank, size); every process of the launch calls it once,
/// before any other PETSc call.
pub fn start() -> Result<(usize, usize), LinalgError> {
    let _petsc = lock()?;
    let (mut rank, mut size): (c_int, c_int) = (0, 1);
    // SAFETY: MPI is initialized (by PETSc, under the lock); each call writes its out parameter.
    let codes = unsafe { (sys::MPI_Comm_rank(comm_world(), &mut rank), sys::MPI_Comm_size(comm_world(), &mut size)) };
    if codes != (0, 0) {
        return Err(LinalgError::Other("MPI_Comm_rank or MPI_Comm_size failed".into()));
    }
    let world = (rank.max(0) as usize, size.max(1) as usize);
    Ok(*WORLD.get_or_init(|| world))
}

/// (rank, size): (0, 1) unless [`start`] found several processes.
pub fn world() -> (usize, usize) {
    WORLD.get().copied().unwrap_or((0, 1))
}

/// Whether the systems are solved across processes.
pub(super) fn distributed() -> bool {
    world().1 > 1
}

/// Whether `flag` holds on any process (collective: every process calls it at the same point).
pub fn any(flag: bool) -> Result<bool, LinalgError> {
    if !distributed() {
        return Ok(flag);
    }
    let _petsc = lock()?;
    let (send, mut recv): (c_int, c_int) = (flag.into(), 0);
    // SAFETY: one int each way, Open MPI's predefined datatype and operation.
    let code = unsafe {
        sys::MPI_Allreduce(
            (&raw const send).cast::<c_void>(),
            (&raw mut recv).cast::<c_void>(),
            1,
            (&raw const sys::ompi_mpi_int).cast_mut().cast(),
            (&raw const sys::ompi_mpi_op_lor).cast_mut().cast(),
            comm_world(),
        )
    };
    if code != 0 {
        return Err(LinalgError::Other(format!("MPI_Allreduce failed (code {code})")));
    }
    Ok(recv != 0)
}

/// Ends every process of the launch with `code` (a process that failed alone cannot leave the
/// others waiting in a collective call).
pub fn abort(code: i32) -> ! {
    if distributed() {
        // SAFETY: MPI is running; MPI_Abort does not return when it succeeds.
        unsafe { sys::MPI_Abort(comm_world(), code) };
    }
    std::process::exit(code)
}
