//! Pointwise geometry of isoparametric cells, used by the compiled kernels: Jacobian of the
//! reference map, physical gradients, interpolation, facet normals and measures.
//!
//! Conventions: `J[a][b] = ∂x_a/∂ξ_b`; `inv = J⁻¹`, so `inv[b][l] = ∂ξ_b/∂x_l` and the
//! physical gradient of a basis function is `Σ_b inv[b][l] ∂φ/∂ξ_b`.

/// The reference-to-physical map at one point.
#[derive(Clone, Copy, Debug)]
pub struct Jacobian<const D: usize> {
    pub j: [[f64; D]; D],
    pub det: f64,
    pub inv: [[f64; D]; D],
}

/// Jacobian at a point from the cell's node coordinates and the reference gradients there.
#[inline(always)]
pub fn jacobian<const D: usize, const N: usize>(coords: &[[f64; D]; N], dref: &[[f64; D]; N]) -> Jacobian<D> {
    let mut j = [[0.0; D]; D];
    for (x, g) in coords.iter().zip(dref) {
        for a in 0..D {
            for b in 0..D {
                j[a][b] += x[a] * g[b];
            }
        }
    }
    let (det, inv) = invert(&j);
    Jacobian { j, det, inv }
}

/// Determinant and inverse of a 1×1, 2×2 or 3×3 matrix (the inverse of a singular matrix is
/// not finite; callers check cells for degeneracy before assembling).
#[inline(always)]
pub fn invert<const D: usize>(m: &[[f64; D]; D]) -> (f64, [[f64; D]; D]) {
    let mut inv = [[0.0; D]; D];
    let det = match D {
        1 => {
            inv[0][0] = 1.0 / m[0][0];
            m[0][0]
        }
        2 => {
            let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
            let r = 1.0 / det;
            inv[0][0] = m[1][1] * r;
            inv[0][1] = -m[0][1] * r;
            inv[1][0] = -m[1][0] * r;
            inv[1][1] = m[0][0] * r;
            det
        }
        3 => {
            let c00 = m[1][1] * m[2][2] - m[1][2] * m[2][1];
            let c01 = m[1][2] * m[2][0] - m[1][0] * m[2][2];
            let c02 = m[1][0] * m[2][1] - m[1][1] * m[2][0];
            let det = m[0][0] * c00 + m[0][1] * c01 + m[0][2] * c02;
            let r = 1.0 / det;
            inv[0][0] = c00 * r;
            inv[1][0] = c01 * r;
            inv[2][0] = c02 * r;
            inv[0][1] = (m[0][2] * m[2][1] - m[0][1] * m[2][2]) * r;
            inv[1][1] = (m[0][0] * m[2][2] - m[0][2] * m[2][0]) * r;
            inv[2][1] = (m[0][1] * m[2][0] - m[0][0] * m[2][1]) * r;
            inv[0][2] = (m[0][1] * m[1][2] - m[0][2] * m[1][1]) * r;
            inv[1][2] = (m[0][2] * m[1][0] - m[0][0] * m[1][2]) * r;
            inv[2][2] = (m[0][0] * m[1][1] - m[0][1] * m[1][0]) * r;
            det
        }
        _ => unreachable!("cells of dimension 1, 2 or 3"),
    };
    (det, inv)
}

/// Physical gradients of all basis functions: `[node][direction]`.
#[inline(always)]
pub fn physical_gradients<const D: usize, const N: usize>(jac: &Jacobian<D>, dref: &[[f64; D]; N]) -> [[f64; D]; N] {
    let mut g = [[0.0; D]; N];
    for (gi, ri) in g.iter_mut().zip(dref) {
        for l in 0..D {
            let mut s = 0.0;
            for b in 0..D {
                s += jac.inv[b][l] * ri[b];
            }
            gi[l] = s;
        }
    }
    g
}

/// Value at a point of a vector field given at the nodes.
#[inline(always)]
pub fn interpolate<const D: usize, const N: usize>(values: &[[f64; D]; N], phi: &[f64; N]) -> [f64; D] {
    let mut v = [0.0; D];
    for (u, p) in values.iter().zip(phi) {
        for k in 0..D {
            v[k] += u[k] * p;
        }
    }
    v
}

