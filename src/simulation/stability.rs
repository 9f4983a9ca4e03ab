//! The critical step of an explicit scheme (one that claims `cfl`, the largest stable ω Δt):
//! Δt_c = cfl / ω_max, with ω_max² the largest eigenvalue of M⁻¹(K + J_C), where J_C is the
//! contact law's tangent with the body pushed into the obstacle (every contact point active, so
//! that the contact's stiffness counts as it will once the body touches). ω_max is estimated at
//! the start of the run by power iteration with the Rayleigh quotient, which approaches it from
//! below: the estimated Δt_c is at most a little above the true one, and the energy guard
//! stops a run that is unstable all the same.

use super::Operators;
use crate::error::CaseError;
use crate::runtime::fem::kernel::Coef;
use crate::runtime::linalg::{Factorization, Structure};
use crate::runtime::nonlinear::statics::Constraints;

/// The estimate, for the refusal's message and the summary.
#[derive(Clone, Copy, Debug)]
pub struct StableStep {
    pub cfl: f64,
    pub omega_max: f64,
    /// cfl / ω_max.
    pub dt: f64,
    /// Contact points active in the pushed state, of all.
    pub active: usize,
    pub points: usize,
}

/// Power iterations at most, and the relative change of the Rayleigh quotient that ends them.
const ITERATIONS: usize = 1000;
const CONVERGED: f64 = 1e-10;

/// Estimates Δt_c for a scheme claiming `cfl`, with the scheme's mass and the problem's
/// obstacle (`g`, `nc` of `coefs`).
pub fn estimate(
    ops: &Operators,
    coefs: &dyn Fn(&str) -> Option<Coef>,
    constraints: &Constraints,
    cfl: f64,
) -> Result<StableStep, CaseError> {
    let asm = ops.asm;
    let n = asm.size();
    let mut a = ops.stiffness.clone();
    let (mut active, mut points) = (0, 0);
    if let Some(probe) = &ops.probe {
        let pushed = pushed_into_obstacle(ops, coefs);
        let mut contact = asm.zero_matrix();
        // Pushed from where it was: a frictional law sticks there, its stiffest state.
        let args = crate::runtime::fem::bound::with_previous(probe.previous(), &[&pushed], &pushed);
        probe.tangent(asm, &args, 0, 0.0, &mut contact);
        a.add_scaled(1.0, &contact);
        let mut switches = Vec::new();
        probe.switches(asm, &args, 0, 0.0, &mut switches);
        points = switches.len();
        active = switches.iter().filter(|s| **s).count();
    }
    let mut mass = Factorization::new(Structure::SymmetricPositiveDefinite);
    mass.factor(ops.scheme_mass()).map_err(|e| CaseError::Option(format!("the scheme's mass: {e}")))?;
    let free = |x: &mut [f64]| x.iter_mut().zip(&constraints.fixed).filter(|(_, f)| **f).for_each(|(x, _)| *x = 0.0);
    // A start with every frequency in it.
    let mut x = scattered(n);
    free(&mut x);
    let (mut ax, mut lambda) = (vec![0.0; n], 0.0f64);
    for _ in 0..ITERATIONS {
        a.mul_vec(&x, &mut ax);
        let xmx = ops.scheme_mass().quad(&x, &x);
        let rayleigh = x.iter().zip(&ax).map(|(p, q)| p * q).sum::<f64>() / xmx;
        let done = (rayleigh - lambda).abs() <= CONVERGED * rayleigh.abs();
        lambda = rayleigh;
        if done {
            break;
        }
        free(&mut ax);
        mass.solve_in_place(&mut ax).map_err(|e| CaseError::Option(format!("the scheme's mass: {e}")))?;
        free(&mut ax);
        let norm = ax.iter().map(|v| v * v).sum::<f64>().sqrt();
        if !(norm > 0.0 && norm.is_finite()) {
            break;
        }
        x.iter_mut().zip(&ax).for_each(|(x, y)| *x = y / norm);
    }
    let omega_max = lambda.max(0.0).sqrt();
    Ok(StableStep { cfl, omega_max, dt: cfl / omega_max, active, points })
}

/// Values in [−½, ½) from a fixed pseudo-random sequence (xorshift): every mode present, the
/// same on every run.
pub(crate) fn scattered(n: usize) -> Vec<f64> {
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    (0..n)
        .map(|_| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        })
        .collect()
}

/// The body translated along the contact normal at the first contact node far enough that every
/// contact node is past the obstacle by a thousandth of the body's size: a rigid motion, so
/// the elastic stress stays zero and a law that compares the stress with the gap (Nitsche's)
/// sees every point in contact.
pub(crate) fn pushed_into_obstacle(ops: &Operators, coefs: &dyn Fn(&str) -> Option<Coef>) -> Vec<f64> {
    let mesh = ops.asm.mesh();
    let d = mesh.dim();
    let n = ops.asm.size();
    let at = |coef: &Option<Coef>, x: &[f64], components: usize| -> Vec<f64> {
        match coef {
            Some(Coef::Constant(v)) => v.clone(),
            Some(Coef::Function { components, f, .. }) => {
                let mut out = vec![0.0; *components];
                f(x, 0.0, &mut out);
                out
            }
            None => vec![0.0; components],
        }
    };
    let (g, nc) = (coefs("g"), coefs("nc"));
    let Some(&first) = ops.contact_nodes.first() else { return vec![0.0; n] };
    let x0 = &mesh.coords[d * first as usize..d * (first as usize + 1)];
    let direction = at(&nc, x0, d);
    let size = (0..d)
        .map(|k| {
            let c = mesh.coords.iter().skip(k).step_by(d);
            c.clone().fold(f64::NEG_INFINITY, |a, &b| a.max(b)) - c.fold(f64::INFINITY, |a, &b| a.min(b))
        })
        .fold(0.0, f64::max);
    // The translation s along `direction` puts node x past the obstacle when
    // s (direction · nc(x)) − g(x) > 0.
    let mut s = 0.0f64;
    for &node in &ops.contact_nodes {
        let x = &mesh.coords[d * node as usize..d * (node as usize + 1)];
        let normal = at(&nc, x, d);
        let along: f64 = direction.iter().zip(&normal).map(|(a, b)| a * b).sum();
        if along > 1e-3 {
            s = s.max((at(&g, x, 1)[0] + 1e-3 * size) / along);
        }
    }
    (0..n).map(|i| s * direction.get(i % d).copied().unwrap_or(0.0)).collect()
}
