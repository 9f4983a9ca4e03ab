//! The exact solution of the compressed bar (docs/mathematics.md §6): Ω = (0, 1), E = ρ = 1, u(1, t) = 0,
//! contact at x = 0, u₀(x) = (1 − x)/2, v₀ = 0. Period 3; zones by s = τ − ⌊τ⌋, τ = t mod 3.
//! A problem reads it as `reference bar` (forms/problems/bar.wf).

use super::Reference;
use crate::simulation::Tools;

/// `reference bar`: the run against the exact solution.
pub struct Bar;

impl Reference for Bar {
    fn name(&self) -> &'static str {
        "bar"
    }

    fn doc(&self) -> &'static str {
        "the compressed bar's exact solution (1D, on [0, 1], E = ρ = 1, u₀ = (1 − x)/2 at rest, held at x = 1)"
    }

    fn dim(&self) -> usize {
        1
    }

    fn functionals(&self) -> &'static [(&'static str, &'static str)] {
        &[
            ("exact_u_error", "‖u − I_h u_ex(t)‖_M, with the mass the scheme steps with"),
            ("exact_u_norm", "‖I_h u_ex(t)‖_M, the same norm of the interpolated exact displacement"),
            ("exact_contact_stress", "the exact contact stress E u_x(0, t) (of t only)"),
            ("exact_contact_displacement", "the exact displacement of the contact point u(0, t) (of t only)"),
        ]
    }

    fn value(&self, which: usize, tools: &Tools, u: &[f64], t: f64) -> f64 {
        let mesh = tools.asm.mesh();
        // A row asks for the error and the norm at one time: the interpolant is made once.
        // Keyed by the time and the mesh (where its nodes are stored, and its end nodes).
        type Last = ((u64, usize, u64, u64), Vec<f64>);
        thread_local!(static LAST: std::cell::RefCell<Last> = const { std::cell::RefCell::new(((0, 0, 0, 0), Vec::new())) });
        let with_interpolant = |f: &dyn Fn(&[f64]) -> f64| {
            let ends = (mesh.node(0)[0].to_bits(), mesh.node(u.len() - 1)[0].to_bits());
            let key = (t.to_bits(), mesh.node(0).as_ptr() as usize, ends.0, ends.1);
            LAST.with(|last| {
                let mut last = last.borrow_mut();
                if last.0 != key || last.1.len() != u.len() {
                    *last = (key, (0..u.len()).map(|i| displacement(mesh.node(i)[0], t)).collect());
                }
                f(&last.1)
            })
        };
        match which {
            0 => with_interpolant(&|exact| {
                let diff: Vec<f64> = u.iter().zip(exact).map(|(a, b)| a - b).collect();
                Tools::quad(&tools.scheme_mass, &diff, &diff).sqrt()
            }),
            1 => with_interpolant(&|exact| Tools::quad(&tools.scheme_mass, exact, exact).sqrt()),
            2 => contact_stress(t),
            _ => displacement(0.0, t),
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
