//! When Newton reuses its factorization: the factored reference and the Jacobian it was built
//! for, low-rank corrections of it towards a changed Jacobian (accepted while they cost less
//! than a refactorization), the previous reference kept for an active set that comes back, and
//! the Cholesky-to-LU fallback. The budgets are in [`JacobianReuse::mean_column_count`].

use tracing::debug;

use crate::linalg::lowrank::LowRank;
use crate::linalg::matrix::SYMMETRY_TOLERANCE;
use crate::linalg::{Counters, Factorization, LinalgError, Matrix, Solver, Structure};
use crate::nonlinear::problem::NonlinearProblem;

mod symmetric;

/// Bytes of cached correction columns (current and previous reference together).
const COLUMN_BYTES: usize = 256 << 20;
/// A previous reference is kept only if its factor is at most this large.
const KEEP_BYTES: usize = 512 << 20;

/// The operator Newton solves with, and the state of its reuse.
pub(super) struct JacobianReuse {
    pub(super) factorization: Option<Factorization>,
    /// With `Structure::Auto`: the factorization of the other structure, kept for its symbolic
    /// analysis, and whether Cholesky has failed (then LU from there on).
    spare: Option<Factorization>,
    spd_failed: bool,
    pub(super) jacobian: Option<Matrix>,
    /// `jacobian` was last written by the problem, which has not changed since.
    jacobian_current: bool,
    /// The active set the current operator (factorization and correction) was built for.
    pub(super) factored_for: Option<Vec<bool>>,
    /// The correction of the factorization towards the current Jacobian (direct solver,
    /// any nonlinear problem), and how many corrections were made.
    pub(super) low_rank: Option<LowRank>,
    updates: usize,
    /// Σ over solves of the correction's size since the last factorization, and whether it
    /// has grown past the cost of refactoring.
    pub(super) overhead: usize,
    pub(super) force_refactor: bool,
    /// The Jacobian of a tangent that is not piecewise was found to differ from the reference
    /// on more than half the dofs, and more than a correction may have (a finite-strain
    /// material's changes everywhere): no correction is attempted again until the operator is
    /// invalidated, since comparing and recording for one cost a tenth of such a step (the
    /// neo-Hookean disc).
    corrections_off: bool,
    /// The reference before the last refactorization, with its correction.
    previous: Option<Reference>,
    /// The symmetric part of a nonsymmetric Jacobian was found no reference ([`symmetric`]):
    /// not positive definite, or too far from J.
    symmetric_failed: bool,
    /// Counters of factorizations no longer kept.
    retired: Counters,
    /// ‖J‖∞ of the current operator, for the round-off of its solves, and their relative
    /// accuracy once its first solve has been checked.
    pub(super) jacobian_norm: f64,
    pub(super) solve_accuracy: Option<f64>,
    /// ‖J₀‖∞ of the factored reference (a bound on ‖J‖∞ is this plus the correction's), and
    /// the relative accuracy its solves are trusted to, once its first solve was checked.
    pub(super) reference_norm: f64,
    pub(super) reference_accuracy: Option<f64>,
}

impl Default for JacobianReuse {
    fn default() -> Self {
        JacobianReuse {
            factorization: None,
            spare: None,
            spd_failed: false,
            jacobian: None,
            jacobian_current: false,
            factored_for: None,
            low_rank: None,
            updates: 0,
            overhead: 0,
            force_refactor: false,
            corrections_off: false,
            previous: None,
            symmetric_failed: false,
            retired: Counters::default(),
            jacobian_norm: f64::INFINITY,
            solve_accuracy: None,
            reference_norm: f64::INFINITY,
            reference_accuracy: None,
        }
    }
}

/// A factor's mean column count nnz(L)/n (see [`JacobianReuse::mean_column_count`]).
fn mean_column_count(f: &Factorization, n: usize) -> Option<usize> {
    f.factor_nnz().map(|nnz| nnz / n.max(1))
}

/// A factored Jacobian, its correction towards the current one, and the correction's cost so far.
struct Reference {
    factorization: Option<Factorization>,
    low_rank: Option<LowRank>,
    overhead: usize,
    /// ‖J₀‖∞ and its solves' trusted accuracy.
    norm: f64,
    accuracy: Option<f64>,
}

