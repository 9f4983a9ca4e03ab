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
    let (send, mut recv): (c_int, c_int) = (flag.into(), 0);
    // SAFETY: Open MPI's predefined int and logical or.
    let (int, or) = unsafe { (datatype(&sys::ompi_mpi_int), op(&sys::ompi_mpi_op_lor)) };
    allreduce((&raw const send).cast(), (&raw mut recv).cast(), int, or)?;
    Ok(recv != 0)
}

/// The sum of `count` over the processes (collective; exact).
pub fn total(count: u64) -> Result<u64, LinalgError> {
    let mut sum = 0u64;
    // SAFETY: Open MPI's predefined unsigned long long and sum.
    let (ull, plus) = unsafe { (datatype(&sys::ompi_mpi_unsigned_long_long), op(&sys::ompi_mpi_op_sum)) };
    allreduce((&raw const count).cast(), (&raw mut sum).cast(), ull, plus)?;
    Ok(sum)
}

/// Each process's `x`, in rank order, on every process (collective).
pub fn gather(x: f64) -> Result<Vec<f64>, LinalgError> {
    let mut all = vec![0.0; world().1];
    let _petsc = lock()?;
    // SAFETY: one double sent, one received from each process into `all` (its length).
    let code = unsafe {
        let double = datatype(&sys::ompi_mpi_double);
        sys::MPI_Allgather((&raw const x).cast(), 1, double, all.as_mut_ptr().cast(), 1, double, comm_world())
    };
    checked("MPI_Allgather", code)?;
    Ok(all)
}

/// Each process's `mine` into `all`, process p's at `all[offsets[p]..offsets[p + 1]]`
/// (collective; `mine` is this process's part, of its length).
pub fn gather_parts(mine: &[f64], offsets: &[usize], all: &mut [f64]) -> Result<(), LinalgError> {
    let int = |i: usize| c_int::try_from(i).map_err(|_| LinalgError::Other(format!("{i} values are too many for MPI")));
    let counts: Vec<c_int> = offsets.windows(2).map(|w| int(w[1] - w[0])).collect::<Result<_, _>>()?;
    let starts: Vec<c_int> = offsets[..offsets.len() - 1].iter().map(|&o| int(o)).collect::<Result<_, _>>()?;
    assert_eq!(all.len(), offsets[offsets.len() - 1], "the whole length");
    let _petsc = lock()?;
    // SAFETY: `mine` has this process's count; `all` holds every part at its offset.
    let code = unsafe {
        let double = datatype(&sys::ompi_mpi_double);
        sys::MPI_Allgatherv(
            mine.as_ptr().cast(),
            int(mine.len())?,
            double,
            all.as_mut_ptr().cast(),
            counts.as_ptr(),
            starts.as_ptr(),
            double,
            comm_world(),
        )
    };
    checked("MPI_Allgatherv", code)
}

/// Rank 0's `bytes` on every process (the others' are replaced). Collective.
pub fn broadcast(bytes: &mut Vec<u8>) -> Result<(), LinalgError> {
    let mut len = u64::try_from(bytes.len()).unwrap_or(u64::MAX);
    let _petsc = lock()?;
    // SAFETY: one unsigned long long, then `len` bytes into a buffer of that length.
    unsafe {
        let ull = datatype(&sys::ompi_mpi_unsigned_long_long);
        checked("MPI_Bcast", sys::MPI_Bcast((&raw mut len).cast(), 1, ull, 0, comm_world()))?;
        let count =
            c_int::try_from(len).map_err(|_| LinalgError::Other(format!("{len} bytes are too many for MPI")))?;
        bytes.resize(count as usize, 0);
        // Nothing to send: an empty vector's pointer is not one MPI accepts.
        if count == 0 {
            return Ok(());
        }
        checked(
            "MPI_Bcast",
            sys::MPI_Bcast(bytes.as_mut_ptr().cast(), count, datatype(&sys::ompi_mpi_byte), 0, comm_world()),
        )
    }
}

/// Open MPI's handle of a predefined datatype: the object's address.
unsafe fn datatype(object: &sys::ompi_predefined_datatype_t) -> sys::MPI_Datatype {
    (&raw const *object).cast_mut()
}

/// Open MPI's handle of a predefined operation: the object's address.
unsafe fn op(object: &sys::ompi_predefined_op_t) -> sys::MPI_Op {
    (&raw const *object).cast_mut()
}

/// One value of `datatype` reduced by `op` over the processes.
fn allreduce(
    send: *const c_void,
    recv: *mut c_void,
    datatype: sys::MPI_Datatype,
    op: sys::MPI_Op,
) -> Result<(), LinalgError> {
    let _petsc = lock()?;
    // SAFETY: one value of `datatype` each way, at addresses the callers own.
    let code = unsafe { sys::MPI_Allreduce(send, recv, 1, datatype, op, comm_world()) };
    checked("MPI_Allreduce", code)
}

fn checked(function: &str, code: c_int) -> Result<(), LinalgError> {
    match code {
        0 => Ok(()),
        _ => Err(LinalgError::Other(format!("{function} failed (code {code})"))),
    }
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
