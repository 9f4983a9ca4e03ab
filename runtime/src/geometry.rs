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