/// Gradient at a point of a vector field given at the nodes: `[component][direction]`.
#[inline(always)]
pub fn gradient<const D: usize, const N: usize>(values: &[[f64; D]; N], dphi: &[[f64; D]; N]) -> [[f64; D]; D] {
    let mut g = [[0.0; D]; D];
    for (u, dp) in values.iter().zip(dphi) {
        for k in 0..D {
            for l in 0..D {
                g[k][l] += u[k] * dp[l];
            }
        }
    }
    g
}

/// Outward unit normal at a facet point and the ratio of physical to reference facet measure
/// (Nanson: |det J| · |J⁻ᵀ N|).
#[inline(always)]
pub fn facet_normal<const D: usize>(jac: &Jacobian<D>, ref_normal: &[f64; D]) -> ([f64; D], f64) {
    let mut n = [0.0; D];
    for (l, nl) in n.iter_mut().enumerate() {
        for b in 0..D {
            *nl += jac.inv[b][l] * ref_normal[b];
        }
    }
    let norm = n.iter().map(|x| x * x).sum::<f64>().sqrt();
    for x in n.iter_mut() {
        *x /= norm;
    }
    (n, norm * jac.det.abs())
}

/// GetFEM's `element_size` of a cell with nodes `coords` (in node order): √d times the largest,
/// over the reference nodes ξ, of the smallest singular value of J(ξ) = Σⱼ xⱼ ⊗ ∇φⱼ(ξ), the
/// Jacobian of the map from the unit-leg reference simplex (in 1D, the length).
pub fn getfem_size(kind: crate::fem::element::ElementKind, coords: &[&[f64]]) -> f64 {
    let d = kind.dim();
    let mut size: f64 = 0.0;
    for xi in kind.reference_nodes() {
        let grads = kind.basis_gradients(&xi);
        let mut j = [[0.0; 3]; 3];
        for (x, g) in coords.iter().zip(&grads) {
            for a in 0..d {
                for b in 0..d {
                    j[a][b] += x[a] * g[b];
                }
            }
        }
        size = size.max(smallest_singular_value(&j, d));
    }
    (d as f64).sqrt() * size
}

/// The smallest singular value of the leading d×d block of `j`: the square root of the
/// smallest eigenvalue of JᵀJ (closed forms for d ≤ 3).
pub fn smallest_singular_value(j: &[[f64; 3]; 3], d: usize) -> f64 {
    let mut m = [[0.0; 3]; 3];
    for a in 0..d {
        for b in 0..d {
            m[a][b] = (0..d).map(|k| j[k][a] * j[k][b]).sum();
        }
    }
    let lambda = match d {
        1 => m[0][0],
        2 => {
            let (p, q) = (0.5 * (m[0][0] + m[1][1]), 0.5 * (m[0][0] - m[1][1]));
            p - (q * q + m[0][1] * m[0][1]).sqrt()
        }
        _ => smallest_eigenvalue_3(&m),
    };
    lambda.max(0.0).sqrt()
}

/// The smallest eigenvalue of a symmetric 3×3 matrix (trigonometric form of the cubic's roots).
fn smallest_eigenvalue_3(m: &[[f64; 3]; 3]) -> f64 {
    let off = m[0][1] * m[0][1] + m[0][2] * m[0][2] + m[1][2] * m[1][2];
    let tr = m[0][0] + m[1][1] + m[2][2];
    if off == 0.0 {
        return m[0][0].min(m[1][1]).min(m[2][2]);
    }
    let q = tr / 3.0;
    let p = ((m[0][0] - q).powi(2) + (m[1][1] - q).powi(2) + (m[2][2] - q).powi(2) + 2.0 * off) / 6.0;
    let p = p.sqrt();
    let b = |i: usize, k: usize| (m[i][k] - if i == k { q } else { 0.0 }) / p;
    let det = b(0, 0) * (b(1, 1) * b(2, 2) - b(1, 2) * b(2, 1)) - b(0, 1) * (b(1, 0) * b(2, 2) - b(1, 2) * b(2, 0))
        + b(0, 2) * (b(1, 0) * b(2, 1) - b(1, 1) * b(2, 0));
    let phi = (0.5 * det).clamp(-1.0, 1.0).acos() / 3.0;
    // The three roots are q + 2p cos(φ + 2πk/3); k = 1 gives the smallest.
    q + 2.0 * p * (phi + 2.0 * std::f64::consts::PI / 3.0).cos()
}