impl JacobianReuse {
    /// Starts from `other`'s symbolic analysis and takes its factor's storage, if this Newton
    /// has no factorization and the other has one (a scheme's initial problem, solved once, and
    /// its first stage); `other` is left to refactor at its next solve.
    pub(super) fn inherit(&mut self, other: &mut JacobianReuse) {
        if self.factorization.is_none()
            && let Some(f) = other.factorization.as_mut()
        {
            self.factorization = Some(f.fork_with_storage());
            other.invalidate();
        }
    }

    /// Starts from `other`'s symbolic analysis, if this Newton has none and the other has one
    /// (a problem with the same Jacobian pattern: a scheme's initial problem and its stages).
    pub(super) fn share_analysis(&mut self, other: &JacobianReuse) {
        if self.factorization.is_none() {
            self.factorization = other.factorization.as_ref().map(Factorization::fork);
        }
    }

    /// Forgets the factorization's validity (the linear part of the problem changed).
    pub(super) fn invalidate(&mut self) {
        self.factored_for = None;
        self.jacobian_current = false;
        self.solve_accuracy = None;
        self.reference_accuracy = None;
        self.low_rank = None;
        self.overhead = 0;
        self.force_refactor = false;
        self.corrections_off = false;
        self.retire_previous();
        self.symmetric_failed = false;
    }

    /// Drops every factorization and correction (their counters are kept): the next solve
    /// runs exactly as a new `Newton`'s would. Checkpoints use it, so that a resumed run and an
    /// uninterrupted one follow the same factorizations and agree bit for bit.
    pub(super) fn forget(&mut self) {
        self.invalidate();
        for f in [self.factorization.take(), self.spare.take()].into_iter().flatten() {
            self.retired = self.retired + f.counters;
        }
        self.spd_failed = false;
        self.jacobian = None;
    }

    fn retire_previous(&mut self) {
        if let Some(f) = self.previous.take().and_then(|r| r.factorization) {
            self.retired = self.retired + f.counters;
        }
    }

    /// Exchanges the current reference with the previous one.
    fn swap_references(&mut self) {
        if let Some(prev) = self.previous.as_mut() {
            std::mem::swap(&mut self.factorization, &mut prev.factorization);
            std::mem::swap(&mut self.low_rank, &mut prev.low_rank);
            std::mem::swap(&mut self.overhead, &mut prev.overhead);
            std::mem::swap(&mut self.reference_norm, &mut prev.norm);
            std::mem::swap(&mut self.reference_accuracy, &mut prev.accuracy);
        }
    }

    /// The factor's mean column count c = nnz(L)/n. A solve pair reads 2·n·c values and a
    /// factorization does about n·c² flops (c/2 solve pairs' worth). A correction reads
    /// `LowRank::entries` more values per solve (k·n for k dense columns; with the factor in node
    /// blocks, the columns of W = L⁻¹U are sparse, about 0.07·n each on the disc): it is
    /// accepted while it reads at most what the factor does (k ≲ c for dense columns), while its
    /// k×k system costs no more than a factorization (k³ ≲ n·c²), and until the corrections
    /// since the factorization have read c/2 solve pairs' worth (Σ entries ≈ n·c²).
    fn mean_column_count(&self, n: usize) -> Option<usize> {
        self.factorization.as_ref().and_then(|f| mean_column_count(f, n))
    }

    /// Largest correction size accepted instead of a refactorization.
    fn rank_limit(&self, n: usize, max_rank: usize) -> usize {
        match &self.factorization {
            Some(f) => self.rank_limit_for(f, n, max_rank),
            None => max_rank.min(32).min(self.column_limit(n)),
        }
    }

    /// [`JacobianReuse::rank_limit`] with `f` as the reference.
    fn rank_limit_for(&self, f: &Factorization, n: usize, max_rank: usize) -> usize {
        let c = mean_column_count(f, n).unwrap_or(0).max(32);
        let k = if f.block().is_some() { ((n * c * c) as f64).cbrt() as usize } else { c };
        max_rank.min(k).min(self.column_limit(n))
    }

    /// Values a correction may read per solve.
    fn entries_limit(&self, n: usize) -> usize {
        self.factorization.as_ref().map_or(32 * n, |f| self.entries_limit_for(f, n))
    }

    /// [`JacobianReuse::entries_limit`] with `f` as the reference.
    fn entries_limit_for(&self, f: &Factorization, n: usize) -> usize {
        mean_column_count(f, n).unwrap_or(0).max(32) * n
    }

    /// Columns the corrections may cache in all (current and previous reference).
    fn column_limit(&self, n: usize) -> usize {
        COLUMN_BYTES / (8 * n.max(1))
    }

