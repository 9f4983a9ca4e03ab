//! Hertz's closed forms for an elastic cylinder (plane strain, per unit length) or ball of
//! radius R on a rigid frictionless plane, with the plane-strain modulus E* = E / (1 − ν²).

use std::f64::consts::PI;

use serde::Serialize;

/// ∫₀¹ (1 − x^{5/2})^{−1/2} dx = (2/5) B(2/5, 1/2): the impact's contact time is twice this
/// times δ_max / v.
pub const IMPACT_INTEGRAL: f64 = 1.471_637_592_162_352_3;

/// Young's modulus, Poisson's ratio, density.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Material {
    pub young: f64,
    pub poisson: f64,
    pub density: f64,
}

impl Material {
    /// The material's E, nu and rho from the files in use.
    pub fn of(run: &crate::references::RunFacts) -> Result<Material, String> {
        let param = |name: &str| {
            (run.param)(name)
                .ok_or_else(|| format!("Hertz's formulas need the material's `{name}`, which the files in use lack"))
        };
        Ok(Material { young: param("E")?, poisson: param("nu")?, density: param("rho")? })
    }

    /// E* = E / (1 − ν²) (the plane is rigid).
    pub fn contact_modulus(&self) -> f64 {
        self.young / (1.0 - self.poisson * self.poisson)
    }

    /// The pressure wave speed c_p = √((λ + 2μ)/ρ).
    pub fn wave_speed(&self) -> f64 {
        let (e, nu) = (self.young, self.poisson);
        (e * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu)) / self.density).sqrt()
    }
}

/// Static contact under a force F (per unit length in 2D): the half-width (2D) or radius (3D)
/// a of the contact zone and the peak pressure p₀; the pressure is p₀ √(1 − r²/a²).
pub fn static_contact(dim: usize, radius: f64, e_star: f64, force: f64) -> (f64, f64) {
    if dim == 2 {
        let a = (4.0 * force * radius / (PI * e_star)).sqrt();
        (a, 2.0 * force / (PI * a))
    } else {
        let a = (3.0 * force * radius / (4.0 * e_star)).cbrt();
        (a, 3.0 * force / (2.0 * PI * a * a))
    }
}

/// The force that makes the contact zone's half-width (radius) `a`.
pub fn force_for(dim: usize, radius: f64, e_star: f64, a: f64) -> f64 {
    if dim == 2 { PI * e_star * a * a / (4.0 * radius) } else { 4.0 * e_star * a.powi(3) / (3.0 * radius) }
}

/// Hertz's pressure at distance r from the centre of the contact zone.
pub fn pressure(a: f64, p0: f64, r: f64) -> f64 {
    if r < a { p0 * (1.0 - (r / a).powi(2)).sqrt() } else { 0.0 }
}

/// The quasi-static impact of a ball at speed v: F = k δ^{3/2} with k = (4/3) E* √R.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Impact {
    pub max_indentation: f64,
    pub peak_force: f64,
    pub contact_duration: f64,
    /// The contact radius at the largest indentation, √(R δ_max).
    pub contact_radius: f64,
}

impl Impact {
    pub fn new(radius: f64, material: &Material, speed: f64) -> Impact {
        let mass = material.density * 4.0 / 3.0 * PI * radius.powi(3);
        let k = stiffness(radius, material);
        let delta = (5.0 * mass * speed * speed / (4.0 * k)).powf(0.4);
        Impact {
            max_indentation: delta,
            peak_force: k * delta.powf(1.5),
            contact_duration: 2.0 * IMPACT_INTEGRAL * delta / speed,
            contact_radius: (radius * delta).sqrt(),
        }
    }

    /// The force history F(t) from first contact, by RK4 on m δ'' = −k δ^{3/2} (for plots).
    pub fn force_history(radius: f64, material: &Material, speed: f64, dt: f64) -> Vec<(f64, f64)> {
        let mass = material.density * 4.0 / 3.0 * PI * radius.powi(3);
        let k = stiffness(radius, material);
        let accel = |d: f64| -k * d.max(0.0).powf(1.5) / mass;
        let (mut t, mut d, mut v) = (0.0, 0.0, speed);
        let mut out = vec![(0.0, 0.0)];
        while d >= 0.0 && out.len() < 1_000_000 {
            let (k1d, k1v) = (v, accel(d));
            let (k2d, k2v) = (v + 0.5 * dt * k1v, accel(d + 0.5 * dt * k1d));
            let (k3d, k3v) = (v + 0.5 * dt * k2v, accel(d + 0.5 * dt * k2d));
            let (k4d, k4v) = (v + dt * k3v, accel(d + dt * k3d));
            d += dt / 6.0 * (k1d + 2.0 * k2d + 2.0 * k3d + k4d);
            v += dt / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
            t += dt;
            out.push((t, k * d.max(0.0).powf(1.5)));
        }
        out
    }
}

fn stiffness(radius: f64, material: &Material) -> f64 {
    4.0 / 3.0 * material.contact_modulus() * radius.sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_impact_integral_is_the_beta_function_value() {
        // ∫₀¹ (1 − x^{5/2})^{−1/2} dx with x = 1 − s²: 2 ∫₀¹ s (1 − (1 − s²)^{5/2})^{−1/2} ds,
        // a smooth integrand (→ 2/√(5/2) at s = 0), by the midpoint rule.
        let n = 200_000;
        let f = |s: f64| 2.0 * s / (1.0 - (1.0 - s * s).powf(2.5)).sqrt();
        let sum: f64 = (0..n).map(|i| f((i as f64 + 0.5) / n as f64)).sum::<f64>() / n as f64;
        assert!((sum - IMPACT_INTEGRAL).abs() < 1e-9, "{sum}");
    }

    #[test]
    fn static_forms_are_consistent() {
        for dim in [2, 3] {
            let (r, e) = (10.0, 53.0);
            let f = force_for(dim, r, e, 0.7);
            let (a, p0) = static_contact(dim, r, e, f);
            assert!((a - 0.7).abs() < 1e-12);
            // The pressure integrates to the force: 2D ∫ p = π a p₀ / 2, 3D 2π a² p₀ / 3.
            let total = if dim == 2 { PI * a * p0 / 2.0 } else { 2.0 * PI * a * a * p0 / 3.0 };
            assert!((total - f).abs() < 1e-12 * f);
        }
    }

    #[test]
    fn the_force_history_lasts_the_contact_time_and_peaks_at_the_peak_force() {
        let m = Material { young: 50.0, poisson: 0.25, density: 1.0 };
        let hertz = Impact::new(10.0, &m, 0.02);
        let history = Impact::force_history(10.0, &m, 0.02, 1e-3);
        let end = history.last().unwrap().0;
        let peak = history.iter().map(|p| p.1).fold(0.0, f64::max);
        assert!((end - hertz.contact_duration).abs() < 2e-3, "{end} {}", hertz.contact_duration);
        assert!((peak - hertz.peak_force).abs() < 1e-6 * hertz.peak_force);
    }
}