/// Diameter of a cell: the largest distance between two of its first `vertices` nodes.
pub fn diameter<const D: usize, const N: usize>(coords: &[[f64; D]; N], vertices: usize) -> f64 {
    let mut h2: f64 = 0.0;
    for a in 0..vertices.min(N) {
        for b in a + 1..vertices.min(N) {
            h2 = h2.max((0..D).map(|k| (coords[a][k] - coords[b][k]).powi(2)).sum());
        }
    }
    h2.sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn getfem_size_of_straight_cells() {
        use crate::fem::element::ElementKind;
        // The reference triangle: J = I, σ_min = 1, size √2. Scaled by 3 along x: σ_min = 1.
        let tri = |p: &[[f64; 2]]| getfem_size(ElementKind::TriangleP1, &p.iter().map(|x| &x[..]).collect::<Vec<_>>());
        assert!((tri(&[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]) - 2f64.sqrt()).abs() < 1e-15);
        assert!((tri(&[[0.0, 0.0], [3.0, 0.0], [0.0, 1.0]]) - 2f64.sqrt()).abs() < 1e-15);
        assert!((tri(&[[0.0, 0.0], [2.0, 0.0], [0.0, 2.0]]) - 2.0 * 2f64.sqrt()).abs() < 1e-14);
        // 1D: the length.
        let seg = getfem_size(ElementKind::IntervalP1, &[&[0.25][..], &[0.75][..]]);
        assert!((seg - 0.5).abs() < 1e-15);
        // A tetrahedron stretched to (2, 3, 5): σ_min = 2, size 2√3.
        let tet: Vec<[f64; 3]> = vec![[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 3.0, 0.0], [0.0, 0.0, 5.0]];
        let s = getfem_size(ElementKind::TetrahedronP1, &tet.iter().map(|x| &x[..]).collect::<Vec<_>>());
        assert!((s - 2.0 * 3f64.sqrt()).abs() < 1e-13, "{s}");
    }

    #[test]
    fn smallest_singular_values_match_a_rotation_of_a_diagonal() {
        // J = R·diag(4, 1, 2.5) with R a rotation: σ_min = 1, in 2D (first block) and 3D.
        let (c, s) = (0.6f64, 0.8f64);
        let j2 = [[4.0 * c, -s, 0.0], [4.0 * s, c, 0.0], [0.0, 0.0, 0.0]];
        assert!((smallest_singular_value(&j2, 2) - 1.0).abs() < 1e-14);
        let r = [[c, -s, 0.0], [s * 0.5, c * 0.5, -0.75f64.sqrt()], [s * 0.75f64.sqrt(), c * 0.75f64.sqrt(), 0.5]];
        let diag = [4.0, 1.0, 2.5];
        let mut j3 = [[0.0; 3]; 3];
        for a in 0..3 {
            for b in 0..3 {
                j3[a][b] = r[a][b] * diag[b];
            }
        }
        assert!((smallest_singular_value(&j3, 3) - 1.0).abs() < 1e-12, "{}", smallest_singular_value(&j3, 3));
    }

    #[test]
    fn inverse_times_matrix_is_identity() {
        let m = [[2.0, 0.3, -0.5], [0.1, 1.5, 0.2], [-0.4, 0.7, 3.0]];
        let (det, inv) = invert(&m);
        assert!(det.abs() > 1.0);
        for i in 0..3 {
            for j in 0..3 {
                let p: f64 = (0..3).map(|k| m[i][k] * inv[k][j]).sum();
                assert!((p - f64::from(i == j)).abs() < 1e-14);
            }
        }
        let m2 = [[2.0, 0.3], [0.1, 1.5]];
        let (d2, i2) = invert(&m2);
        assert!((d2 - 2.97).abs() < 1e-14);
        assert!((m2[0][0] * i2[0][1] + m2[0][1] * i2[1][1]).abs() < 1e-14);
    }
}
