//! The contact zone and the pressure profile of a solution, sampled at many points of the
//! contact facets (the pressure is the contact law's `contact_pressure` integrand).

use crate::runtime::fem::assembly::Assembler;
use crate::runtime::fem::bound::BoundFunctional;
use crate::runtime::fem::quadrature::sampling_rule;

/// Sampling points per edge (2D), or sub-triangles per edge of a face (3D): the measure of the
/// contact zone is exact up to the part of a facet between two samples.
const SAMPLES: usize = 16;

/// The pressure at one sample of the contact boundary.
#[derive(Clone, Copy, Debug)]
pub struct Sample {
    /// Horizontal distance to the first contact point (the origin).
    pub r: f64,
    /// The contact pressure (≥ 0).
    pub p: f64,
    /// The sample's share of the boundary's projection onto the plane.
    pub weight: f64,
}

/// Samples the contact pressure of `u` (the negative of the contact law's λ ≤ 0) on the part
/// of the contact boundary that faces the plane (outward normal pointing down), where the
/// horizontal distance names a point.
pub fn sample(asm: &Assembler, pressure: &dyn BoundFunctional, u: &[f64]) -> Vec<Sample> {
    let d = asm.mesh().dim();
    let rule = sampling_rule(d - 1, if d == 2 { SAMPLES } else { SAMPLES / 2 });
    pressure
        .facet_point_values(asm, &rule, &[u], 0.0)
        .into_iter()
        .filter(|pv| pv.normal[d - 1] < 0.0)
        .map(|pv| Sample {
            r: pv.x[..d - 1].iter().map(|x| x * x).sum::<f64>().sqrt(),
            p: -pv.value,
            weight: pv.weight * pv.normal[d - 1].abs(),
        })
        .collect()
}

/// What the samples show, for the full body of a model reduced by symmetry (`copies` of it make
/// the body: 2 for the half x ≥ 0 in 2D, 4 for the quarter x, y ≥ 0 in 3D).
#[derive(Clone, Copy, Debug)]
pub struct Zone {
    /// Half-width (2D) or radius (3D) of the zone where the pressure is positive.
    pub size: f64,
    pub peak_pressure: f64,
}

/// The contact zone's size from its measure, and the peak (centre) pressure from the samples
/// within a/4 of the first contact point, Σ w p_h / Σ w s(r) with Hertz's shape s(r) =
/// √(1 − r²/a²) ≥ 0.968 there: a single sample carries the discrete pressure's oscillation
/// between quadrature points (a penalty's especially), this mean does not.
pub fn zone(dim: usize, copies: f64, samples: &[Sample], hertz_size: f64) -> Result<Zone, String> {
    let measure: f64 = samples.iter().filter(|s| s.p > 0.0).map(|s| s.weight).sum();
    // The whole body's zone is the strip [−a, a] in 2D, the disc r < a in 3D.
    let whole = copies * measure;
    let size = if dim == 2 { whole / 2.0 } else { (whole / std::f64::consts::PI).sqrt() };
    let (mut pw, mut sw) = (0.0, 0.0);
    for s in samples.iter().filter(|s| s.r < hertz_size / 4.0) {
        pw += s.weight * s.p;
        sw += s.weight * (1.0 - (s.r / hertz_size).powi(2)).sqrt();
    }
    if size == 0.0 || sw == 0.0 {
        return Err(format!(
            "no contact pressure to measure: of {} samples facing the plane, {} press on it and {} lie within a/4 = {:.4} of the first contact point",
            samples.len(),
            samples.iter().filter(|s| s.p > 0.0).count(),
            samples.iter().filter(|s| s.r < hertz_size / 4.0).count(),
            hertz_size / 4.0
        ));
    }
    Ok(Zone { size, peak_pressure: pw / sw })
}

/// ‖p_h − p‖ / ‖p‖ in L² on Γ_C's projection onto the plane, against a profile p(r).
pub fn l2_error(samples: &[Sample], exact: impl Fn(f64) -> f64) -> f64 {
    let (mut err, mut norm) = (0.0, 0.0);
    for s in samples {
        let p = exact(s.r);
        err += s.weight * (s.p - p).powi(2);
        norm += s.weight * p * p;
    }
    (err / norm).sqrt()
}

/// The samples averaged in `bins` rings of equal width out to `r_max` (for plots).
pub fn binned(samples: &[Sample], r_max: f64, bins: usize) -> Vec<(f64, f64)> {
    let mut sum = vec![(0.0, 0.0); bins];
    for s in samples.iter().filter(|s| s.r < r_max) {
        let b = ((s.r / r_max * bins as f64) as usize).min(bins - 1);
        sum[b].0 += s.weight * s.p;
        sum[b].1 += s.weight;
    }
    sum.iter()
        .enumerate()
        .filter(|(_, (_, w))| *w > 0.0)
        .map(|(b, (pw, w))| ((b as f64 + 0.5) * r_max / bins as f64, pw / w))
        .collect()
}