    /// Columns cached by both references' corrections.
    fn cached_columns(&self) -> usize {
        let current = self.low_rank.as_ref().map_or(0, LowRank::cached);
        current + self.previous.as_ref().and_then(|r| r.low_rank.as_ref()).map_or(0, LowRank::cached)
    }

    /// Σ of values read by corrections over solves after which the reference is refactored:
    /// with dense columns, what a refactorization costs. Sparse columns are never refactored
    /// away: their cost per solve is bounded by `entries_limit` and `rank_limit`, and a
    /// reference refactored at one contact state is as far from the next (bench disc).
    pub(super) fn overhead_budget(&self, n: usize) -> usize {
        if self.factorization.as_ref().is_some_and(|f| f.block().is_some()) {
            return usize::MAX;
        }
        self.mean_column_count(n).unwrap_or(0).max(32).pow(2) * n
    }

    /// Stored values of the current Cholesky factor, if there is one.
    pub(super) fn factor_nnz(&self) -> Option<usize> {
        self.factorization.as_ref().and_then(Factorization::factor_nnz)
    }

    /// Symbolic and numeric factorizations, low-rank corrections and solves so far.
    pub(super) fn counters(&self) -> Counters {
        let c = |f: &Option<Factorization>| f.as_ref().map(|f| f.counters).unwrap_or_default();
        let previous = self.previous.as_ref().map(|r| c(&r.factorization)).unwrap_or_default();
        let mut all = c(&self.factorization) + c(&self.spare) + previous + self.retired;
        all.updates = self.updates;
        all
    }

    /// Makes the operator the Jacobian at w: a low-rank correction of the factored reference
    /// when the factorization is direct and the change small enough, else a refactorization
    /// (which becomes the new reference; for a nonsymmetric J, its symmetric part corrected
    /// where that works: [`symmetric`]). Returns whether it factored J. The correction is of
    /// the Jacobian's values where they changed, so a problem that is not piecewise (a
    /// frictional law, whose tangent turns with the slip) is corrected as exactly as one whose
    /// tangent changes only with its active set. `piecewise`: the tangent at w is decided by
    /// the active set.
    pub(super) fn new_operator(
        &mut self,
        p: &mut impl NonlinearProblem,
        w: &[f64],
        solver: Solver,
        max_rank: usize,
        piecewise: bool,
    ) -> Result<bool, LinalgError> {
        let mut assembled = false;
        if !self.force_refactor && self.low_rank.is_some() {
            assembled = true;
            let mut j = self.jacobian.take().expect("assembled with the reference");
            Self::assemble(p, w, &mut j, self.jacobian_current);
            self.jacobian_current = true;
            let entries = p.varying_entries();
            let mut dofs = self.low_rank.as_ref().map(|lr| lr.changed_dofs(&j, entries)).unwrap_or_default();
            self.corrections_off =
                !piecewise && 2 * dofs.len() > j.size() && dofs.len() > self.rank_limit(j.size(), max_rank);
            // The previous reference, if the active set has come back near it.
            let budget = self.overhead_budget(j.size());
            if let Some(other) = self
                .previous
                .as_ref()
                .filter(|r| r.overhead <= budget)
                .and_then(|r| r.low_rank.as_ref())
                .map(|lr| lr.changed_dofs(&j, entries))
                && other.len() < dofs.len()
            {
                self.swap_references();
                dofs = other;
            }
            let new_columns = self.low_rank.as_ref().map_or(0, |lr| lr.missing(&dofs));
            // The limit on the correction's small system applies to its rank-one terms, if the
            // problem gives its elements (a few per switched point, where the dofs are a cell's).
            let limit = self.rank_limit(j.size(), max_rank);
            let by_terms = self.low_rank.as_ref().is_some_and(LowRank::has_elements);
            let updated = (by_terms || dofs.len() <= limit)
                && self.cached_columns() + new_columns <= self.column_limit(j.size())
                && match (self.low_rank.as_mut(), self.factorization.as_mut()) {
                    (Some(lr), Some(f)) => {
                        let elements = if by_terms { p.tangent_elements(w) } else { None };
                        lr.update(&j, dofs, f, elements.as_ref(), limit).is_ok_and(|made| made)
                            && lr.entries() <= self.entries_limit(j.size())
                    }
                    _ => false,
                };
            self.jacobian = Some(j);
            if updated {
                let lr = self.low_rank.as_ref().expect("updated");
                debug!(
                    rank = lr.rank(),
                    terms = lr.terms(),
                    entries = lr.entries(),
                    cached = lr.cached(),
                    "low-rank update"
                );
                self.updates += 1;
                return Ok(false);
            }
        }
        // A correction whose solve proved inaccurate asks for J itself, not another correction.
        let forced = std::mem::take(&mut self.force_refactor);
        // The factored reference becomes the previous one, if it is worth keeping; the new
        // factorization shares its symbolic analysis.
        let keep = self.low_rank.is_some()
            && self.factorization.as_ref().and_then(Factorization::factor_nnz).is_some_and(|nnz| 8 * nnz <= KEEP_BYTES);
        if keep && let Some(f) = self.factorization.as_ref() {
            let fork = f.fork();
            self.retire_previous();
            let old = self.factorization.replace(fork);
            self.previous = Some(Reference {
                factorization: old,
                low_rank: self.low_rank.take(),
                overhead: self.overhead,
                norm: self.reference_norm,
                accuracy: self.reference_accuracy,
            });
        }
        self.low_rank = None;
        self.overhead = 0;
        self.reference_accuracy = None;
        if !forced && self.symmetric_reference(p, w, assembled, solver, max_rank)? {
            return Ok(false);
        }
        // (`symmetric_reference` assembles J at w whether or not it applies.)
        self.refactor(p, w, assembled || !forced, solver)?;
        let direct = self.factorization.as_ref().is_some_and(Factorization::is_direct);
        if direct && max_rank > 0 && !self.corrections_off {
            let mut lr = LowRank::new(self.jacobian.as_ref().expect("assembled by refactor"));
            lr.set_elements(p.tangent_elements(w));
            self.low_rank = Some(lr);
        }
        Ok(true)
    }

