//! Reusable factorizations: faer's sparse Cholesky and LU, a diagonal's inverse, or
//! preconditioned Krylov iterations, chosen by [`Solver`] and [`Structure`]. The symbolic
//! analysis (fill-reducing ordering, elimination tree) is computed once per pattern and only
//! the numeric factorization reruns when asked; [`Counters`] make the reuse testable.

use std::sync::Arc;

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::cholesky::{self, LltRef, SymbolicCholesky};
use faer::sparse::linalg::lu::{self, LuRef, NumericLu, SymbolicLu};
use faer::sparse::linalg::{SupernodalThreshold, SymbolicSupernodalParams};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Side};

use crate::linalg::block_factor::BlockFactor;
use crate::linalg::matrix::{LinalgError, Matrix};
use crate::linalg::pattern::Pattern;

/// The approximate-minimum-degree ordering of the pattern's node graph, each node's dofs kept
/// together and in order (so that the Cholesky factor is made of node blocks): the dof at each
/// position of the elimination, and the inverse permutation.
pub(crate) fn node_ordering(pattern: &Pattern) -> Result<(Vec<usize>, Vec<usize>), LinalgError> {
    use faer::sparse::linalg::amd;
    let nodes = pattern.num_nodes();
    let mut col_ptr = Vec::with_capacity(nodes + 1);
    col_ptr.push(0);
    let mut row_idx = Vec::new();
    for j in 0..nodes {
        row_idx.extend(pattern.neighbours(j).iter().map(|&i| i as usize));
        col_ptr.push(row_idx.len());
    }
    let graph = SymbolicSparseColMatRef::new_checked(nodes, nodes, &col_ptr, None, &row_idx);
    let (mut perm, mut inverse) = (vec![0usize; nodes], vec![0usize; nodes]);
    let mut mem = MemBuffer::try_new(amd::order_scratch::<usize>(nodes, row_idx.len()))
        .map_err(|_| LinalgError::Other("out of memory".into()))?;
    amd::order(&mut perm, &mut inverse, graph, Default::default(), MemStack::new(&mut mem))
        .map_err(|e| LinalgError::Other(format!("{e:?}")))?;
    let d = pattern.dim();
    let order: Vec<usize> = perm.iter().flat_map(|&node| (0..d).map(move |m| node * d + m)).collect();
    let mut inverse = vec![0; order.len()];
    order.iter().enumerate().for_each(|(k, &i)| inverse[i] = k);
    Ok((order, inverse))
}

/// Which factorization to use.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Structure {
    /// Sparse Cholesky (only the lower triangle is read).
    SymmetricPositiveDefinite,
    /// Sparse LU with partial pivoting.
    General,
    /// Decided at each factorization: Cholesky when the matrix is symmetric (to round-off),
    /// LU otherwise or once Cholesky has met a non-positive pivot.
    Auto,
}

/// How many times each phase ran.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counters {
    pub symbolic: usize,
    pub numeric: usize,
    pub solves: usize,
    /// Krylov iterations over all solves (iterative solver).
    pub iterations: usize,
    /// Low-rank corrections of a factorization in place of a refactorization (Newton).
    pub updates: usize,
}

impl std::ops::Add for Counters {
    type Output = Counters;
    fn add(self, o: Counters) -> Counters {
        Counters {
            symbolic: self.symbolic + o.symbolic,
            numeric: self.numeric + o.numeric,
            solves: self.solves + o.solves,
            iterations: self.iterations + o.iterations,
            updates: self.updates + o.updates,
        }
    }
}

