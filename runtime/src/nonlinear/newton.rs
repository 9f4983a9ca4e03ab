//! Semi-smooth Newton for R(w) = 0 with contact.
//!
//! Stops when ‖R(w)‖∞ ≤ tol·‖R(w⁰)‖∞, when the last step kept the active set and changed w by
//! at most tol·‖w‖∞, or when R is at round-off: ‖R‖∞ ≤ 512ε times the largest term summed in
//! R (the problem's `magnitude`). The scale is R's own: a right-hand side dominated by inertia
//! (∝ 1/Δt²) does not set it. It iterates at least once unless R(w⁰) is at round-off already.
//! The contact tangent depends
//! on the state only through the active set, so the problem reports its active set at each
//! iterate; while it is the one the current operator was built for, the Jacobian is neither
//! reassembled nor refactored. When it changes, the new Jacobian is assembled and, if it
//! differs from the factored one on few enough dofs, the factorization is corrected
//! (`lowrank`) instead of recomputed. The factorization survives between solves (time steps)
//! until `invalidate` is called. Where a step keeps the active set, R is affine and the new
//! residual is the solve's error: each new factorization's first solve is checked (J δ + R),
//! and the later ones, when that one was accurate, are bounded by its accuracy and round-off,
//! not evaluated. A corrected operator's first solve is bounded the same way by the
//! reference's accuracy plus the residual the correction reports it leaves (`LowRank::solve`),
//! and checked only when that bound is not small.
//!
//! Iterative solves are inexact Newton steps: each is asked for what its iteration needs
//! (`forcing`): a loose 1e-3 where the active set is expected to change, else just below the
//! stopping threshold, so that no solve is carried far past what Newton will use.

use tracing::debug;

use crate::linalg::norms::norm_inf;
use crate::nonlinear::problem::NonlinearProblem;

use crate::linalg::{Factorization, LinalgError, Matrix, Solver, Structure};
use crate::nonlinear::reuse::JacobianReuse;

/// A residual at most this times its terms' magnitude is round-off (a few hundred roundings).
pub const ROUNDOFF: f64 = 512.0 * f64::EPSILON;

/// Largest accepted ‖J δ + R‖∞ / ‖R‖∞ of a Newton step; above it the Jacobian is treated as
/// singular (round-off in a sound solve stays orders of magnitude below).
const LINEAR_TOLERANCE: f64 = 1e-6;

/// Largest relative error ‖J δ + R‖∞ / ‖R‖∞ of a new operator's first solve for its later
/// solves to go unchecked (ten times it bounds theirs).
const TRUSTED_ACCURACY: f64 = 1e-12;

/// Largest contraction ‖R_{k+1}‖∞ / ‖R_k‖∞ for which the operator of a tangent that is not
/// piecewise (a finite-strain material) is kept at the next iterate instead of refactored:
/// simplified (chord) Newton, whose error contracts by about ‖J̃⁻¹(J − J̃)‖ per step. Its
/// iterations cost a residual and a solve pair; a refactorization costs the tangent's assembly
/// and the factor. On the neo-Hookean disc (h = 1, 1000 steps) thresholds of 0.001, 0.01, 0.1
/// and 0.3 gave 5.25, 3.77, 3.17 and 3.18 ms per step (docs/mathematics.md §8).
const CHORD_RATE: f64 = 0.1;

/// η of an iterative solve whose iteration is expected to change the active set (the step's
/// first, when the last step's first did). On the 47k-unknown ball through impact (50 steps),
/// 1e-3 saved more Krylov iterations than 1e-2 or 1e-4.
const LOOSE: f64 = 1e-3;

/// The fraction of Newton's threshold a solve that may end Newton leaves in ‖J δ + R‖₂. The
/// energy columns are differences of energies 10³–10⁵ times larger, so they are the first to
/// show a solve's error: on the same run, 0.5 left 3.7e-8 of their scale between block-Jacobi
/// CG and the direct path, 0.01 left 2.9e-8 with PETSc's GAMG, and 1e-3 leaves 1.9e-9 and
/// 5.4e-9 (with 4772 → 3232 and 1260 → 926 Krylov iterations against a fixed 1e-12).
const FINISH: f64 = 1e-3;

