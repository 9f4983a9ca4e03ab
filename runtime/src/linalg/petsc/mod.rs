//! PETSc as a linear solver (feature `petsc`): Krylov methods (conjugate gradients for
//! symmetric tangents, GMRES otherwise) preconditioned by block Jacobi with ILU(0) per process,
//! or by GAMG, whose near-null space is the rigid-body modes of the nodes' coordinates, where
//! one level does not do (see [`ONE_LEVEL_LIMIT`]); any of which the user's PETSc options
//! replace (`-ksp_type preonly -pc_type lu -pc_factor_mat_solver_type mumps`).
//!
//! Every PETSc call goes through [`call`], which turns an error code into a
//! [`LinalgError::Petsc`] with PETSc's own message (an error handler records it instead of
//! printing), so that no PETSc error aborts the process. PETSc is not thread-safe: every
//! operation holds one process-wide lock ([`lock`]).

pub mod ranks;
mod sys;

use std::cell::{Cell, RefCell};
use std::ffi::{CStr, CString, c_char, c_int, c_void};
use std::sync::{Arc, Mutex, MutexGuard};

use crate::linalg::pattern::Pattern;
use crate::linalg::{LinalgError, Matrix};

thread_local! {
    /// The message of the last error PETSc raised on this thread.
    static LAST_ERROR: RefCell<String> = const { RefCell::new(String::new()) };
}

/// Records the first report of an error (PETSc calls the handler again for each function the
/// error passes through on its way up).
unsafe extern "C" fn record_error(
    _comm: sys::MPI_Comm,
    _line: c_int,
    function: *const c_char,
    _file: *const c_char,
    code: sys::PetscErrorCode,
    kind: c_int,
    message: *const c_char,
    _context: *mut c_void,
) -> sys::PetscErrorCode {
    let text = |p: *const c_char| {
        if p.is_null() {
            String::new()
        } else {
            // SAFETY: PETSc passes NUL-terminated strings that live for the call.
            unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned()
        }
    };
    const PETSC_ERROR_INITIAL: c_int = 0;
    if kind == PETSC_ERROR_INITIAL {
        let what = format!("{}: {}", text(function), text(message).trim());
        LAST_ERROR.with(|e| *e.borrow_mut() = what);
    }
    code
}

/// `Ok` for PETSc's success code; otherwise the error with the message PETSc recorded.
fn call(function: &'static str, code: sys::PetscErrorCode) -> Result<(), LinalgError> {
    if code == 0 {
        return Ok(());
    }
    let message = LAST_ERROR.with(|e| std::mem::take(&mut *e.borrow_mut()));
    Err(LinalgError::Petsc { function, code, message })
}

/// Whether PETSc has started, and whether it has ended (it cannot start again).
struct State {
    started: bool,
    finished: bool,
}

static STATE: Mutex<State> = Mutex::new(State { started: false, finished: false });

thread_local! {
    /// Whether this thread holds [`STATE`]'s lock (objects dropped under it must not take it
    /// again).
    static HOLDING: Cell<bool> = const { Cell::new(false) };
}