/// The inverse of `a`'s diagonal if every entry off it is zero (none otherwise, after the first
/// nonzero found); a zero on it is singular, a non-positive one not positive definite.
fn diagonal_inverse(a: &Matrix, structure: Structure) -> Result<Option<Vec<f64>>, LinalgError> {
    let p = &a.pattern;
    let n = a.size();
    let mut diagonal = vec![0.0; n];
    for j in 0..n {
        for k in p.col_ptr[j]..p.col_ptr[j + 1] {
            if p.row_idx[k] == j {
                diagonal[j] = a.values[k];
            } else if a.values[k] != 0.0 {
                return Ok(None);
            }
        }
    }
    for (index, d) in diagonal.iter_mut().enumerate() {
        if structure == Structure::SymmetricPositiveDefinite && *d <= 0.0 {
            return Err(LinalgError::NotPositiveDefinite { index });
        }
        if *d == 0.0 || !d.is_finite() {
            return Err(LinalgError::Singular { index: Some(index) });
        }
        *d = 1.0 / *d;
    }
    Ok(Some(diagonal))
}

/// How a `Factorization` solves: a sparse direct factorization, preconditioned Krylov
/// iterations (conjugate gradients for SPD matrices, BiCGStab otherwise; memory of the matrix
/// only), by size: direct in 1D, iterative above [`AUTO_ITERATIVE_DOFS`] unknowns in 2D and 3D
/// (PETSc in a run of several processes); or PETSc's Krylov solvers with block Jacobi or
/// algebraic multigrid (feature `petsc`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Solver {
    Direct,
    Iterative,
    #[default]
    Auto,
    Petsc,
}

/// Above this many unknowns `Solver::Auto` iterates, in 3D and in 2D. Measured with
/// `bench sphere` (50 steps through the first contact, each active-set change a new
/// factorization): at 14 739 unknowns iterating is 1.7 times faster and takes half the memory,
/// at 46 875 5.3 times faster with a third of the memory. In 2D the factors fill far less; the
/// 2D threshold is not measured (docs/mathematics.md §5, linear solvers).
pub const AUTO_ITERATIVE_DOFS: [usize; 2] = [10_000, 100_000];

impl Solver {
    pub fn parse(s: &str) -> Result<Solver, String> {
        match s {
            "direct" => Ok(Solver::Direct),
            "iterative" => Ok(Solver::Iterative),
            "auto" => Ok(Solver::Auto),
            "petsc" if cfg!(feature = "petsc") => Ok(Solver::Petsc),
            "petsc" => Err(
                "`petsc`: this signorini was built without PETSc (build it with `--features petsc`, README: Large runs)"
                    .into(),
            ),
            _ => Err(format!("`{s}`: expected direct, iterative, auto or petsc")),
        }
    }

    /// Whether PETSc solves: when chosen, and by default in a run of several processes (which
    /// PETSc solves together).
    pub fn petsc(self) -> bool {
        self == Solver::Petsc || (self == Solver::Auto && crate::linalg::ranks::world().1 > 1)
    }

    /// Whether a system of `n` unknowns in dimension `dim` is solved iteratively.
    pub fn iterates(self, n: usize, dim: usize) -> bool {
        match self {
            Solver::Direct => false,
            Solver::Iterative | Solver::Petsc => true,
            // In 1D the matrix is banded: its factor does not fill, and a direct solve is always
            // the cheaper (100 001 unknowns of the bar: 48.8 s for two steps by Jacobi-CG).
            Solver::Auto => self.petsc() || (dim > 1 && n > AUTO_ITERATIVE_DOFS[if dim >= 3 { 0 } else { 1 }]),
        }
    }
}

enum Factors {
    None,
    Krylov(Box<crate::linalg::krylov::Krylov>),
    #[cfg(feature = "petsc")]
    Petsc(Box<crate::linalg::petsc::PetscSolver>),
    /// A diagonal matrix's inverse (a lumped mass: an explicit scheme's step is a division).
    Diagonal(Vec<f64>),
    /// faer's factor, and its copy in node blocks that the solves use (faer's values are then
    /// dropped until the next factorization).
    Llt {
        symbolic: Arc<SymbolicCholesky<usize>>,
        values: Vec<f64>,
        block: Option<Box<BlockFactor>>,
        factored: bool,
    },
    Lu {
        symbolic: Arc<SymbolicLu<usize>>,
        numeric: Box<NumericLu<usize, f64>>,
        factored: bool,
    },
}

