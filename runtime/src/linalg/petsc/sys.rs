//! The part of PETSc's C API the solver calls, declared by hand for the PETSc this feature
//! builds against (Debian's libpetsc-real3.18-dev): real double scalars, 32-bit `PetscInt`,
//! Open MPI (whose handles are pointers to its predefined objects), and the few MPI calls the
//! runs across processes make. `build.rs` checks the version through pkg-config.

// Names as in C.
#![allow(non_camel_case_types, non_upper_case_globals, clippy::upper_case_acronyms)]

use std::ffi::{c_char, c_int, c_void};

pub type PetscErrorCode = c_int;
pub type PetscInt = i32;
pub type PetscCount = isize;
pub type PetscScalar = f64;
pub type PetscReal = f64;
/// `PetscBool` is a C enum: `PETSC_FALSE` = 0, `PETSC_TRUE` = 1.
pub type PetscBool = c_int;
pub const PETSC_TRUE: PetscBool = 1;
/// Open MPI's communicator handle.
pub type MPI_Comm = *mut c_void;

macro_rules! opaque {
    ($($name:ident => $handle:ident),* $(,)?) => {$(
        #[repr(C)]
        pub struct $name {
            _private: [u8; 0],
        }
        pub type $handle = *mut $name;
    )*};
}
opaque!(
    _p_Mat => Mat,
    _p_Vec => Vec,
    _p_KSP => KSP,
    _p_PC => PC,
    _p_MatNullSpace => MatNullSpace,
    _p_PetscSF => VecScatter,
    ompi_predefined_datatype_t => MPI_Datatype,
    ompi_predefined_op_t => MPI_Op,
);

/// `InsertMode::INSERT_VALUES`.
pub const INSERT_VALUES: c_int = 1;
/// `MatOption` values (petscmat.h).
pub const MAT_SYMMETRIC: c_int = 1;
pub const MAT_SYMMETRY_ETERNAL: c_int = 10;
pub const MAT_SPD: c_int = 15;
/// `KSPNormType::KSP_NORM_UNPRECONDITIONED`, `PCSide::PC_RIGHT`.
pub const KSP_NORM_UNPRECONDITIONED: c_int = 2;
pub const PC_RIGHT: c_int = 1;
/// `ScatterMode::SCATTER_FORWARD`.
pub const SCATTER_FORWARD: c_int = 0;
/// `PETSC_DEFAULT` for tolerances.
pub const PETSC_DEFAULT: PetscReal = -2.0;

/// An error handler: PETSc calls it with the error's origin and message.
pub type ErrorHandler = unsafe extern "C" fn(
    comm: MPI_Comm,
    line: c_int,
    function: *const c_char,
    file: *const c_char,
    code: PetscErrorCode,
    kind: c_int,
    message: *const c_char,
    context: *mut c_void,
) -> PetscErrorCode;

/// Open MPI's communicator object.
#[repr(C)]
pub struct ompi_communicator_t {
    _private: [u8; 0],
}