/// At round-off, or after at least one iteration below the relative threshold or with a step
/// too small to matter.
fn converged(res: f64, floor: f64, threshold: f64, iterated: bool, small_step: bool) -> bool {
    res <= floor || (iterated && (res <= threshold || small_step))
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NewtonOptions {
    pub tol: f64,
    pub max_iterations: usize,
    /// Backtracking on ‖R‖₂ (halving the step up to 10 times), for every problem; a problem
    /// that is not piecewise (frictional) backtracks without it once three full steps have not
    /// lowered its residual.
    pub line_search: bool,
    /// Chord Newton for a tangent that is not piecewise: its factored operator is kept while
    /// it contracts the residual fast enough ([`CHORD_RATE`]). For a problem solved again and
    /// again (a time stepper's stages) whose refactorization costs more than a few iterations;
    /// not with `line_search`.
    pub chord: bool,
    /// How the Jacobian systems are solved.
    pub solver: Solver,
    /// Cap on the number of dofs on which a new Jacobian may differ from the factored one and
    /// be solved by a low-rank correction instead of a refactorization (0: always refactor).
    /// Below the cap the limit is the factor's mean column count c = nnz(L)/n (see
    /// `Newton::rank_limit`).
    pub max_rank: usize,
}

/// Default `max_rank`.
pub const MAX_RANK: usize = 1024;

impl Default for NewtonOptions {
    fn default() -> Self {
        NewtonOptions {
            tol: 1e-10,
            max_iterations: 25,
            line_search: false,
            chord: false,
            solver: Solver::Auto,
            max_rank: MAX_RANK,
        }
    }
}

/// One Newton iteration, as logged.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Iteration {
    /// ‖R‖∞ after the step.
    pub residual: f64,
    /// Active contact points at the iterate the step was computed from.
    pub active: usize,
    /// The Jacobian was refactored for this step (the active set changed and the change was
    /// too large for a low-rank correction).
    pub refactored: bool,
    /// The factorization was corrected for a changed active set instead.
    pub updated: bool,
    /// Step length (1 without line search).
    pub step: f64,
    /// The relative tolerance the step's iterative solve was given (none: a direct solve).
    pub tolerance: Option<f64>,
}

#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct NewtonReport {
    pub initial_residual: f64,
    pub history: Vec<Iteration>,
}

impl NewtonReport {
    pub fn iterations(&self) -> usize {
        self.history.len()
    }