/// A reusable sparse factorization.
pub struct Factorization {
    structure: Structure,
    solver: Solver,
    factors: Factors,
    /// The pattern the symbolic analysis belongs to.
    pattern: Option<Arc<Pattern>>,
    par: Par,
    pub counters: Counters,
    /// The solves' vector in elimination order (kept between solves).
    work: Vec<f64>,
    /// The nodes' coordinates (`nodes × dim`), for a multigrid's near-null space.
    coordinates: Option<Arc<[f64]>>,
    /// Relative residual ‖b − A x‖₂ ≤ tolerance·‖b‖₂ at which iterative solves stop.
    tolerance: f64,
}

impl Factorization {
    /// Sequential by default, so results do not depend on the number of threads.
    pub fn new(structure: Structure) -> Self {
        Factorization {
            structure,
            solver: Solver::Direct,
            factors: Factors::None,
            pattern: None,
            par: Par::Seq,
            counters: Counters::default(),
            work: Vec::new(),
            coordinates: None,
            tolerance: crate::linalg::krylov::TOLERANCE,
        }
    }

    /// Solves with `solver` (direct by default).
    pub fn with_solver(mut self, solver: Solver) -> Self {
        self.solver = solver;
        self
    }

    /// The nodes' coordinates (`nodes × dim`, row-major) when the unknowns are their
    /// displacements: algebraic multigrid (PETSc's GAMG) takes their rigid-body modes as its
    /// near-null space.
    pub fn with_coordinates(mut self, coordinates: Option<Arc<[f64]>>) -> Self {
        self.coordinates = coordinates;
        self
    }

    /// Uses `threads` threads (0: all) in factorizations and solves.
    pub fn with_threads(mut self, threads: usize) -> Self {
        self.par = if threads == 1 { Par::Seq } else { Par::rayon(threads) };
        self
    }

    pub fn structure(&self) -> Structure {
        self.structure
    }

    /// Iterative solves from now on stop at ‖b − A x‖₂ ≤ `rtol`·‖b‖₂ (default
    /// [`TOLERANCE`](crate::linalg::krylov::TOLERANCE)): Newton asks each solve for the accuracy
    /// its iteration needs. Returns the tolerance they will stop at (a user's PETSc `-ksp_rtol`
    /// stands). Direct solves are unaffected.
    pub fn set_tolerance(&mut self, rtol: f64) -> f64 {
        self.tolerance = rtol;
        #[cfg(feature = "petsc")]
        if let Factors::Petsc(k) = &self.factors {
            return k.tolerance(rtol);
        }
        rtol
    }

    /// Whether solves stop at a tolerance (Krylov methods, ours or PETSc's).
    pub fn iterates(&self) -> bool {
        match &self.factors {
            Factors::Krylov(_) => true,
            #[cfg(feature = "petsc")]
            Factors::Petsc(_) => true,
            _ => false,
        }
    }