/// The process-wide lock, held.
struct Held(MutexGuard<'static, State>);

impl Drop for Held {
    fn drop(&mut self) {
        HOLDING.set(false);
    }
}

/// The lock every use of PETSc holds, with PETSc started (once per process, reading
/// `PETSC_OPTIONS`, errors recorded rather than printed).
fn lock() -> Result<Held, LinalgError> {
    // A panic while holding the lock leaves PETSc's objects as they were: still usable.
    let mut state = Held(STATE.lock().unwrap_or_else(|poisoned| poisoned.into_inner()));
    HOLDING.set(true);
    if state.0.finished {
        return Err(LinalgError::Other("PETSc was used after it ended (finalize_petsc)".into()));
    }
    if !state.0.started {
        let mut done: sys::PetscBool = 0;
        // SAFETY: PetscInitialized only writes the flag.
        call("PetscInitialized", unsafe { sys::PetscInitialized(&mut done) })?;
        if done == 0 {
            // SAFETY: called once, under the lock, before any other PETSc object exists.
            call("PetscInitializeNoArguments", unsafe { sys::PetscInitializeNoArguments() })?;
        }
        // SAFETY: the handler has PETSc's handler signature and keeps no context.
        call("PetscPushErrorHandler", unsafe { sys::PetscPushErrorHandler(record_error, std::ptr::null_mut()) })?;
        state.0.started = true;
    }
    Ok(state)
}

/// Options for every PETSc solver of this process, in PETSc's syntax (`-ksp_rtol 1e-8
/// -pc_type hypre`); they are applied over the solver's defaults, as `PETSC_OPTIONS` is.
pub fn set_options(options: &str) -> Result<(), LinalgError> {
    let _petsc = lock()?;
    insert_options(options)
}

fn insert_options(options: &str) -> Result<(), LinalgError> {
    let text = CString::new(options).map_err(|_| LinalgError::Other("PETSc options contain a NUL byte".into()))?;
    // SAFETY: a NUL-terminated string; a null options database means the global one.
    call("PetscOptionsInsertString", unsafe { sys::PetscOptionsInsertString(std::ptr::null_mut(), text.as_ptr()) })?;
    // PETSc reads -log_view when it starts, before these options: its log is started here
    // (PetscFinalize fails otherwise).
    if options.split_whitespace().any(|o| o.starts_with("-log_view")) {
        // SAFETY: PETSc is initialized; starting its default log twice is harmless.
        call("PetscLogDefaultBegin", unsafe { sys::PetscLogDefaultBegin() })?;
    }
    Ok(())
}

/// Ends PETSc (writing what `-log_view` and the like asked for), if it started; no PETSc
/// solver may be used afterwards.
pub fn finalize() -> Result<(), LinalgError> {
    let mut state = lock_if_started()?;
    if let Some(state) = state.as_mut() {
        // SAFETY: PETSc started and, the caller says, none of its objects is used again.
        call("PetscFinalize", unsafe { sys::PetscFinalize() })?;
        state.0.finished = true;
    }
    Ok(())
}

fn lock_if_started() -> Result<Option<Held>, LinalgError> {
    let state = STATE.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    let (started, finished) = (state.started, state.finished);
    drop(state);
    if started && !finished { lock().map(Some) } else { Ok(None) }
}

/// The processes that solve a system together: all of an `mpirun` launch, or this one alone.
fn comm() -> sys::MPI_Comm {
    if ranks::distributed() { ranks::comm_world() } else { comm_self() }
}

fn comm_self() -> sys::MPI_Comm {
    // Only the address of Open MPI's predefined communicator is taken (no read of the static).
    (&raw const sys::ompi_mpi_comm_self).cast_mut().cast()
}

/// An index as PETSc's 32-bit `PetscInt`.
fn petsc_int(i: usize) -> Result<sys::PetscInt, LinalgError> {
    sys::PetscInt::try_from(i).map_err(|_| {
        LinalgError::Other(format!(
            "{i} does not fit PETSc's 32-bit indices (a PETSc built with 64-bit indices is needed)"
        ))
    })
}

macro_rules! handle {
    ($name:ident, $raw:ty, $destroy:ident) => {
        /// Owns a PETSc object, destroyed when dropped.
        struct $name($raw);
        impl Drop for $name {
            fn drop(&mut self) {
                if !self.0.is_null() {
                    // SAFETY: the object was created by PETSc and is destroyed once, here.
                    unsafe { sys::$destroy(&mut self.0) };
                }
            }
        }
    };
}
handle!(OwnedMat, sys::Mat, MatDestroy);
handle!(OwnedVec, sys::Vec, VecDestroy);
handle!(OwnedKsp, sys::KSP, KSPDestroy);
handle!(OwnedNullSpace, sys::MatNullSpace, MatNullSpaceDestroy);
handle!(OwnedScatter, sys::VecScatter, VecScatterDestroy);

mod layout;
use layout::Layout;
pub use layout::partition_nodes;

impl OwnedVec {
    /// Runs `f` on the vector's values.
    fn with_values<T>(&mut self, n: usize, f: impl FnOnce(&mut [f64]) -> T) -> Result<T, LinalgError> {
        let mut array: *mut f64 = std::ptr::null_mut();
        // SAFETY: the vector is valid; PETSc hands out its local array until restored.
        call("VecGetArray", unsafe { sys::VecGetArray(self.0, &mut array) })?;
        // SAFETY: a local array of `n` values (the caller's size of this vector), restored below.
        let out = f(unsafe { std::slice::from_raw_parts_mut(array, n) });
        // SAFETY: the array obtained above.
        call("VecRestoreArray", unsafe { sys::VecRestoreArray(self.0, &mut array) })?;
        Ok(out)
    }
}

/// A Krylov solver of PETSc for one matrix pattern, whose values change between solves.
pub struct PetscSolver {
    ksp: OwnedKsp,
    matrix: OwnedMat,
    rhs: OwnedVec,
    solution: OwnedVec,
    pattern: Arc<Pattern>,
    /// The values PETSc holds, when each process holds the whole matrix: the same values again
    /// keep the preconditioner (whose setup, GAMG's above all, costs solves). In a split run
    /// (each process holding its part, `Pattern::ownership`) each compares its own rows, which
    /// are what PETSc holds of it (`Split::buffer`).
    values: Vec<f64>,
    /// Across processes: the split, and what gathers the solution on every process.
    split: Option<Split>,
    /// Iterations per digit gained (see [`digits`]) of the first solve with the preconditioner in
    /// use; none when the next solve sets one up.
    baseline: Option<f64>,
    /// Whether the preconditioner in use has stopped serving (a solve took more than
    /// [`LAG_GROWTH`] times the first's iterations): the next new values get one of their own.
    stale: bool,
    /// The Krylov method's tolerances (ours, or the user's options): a solve with a kept
    /// preconditioner stops earlier and sets one up again.
    tolerances: (f64, f64, f64, sys::PetscInt),
    /// The relative tolerance is the user's (`-ksp_rtol`), not the caller's.
    user_rtol: bool,
    /// The preconditioner is still the first choice, block Jacobi, and may become GAMG (see
    /// [`ONE_LEVEL_LIMIT`]); false once it has, or when the user chose one (`-pc_type`).
    adaptive: bool,
    /// The KSP applies its preconditioner once (`-ksp_type preonly`, a factorization through
    /// PETSc): the preconditioner is the solve, so it is never kept for new values.
    preonly: bool,
    /// Krylov iterations of the last solve.
    pub iterations: usize,
    /// Preconditioners set up so far.
    pub setups: usize,
}

/// A preconditioner is kept for new values (Newton's next tangent, the contact terms changed)
/// until a solve takes more than this many times the iterations of its first solve: a GAMG
/// setup costs tens of iterations (an ILU(0) a few), while the preconditioner of a nearby
/// matrix costs a few.
const LAG_GROWTH: f64 = 2.0;

/// The decimal digits a solve to the relative tolerance `rtol` gains (at least one): the solves'
/// tolerances vary (inexact Newton), so iterations are compared per digit.
fn digits(rtol: f64) -> f64 {
    (-rtol.log10()).max(1.0)
}

/// Iterations per digit gained above which a solve with a new block-Jacobi preconditioner
/// gives up, and the solver turns to GAMG and solves again (until its next checkpoint, which
/// starts every solver afresh). A time step's matrix c·M + K + J_C, c ∝ 1/Δt², is conditioned
/// by its mass term: on the sphere through impact (Newmark, Δt = 0.02) block Jacobi with ILU(0)
/// per process took 15 iterations per solve at 108k unknowns and 22 at 274k, GAMG 16 and 25,
/// each of GAMG's costing 3.1 of block Jacobi's (3.4 against 12.5 s per step at 274k); under
/// 2 per digit. A stiffness alone is not: the static Hertz ball at 51k unknowns took 212
/// iterations per solve to 1e-12 (18 per digit) against GAMG's 39 (36.5 against 27.3 s). The
/// limit sits between.
const ONE_LEVEL_LIMIT: f64 = 8.0;

/// A system solved across processes. Every process holds the whole matrix and right-hand side
/// (it assembled them); it gives PETSc its own rows, and receives the whole solution.
struct Split {
    layout: Arc<Layout>,
    /// The indices in the matrix's values of this process's entries, in the order PETSc was
    /// given them.
    picked: Vec<usize>,
    /// Their values.
    buffer: Vec<f64>,
    gather: OwnedScatter,
    /// The whole solution, in PETSc's numbering.
    all: OwnedVec,
}

// SAFETY: the PETSc objects are owned by this value alone, and every PETSc call holds the
// process-wide lock, so PETSc is never entered from two threads at once.
unsafe impl Send for PetscSolver {}

impl PetscSolver {
    /// A solver for `a`'s pattern with `a`'s values: CG (`symmetric`) or GMRES, preconditioned
    /// by block Jacobi, or GAMG with the rigid-body modes of `coordinates` (`nodes × dim`,
    /// row-major, when the unknowns are the nodes' displacements) where block Jacobi needs too
    /// many iterations, stopping at a relative residual `rtol`; the user's options then apply.
    pub fn new(a: &Matrix, symmetric: bool, coordinates: Option<&[f64]>, rtol: f64) -> Result<Self, LinalgError> {
        let _petsc = lock()?;
        let n = a.size();
        let size = petsc_int(n)?;
        let comm = comm();
        let layout = match ranks::distributed() {
            true => {
                let (rank, count) = ranks::world();
                Some(Layout::of(&a.pattern, rank, count)?)
            }
            false => None,
        };
        let local_n = layout.as_ref().map_or(n, |l| l.mine.len());
        let local = petsc_int(local_n)?;
        let mut matrix = OwnedMat(std::ptr::null_mut());
        // SAFETY: PETSc is initialized; each call gets valid handles and writes only its out
        // parameters.
        unsafe {
            call("MatCreate", sys::MatCreate(comm, &mut matrix.0))?;
            call("MatSetSizes", sys::MatSetSizes(matrix.0, local, local, size, size))?;
            call("MatSetType", sys::MatSetType(matrix.0, c"aij".as_ptr()))?;
            call("MatSetBlockSize", sys::MatSetBlockSize(matrix.0, petsc_int(a.pattern.dim())?))?;
        }
        let p = &a.pattern;
        let mut rows = Vec::with_capacity(p.nnz());
        let mut cols = Vec::with_capacity(p.nnz());
        let mut picked = Vec::new();
        for j in 0..n {
            for k in p.col_ptr[j]..p.col_ptr[j + 1] {
                let i = p.row_idx[k];
                match &layout {
                    // This process's rows only, in PETSc's numbering.
                    Some(l) => {
                        let row = l.to_petsc[i] as usize;
                        if (l.first..l.first + local_n).contains(&row) {
                            rows.push(l.to_petsc[i]);
                            cols.push(l.to_petsc[j]);
                            picked.push(k);
                        }
                    }
                    None => {
                        rows.push(petsc_int(i)?);
                        cols.push(petsc_int(j)?);
                    }
                }
            }
        }
        // SAFETY: `rows` and `cols` hold nnz indices each (PETSc copies them).
        unsafe {
            call(
                "MatSetPreallocationCOO",
                sys::MatSetPreallocationCOO(
                    matrix.0,
                    rows.len() as sys::PetscCount,
                    rows.as_mut_ptr(),
                    cols.as_mut_ptr(),
                ),
            )?;
            if symmetric {
                for option in [sys::MAT_SYMMETRIC, sys::MAT_SYMMETRY_ETERNAL, sys::MAT_SPD] {
                    call("MatSetOption", sys::MatSetOption(matrix.0, option, sys::PETSC_TRUE))?;
                }
            }
        }
        let dim = p.dim();
        if let Some(coords) = coordinates.filter(|c| c.len() == n) {
            let mut vec = OwnedVec(std::ptr::null_mut());
            // SAFETY: a vector of the coordinates' length with block size `dim`.
            unsafe {
                call("VecCreate", sys::VecCreate(comm, &mut vec.0))?;
                call("VecSetSizes", sys::VecSetSizes(vec.0, local, size))?;
                call("VecSetBlockSize", sys::VecSetBlockSize(vec.0, petsc_int(dim)?))?;
                call("VecSetFromOptions", sys::VecSetFromOptions(vec.0))?;
            }
            vec.with_values(local_n, |v| match &layout {
                Some(l) => v.iter_mut().zip(&l.mine).for_each(|(x, &dof)| *x = coords[dof]),
                None => v.copy_from_slice(coords),
            })?;
            let mut space = OwnedNullSpace(std::ptr::null_mut());
            // SAFETY: the matrix keeps its own reference to the null space.
            unsafe {
                call("MatNullSpaceCreateRigidBody", sys::MatNullSpaceCreateRigidBody(vec.0, &mut space.0))?;
                call("MatSetNearNullSpace", sys::MatSetNearNullSpace(matrix.0, space.0))?;
            }
        }
        let (mut solution, mut rhs) = (OwnedVec(std::ptr::null_mut()), OwnedVec(std::ptr::null_mut()));
        // SAFETY: vectors compatible with the matrix.
        call("MatCreateVecs", unsafe { sys::MatCreateVecs(matrix.0, &mut solution.0, &mut rhs.0) })?;
        let mut ksp = OwnedKsp(std::ptr::null_mut());
        let mut pc: sys::PC = std::ptr::null_mut();
        // SAFETY: a KSP on the matrix; the PC handle is borrowed from it.
        unsafe {
            call("KSPCreate", sys::KSPCreate(comm, &mut ksp.0))?;
            call("KSPSetType", sys::KSPSetType(ksp.0, if symmetric { c"cg" } else { c"gmres" }.as_ptr()))?;
            call("KSPGetPC", sys::KSPGetPC(ksp.0, &mut pc))?;
            call("PCSetType", sys::PCSetType(pc, c"bjacobi".as_ptr()))?;
            // The tolerance bounds the true residual ‖b − A x‖ / ‖b‖, as the other solvers':
            // GMRES then preconditions on the right.
            call("KSPSetNormType", sys::KSPSetNormType(ksp.0, sys::KSP_NORM_UNPRECONDITIONED))?;
            if !symmetric {
                call("KSPSetPCSide", sys::KSPSetPCSide(ksp.0, sys::PC_RIGHT))?;
            }
            call("KSPSetTolerances", sys::KSPSetTolerances(ksp.0, rtol, 0.0, sys::PETSC_DEFAULT, 10_000))?;
            call("KSPSetFromOptions", sys::KSPSetFromOptions(ksp.0))?;
        }
        let mut tolerances = (0.0, 0.0, 0.0, 0);
        // SAFETY: a valid KSP writing its four tolerances.
        call("KSPGetTolerances", unsafe {
            sys::KSPGetTolerances(ksp.0, &mut tolerances.0, &mut tolerances.1, &mut tolerances.2, &mut tolerances.3)
        })?;
        // `-ksp_rtol` given by the user stands, otherwise each solve's is Newton's; `-pc_type`
        // given by the user is kept.
        let (user_rtol, user_pc) = (given(c"-ksp_rtol")?, given(c"-pc_type")?);
        let mut kind: *const c_char = std::ptr::null();
        // SAFETY: a valid KSP; the type string is PETSc's own, read here only.
        call("KSPGetType", unsafe { sys::KSPGetType(ksp.0, &mut kind) })?;
        // SAFETY: PETSc returns a NUL-terminated name (or null before a type is set).
        let preonly = !kind.is_null() && unsafe { CStr::from_ptr(kind) } == c"preonly";
        let split = match layout {
            Some(layout) => {
                let (mut gather, mut all) = (OwnedScatter(std::ptr::null_mut()), OwnedVec(std::ptr::null_mut()));
                // SAFETY: a scatter from the distributed solution to a whole copy on each process.
                call("VecScatterCreateToAll", unsafe {
                    sys::VecScatterCreateToAll(solution.0, &mut gather.0, &mut all.0)
                })?;
                let buffer = vec![0.0; picked.len()];
                Some(Split { layout, picked, buffer, gather, all })
            }
            None => None,
        };
        let mut solver = PetscSolver {
            ksp,
            matrix,
            rhs,
            solution,
            pattern: a.pattern.clone(),
            values: Vec::new(),
            split,
            baseline: None,
            stale: false,
            tolerances,
            user_rtol,
            adaptive: !user_pc,
            preonly,
            iterations: 0,
            setups: 0,
        };
        solver.take_values(a)?;
        Ok(solver)
    }

    /// Whether `a` has the pattern this solver was built for.
    pub fn fits(&self, a: &Matrix) -> bool {
        Arc::ptr_eq(&self.pattern, &a.pattern)
    }

    /// Takes `a`'s values (same pattern); the preconditioner of the last values is kept while it
    /// serves (see [`LAG_GROWTH`]), and rebuilt at the next solve otherwise.
    pub fn set_values(&mut self, a: &Matrix) -> Result<(), LinalgError> {
        // Setting values is collective: in a split run every process sets them when any
        // process's part changed (asked before PETSc's lock, which the exchange takes).
        let same = match (a.pattern.ownership(), &self.split) {
            (Some(o), Some(s)) => !o.any(s.picked.iter().zip(&s.buffer).any(|(&k, v)| a.values[k] != *v)),
            _ => self.values == a.values,
        };
        if same {
            return Ok(());
        }
        let _petsc = lock()?;
        self.take_values(a)
    }

    fn take_values(&mut self, a: &Matrix) -> Result<(), LinalgError> {
        debug_assert!(self.fits(a));
        if a.pattern.ownership().is_none() {
            self.values.clone_from(&a.values);
        }
        let values = match &mut self.split {
            Some(s) => {
                s.buffer.iter_mut().zip(&s.picked).for_each(|(v, &k)| *v = a.values[k]);
                s.buffer.as_ptr()
            }
            None => a.values.as_ptr(),
        };
        // SAFETY: the values are in the order of the COO indices given at creation (column by
        // column of the same pattern: all of them, or this process's rows), as many.
        unsafe {
            call("MatSetValuesCOO", sys::MatSetValuesCOO(self.matrix.0, values, sys::INSERT_VALUES))?;
            call("KSPSetOperators", sys::KSPSetOperators(self.ksp.0, self.matrix.0, self.matrix.0))?;
        }
        self.reuse(self.baseline.is_some() && !self.stale)
    }

    /// Whether the next solve keeps the preconditioner it has (the Krylov method always applies
    /// the matrix's current values; with `preonly` there is none, and it is never kept).
    fn reuse(&mut self, keep: bool) -> Result<(), LinalgError> {
        if !keep {
            (self.baseline, self.stale) = (None, false);
        }
        let keep = keep && !self.preonly;
        // SAFETY: a valid KSP; the flag only decides whether KSPSolve sets the PC up again.
        call("KSPSetReusePreconditioner", unsafe { sys::KSPSetReusePreconditioner(self.ksp.0, keep.into()) })
    }

    /// One Krylov solve of the right-hand side in place: its iterations and PETSc's reason.
    fn krylov(&mut self) -> Result<(usize, c_int), LinalgError> {
        let (rtol, abstol, dtol, most) = self.tolerances;
        let digits = digits(rtol);
        let cap = |its: f64| most.min(its.ceil() as sys::PetscInt);
        let limit = match self.baseline {
            // With a kept preconditioner, past a few times its first solve's iterations (per
            // digit gained) a new one is cheaper.
            Some(rate) => cap(4.0 * rate * digits + 20.0),
            // A new block-Jacobi preconditioner that needs more than this is replaced by GAMG.
            None if self.adaptive => cap(ONE_LEVEL_LIMIT * digits),
            None => most,
        };
        let (mut its, mut reason): (sys::PetscInt, c_int) = (0, 0);
        // SAFETY: vectors and KSP created together for this size.
        unsafe {
            call("KSPSetTolerances", sys::KSPSetTolerances(self.ksp.0, rtol, abstol, dtol, limit))?;
            call("KSPSolve", sys::KSPSolve(self.ksp.0, self.rhs.0, self.solution.0))?;
            call("KSPGetIterationNumber", sys::KSPGetIterationNumber(self.ksp.0, &mut its))?;
            call("KSPGetConvergedReason", sys::KSPGetConvergedReason(self.ksp.0, &mut reason))?;
        }
        Ok((its.max(0) as usize, reason))
    }

    /// The relative tolerance a solve asked for `rtol` stops at: the user's `-ksp_rtol` if given.
    pub fn tolerance(&self, rtol: f64) -> f64 {
        if self.user_rtol { self.tolerances.0 } else { rtol }
    }

    /// Solves `A x = b` in place to the relative tolerance `rtol` (see [`Self::tolerance`]), from
    /// x = 0 (Newton's corrections shrink from one solve to the next: the last one is a worse
    /// first guess than none).
    pub fn solve_in_place(&mut self, b: &mut [f64], rtol: f64) -> Result<(), LinalgError> {
        let _petsc = lock()?;
        if !self.user_rtol {
            self.tolerances.0 = rtol;
        }
        let n = b.len();
        let local = self.split.as_ref().map_or(n, |s| s.layout.mine.len());
        self.rhs.with_values(local, |v| match &self.split {
            Some(s) => v.iter_mut().zip(&s.layout.mine).for_each(|(x, &dof)| *x = b[dof]),
            None => v.copy_from_slice(b),
        })?;
        let digits = digits(self.tolerances.0);
        let (mut its, mut reason) = self.krylov()?;
        let mut total = its;
        if reason <= 0 && self.baseline.is_some() {
            // A kept preconditioner that no longer serves: set up for these values, again.
            self.reuse(false)?;
            (its, reason) = self.krylov()?;
            total += its;
        }
        if reason <= 0 && self.adaptive {
            // A new block-Jacobi preconditioner that failed or reached its limit: too hard for
            // one level, multigrid from now on.
            tracing::info!(iterations = its, "block Jacobi does not serve this matrix: PETSc's GAMG from now on");
            let mut pc: sys::PC = std::ptr::null_mut();
            // SAFETY: the KSP's own PC; the user's -pc_gamg_* options apply to it.
            unsafe {
                call("KSPGetPC", sys::KSPGetPC(self.ksp.0, &mut pc))?;
                call("PCSetType", sys::PCSetType(pc, c"gamg".as_ptr()))?;
                call("PCSetFromOptions", sys::PCSetFromOptions(pc))?;
            }
            self.adaptive = false;
            self.setups += 1;
            self.reuse(false)?;
            (its, reason) = self.krylov()?;
            total += its;
        }
        self.iterations = total;
        if reason <= 0 {
            return Err(diverged(reason, total));
        }
        match self.baseline {
            None => {
                self.baseline = Some(its as f64 / digits);
                self.setups += 1;
            }
            // Tolerances differ from solve to solve (inexact Newton): iterations per digit.
            Some(rate) => self.stale |= its as f64 > LAG_GROWTH * rate * digits + 2.0,
        }
        match &mut self.split {
            Some(s) => {
                // SAFETY: the scatter was created from this solution vector to `all`.
                unsafe {
                    let (from, to) = (self.solution.0, s.all.0);
                    call(
                        "VecScatterBegin",
                        sys::VecScatterBegin(s.gather.0, from, to, sys::INSERT_VALUES, sys::SCATTER_FORWARD),
                    )?;
                    call(
                        "VecScatterEnd",
                        sys::VecScatterEnd(s.gather.0, from, to, sys::INSERT_VALUES, sys::SCATTER_FORWARD),
                    )?;
                }
                let to_petsc = &s.layout.to_petsc;
                s.all.with_values(n, |x| b.iter_mut().zip(to_petsc).for_each(|(v, &p)| *v = x[p as usize]))?;
            }
            None => self.solution.with_values(n, |x| b.copy_from_slice(x))?,
        }
        if b.iter().all(|v| v.is_finite()) { Ok(()) } else { Err(LinalgError::Singular { index: None }) }
    }
}

/// Whether the user's options (`--petsc-options`, `PETSC_OPTIONS`) name `option`.
fn given(option: &CStr) -> Result<bool, LinalgError> {
    let mut set = 0;
    // SAFETY: the global options database, a NUL-terminated name, one flag written.
    call("PetscOptionsHasName", unsafe {
        sys::PetscOptionsHasName(std::ptr::null_mut(), std::ptr::null(), option.as_ptr(), &mut set)
    })?;
    Ok(set != 0)
}

/// The error of a Krylov solve that stopped without converging.
fn diverged(reason: c_int, iterations: usize) -> LinalgError {
    const DIVERGED_INDEFINITE_PC: c_int = -8;
    const DIVERGED_INDEFINITE_MAT: c_int = -10;
    if reason == DIVERGED_INDEFINITE_MAT || reason == DIVERGED_INDEFINITE_PC {
        return LinalgError::NotPositiveDefinite { index: 0 };
    }
    // SAFETY: PETSc's table of reason names covers every reason a solve returns.
    let name = unsafe {
        let entry = *sys::KSPConvergedReasons.offset(reason as isize);
        if entry.is_null() { format!("reason {reason}") } else { CStr::from_ptr(entry).to_string_lossy().into_owned() }
    };
    LinalgError::Other(format!(
        "PETSc's Krylov solve did not converge ({name} after {iterations} iterations); other options may help, e.g. --petsc-options \"-ksp_type preonly -pc_type lu -pc_factor_mat_solver_type mumps\""
    ))
}