    /// The residuals from the first, with each iterate's active points (and the tolerance of
    /// an iterative solve): what a failure message shows.
    pub fn describe(&self) -> String {
        let mut text = format!("residual {:.3e}", self.initial_residual);
        for it in &self.history {
            match it.tolerance {
                Some(eta) => {
                    text.push_str(&format!(" → {:.3e} ({} active, solved to {eta:.0e})", it.residual, it.active))
                }
                None => text.push_str(&format!(" → {:.3e} ({} active)", it.residual, it.active)),
            }
        }
        text
    }
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum NewtonError {
    #[error("Newton did not converge in {} iterations (residual {:.3e}, tolerance {:.3e})", .report.iterations(), .report.history.last().map_or(.report.initial_residual, |i| i.residual), .threshold)]
    IterationLimit { report: NewtonReport, threshold: f64 },
    #[error("Newton produced non-finite values at iteration {}", .report.iterations())]
    NonFinite { report: NewtonReport },
    #[error("Newton's linear solve failed at iteration {}: {source}", .report.iterations() + 1)]
    Linear { source: LinalgError, report: NewtonReport },
}

impl NewtonError {
    /// What Newton saw before it failed.
    pub fn report(&self) -> &NewtonReport {
        match self {
            NewtonError::IterationLimit { report, .. } | NewtonError::NonFinite { report } => report,
            NewtonError::Linear { report, .. } => report,
        }
    }
}

/// Newton's method with a reusable factorization.
pub struct Newton {
    pub options: NewtonOptions,
    /// The factored operator and when it is reused, corrected or refactored.
    reuse: JacobianReuse,
    scratch: Scratch,
    /// The last solve's first iteration changed the active set: the next one's first solve is
    /// expected to as well, and is loose ([`LOOSE`]).
    first_changed: bool,
    /// The operator of a tangent that is not piecewise may be kept at the next iterate (chord
    /// Newton): it was last rebuilt by a refactorization, not a cheap correction, and its last
    /// step contracted the residual by at most [`CHORD_RATE`].
    keep_operator: bool,
    /// The operator was last rebuilt by refactoring a direct factorization.
    refactored: bool,
}

/// Newton's vectors, kept between solves.
#[derive(Default)]
struct Scratch {
    r: Vec<f64>,
    delta: Vec<f64>,
    jd: Vec<f64>,
    /// The active set the step starts from, and the one at its end.
    set: Vec<bool>,
    after: Vec<bool>,
}

/// What one solve carries from one Newton iteration to the next.
struct Progress {
    /// The convergence measure: ‖R‖∞ (plus what `carried` bounds).
    res: f64,
    /// Newton's threshold on `res` for this solve.
    threshold: f64,
    /// The active set at the iterate, when the last step found it (in `Scratch::after`), and
    /// whether it decides the tangent there.
    known: bool,
    piecewise_after: bool,
    /// ‖R‖₂ at the last solve's start (iterative solves).
    last_norm2: Option<f64>,
    small_step: bool,
    /// A bound on what R(w) holds beyond r: the errors of solves whose residual was then
    /// evaluated on the nonlinear terms' dofs only (`residual_on_support`).
    carried: f64,
    /// Backtracking (`line_search`, or where full steps stall: a problem that is not
    /// piecewise, a frictional law, may cycle between stick and slip; semi-smooth Newton on a
    /// piecewise one converges without it, through residuals that grow on the way).
    search: bool,
    best: f64,
    stalled: usize,
    /// The last step was a chord step (its operator kept from an earlier iterate).
    stale: bool,
    /// ‖r‖∞ of the r the next solve is given.
    norm_r: f64,
}

impl Progress {
    fn new(r0: f64, threshold: f64, line_search: bool) -> Self {
        Progress {
            res: r0,
            threshold,
            known: false,
            piecewise_after: false,
            last_norm2: None,
            small_step: false,
            carried: 0.0,
            search: line_search,
            best: r0,
            stalled: 0,
            stale: false,
            norm_r: r0,
        }
    }

    /// The active set at the iterate into `scratch.set` (the one the last step found, if it
    /// did), and whether it decides the tangent there.
    fn active_set(&mut self, p: &mut impl NonlinearProblem, w: &[f64], scratch: &mut Scratch) -> bool {
        let piecewise = if self.known {
            std::mem::swap(&mut scratch.set, &mut scratch.after);
            self.piecewise_after
        } else {
            scratch.set.clear();
            p.active_set(w, &mut scratch.set)
        };
        self.known = false;
        piecewise
    }