    /// Factors `a`: the symbolic analysis if `a`'s pattern is new, the numeric factorization
    /// always.
    pub fn factor(&mut self, a: &Matrix) -> Result<(), LinalgError> {
        let n = a.size();
        // A process's part of a matrix (a split run) is not the matrix: PETSc solves it.
        if a.pattern.ownership().is_none()
            && let Some(inverse) = diagonal_inverse(a, self.structure)?
        {
            self.factors = Factors::Diagonal(inverse);
            self.pattern = None;
            return Ok(());
        }
        if self.solver.petsc() {
            return self.factor_petsc(a);
        }
        if self.solver.iterates(n, a.pattern.dim()) {
            let k =
                crate::linalg::krylov::Krylov::new(a.clone(), self.structure == Structure::SymmetricPositiveDefinite)?;
            self.factors = Factors::Krylov(Box::new(k));
            self.pattern = Some(a.pattern.clone());
            self.counters.numeric += 1;
            return Ok(());
        }
        let same_pattern = self.pattern.as_ref().is_some_and(|p| Arc::ptr_eq(p, &a.pattern));
        let sym = SymbolicSparseColMatRef::new_checked(n, n, &a.pattern.col_ptr, None, &a.pattern.row_idx);
        if !same_pattern {
            self.factors = match self.structure {
                Structure::SymmetricPositiveDefinite => {
                    let (order, inverse) = node_ordering(&a.pattern)?;
                    // The solves read a copy in node blocks (`block_factor`), so faer's layout
                    // only decides how fast it factors: supernodal (criterion: 13.3 against
                    // 46.4 ms simplicial at 12 482 unknowns), with no relaxed supernodes, whose
                    // explicit zeros the solves would read.
                    let symbolic = cholesky::factorize_symbolic_cholesky(
                        sym,
                        Side::Lower,
                        cholesky::SymmetricOrdering::Custom(faer::perm::PermRef::new_checked(&order, &inverse, n)),
                        cholesky::CholeskySymbolicParams {
                            supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
                            supernodal_params: SymbolicSupernodalParams { relax: None },
                            ..Default::default()
                        },
                    )
                    .map_err(|e| LinalgError::Other(format!("{e:?}")))?;
                    Factors::Llt { values: Vec::new(), symbolic: Arc::new(symbolic), block: None, factored: false }
                }
                Structure::General | Structure::Auto => {
                    let symbolic = lu::factorize_symbolic_lu(sym, Default::default())
                        .map_err(|e| LinalgError::Other(format!("{e:?}")))?;
                    Factors::Lu { symbolic: Arc::new(symbolic), numeric: Box::new(NumericLu::new()), factored: false }
                }
            };
            self.pattern = Some(a.pattern.clone());
            self.counters.symbolic += 1;
        }
        let mat = SparseColMatRef::new(sym, &a.values);
        let par = self.par;
        self.counters.numeric += 1;
        match &mut self.factors {
            Factors::Llt { symbolic, values, block, factored } => {
                *factored = false;
                let old = block.take().map(|b| *b);
                values.resize(symbolic.len_val(), 0.0);
                let req = symbolic.factorize_numeric_llt_scratch::<f64>(par, Default::default());
                let mut mem = MemBuffer::try_new(req).map_err(|_| LinalgError::Other("out of memory".into()))?;
                symbolic
                    .factorize_numeric_llt(
                        values,
                        mat,
                        Side::Lower,
                        Default::default(),
                        par,
                        MemStack::new(&mut mem),
                        Default::default(),
                    )
                    .map_err(|e| match e {
                        faer::linalg::solvers::LltError::NonPositivePivot { index } => {
                            LinalgError::NotPositiveDefinite { index }
                        }
                    })?;
                *block = BlockFactor::reusing(symbolic, values, a.pattern.dim(), old).map(Box::new);
                if block.is_some() {
                    *values = Vec::new();
                }
                *factored = true;
            }
            Factors::Lu { symbolic, numeric, factored } => {
                *factored = false;
                let req = symbolic.factorize_numeric_lu_scratch::<f64>(par, Default::default());
                let mut mem = MemBuffer::try_new(req).map_err(|_| LinalgError::Other("out of memory".into()))?;
                symbolic.factorize_numeric_lu(numeric, mat, par, MemStack::new(&mut mem), Default::default()).map_err(
                    |e| match e {
                        faer::sparse::linalg::LuError::SymbolicSingular { index } => {
                            LinalgError::Singular { index: Some(index) }
                        }
                        other => LinalgError::Other(format!("{other:?}")),
                    },
                )?;
                *factored = true;
            }
            _ => unreachable!("symbolic analysis done above"),
        }
        Ok(())
    }

