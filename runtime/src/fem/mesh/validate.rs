//! Mesh errors and the geometric check every mesh passes before use: finite coordinates, node
//! numbers in range, and cells that are neither degenerate nor inverted (the Jacobian of the
//! isoparametric map keeps one sign, away from zero, at every node of the cell); then the
//! topological checks of `integrity` (no repeated or overlapping cells).

use super::Mesh;

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MeshError {
    /// A problem at a line of an ASCII file.
    #[error("{file}:{line}: {reason}")]
    Line { file: String, line: usize, reason: String },
    /// A problem at a byte offset of a binary file.
    #[error("{file}: at byte {offset}: {reason}")]
    Byte { file: String, offset: usize, reason: String },
    /// A problem with a file as a whole.
    #[error("{file}: {reason}")]
    File { file: String, reason: String },
    #[error("node {node} has a non-finite coordinate")]
    NonFinite { node: usize },
    #[error("cell {cell} refers to node {node}, but there are {nodes} nodes")]
    NodeOutOfRange { cell: usize, node: usize, nodes: usize },
    #[error("cell {cell} is degenerate (Jacobian determinant {det:e} at node {at})")]
    Degenerate { cell: usize, at: usize, det: f64 },
    #[error("cell {cell} is inverted (its Jacobian determinant changes sign between its nodes)")]
    Inverted { cell: usize },
    #[error("no boundary region named `{name}` (regions: {})", if known.is_empty() { "none".to_string() } else { known.join(", ") })]
    NoSuchRegion { name: String, known: Vec<String> },
    #[error("the mesh has no cells")]
    Empty,
    #[error("cells {first} and {second} have the same vertices (a cell listed twice)")]
    DuplicateCell { first: usize, second: usize },
    #[error("cells {} share one facet, which bounds at most two cells: they overlap", list(cells))]
    FacetSharedByMany { cells: Vec<usize> },
    #[error("cells {first} and {second} share a facet and lie on the same side of it: they overlap (the mesh folds)")]
    SameSide { first: usize, second: usize },
    #[error("boundary region `{name}` {reason}")]
    EmptyRegion { name: String, reason: String },
}

fn list(cells: &[usize]) -> String {
    let s: Vec<String> = cells.iter().map(usize::to_string).collect();
    s.join(", ")
}

impl Mesh {
    /// Checks coordinates, connectivity, cell geometry, and that the cells neither repeat nor
    /// overlap (`integrity`).
    pub fn validate(&self) -> Result<(), MeshError> {
        if self.num_cells() == 0 {
            return Err(MeshError::Empty);
        }
        let d = self.dim();
        let nodes = self.num_nodes();
        if let Some(i) = self.coords.iter().position(|x| !x.is_finite()) {
            return Err(MeshError::NonFinite { node: i / d });
        }
        let ref_nodes = self.kind.reference_nodes();
        let grads: Vec<Vec<Vec<f64>>> = ref_nodes.iter().map(|p| self.kind.basis_gradients(p)).collect();
        for c in 0..self.num_cells() {
            let cell = self.cell(c);
            if let Some(&bad) = cell.iter().find(|&&n| n as usize >= nodes) {
                return Err(MeshError::NodeOutOfRange { cell: c, node: bad as usize, nodes });
            }
            let h = self.cell_diameter(c);
            let tol = 1e-10 * h.powi(d as i32);
            let mut sign = 0.0;
            for (at, g) in grads.iter().enumerate() {
                let mut j = [[0.0; 3]; 3];
                for (a, &node) in cell.iter().enumerate() {
                    let p = self.node(node as usize);
                    for r in 0..d {
                        for s in 0..d {
                            j[r][s] += p[r] * g[a][s];
                        }
                    }
                }
                let det = super::det(&j, d);
                if det.abs() <= tol || !det.is_finite() {
                    return Err(MeshError::Degenerate { cell: c, at, det });
                }
                if sign == 0.0 {
                    sign = det.signum();
                } else if det.signum() != sign {
                    return Err(MeshError::Inverted { cell: c });
                }
            }
        }
        super::integrity::check(self)
    }
}