    /// Keeps the best residual so far; three full steps without a new best turn backtracking
    /// on from here on (a tangent that is not piecewise only).
    fn note_best(&mut self, piecewise: bool) {
        if self.res < self.best {
            (self.best, self.stalled) = (self.res, 0);
        } else {
            self.stalled += 1;
            self.search |= !piecewise && self.stalled >= 3;
        }
    }
}

/// One Newton step's linear solve: what it was asked for and what is known of its accuracy.
struct Solved {
    /// The relative tolerance an iterative solve was given (none: a direct solve).
    eta: Option<f64>,
    /// ‖R‖₂ at the solve (iterative solves; 0 otherwise).
    norm2_r: f64,
    /// The step is the solve's first.
    first: bool,
    /// The solve was loose ([`LOOSE`]): the active set is expected to change.
    loose: bool,
    /// The relative accuracy a trusted operator's solves have.
    trusted: Option<f64>,
    /// A corrected operator's first solve, estimated from its reference's accuracy and the
    /// correction's own residual.
    estimate: Option<f64>,
    /// Its accuracy is measured by a product J δ.
    checked: bool,
}

impl Newton {
    pub fn new(options: NewtonOptions) -> Self {
        Newton {
            options,
            reuse: JacobianReuse::default(),
            scratch: Scratch::default(),
            first_changed: false,
            keep_operator: false,
            refactored: false,
        }
    }

    /// Starts from `other`'s symbolic analysis and takes its factor's storage, if this Newton
    /// has no factorization and the other has one (a scheme's initial problem, solved once, and
    /// its first stage); `other` is left to refactor at its next solve.
    pub fn inherit(&mut self, other: &mut Newton) {
        self.reuse.inherit(&mut other.reuse);
    }

    /// Starts from `other`'s symbolic analysis, if this Newton has none and the other has one
    /// (a problem with the same Jacobian pattern: a scheme's initial problem and its stages).
    pub fn share_analysis(&mut self, other: &Newton) {
        self.reuse.share_analysis(&other.reuse);
    }

    /// Forgets the factorization's validity (the linear part of the problem changed).
    pub fn invalidate(&mut self) {
        self.reuse.invalidate();
        self.keep_operator = false;
    }

    /// Drops every factorization and correction (their counters are kept): the next solve
    /// runs exactly as a new `Newton`'s would. Checkpoints use it, so that a resumed run and an
    /// uninterrupted one follow the same factorizations and agree bit for bit.
    pub fn forget(&mut self) {
        self.reuse.forget();
        self.first_changed = false;
        self.keep_operator = false;
    }

    /// Stored values of the current Cholesky factor, if there is one.
    pub fn factor_nnz(&self) -> Option<usize> {
        self.reuse.factor_nnz()
    }

    /// Symbolic and numeric factorizations, low-rank corrections and solves so far.
    pub fn counters(&self) -> crate::linalg::Counters {
        self.reuse.counters()
    }

    /// Solves R(w) = 0 starting from `w`, which holds the solution on success.
    pub fn solve(&mut self, p: &mut impl NonlinearProblem, w: &mut [f64]) -> Result<NewtonReport, NewtonError> {
        // The vectors live from one solve (time step) to the next.
        let mut scratch = std::mem::take(&mut self.scratch);
        let n = w.len();
        for v in [&mut scratch.r, &mut scratch.delta, &mut scratch.jd] {
            v.resize(n, 0.0);
        }
        let result = self.solve_with(p, w, &mut scratch);
        self.scratch = scratch;
        result
    }