    /// A second factorization of the same structure that shares this one's symbolic analysis
    /// (with its own counters, starting at zero).
    pub fn fork(&self) -> Factorization {
        let factors = match &self.factors {
            Factors::Llt { symbolic, .. } => {
                Factors::Llt { symbolic: symbolic.clone(), values: Vec::new(), block: None, factored: false }
            }
            Factors::Lu { symbolic, .. } => {
                Factors::Lu { symbolic: symbolic.clone(), numeric: Box::new(NumericLu::new()), factored: false }
            }
            _ => Factors::None,
        };
        let pattern = if matches!(factors, Factors::None) { None } else { self.pattern.clone() };
        Factorization {
            structure: self.structure,
            solver: self.solver,
            factors,
            pattern,
            par: self.par,
            counters: Counters::default(),
            work: Vec::new(),
            coordinates: self.coordinates.clone(),
            tolerance: crate::linalg::krylov::TOLERANCE,
        }
    }

    /// As [`Factorization::fork`], taking this one's numeric storage along (this one is left
    /// unfactored, its analysis kept): the fork's first factorization then writes into memory
    /// already in use, where fresh storage costs zeroing and page faults.
    pub fn fork_with_storage(&mut self) -> Factorization {
        let mut fork = self.fork();
        if let (Factors::Llt { values, block, factored, .. }, Factors::Llt { values: to, block: to_block, .. }) =
            (&mut self.factors, &mut fork.factors)
        {
            *to = std::mem::take(values);
            *to_block = block.take();
            *factored = false;
        }
        fork
    }

    /// Stored values of the Cholesky factor L, if that is what was computed.
    pub fn factor_nnz(&self) -> Option<usize> {
        match &self.factors {
            Factors::Llt { block: Some(b), factored: true, .. } => Some(b.nnz()),
            Factors::Llt { symbolic, factored: true, .. } => Some(symbolic.len_val()),
            _ => None,
        }
    }

    /// The Cholesky factor in node blocks, if that is what the last factorization computed.
    pub fn block(&self) -> Option<&BlockFactor> {
        match &self.factors {
            Factors::Llt { block: Some(b), factored: true, .. } => Some(b),
            _ => None,
        }
    }

    /// Whether the last `factor` computed sparse factors (not a Krylov solver).
    pub fn is_direct(&self) -> bool {
        matches!(self.factors, Factors::Llt { factored: true, .. } | Factors::Lu { factored: true, .. })
    }

    /// Solves `A X = B` in place for the `ncols` columns of `b` (column-major) with the last
    /// direct factorization.
    pub fn solve_many_in_place(&mut self, b: &mut [f64], ncols: usize) -> Result<(), LinalgError> {
        let n = b.len() / ncols.max(1);
        if let Factors::Diagonal(inverse) = &self.factors {
            for x in b.chunks_exact_mut(n.max(1)) {
                x.iter_mut().zip(inverse).for_each(|(x, d)| *x *= d);
            }
            self.counters.solves += ncols;
            return Ok(());
        }
        let par = self.par;
        let rhs = MatMut::from_column_major_slice_mut(b, n, ncols);
        match &self.factors {
            Factors::Llt { block: Some(block), factored: true, .. } => {
                for x in b.chunks_exact_mut(n.max(1)) {
                    block.solve_in_place(x, &mut self.work);
                }
            }
            Factors::Llt { symbolic, values, factored: true, .. } => {
                let mut mem = MemBuffer::new(symbolic.solve_in_place_scratch::<f64>(ncols, par));
                LltRef::new(symbolic, values).solve_in_place_with_conj(Conj::No, rhs, par, MemStack::new(&mut mem));
            }
            Factors::Lu { symbolic, numeric, factored: true } => {
                let mut mem = MemBuffer::new(symbolic.solve_in_place_scratch::<f64>(ncols, par));
                LuRef::new_unchecked(symbolic, numeric).solve_in_place_with_conj(
                    Conj::No,
                    rhs,
                    par,
                    MemStack::new(&mut mem),
                );
            }
            _ => return Err(LinalgError::NotFactored),
        }
        self.counters.solves += ncols;
        if b.iter().all(|v| v.is_finite()) { Ok(()) } else { Err(LinalgError::Singular { index: None }) }
    }

