//! The tangent's part through the facing point's sliding as the bodies move.

use super::*;

impl PairForm<'_> {
    /// Adds to `ke` the tangent's part through the facing point's motion. The facing point y
    /// is where (p_s − p_m(y))·t_α = 0, with p = x + u the deformed positions and
    /// t_α = (I + ∇u_m) T_α the deformed facet's tangents; its variation gives
    /// G δξ = (δu_s(x) − δu_m(y))·t_α + (p_s − p_m)·∇δu_m T_α, with
    /// G_αβ = t_α·t_β − (p_s − p_m)·∂_β t_α (the deformed facet's curvature, P2 only), and
    /// δy = T_α δξ_α. The residual's rate along δy is the kernel's sliding rates plus, on the
    /// facing nodes, the coefficients times the basis functions' gradients and (P2) second
    /// derivatives. `rates` holds the residual's coefficients then their sliding rates.
    pub(super) fn add_sliding(&self, e: &PairElement, rates: &[f64], d: usize, ke: &mut [f64]) {
        if !e.slides {
            return;
        }
        let (n, half) = (e.nodes.len(), e.nodes.len() / 2);
        let moving = CONFIGURATION;
        let (own_u, facing_u) = (&e.point.own.fields[moving], &e.point.facing.fields[moving]);
        let gap: [f64; MAX_DIM] =
            std::array::from_fn(|r| (e.point.own.x[r] + own_u.value[r]) - (e.point.facing.x[r] + facing_u.value[r]));
        let q = d - 1;
        let big_t = &e.tangents;
        let t: Vec<[f64; MAX_DIM]> = big_t
            .iter()
            .map(|ta| std::array::from_fn(|r| ta[r] + (0..d).map(|c| facing_u.grad[r][c] * ta[c]).sum::<f64>()))
            .collect();
        let dot = |a: &[f64; MAX_DIM], b: &[f64; MAX_DIM]| (0..d).map(|r| a[r] * b[r]).sum::<f64>();
        // G_αβ = t_α·t_β − gap·∂_β t_α, ∂_β t_α = (I + ∇u_m) ∂_β T_α + ∇∇u_m : T_α ⊗ T_β.
        let metric = |alpha: usize, beta: usize| {
            let mut g = dot(&t[alpha], &t[beta]);
            if let Some(c) = &e.curvature {
                let dt = &c.dtangents[alpha][beta];
                for r in 0..d {
                    let mut bend = dt[r] + (0..d).map(|k| facing_u.grad[r][k] * dt[k]).sum::<f64>();
                    for l in 0..d {
                        for m in 0..d {
                            bend += facing_u.hess[r][l][m] * big_t[alpha][l] * big_t[beta][m];
                        }
                    }
                    g -= gap[r] * bend;
                }
            }
            g
        };
        // G⁻¹, (d − 1) × (d − 1).
        let ginv: [[f64; 2]; 2] = match q {
            0 => return,
            1 => [[1.0 / metric(0, 0), 0.0], [0.0, 0.0]],
            _ => {
                let (a, b, c) = (metric(0, 0), metric(0, 1), metric(1, 1));
                let det = a * c - b * b;
                [[c / det, -b / det], [-b / det, a / det]]
            }
        };
        // Y[r][(b, m)]: the rate of y_r with dof m of node b.
        let mut y = vec![0.0; d * n * d];
        for b in 0..n {
            for mm in 0..d {
                // The right-hand side's α entries for this dof.
                let mut rhs = [0.0; 2];
                for (alpha, slot) in rhs.iter_mut().enumerate().take(q) {
                    *slot = if b < half {
                        t[alpha][mm] * e.phi[b]
                    } else {
                        let along = (0..d).map(|c| e.dphi[b][c] * big_t[alpha][c]).sum::<f64>();
                        -t[alpha][mm] * e.phi[b] + gap[mm] * along
                    };
                }
                for r in 0..d {
                    let mut v = 0.0;
                    for alpha in 0..q {
                        let dxi = (0..q).map(|beta| ginv[alpha][beta] * rhs[beta]).sum::<f64>();
                        v += big_t[alpha][r] * dxi;
                    }
                    y[(r * n + b) * d + mm] = v;
                }
            }
        }
        let side = d + d * d;
        let (coefficients, sliding) = (&rates[..2 * side], &rates[2 * side..]);
        for a in 0..n {
            let off = if a < half { 0 } else { side };
            for k in 0..d {
                // ∂R_(a,k)/∂y_r.
                let mut along = [0.0; MAX_DIM];
                for (r, slot) in along.iter_mut().enumerate().take(d) {
                    let mut v = sliding[(off + k) * d + r] * e.phi[a];
                    for l in 0..d {
                        v += sliding[(off + d + k * d + l) * d + r] * e.dphi[a][l];
                    }
                    if a >= half {
                        v += coefficients[off + k] * e.dphi[a][r];
                        if let Some(c) = &e.curvature {
                            v += (0..d)
                                .map(|l| coefficients[off + d + k * d + l] * c.d2phi[a - half][l][r])
                                .sum::<f64>();
                        }
                    }
                    *slot = v;
                }
                for b in 0..n {
                    for mm in 0..d {
                        let v = (0..d).map(|r| along[r] * y[(r * n + b) * d + mm]).sum::<f64>();
                        ke[(a * d + k) * n * d + b * d + mm] += e.weight * v;
                    }
                }
            }
        }
    }
}