    fn solve_with(
        &mut self,
        p: &mut impl NonlinearProblem,
        w: &mut [f64],
        scratch: &mut Scratch,
    ) -> Result<NewtonReport, NewtonError> {
        p.residual(w, &mut scratch.r);
        let r0 = norm_inf(&scratch.r);
        let mut report = NewtonReport { initial_residual: r0, history: Vec::new() };
        if !r0.is_finite() {
            return Err(NewtonError::NonFinite { report });
        }
        // Floored at the smallest normal number: a state decaying to zero (a damped scheme run
        // for long) makes the thresholds underflow to 0, which no subnormal residual could reach.
        let floor = (ROUNDOFF * p.magnitude()).max(f64::MIN_POSITIVE);
        let threshold = (self.options.tol * r0).max(floor);
        let mut s = Progress::new(r0, threshold, self.options.line_search);
        while !converged(s.res, floor, threshold, !report.history.is_empty(), s.small_step) {
            if report.history.len() >= self.options.max_iterations {
                return Err(NewtonError::IterationLimit { report, threshold });
            }
            let piecewise = s.active_set(p, w, scratch);
            let active = scratch.set.iter().filter(|b| **b).count();
            let (refactor, updated) = match self.operator_for(p, w, &scratch.set, piecewise) {
                Ok(built) => built,
                Err(source) => return Err(NewtonError::Linear { source, report }),
            };
            let first = report.history.is_empty();
            let solved = match self.solve_linear(scratch, piecewise, first, &mut s) {
                Ok(solved) => solved,
                Err(source) => return Err(NewtonError::Linear { source, report }),
            };
            let linear = self.linear_residual(p, &solved, scratch, s.norm_r);
            // An iterative solve's residual is what it was asked for (its ∞-norm at most its 2-norm).
            let allowed =
                solved.eta.map_or(LINEAR_TOLERANCE, |eta| LINEAR_TOLERANCE.max(2.0 * eta * solved.norm2_r / s.norm_r));
            if linear.is_nan() || linear > allowed {
                if self.reuse.low_rank.as_ref().is_some_and(|lr| lr.rank() > 0) {
                    // An ill-conditioned correction: refactor at this iterate and retry.
                    debug!(linear_residual = linear, "low-rank correction inaccurate: refactoring");
                    self.reuse.force_refactor = true;
                    self.reuse.factored_for = None;
                    self.reuse.solve_accuracy = None;
                    continue;
                }
                let source = LinalgError::Singular { index: None };
                debug!(linear_residual = linear, "the Jacobian is singular to working precision");
                return Err(NewtonError::Linear { source, report });
            }
            self.trust(&solved, linear, refactor);
            let before = s.res;
            s.stale = !piecewise && !refactor && !updated;
            let step = if piecewise && !self.options.line_search {
                self.affine_step(p, w, scratch, &solved, &mut s)
            } else {
                self.full_step(p, w, scratch, &mut s)
            };
            s.note_best(piecewise);
            if !piecewise {
                self.keep_for_chord(refactor, updated, s.res / before);
            }
            let it = Iteration { residual: s.res, active, refactored: refactor, updated, step, tolerance: solved.eta };
            debug!(
                iteration = report.history.len() + 1,
                residual = it.residual,
                active,
                refactor,
                updated,
                step,
                tolerance = it.tolerance,
                "newton"
            );
            report.history.push(it);
            if !s.res.is_finite() || w.iter().any(|x| !x.is_finite()) {
                return Err(NewtonError::NonFinite { report });
            }
        }
        Ok(report)
    }

    /// The operator for the active set `set`: kept while `set` is the one it was factored for
    /// and the tangent piecewise, or not piecewise but kept by chord Newton (`keep_operator`),
    /// else a new one, corrected or refactored. Returns whether it was refactored, and whether
    /// corrected.
    fn operator_for(
        &mut self,
        p: &mut impl NonlinearProblem,
        w: &[f64],
        set: &[bool],
        piecewise: bool,
    ) -> Result<(bool, bool), LinalgError> {
        let changed = (!piecewise && !self.keep_operator)
            || self.reuse.force_refactor
            || self.reuse.factored_for.as_deref() != Some(set);
        if !changed {
            return Ok((false, false));
        }
        self.reuse.factored_for = None;
        let full = self.reuse.new_operator(p, w, self.options.solver, self.options.max_rank, piecewise)?;
        let (refactor, updated) = (full, !full);
        self.reuse.factored_for = Some(set.to_vec());
        self.reuse.jacobian_norm = match (updated, &self.reuse.low_rank) {
            (true, Some(lr)) => self.reuse.reference_norm + lr.change_norm(),
            _ => {
                self.reuse.reference_norm = self.reuse.jacobian.as_ref().map_or(f64::INFINITY, Matrix::norm_inf);
                self.reuse.reference_norm
            }
        };
        self.reuse.solve_accuracy = None;
        Ok((refactor, updated))
    }