    /// Assembles and factors the Jacobian at w; a failed Cholesky falls back to LU.
    /// `assembled`: the Jacobian at w is already in place (from a low-rank attempt).
    fn refactor(
        &mut self,
        p: &mut impl NonlinearProblem,
        w: &[f64],
        assembled: bool,
        solver: Solver,
    ) -> Result<(), LinalgError> {
        let current = self.jacobian.is_some() && self.jacobian_current;
        let j = self.jacobian.get_or_insert_with(|| p.jacobian_matrix());
        if !assembled {
            Self::assemble(p, w, j, current);
        }
        self.jacobian_current = true;
        let want = match p.structure() {
            Structure::Auto if self.spd_failed || !j.is_symmetric_everywhere(SYMMETRY_TOLERANCE) => Structure::General,
            Structure::Auto => Structure::SymmetricPositiveDefinite,
            s => s,
        };
        if self.factorization.as_ref().is_some_and(|f| f.structure() != want) {
            std::mem::swap(&mut self.factorization, &mut self.spare);
        }
        let f = match &mut self.factorization {
            Some(f) if f.structure() == want => f,
            slot => {
                let old =
                    slot.replace(Factorization::new(want).with_solver(solver).with_coordinates(p.node_coordinates()));
                if let Some(old) = old
                    && let Some(replaced) = self.spare.replace(old)
                {
                    self.retired = self.retired + replaced.counters;
                }
                slot.as_mut().expect("just set")
            }
        };
        match f.factor(j) {
            Err(LinalgError::NotPositiveDefinite { .. }) if f.structure() == Structure::SymmetricPositiveDefinite => {
                debug!("Jacobian not positive definite: switching to LU");
                self.spd_failed = true;
                let counters = f.counters;
                let mut lu =
                    Factorization::new(Structure::General).with_solver(solver).with_coordinates(p.node_coordinates());
                lu.counters = counters;
                lu.factor(j)?;
                *f = lu;
                Ok(())
            }
            other => other,
        }
    }

    /// Writes the Jacobian at w into `j`: only what can differ if `current` (j holds the
    /// problem's last Jacobian) and the problem can, else from zero.
    fn assemble(p: &mut impl NonlinearProblem, w: &[f64], j: &mut Matrix, current: bool) {
        if current && p.update_jacobian(w, j) {
            // Test builds check the update against the whole assembly, bit for bit.
            if cfg!(debug_assertions) {
                let mut whole = p.jacobian_matrix();
                p.jacobian(w, &mut whole);
                let same = whole.values.iter().zip(&j.values).all(|(a, b)| a.to_bits() == b.to_bits());
                assert!(same, "update_jacobian differs from jacobian");
            }
            return;
        }
        j.values.iter_mut().for_each(|v| *v = 0.0);
        p.jacobian(w, j);
    }
}
