//! What Newton asks of a problem: its residual, its active set, its Jacobian (whole, updated
//! where it can change, or as element matrices), and the structure of its tangent.

use crate::linalg::element_matrices::ElementMatrices;
use crate::linalg::pattern::Entries;
use crate::linalg::{Matrix, Structure};

/// A nonlinear system R(w) = 0 with a (semi-smooth) Jacobian.
pub trait NonlinearProblem {
    /// Writes R(w) (zero on constrained dofs).
    fn residual(&mut self, w: &[f64], r: &mut [f64]);
    /// Writes R(w) on the dofs where the nonlinear terms can be nonzero, and zero elsewhere;
    /// false (r unspecified) if the problem does not know those dofs. Newton calls it when w
    /// = w₀ + δ for a δ that solved J δ = −R(w₀) to a known accuracy and the active set
    /// changed: elsewhere R(w) = R(w₀) + J δ is then that solve's error, which Newton carries
    /// in its bounds (and evaluates the whole residual when that bound alone keeps it from
    /// converging). With a factor in node blocks, the next solve's forward pass then visits
    /// the ancestors of these dofs only.
    fn residual_on_support(&mut self, _w: &[f64], _r: &mut [f64]) -> bool {
        false
    }
    /// The largest ∞-norm among the terms summed in the last `residual` (stiffness, inertia,
    /// contact, loads): the residual's round-off is about ε times this.
    fn magnitude(&self) -> f64;
    /// Writes the active set at w. Returns false if the Jacobian depends on w otherwise (then
    /// it is rebuilt at every iteration).
    fn active_set(&mut self, w: &[f64], out: &mut Vec<bool>) -> bool;
    /// Writes the Jacobian at w (constrained rows and columns replaced by the identity) into
    /// a zeroed `j`.
    fn jacobian(&mut self, w: &[f64], j: &mut Matrix);
    /// Makes `j`, which holds what this problem's last `jacobian` or `update_jacobian` wrote
    /// (the problem unchanged since), the Jacobian at w by rewriting only what can differ;
    /// false if it cannot (Newton then zeroes j and calls `jacobian`).
    fn update_jacobian(&mut self, _w: &[f64], _j: &mut Matrix) -> bool {
        false
    }
    /// Writes y = J x for `j`, which holds what this problem's last `jacobian` or
    /// `update_jacobian` wrote (the problem unchanged since), by a route that reads less than j
    /// (its constant part's lower half and the entries that vary); false if the problem has
    /// none (Newton then multiplies by j).
    fn jacobian_product(&mut self, _j: &Matrix, _x: &[f64], _y: &mut [f64]) -> bool {
        false
    }
    /// An empty matrix with the Jacobian's pattern.
    fn jacobian_matrix(&self) -> Matrix;
    /// Cholesky for symmetric positive definite Jacobians, LU otherwise.
    fn structure(&self) -> Structure;
    /// The entries outside which the Jacobian is the same at every w, if the problem knows
    /// them: corrections then compare Jacobians there only.
    fn varying_entries(&self) -> Option<&Entries> {
        None
    }
    /// The coordinates of the nodes whose displacements are the unknowns (`nodes × dim`,
    /// row-major), if they are: algebraic multigrid builds its near-null space (the rigid-body
    /// modes) from them.
    fn node_coordinates(&self) -> Option<std::sync::Arc<[f64]>> {
        None
    }
    /// The part of the Jacobian at w that varies with w, as element matrices (always the same
    /// elements), if the problem can give it: corrections then have the rank of the elements'
    /// changes rather than of the dofs they touch.
    fn tangent_elements(&mut self, _w: &[f64]) -> Option<ElementMatrices> {
        None
    }
}
