//! The symmetric part of a nonsymmetric Jacobian as the factored reference, for a contact law
//! whose tangent is nonsymmetric only in the rows of the contact zone (Coulomb friction,
//! Nitsche with θ ≠ 1), on an elastic body whose inertia and stiffness are symmetric positive
//! definite. Factoring J itself means LU there, whose corrections have dense columns J⁻¹eᵢ, so
//! only about nnz(L)/n of them pay for themselves: a sliding contact zone wider than that made
//! Newton refactor at almost every iteration (155 LU factorizations per 1000 steps on the disc
//! at h = 1). Instead S, J with its nonsymmetric pairs replaced by their mean, is factored by
//! Cholesky in node blocks, and J = S + (J − S) is solved with the correction on the dofs where
//! J − S has entries, whose columns L⁻¹eᵢ are sparse; later iterates correct the same S as a
//! frictionless law's do its reference, and a new S is factored only when their change
//! outgrows a correction. Where S is not positive
//! definite, or the first correction is too large (a nonsymmetric part spread over the whole
//! body), J is factored by LU as before.

use tracing::debug;

use super::JacobianReuse;
use crate::linalg::lowrank::LowRank;
use crate::linalg::matrix::SYMMETRY_TOLERANCE;
use crate::linalg::{Factorization, LinalgError, Solver, Structure};
use crate::nonlinear::problem::NonlinearProblem;

impl JacobianReuse {
    /// Makes the operator the symmetric part of the Jacobian at w, factored, corrected towards
    /// J. Returns false, leaving J at w in `jacobian`, where that does not apply (see the
    /// module's documentation). `assembled`: J at w is in `jacobian` already.
    pub(super) fn symmetric_reference(
        &mut self,
        p: &mut impl NonlinearProblem,
        w: &[f64],
        assembled: bool,
        solver: Solver,
        max_rank: usize,
    ) -> Result<bool, LinalgError> {
        let current = self.jacobian.is_some() && self.jacobian_current;
        let j = self.jacobian.get_or_insert_with(|| p.jacobian_matrix());
        if !assembled {
            Self::assemble(p, w, j, current);
        }
        self.jacobian_current = true;
        // (Corrections need a direct factorization, on one process.)
        let direct = !solver.iterates(j.size(), j.pattern.dim()) && j.pattern.ownership().is_none();
        if max_rank == 0 || self.symmetric_failed || p.structure() != Structure::General || !direct {
            return Ok(false);
        }
        let s = j.symmetrized(SYMMETRY_TOLERANCE);
        // A Cholesky factorization from an earlier reference shares its symbolic analysis.
        let spd = |f: &Option<Factorization>| {
            f.as_ref().is_some_and(|f| f.structure() == Structure::SymmetricPositiveDefinite)
        };
        let mut f = if spd(&self.factorization) {
            self.factorization.take()
        } else if spd(&self.spare) {
            self.spare.take()
        } else {
            None
        }
        .unwrap_or_else(|| {
            Factorization::new(Structure::SymmetricPositiveDefinite)
                .with_solver(solver)
                .with_coordinates(p.node_coordinates())
        });
        let factored = match f.factor(&s) {
            Ok(()) => f.is_direct() && f.block().is_some(),
            Err(LinalgError::NotPositiveDefinite { .. }) => false,
            Err(e) => {
                self.keep_aside(f);
                return Err(e);
            }
        };
        let mut lr = LowRank::new(&s);
        let j = self.jacobian.as_ref().expect("assembled above");
        let dofs = lr.changed_dofs(j, None);
        let rank = dofs.len();
        let limit = self.rank_limit_for(&f, j.size(), max_rank);
        let corrected = factored
            && rank <= limit
            && lr.update(j, dofs, &mut f, None, limit).is_ok_and(|made| made)
            && lr.entries() <= self.entries_limit_for(&f, j.size());
        if !corrected {
            debug!(factored, rank, "the symmetric part is no reference: J is factored");
            // Not positive definite here, or J's nonsymmetric part too wide: not tried again
            // until the operator is invalidated.
            self.symmetric_failed = true;
            self.keep_aside(f);
            return Ok(false);
        }
        debug!(rank = lr.rank(), entries = lr.entries(), "symmetric part factored, corrected towards J");
        // J's own factorization (LU), if any, becomes the spare, for its symbolic analysis.
        if let Some(old) = self.factorization.replace(f)
            && let Some(replaced) = self.spare.replace(old)
        {
            self.retired = self.retired + replaced.counters;
        }
        self.reference_norm = s.norm_inf();
        self.low_rank = Some(lr);
        self.updates += 1;
        Ok(true)
    }

    /// Keeps a Cholesky factorization that is not the operator for its symbolic analysis: in
    /// the empty operator slot (the refactorization then swaps it with the spare) or as the
    /// spare.
    fn keep_aside(&mut self, f: Factorization) {
        if self.factorization.is_none() {
            self.factorization = Some(f);
        } else if let Some(replaced) = self.spare.replace(f) {
            self.retired = self.retired + replaced.counters;
        }
    }
}
