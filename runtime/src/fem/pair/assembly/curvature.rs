//! The facing side's second-order data on P2 cells, for the tangent's sliding part: as the
//! facing point slides, the facing fields' gradients move along their second derivatives, the
//! facing normal along the surface's curvature, and the facing facet's tangents along the
//! geometry map's second derivatives. All vanish on P1 cells (straight facets, linear fields).

use super::*;

/// The second-order data of a facing point.
pub(super) struct Curvature {
    /// Physical second derivatives of the facing cell's basis functions: `[a][l][m]`.
    pub d2phi: Vec<[[f64; MAX_DIM]; MAX_DIM]>,
    /// ∂T_α/∂s_β, the facing facet's reference tangents' rates along it: `[α][β][r]`.
    pub dtangents: [[[f64; MAX_DIM]; 2]; 2],
}

/// Fills the facing side's fields' second derivatives and its normal's rate (`other`, at a
/// point of `cell` with reference normal `ref_normal`), and returns the basis functions'
/// second derivatives and the tangents' rates (the facet's reference edges `edges`); `href`
/// the basis' reference second derivatives.
pub(super) fn curvature(
    mesh: &Mesh,
    cell: usize,
    href: &[Vec<Vec<f64>>],
    other: &mut Side,
    ref_normal: &[f64],
    edges: &[[f64; MAX_DIM]],
    fields: &[&[f64]],
) -> Curvature {
    let d = mesh.dim();
    let nodes = mesh.cell(cell);
    // x2[r][b][c] = ∂²x_r/∂ξ_b∂ξ_c, the geometry map's second derivatives.
    let mut x2 = [[[0.0; MAX_DIM]; MAX_DIM]; MAX_DIM];
    for (a, &n) in nodes.iter().enumerate() {
        let p = mesh.node(n as usize);
        for r in 0..d {
            for b in 0..d {
                for c in 0..d {
                    x2[r][b][c] += p[r] * href[a][b][c];
                }
            }
        }
    }
    let (_, inv) = invert(&other.jacobian, d);
    // φ(ξ) = ψ(x(ξ)): ∂²ψ/∂x_l∂x_m = Σ J⁻¹_bl J⁻¹_cm (∂²φ/∂ξ_b∂ξ_c − Σ_k ∂ψ/∂x_k x2[k][b][c]).
    let d2phi: Vec<[[f64; MAX_DIM]; MAX_DIM]> = (0..nodes.len())
        .map(|a| {
            let mut reduced = [[0.0; MAX_DIM]; MAX_DIM];
            for b in 0..d {
                for c in 0..d {
                    reduced[b][c] = href[a][b][c] - (0..d).map(|k| other.dphi[a][k] * x2[k][b][c]).sum::<f64>();
                }
            }
            std::array::from_fn(|l| {
                std::array::from_fn(|m| {
                    if l >= d || m >= d {
                        return 0.0;
                    }
                    (0..d)
                        .flat_map(|b| (0..d).map(move |c| (b, c)))
                        .map(|(b, c)| inv[b][l] * reduced[b][c] * inv[c][m])
                        .sum()
                })
            })
        })
        .collect();
    for (at, u) in other.side.fields.iter_mut().zip(fields) {
        for (a, &n) in nodes.iter().enumerate() {
            for k in 0..d {
                let ua = u.get(n as usize * d + k).copied().unwrap_or(f64::NAN);
                for l in 0..d {
                    for m in 0..d {
                        at.hess[k][l][m] += d2phi[a][l][m] * ua;
                    }
                }
            }
        }
    }
    other.side.normal_rate = normal_rate(&inv, &x2, ref_normal, &other.side.normal, d);
    let mut dtangents = [[[0.0; MAX_DIM]; 2]; 2];
    for (alpha, ea) in edges.iter().enumerate() {
        for (beta, eb) in edges.iter().enumerate() {
            for r in 0..d {
                dtangents[alpha][beta][r] =
                    (0..d).flat_map(|b| (0..d).map(move |c| (b, c))).map(|(b, c)| x2[r][b][c] * ea[b] * eb[c]).sum();
            }
        }
    }
    Curvature { d2phi, dtangents }
}

/// ∂n/∂x along the surface: n = m/|m| with m = J⁻ᵀ N (N the reference cell's facet normal),
/// ∂m/∂ξ_c = −J⁻ᵀ (∂J/∂ξ_c)ᵀ m, projected on the tangent plane on both sides.
fn normal_rate(
    inv: &[[f64; MAX_DIM]; MAX_DIM],
    x2: &[[[f64; MAX_DIM]; MAX_DIM]; MAX_DIM],
    ref_normal: &[f64],
    normal: &[f64; MAX_DIM],
    d: usize,
) -> [[f64; MAX_DIM]; MAX_DIM] {
    let m: Vec<f64> = (0..d).map(|l| (0..d).map(|b| inv[b][l] * ref_normal[b]).sum()).collect();
    let size = m.iter().map(|v| v * v).sum::<f64>().sqrt();
    // dm[l][c] = ∂m_l/∂ξ_c = −Σ_{r,e} m_r x2[r][e][c] J⁻¹_el.
    let mut dm = [[0.0; MAX_DIM]; MAX_DIM];
    for l in 0..d {
        for c in 0..d {
            dm[l][c] = -(0..d)
                .flat_map(|r| (0..d).map(move |e| (r, e)))
                .map(|(r, e)| m[r] * x2[r][e][c] * inv[e][l])
                .sum::<f64>();
        }
    }
    // ∂n_k/∂x_q = (I − n nᵀ)_kl ∂m_l/∂x_q / |m|, ∂/∂x_q = Σ_c J⁻¹_cq ∂/∂ξ_c.
    let project = |k: usize, l: usize| f64::from(u8::from(k == l)) - normal[k] * normal[l];
    let mut dn = [[0.0; MAX_DIM]; MAX_DIM];
    for k in 0..d {
        for q in 0..d {
            dn[k][q] =
                (0..d).map(|l| project(k, l) * (0..d).map(|c| dm[l][c] * inv[c][q]).sum::<f64>()).sum::<f64>() / size;
        }
    }
    std::array::from_fn(|k| std::array::from_fn(|r| (0..d).map(|q| dn[k][q] * project(q, r)).sum()))
}