    /// Whether the next iterate of a tangent that is not piecewise keeps this operator: if its
    /// last rebuild refactored a direct factorization (a correction is cheap to make again:
    /// a frictional law's, on the contact dofs), and this step contracted the residual by at
    /// most [`CHORD_RATE`].
    fn keep_for_chord(&mut self, refactor: bool, updated: bool, contraction: f64) {
        let direct = self.reuse.factorization.as_ref().is_some_and(Factorization::is_direct);
        if refactor || updated {
            self.refactored = refactor && direct;
        }
        self.keep_operator =
            self.options.chord && !self.options.line_search && self.refactored && contraction <= CHORD_RATE;
    }

    /// Solves J δ = −R into `delta`, asking an iterative solve for what this iteration needs,
    /// and says what is known of the solve's accuracy.
    fn solve_linear(
        &mut self,
        scratch: &mut Scratch,
        piecewise: bool,
        first: bool,
        s: &mut Progress,
    ) -> Result<Solved, LinalgError> {
        let (r, delta) = (&scratch.r, &mut scratch.delta);
        delta.iter_mut().zip(r.iter()).for_each(|(d, ri)| *d = -ri);
        let f = self.reuse.factorization.as_mut().expect("factored above");
        let iterative = f.iterates();
        let norm2_r = if iterative { norm2(r) } else { 0.0 };
        // A tangent the set does not decide (a frictional law in contact) converges
        // superlinearly at best: its early solves need only Eisenstat and Walker's accuracy.
        let superlinear = (!piecewise).then(|| s.last_norm2.map_or(LOOSE, |last| 0.9 * (norm2_r / last).powi(2)));
        s.last_norm2 = Some(norm2_r);
        let plain = piecewise && !self.options.line_search;
        let loose = iterative && plain && first && self.first_changed;
        let eta = iterative.then(|| f.set_tolerance(forcing(norm2_r, s.threshold, loose, superlinear)));
        // (A kept operator's solves are trusted whether or not the tangent is piecewise.)
        let trusted = self.reuse.solve_accuracy;
        // A correction of a reference whose solves are trusted reports the residual it
        // leaves itself (`LowRank::solve`): its first solve needs no product J δ then.
        let defect = trusted.is_none() && plain && self.reuse.reference_accuracy.is_some();
        let f = self.reuse.factorization.as_mut().expect("factored above");
        let defect = match &self.reuse.low_rank {
            Some(lr) => lr.solve(f, delta, defect)?,
            None => f.solve_in_place(delta).map(|()| None)?,
        };
        if let Some(lr) = &self.reuse.low_rank {
            self.reuse.overhead = self.reuse.overhead.saturating_add(lr.entries());
            self.reuse.force_refactor = self.reuse.overhead > self.reuse.overhead_budget(delta.len());
        }
        // A direct solve is backward stable unless the operator is numerically singular or
        // its correction ill-conditioned: the first solve with a new operator is checked
        // (J δ + R), and if it is accurate, ten times its relative error bounds the later
        // solves' (no product J δ for them). Iterative solves are always checked. A
        // corrected operator's first solve is estimated instead, when its reference's solves
        // are trusted: their accuracy plus the correction's own residual, if that is small.
        // (`norm_r` is ‖r‖∞ here: the loop goes on only after a step that evaluated r.)
        let estimate =
            defect.zip(self.reuse.reference_accuracy).map(|(d, a)| a + d / s.norm_r).filter(|e| *e <= TRUSTED_ACCURACY);
        let checked = trusted.is_none() && estimate.is_none();
        Ok(Solved { eta, norm2_r, first, loose, trusted, estimate, checked })
    }