unsafe extern "C" {
    /// Open MPI's `MPI_COMM_SELF`, `MPI_COMM_WORLD`, `MPI_INT`, `MPI_BYTE`, `MPI_DOUBLE`,
    /// `MPI_UNSIGNED_LONG_LONG`, `MPI_LOR` and `MPI_SUM` are the addresses of these
    /// objects.
    pub static ompi_mpi_comm_self: ompi_communicator_t;
    pub static ompi_mpi_comm_world: ompi_communicator_t;
    pub static ompi_mpi_int: ompi_predefined_datatype_t;
    pub static ompi_mpi_byte: ompi_predefined_datatype_t;
    pub static ompi_mpi_double: ompi_predefined_datatype_t;
    pub static ompi_mpi_unsigned_long_long: ompi_predefined_datatype_t;
    pub static ompi_mpi_op_lor: ompi_predefined_op_t;
    pub static ompi_mpi_op_sum: ompi_predefined_op_t;

    pub fn MPI_Comm_rank(comm: MPI_Comm, rank: *mut c_int) -> c_int;
    pub fn MPI_Comm_size(comm: MPI_Comm, size: *mut c_int) -> c_int;
    pub fn MPI_Allreduce(
        send: *const c_void,
        recv: *mut c_void,
        count: c_int,
        datatype: MPI_Datatype,
        op: MPI_Op,
        comm: MPI_Comm,
    ) -> c_int;
    pub fn MPI_Allgather(
        send: *const c_void,
        send_count: c_int,
        send_type: MPI_Datatype,
        recv: *mut c_void,
        recv_count: c_int,
        recv_type: MPI_Datatype,
        comm: MPI_Comm,
    ) -> c_int;
    pub fn MPI_Allgatherv(
        send: *const c_void,
        send_count: c_int,
        send_type: MPI_Datatype,
        recv: *mut c_void,
        recv_counts: *const c_int,
        displacements: *const c_int,
        recv_type: MPI_Datatype,
        comm: MPI_Comm,
    ) -> c_int;
    pub fn MPI_Bcast(buffer: *mut c_void, count: c_int, datatype: MPI_Datatype, root: c_int, comm: MPI_Comm) -> c_int;
    pub fn MPI_Abort(comm: MPI_Comm, code: c_int) -> c_int;
    /// Indexed by a `KSPConvergedReason` (negative ones too: it points inside its table).
    pub static KSPConvergedReasons: *const *const c_char;

    pub fn PetscInitializeNoArguments() -> PetscErrorCode;
    pub fn PetscInitialized(done: *mut PetscBool) -> PetscErrorCode;
    pub fn PetscFinalize() -> PetscErrorCode;
    pub fn PetscOptionsInsertString(options: *mut c_void, text: *const c_char) -> PetscErrorCode;
    pub fn PetscLogDefaultBegin() -> PetscErrorCode;
    pub fn PetscPushErrorHandler(handler: ErrorHandler, context: *mut c_void) -> PetscErrorCode;

    pub fn MatCreate(comm: MPI_Comm, mat: *mut Mat) -> PetscErrorCode;
    pub fn MatSetSizes(mat: Mat, m: PetscInt, n: PetscInt, big_m: PetscInt, big_n: PetscInt) -> PetscErrorCode;
    pub fn MatSetType(mat: Mat, kind: *const c_char) -> PetscErrorCode;
    pub fn MatSetBlockSize(mat: Mat, bs: PetscInt) -> PetscErrorCode;
    pub fn MatSetOption(mat: Mat, option: c_int, flag: PetscBool) -> PetscErrorCode;
    pub fn MatSetPreallocationCOO(mat: Mat, n: PetscCount, i: *mut PetscInt, j: *mut PetscInt) -> PetscErrorCode;
    pub fn MatSetValuesCOO(mat: Mat, values: *const PetscScalar, mode: c_int) -> PetscErrorCode;
    pub fn MatSetNearNullSpace(mat: Mat, space: MatNullSpace) -> PetscErrorCode;
    pub fn MatCreateVecs(mat: Mat, right: *mut Vec, left: *mut Vec) -> PetscErrorCode;
    pub fn MatDestroy(mat: *mut Mat) -> PetscErrorCode;

    pub fn MatNullSpaceCreateRigidBody(coords: Vec, space: *mut MatNullSpace) -> PetscErrorCode;
    pub fn MatNullSpaceDestroy(space: *mut MatNullSpace) -> PetscErrorCode;

    pub fn VecCreate(comm: MPI_Comm, vec: *mut Vec) -> PetscErrorCode;
    pub fn VecSetSizes(vec: Vec, n: PetscInt, big_n: PetscInt) -> PetscErrorCode;
    pub fn VecSetBlockSize(vec: Vec, bs: PetscInt) -> PetscErrorCode;
    pub fn VecSetFromOptions(vec: Vec) -> PetscErrorCode;
    pub fn VecGetArray(vec: Vec, array: *mut *mut PetscScalar) -> PetscErrorCode;
    pub fn VecRestoreArray(vec: Vec, array: *mut *mut PetscScalar) -> PetscErrorCode;
    pub fn VecDestroy(vec: *mut Vec) -> PetscErrorCode;
    pub fn VecScatterCreateToAll(vec: Vec, scatter: *mut VecScatter, all: *mut Vec) -> PetscErrorCode;
    pub fn VecScatterBegin(scatter: VecScatter, x: Vec, y: Vec, insert: c_int, mode: c_int) -> PetscErrorCode;
    pub fn VecScatterEnd(scatter: VecScatter, x: Vec, y: Vec, insert: c_int, mode: c_int) -> PetscErrorCode;
    pub fn VecScatterDestroy(scatter: *mut VecScatter) -> PetscErrorCode;

    pub fn KSPCreate(comm: MPI_Comm, ksp: *mut KSP) -> PetscErrorCode;
    pub fn KSPSetOperators(ksp: KSP, a: Mat, p: Mat) -> PetscErrorCode;
    pub fn KSPSetType(ksp: KSP, kind: *const c_char) -> PetscErrorCode;
    pub fn KSPGetType(ksp: KSP, kind: *mut *const c_char) -> PetscErrorCode;
    pub fn KSPGetPC(ksp: KSP, pc: *mut PC) -> PetscErrorCode;
    pub fn PCSetType(pc: PC, kind: *const c_char) -> PetscErrorCode;
    pub fn PCSetFromOptions(pc: PC) -> PetscErrorCode;
    pub fn PetscOptionsHasName(
        options: *mut c_void,
        pre: *const c_char,
        name: *const c_char,
        set: *mut PetscBool,
    ) -> PetscErrorCode;
    pub fn KSPSetTolerances(
        ksp: KSP,
        rtol: PetscReal,
        abstol: PetscReal,
        dtol: PetscReal,
        maxits: PetscInt,
    ) -> PetscErrorCode;
    pub fn KSPGetTolerances(
        ksp: KSP,
        rtol: *mut PetscReal,
        abstol: *mut PetscReal,
        dtol: *mut PetscReal,
        maxits: *mut PetscInt,
    ) -> PetscErrorCode;
    pub fn KSPSetNormType(ksp: KSP, norm: c_int) -> PetscErrorCode;
    pub fn KSPSetPCSide(ksp: KSP, side: c_int) -> PetscErrorCode;
    pub fn KSPSetFromOptions(ksp: KSP) -> PetscErrorCode;
    pub fn KSPSetReusePreconditioner(ksp: KSP, reuse: PetscBool) -> PetscErrorCode;
    pub fn KSPSolve(ksp: KSP, b: Vec, x: Vec) -> PetscErrorCode;
    pub fn KSPGetIterationNumber(ksp: KSP, its: *mut PetscInt) -> PetscErrorCode;
    pub fn KSPGetConvergedReason(ksp: KSP, reason: *mut c_int) -> PetscErrorCode;
    pub fn KSPDestroy(ksp: *mut KSP) -> PetscErrorCode;
}
