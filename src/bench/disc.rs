//! `signorini bench disc`: time per step of the bouncing disc (issue 5), Newmark with Nitsche
//! θ = 1, Δt = 0.02, 1000 steps (to t = 20: fall, impact, rebound), on each given mesh. The
//! stepper alone is timed (mesh reading, assembly of the linear forms, measurements and output
//! are not); per run we record the mean and the median over steps, and report the medians of
//! these over the repeated runs.

use std::path::PathBuf;

use serde::Serialize;

use super::median;
use crate::cases::CaseError;
use crate::cases::disc::{self, Options};

#[derive(Clone, Debug, Serialize)]
pub struct DiscTiming {
    pub mesh: String,
    pub dofs: usize,
    pub steps: usize,
    pub newton_total: usize,
    pub factorizations: usize,
    /// Median over runs of (stepping time / steps).
    pub ms_per_step: f64,
    /// Median over runs of the median step time.
    pub median_step_ms: f64,
    /// Median over runs of the whole run (setup and measurements included) / steps.
    pub ms_per_step_with_setup: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct Report {
    pub dt: f64,
    pub t_end: f64,
    pub repeats: usize,
    pub meshes: Vec<DiscTiming>,
}

pub fn disc(meshes: &[PathBuf], repeats: usize, progress: &mut dyn FnMut(&str)) -> Result<Report, CaseError> {
    let base = Options::default();
    let mut out = Vec::new();
    for path in meshes {
        let opts = Options { mesh: Some(path.clone()), ..base.clone() };
        let (mut mean, mut med, mut whole) = (Vec::new(), Vec::new(), Vec::new());
        let mut last = None;
        for _ in 0..repeats.max(1) {
            let s = disc::run(&opts)?.summary;
            let steps = s.steps.max(1) as f64;
            mean.push(s.stepping_seconds / steps * 1e3);
            med.push(s.step_median_seconds * 1e3);
            whole.push(s.seconds_per_step * 1e3);
            last = Some(s);
        }
        let s = last.expect("at least one run");
        let t = DiscTiming {
            mesh: path.display().to_string(),
            dofs: s.dofs,
            steps: s.steps,
            newton_total: s.newton_total,
            factorizations: s.factorizations,
            ms_per_step: median(mean),
            median_step_ms: median(med),
            ms_per_step_with_setup: median(whole),
        };
        progress(&format!(
            "{}: {} dofs, {} steps, {} Newton iterations, {} factorizations; {:.3} ms/step stepping (median step {:.3} ms), {:.3} ms/step whole run",
            t.mesh,
            t.dofs,
            t.steps,
            t.newton_total,
            t.factorizations,
            t.ms_per_step,
            t.median_step_ms,
            t.ms_per_step_with_setup
        ));
        out.push(t);
    }
    Ok(Report { dt: base.dt, t_end: base.t_end, repeats, meshes: out })
}