    /// The solve's relative residual ‖J δ + R‖∞ / ‖R‖∞: estimated, bounded (0: trusted), or
    /// measured by the product J δ, which is left in `scratch.jd`.
    fn linear_residual(
        &self,
        p: &mut impl NonlinearProblem,
        solved: &Solved,
        scratch: &mut Scratch,
        norm_r: f64,
    ) -> f64 {
        let Scratch { r, delta, jd, .. } = scratch;
        let j = self.reuse.jacobian.as_ref().expect("assembled above");
        if let Some(e) = solved.estimate {
            return e;
        }
        if !solved.checked {
            return 0.0;
        }
        // Aᵀ δ reads half the bytes, but only a problem declared symmetric is sure to stay
        // so (under Structure::Auto a corrected Cholesky reference may meet a nonsymmetric J).
        if p.jacobian_product(j, delta, jd) {
            // Test builds check the problem's product against j's, to round-off.
            if cfg!(debug_assertions) {
                let mut full = vec![0.0; delta.len()];
                j.mul_vec(delta, &mut full);
                let scale = j.norm_inf() * norm_inf(delta);
                let err = full.iter().zip(jd.iter()).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
                assert!(err <= 64.0 * f64::EPSILON * scale, "jacobian_product differs by {err:e}");
            }
        } else if p.structure() == Structure::SymmetricPositiveDefinite {
            j.mul_vec_transposed(delta, jd);
        } else {
            j.mul_vec(delta, jd);
        }
        jd.iter().zip(r.iter()).map(|(a, b)| (a + b).abs()).fold(0.0, f64::max) / norm_r
    }

    /// Only an operator whose first solve was accurate to near round-off is trusted; an
    /// ill-conditioned one (a huge penalty or Nitsche parameter) is checked at every solve.
    fn trust(&mut self, solved: &Solved, linear: f64, refactor: bool) {
        if solved.trusted.is_none()
            && linear <= TRUSTED_ACCURACY
            && self.reuse.factorization.as_ref().is_some_and(Factorization::is_direct)
        {
            self.reuse.solve_accuracy = Some(10.0 * linear);
            // A new factorization's first solve, checked: the reference its corrections
            // are estimated from.
            if refactor && solved.checked {
                self.reuse.reference_accuracy = self.reuse.solve_accuracy;
            }
        }
    }

    /// The full step of a piecewise tangent without line search. R is affine wherever the
    /// active set is the one J was built for: if it still is at the new iterate, R there is
    /// R + J δ (or, after a trusted or estimated solve, bounded by the solve's error), and no
    /// assembly is needed. Leaves the new active set in `scratch.after`.
    fn affine_step(
        &mut self,
        p: &mut impl NonlinearProblem,
        w: &mut [f64],
        scratch: &mut Scratch,
        solved: &Solved,
        s: &mut Progress,
    ) -> f64 {
        let Scratch { r, delta, jd, set, after } = scratch;
        let threshold = s.threshold;
        // The relative accuracy of this solve, where it is not measured by a product.
        let accuracy = solved.trusted.or(solved.estimate);
        w.iter_mut().zip(delta.iter()).for_each(|(x, d)| *x += d);
        after.clear();
        s.piecewise_after = p.active_set(w, after);
        let kept = s.piecewise_after && after == set;
        // After a trusted or estimated solve R there is the solve's error: its relative
        // accuracy times ‖R‖, plus the round-off ε‖J‖‖δ‖ of the solve.
        let norm_delta = norm_inf(delta);
        let bound = accuracy.map(|a| a * s.norm_r + ROUNDOFF * self.reuse.jacobian_norm * norm_delta + s.carried);
        let estimated = kept && bound.is_some_and(|b| b <= threshold);
        if estimated {
            s.res = bound.expect("trusted");
        } else if kept && solved.checked {
            r.iter_mut().zip(jd.iter()).for_each(|(ri, x)| *ri += x);
        } else if let Some(b) = bound.filter(|_| !kept)
            && p.residual_on_support(w, r)
        {
            // The set changed where the nonlinear terms are: elsewhere R is this
            // solve's error, bounded by b.
            s.carried = b;
        } else {
            p.residual(w, r);
            s.carried = 0.0;
        }
        if !estimated {
            s.norm_r = norm_inf(r);
            if s.carried > 0.0 && s.norm_r <= threshold && s.norm_r + s.carried > threshold {
                // Only the carried bound stands between r and convergence: the whole
                // residual decides (and the next solve is never given an r of zero).
                p.residual(w, r);
                s.carried = 0.0;
                s.norm_r = norm_inf(r);
            }
            s.res = s.norm_r + s.carried;
        }
        s.small_step = kept && !solved.loose && norm_delta <= self.options.tol * norm_inf(w);
        if solved.first {
            self.first_changed = !kept;
        }
        s.known = true;
        1.0
    }

