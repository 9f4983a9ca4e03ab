//! Where a displacement turns a cell inside out: the volume ratio J = det(I + ∇u) of each
//! cell's map moved by u (x → x + u), at its nodes and quadrature points.
//! A finite-strain material's stored energy is not defined for J ≤ 0 (ln J), and its stress
//! becomes NaN there: this says where, in terms of the mesh, without naming a material.

use super::Mesh;

/// The cell with the least corner volume ratio, when it is not positive.
#[derive(Clone, Debug, PartialEq)]
pub struct Inverted {
    pub cell: usize,
    /// The cell's corners, at their reference positions.
    pub corners: Vec<Vec<f64>>,
    /// The least volume ratio det(I + ∇u) found in the cell.
    pub j: f64,
}

impl std::fmt::Display for Inverted {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.corners.is_empty() {
            return write!(f, "a cell of another process is inverted (J = det(I + grad u) ≤ 0 in it)");
        }
        let at: Vec<String> = self
            .corners
            .iter()
            .map(|x| format!("({})", x.iter().map(|c| format!("{c:.6}")).collect::<Vec<_>>().join(", ")))
            .collect();
        write!(
            f,
            "cell {} (corners at {}) is inverted: its volume ratio J = det(I + grad u) reaches {:.6e}",
            self.cell,
            at.join(", "),
            self.j
        )
    }
}

/// det(Σ_a x_a ⊗ ∇N_a) of a cell's nodes `x` (nodes × d) with reference gradients `g`.
fn jacobian_det(x: &[[f64; 3]], g: &[Vec<f64>], d: usize) -> f64 {
    let mut j = [[0.0; 3]; 3];
    for (a, p) in x.iter().enumerate().take(g.len()) {
        for r in 0..d {
            for s in 0..d {
                j[r][s] += p[r] * g[a][s];
            }
        }
    }
    super::det(&j, d)
}

/// The cell whose map moved by `u` (nodes × d) has the least volume ratio J = det(I + ∇u)
/// at its nodes and at the points of the quadrature rules to degree 12, if it is not positive (or not finite: a
/// NaN displacement). For P1 cells J is constant; for P2 (isoparametric) cells it is a
/// polynomial, sampled where the forms read it.
pub fn most_inverted(mesh: &Mesh, u: &[f64]) -> Option<Inverted> {
    let d = mesh.dim();
    if u.len() != mesh.num_nodes() * d {
        return None;
    }
    // The nodes, and the points of the rules of even degree to 12: where the forms read J.
    let mut points = mesh.kind.reference_nodes();
    for degree in (2..=12).step_by(2) {
        points.extend(crate::fem::quadrature::simplex_rule(d, degree).points);
    }
    let grads: Vec<Vec<Vec<f64>>> = points.iter().map(|p| mesh.kind.basis_gradients(p)).collect();
    let per = mesh.cell(0).len();
    let (mut reference, mut moved) = (vec![[0.0; 3]; per], vec![[0.0; 3]; per]);
    let mut worst: Option<(usize, f64)> = None;
    for c in 0..mesh.num_cells() {
        for (k, &node) in mesh.cell(c).iter().enumerate() {
            let x = mesh.node(node as usize);
            for i in 0..d {
                reference[k][i] = x[i];
                moved[k][i] = x[i] + u[node as usize * d + i];
            }
        }
        for g in &grads {
            let j = jacobian_det(&moved, g, d) / jacobian_det(&reference, g, d);
            if (j <= 0.0 || j.is_nan()) && worst.is_none_or(|(_, w)| j < w || j.is_nan()) {
                worst = Some((c, j));
            }
        }
        if worst.is_some_and(|(_, j)| j.is_nan()) {
            break;
        }
    }
    worst.map(|(cell, j)| Inverted {
        cell,
        corners: mesh.cell(cell)[..=d].iter().map(|&n| mesh.node(n as usize).to_vec()).collect(),
        j,
    })
}

/// The most inverted cell of `u` on the assembler's mesh, decided alike by every process of a
/// split run (one that sees none says so with an empty `Inverted` when another does).
pub fn anywhere(asm: &crate::fem::assembly::Assembler, u: &[f64]) -> Option<Inverted> {
    let here = most_inverted(asm.mesh(), u);
    let anywhere = match asm.pattern().ownership() {
        Some(o) => o.any(here.is_some()),
        None => here.is_some(),
    };
    anywhere.then(|| here.unwrap_or(Inverted { cell: usize::MAX, corners: Vec::new(), j: f64::NAN }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::element::ElementKind;

    fn square() -> Mesh {
        // Two triangles of the unit square.
        let coords = vec![0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0, 1.0];
        Mesh::from_cells(ElementKind::TriangleP1, coords, vec![0, 1, 2, 0, 2, 3])
    }

    #[test]
    fn a_stretch_inverts_nothing_and_a_fold_inverts_the_folded_cell() {
        let mesh = square();
        // u = (x, 0): F = diag(2, 1), J = 2 everywhere.
        let stretch: Vec<f64> = (0..4).flat_map(|i| [mesh.node(i)[0], 0.0]).collect();
        assert_eq!(most_inverted(&mesh, &stretch), None);
        // Node 1 moved across the diagonal to (0.2, 0.9): the first cell turns inside out.
        let mut fold = vec![0.0; 8];
        fold[2] = -0.8;
        fold[3] = 0.9;
        let inverted = most_inverted(&mesh, &fold).expect("folded");
        assert_eq!(inverted.cell, 0);
        // The moved triangle (0,0), (0.2,0.9), (1,1) has signed area (0.2 − 0.9)/2 against 1/2:
        // J = −0.7 everywhere in it.
        assert!((inverted.j - (0.2 * 1.0 - 0.9 * 1.0)).abs() < 1e-15, "J = {}", inverted.j);
        assert!(inverted.to_string().contains("cell 0"));
    }
}
