//! Checks of the scalars an elimination divides by and of stage times, by sampling: every
//! combination of each parameter's default and range ends (just inside open ends), with a few
//! step sizes dt > 0.

use super::affine;
use super::compiler::Compiler;
use crate::check::SchemeParamInfo;
use crate::ir::graph::NodeId;

/// The step sizes every sample is taken at.
const STEPS: [f64; 4] = [1e-4, 1e-2, 1.0, 100.0];

/// Values at which a pivot is checked: the default, and the ends of the range (just inside
/// open ends; a large value for infinite ones).
fn samples(p: &SchemeParamInfo) -> Vec<f64> {
    let mut s = vec![p.default];
    if let Some(r) = p.range {
        let span = if r.lo.is_finite() && r.hi.is_finite() { r.hi - r.lo } else { 1.0 };
        let lo = if r.lo.is_finite() { if r.lo_closed { r.lo } else { r.lo + 1e-6 * span } } else { -1e6 };
        let hi = if r.hi.is_finite() { if r.hi_closed { r.hi } else { r.hi - 1e-6 * span } } else { 1e6 };
        s.extend([lo, hi, 0.5 * (lo + hi)]);
    }
    s
}

impl Compiler<'_> {
    /// Where (params, dt) a coefficient is not finite, among the pivot check's samples.
    pub(super) fn not_finite_at(&self, c: NodeId) -> Option<String> {
        let samples: Vec<Vec<f64>> = self.params.iter().map(samples).collect();
        let mut points: Vec<Vec<f64>> = vec![Vec::new()];
        for s in &samples {
            points = points.iter().flat_map(|p| s.iter().map(move |v| [p.as_slice(), &[*v]].concat())).collect();
        }
        for values in &points {
            for dt in STEPS {
                let v = affine::eval(&self.g, c, values, dt, 0.0);
                if !v.is_finite() {
                    let ps: Vec<String> =
                        self.params.iter().zip(values).map(|(p, v)| format!("{} = {v}, ", p.name)).collect();
                    return Some(format!("{v} at {}dt = {dt}, t = 0", ps.concat()));
                }
            }
        }
        None
    }

    /// Checks that a pivot coefficient keeps one sign, away from zero, over the parameter
    /// ranges and dt > 0; the error says where it does not.
    pub(super) fn check_pivot(&self, c: NodeId) -> Result<(), String> {
        let samples: Vec<Vec<f64>> = self.params.iter().map(samples).collect();
        let mut index = vec![0usize; samples.len()];
        let mut sign = 0.0;
        loop {
            let values: Vec<f64> = index.iter().zip(&samples).map(|(&i, s)| s[i]).collect();
            for dt in STEPS {
                let v = affine::eval(&self.g, c, &values, dt, 0.0);
                let described = || {
                    let ps: Vec<String> =
                        self.params.iter().zip(&values).map(|(p, v)| format!("{} = {v}", p.name)).collect();
                    let shown = if v == 0.0 { "0".to_string() } else { format!("{v:e}") };
                    format!(
                        "it is {shown} at {}dt = {dt}",
                        if ps.is_empty() { String::new() } else { format!("{}, ", ps.join(", ")) }
                    )
                };
                if !v.is_finite() || v == 0.0 {
                    return Err(described());
                }
                if sign == 0.0 {
                    sign = v.signum();
                } else if v.signum() != sign {
                    return Err(format!("it changes sign: {}", described()));
                }
            }
            // Next combination of samples.
            let mut k = 0;
            loop {
                if k == index.len() {
                    return Ok(());
                }
                index[k] += 1;
                if index[k] < samples[k].len() {
                    break;
                }
                index[k] = 0;
                k += 1;
            }
        }
    }
}
