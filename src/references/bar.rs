//! The exact solution of the compressed bar (docs/mathematics.md §6): Ω = (0, 1), E = ρ = 1, u(1, t) = 0,
//! contact at x = 0, u₀(x) = (1 − x)/2, v₀ = 0. Period 3; zones by s = τ − ⌊τ⌋, τ = t mod 3.
//! A problem reads it as `reference bar` (forms/problems/bar.wf).

use std::cell::RefCell;

use super::{At, BoundReference, Reference, RunFacts};

/// `reference bar`: the run against the exact solution.
pub struct Bar;

/// Its functionals, in the order of [`Bar::functionals`]'s names.
#[derive(Clone, Copy)]
enum Functional {
    Error,
    Norm,
    ContactStress,
    ContactDisplacement,
}

const FUNCTIONALS: &[(&str, &str, Functional)] = &[
    ("exact_u_error", "‖u − I_h u_ex(t)‖_M, with the mass the scheme steps with", Functional::Error),
    ("exact_u_norm", "‖I_h u_ex(t)‖_M, the same norm of the interpolated exact displacement", Functional::Norm),
    ("exact_contact_stress", "the exact contact stress E u_x(0, t) (of t only)", Functional::ContactStress),
    (
        "exact_contact_displacement",
        "the exact displacement of the contact point u(0, t) (of t only)",
        Functional::ContactDisplacement,
    ),
];

impl Reference for Bar {
    fn name(&self) -> &'static str {
        "bar"
    }

    fn doc(&self) -> &'static str {
        "the compressed bar's exact solution (1D, on [0, 1], E = ρ = 1, u₀ = (1 − x)/2 at rest from t = 0, held at x = 1)"
    }

    fn dims(&self) -> &'static [usize] {
        &[1]
    }

    fn functionals(&self) -> Vec<(&'static str, &'static str)> {
        FUNCTIONALS.iter().map(|(name, doc, _)| (*name, *doc)).collect()
    }

    fn bind(&self, run: &RunFacts) -> Result<Box<dyn BoundReference>, String> {
        for p in ["E", "rho"] {
            if let Some(v) = (run.param)(p).filter(|v| *v != 1.0) {
                return Err(format!("it is the solution for E = ρ = 1, and this run has {p} = {v}"));
            }
        }
        if run.t_start != 0.0 {
            return Err(format!("it starts at t = 0, and this run at t = {}", run.t_start));
        }
        let nodes: Vec<f64> = (0..run.mesh.num_nodes()).map(|i| run.mesh.node(i)[0]).collect();
        let (lo, hi) = nodes.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| (a.min(*x), b.max(*x)));
        if lo != 0.0 || hi != 1.0 {
            return Err(format!("it is the solution on [0, 1], and this mesh spans [{lo}, {hi}]"));
        }
        Ok(Box::new(BoundBar { nodes, interpolant: RefCell::new((f64::NAN, Vec::new())) }))
    }
}

/// The bar's solution on one run's mesh.
struct BoundBar {
    /// The nodes' positions (one unknown per node in 1D).
    nodes: Vec<f64>,
    /// The interpolant at the last time asked (a row asks for the error and the norm at one).
    interpolant: RefCell<(f64, Vec<f64>)>,
}

impl BoundReference for BoundBar {
    fn value(&self, which: usize, at: &At) -> f64 {
        let (mass, u, t) = (at.mass, at.u, at.t);
        let with_interpolant = |f: &dyn Fn(&[f64]) -> f64| {
            let mut last = self.interpolant.borrow_mut();
            if last.0.to_bits() != t.to_bits() {
                *last = (t, self.nodes.iter().map(|&x| displacement(x, t)).collect());
            }
            f(&last.1)
        };
        match FUNCTIONALS.get(which).map(|f| f.2) {
            Some(Functional::Error) => with_interpolant(&|exact| {
                let diff: Vec<f64> = u.iter().zip(exact).map(|(a, b)| a - b).collect();
                mass.quad(&diff, &diff).sqrt()
            }),
            Some(Functional::Norm) => with_interpolant(&|exact| mass.quad(exact, exact).sqrt()),
            Some(Functional::ContactStress) => contact_stress(t),
            Some(Functional::ContactDisplacement) => displacement(0.0, t),
            None => f64::NAN,
        }
    }
}

/// u(x, t).
pub fn displacement(x: f64, t: f64) -> f64 {
    let tau = t.rem_euclid(3.0);
    let phase = tau.floor().min(2.0);
    let s = tau - phase;
    let left = s >= x; // zones II and IV
    let upper = s > 1.0 - x; // zones III and IV
    match (phase as u8, left, upper) {
        (0, false, _) => (1.0 - x) / 2.0,
        (0, true, _) => (1.0 - s) / 2.0,
        (1, false, false) => -s / 2.0,
        (1, true, false) => -x / 2.0,
        (1, false, true) => (x - 1.0) / 2.0,
        (1, true, true) => (s - 1.0) / 2.0,
        (_, _, false) => s / 2.0,
        (_, _, true) => (1.0 - x) / 2.0,
    }
}

/// Contact stress E u_x(0, t): −½ while in contact (τ ∈ (1, 2)), else 0.
pub fn contact_stress(t: f64) -> f64 {
    let tau = t.rem_euclid(3.0);
    if tau > 1.0 && tau < 2.0 { -0.5 } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_the_contact_point_table_and_the_initial_data() {
        for k in 0..=100 {
            let x = k as f64 / 100.0;
            assert!((displacement(x, 0.0) - (1.0 - x) / 2.0).abs() < 1e-15);
            assert_eq!(displacement(1.0, 0.37 * k as f64), 0.0);
        }
        for k in 0..300 {
            let t = k as f64 * 0.01;
            let tau = t % 3.0;
            let u0 = if tau <= 1.0 {
                (1.0 - tau) / 2.0
            } else if tau <= 2.0 {
                0.0
            } else {
                (tau - 2.0) / 2.0
            };
            assert!((displacement(0.0, t) - u0).abs() < 1e-14, "t = {t}");
        }
    }

    /// The solution is continuous in x and t and satisfies d'Alembert's identity
    /// u(x−h, t) + u(x+h, t) = u(x, t−h) + u(x, t+h) (wave speed 1) inside the bar.
    #[test]
    fn is_continuous_and_solves_the_wave_equation() {
        let h = 1.0 / 64.0;
        for i in 1..64 {
            for n in 1..400 {
                let (x, t) = (i as f64 * h, n as f64 * h);
                let lhs = displacement(x - h, t) + displacement(x + h, t);
                let rhs = displacement(x, t - h) + displacement(x, t + h);
                assert!((lhs - rhs).abs() < 1e-13, "x = {x}, t = {t}: {lhs} vs {rhs}");
                assert!((displacement(x + 1e-9, t) - displacement(x, t)).abs() < 1e-8);
            }
        }
    }
}