    /// A step with line search, or of a tangent that is not piecewise: R evaluated at the new
    /// iterate, into `scratch.r`.
    fn full_step(&self, p: &mut impl NonlinearProblem, w: &mut [f64], scratch: &mut Scratch, s: &mut Progress) -> f64 {
        let Scratch { r, delta, set, after, .. } = &mut *scratch;
        let step = self.step(p, w, delta, r, s.search);
        after.clear();
        p.active_set(w, after);
        let res = norm_inf(r);
        // A step is the error it leaves only where Newton converges faster than linearly; a
        // chord step contracting by θ leaves about θ/(1 − θ) of itself, at most itself for
        // θ ≤ 1/2.
        s.small_step = after == set
            && step * norm_inf(delta) <= self.options.tol * norm_inf(w)
            && (!s.stale || res <= 0.5 * s.res);
        s.res = res;
        s.norm_r = s.res;
        s.carried = 0.0;
        step
    }

    /// Takes the step (with backtracking if `search`); leaves R at the new iterate in `r`.
    fn step(&self, p: &mut impl NonlinearProblem, w: &mut [f64], delta: &[f64], r: &mut [f64], search: bool) -> f64 {
        let start: Vec<f64> = if search { w.to_vec() } else { Vec::new() };
        let norm0 = if search { norm2(r) } else { 0.0 };
        let mut alpha = 1.0;
        loop {
            if search {
                w.iter_mut().zip(&start).zip(delta).for_each(|((x, s), d)| *x = s + alpha * d);
            } else {
                w.iter_mut().zip(delta).for_each(|(x, d)| *x += d);
            }
            p.residual(w, r);
            if !search || norm2(r) <= (1.0 - 1e-4 * alpha) * norm0 || alpha < 1e-3 {
                return alpha;
            }
            alpha *= 0.5;
        }
    }
}

/// The relative tolerance η of an iterative solve, ‖J δ + R‖₂ ≤ η‖R‖₂ (inexact Newton): loose
/// where the iteration is expected to change the active set, whose next iteration corrects the
/// solve's error anyway; otherwise what brings R below Newton's threshold (the 2-norm bounds
/// the ∞-norm the threshold is in), or `superlinear` if that is looser (Eisenstat–Walker's
/// choice 2 for a tangent that is not piecewise: 0.9 (‖R_k‖/‖R_{k−1}‖)², LOOSE first), never
/// tighter than the solvers' default.
fn forcing(norm2_r: f64, threshold: f64, loose: bool, superlinear: Option<f64>) -> f64 {
    let tight = crate::linalg::krylov::TOLERANCE;
    let finish = FINISH * threshold / norm2_r;
    // The clamp also catches a zero or infinite ‖R‖₂ (NaN falls to the tight end).
    if loose { LOOSE } else { superlinear.map_or(finish, |s| s.max(finish)).clamp(tight, LOOSE).max(tight) }
}

/// ‖v‖₂, scaled by ‖v‖∞ so that neither tiny nor huge entries under- or overflow.
fn norm2(v: &[f64]) -> f64 {
    let scale = norm_inf(v);
    if scale == 0.0 || !scale.is_finite() {
        return scale;
    }
    scale * v.iter().map(|x| (x / scale) * (x / scale)).sum::<f64>().sqrt()
}