    /// Solves `A x = b` in place with the Cholesky factor in node blocks, applying `between` to
    /// L⁻¹ b (in elimination order) before the backward pass (see `lowrank`).
    pub fn solve_split_in_place(&mut self, b: &mut [f64], between: impl FnOnce(&mut [f64])) -> Result<(), LinalgError> {
        let Factors::Llt { block: Some(block), factored: true, .. } = &self.factors else {
            return Err(LinalgError::NotFactored);
        };
        block.solve_with(b, &mut self.work, between);
        self.counters.solves += 1;
        if b.iter().all(|v| v.is_finite()) { Ok(()) } else { Err(LinalgError::Singular { index: None }) }
    }

    /// Solves `A x = b` in place with the last factorization; a non-finite result (a
    /// numerically singular matrix) is an error.
    pub fn solve_in_place(&mut self, b: &mut [f64]) -> Result<(), LinalgError> {
        if let Factors::Diagonal(inverse) = &self.factors {
            b.iter_mut().zip(inverse).for_each(|(x, d)| *x *= d);
            self.counters.solves += 1;
            return Ok(());
        }
        if let Factors::Krylov(k) = &mut self.factors {
            let result = k.solve_in_place(b, self.tolerance);
            self.counters.iterations += k.iterations;
            self.counters.solves += 1;
            return result;
        }
        #[cfg(feature = "petsc")]
        if let Factors::Petsc(k) = &mut self.factors {
            let setups = k.setups;
            let result = k.solve_in_place(b, self.tolerance);
            // A PETSc solver's factorizations are its preconditioner's setups.
            self.counters.numeric += k.setups - setups;
            self.counters.iterations += k.iterations;
            self.counters.solves += 1;
            return result;
        }
        self.solve_many_in_place(b, 1)
    }

    /// A PETSc solver for `a`: its values into the solver of the same pattern, else a new one.
    #[cfg(feature = "petsc")]
    fn factor_petsc(&mut self, a: &Matrix) -> Result<(), LinalgError> {
        if let Factors::Petsc(k) = &mut self.factors
            && k.fits(a)
        {
            return k.set_values(a);
        }
        let symmetric = self.structure == Structure::SymmetricPositiveDefinite;
        let k = crate::linalg::petsc::PetscSolver::new(
            a,
            symmetric,
            self.coordinates.as_deref(),
            crate::linalg::krylov::TOLERANCE,
        )?;
        self.factors = Factors::Petsc(Box::new(k));
        self.pattern = Some(a.pattern.clone());
        self.counters.symbolic += 1;
        Ok(())
    }

    #[cfg(not(feature = "petsc"))]
    fn factor_petsc(&mut self, _a: &Matrix) -> Result<(), LinalgError> {
        Err(LinalgError::Other("this signorini was built without PETSc (`--features petsc`)".into()))
    }
}

#[cfg(test)]
mod tests {
    use super::{AUTO_ITERATIVE_DOFS, Solver};

    /// `auto` factorizes every 1D system (banded: no fill), and iterates above the thresholds in
    /// 2D and 3D.
    #[test]
    fn auto_is_direct_in_1d_at_any_size() {
        assert!(!Solver::Auto.iterates(10_000_000, 1));
        assert!(Solver::Auto.iterates(AUTO_ITERATIVE_DOFS[1] + 1, 2));
        assert!(!Solver::Auto.iterates(AUTO_ITERATIVE_DOFS[1], 2));
        assert!(Solver::Auto.iterates(AUTO_ITERATIVE_DOFS[0] + 1, 3));
        assert!(Solver::Iterative.iterates(10, 1));
    }
}
