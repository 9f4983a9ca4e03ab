//! `signorini bench disc`: time per step of the bouncing disc (issue 5; the problem of
//! forms/library.toml's `[bench]`), with the library's default scheme and contact law and the
//! problem's own Δt and end time (fall, impact, rebound), on each given mesh. The
//! stepper alone is timed (mesh reading, assembly of the linear forms, measurements and output
//! are not); per run we record the mean and the median over steps, and report the medians of
//! these over the repeated runs.
//!
//! Cost model: a step whose active set does not change needs one residual (a sparse product
//! with the step matrix's pattern, plus the contact facets) and one pair of triangular solves
//! with the stored factor. The model is the bytes these read (8 per stored value of L for each
//! of the two solves; 8 per value and 8 per row index of the matrix; three vectors) divided by
//! a bandwidth measured here, one thread, by a triad a = b + s·c, in two ways:
//! - STREAM's: arrays of four times the last-level cache each (STREAM's rule), so main
//!   memory's bandwidth. This is the model the goal is stated against.
//! - In cache: arrays of the working set's total size. The small meshes' working set lives in
//!   the cache, and this is the speed it could be read at there: the stricter model. How far
//!   it is from main memory's depends on the machine (3 to 4.5 times on the one of
//!   2026-11-26, docs/mathematics.md), so both are reported.

use std::path::PathBuf;

use std::time::Instant;

use serde::{Deserialize, Serialize};

use crate::cases::disc;
use crate::error::CaseError;
use crate::problem::run::Options;
use crate::resources::median;

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct DiscTiming {
    pub mesh: String,
    pub dofs: usize,
    pub steps: usize,
    pub newton_total: usize,
    pub factorizations: usize,
    /// Median over runs of (stepping time / steps), and the fastest and slowest run's: their
    /// spread tells how busy the machine was.
    pub ms_per_step: f64,
    pub ms_per_step_fastest: f64,
    pub ms_per_step_slowest: f64,
    /// Median over runs of the median step time.
    pub median_step_ms: f64,
    /// Median over runs of the whole run (setup and measurements included) / steps.
    pub ms_per_step_with_setup: f64,
    /// Per 1000 steps: full numeric factorizations, and active-set changes absorbed by a
    /// low-rank correction instead.
    pub factorizations_per_1000: f64,
    pub low_rank_updates_per_1000: f64,
    /// Stored entries of the step matrix and of its Cholesky factor.
    pub matrix_nnz: usize,
    pub factor_nnz: Option<usize>,
    /// The cost model: bytes read by one residual product and one solve pair, STREAM's triad
    /// bandwidth out of cache (GB/s), the time this gives, and `ms_per_step` / `model_ms`.
    pub model_bytes: f64,
    pub stream_gb_s: f64,
    pub model_ms: f64,
    pub measured_over_model: f64,
    /// `median_step_ms` / `model_ms`: the model is that of a step keeping its active set, which
    /// the median step is; the mean also carries the steps that change it.
    pub median_over_model: f64,
    /// The stricter model: the same bytes at the triad bandwidth of a working set of their
    /// size (in cache for the small meshes), and `ms_per_step` over it.
    pub cache_gb_s: f64,
    pub cache_model_ms: f64,
    pub measured_over_cache_model: f64,
    /// The explicit run of forms/library.toml (central differences, lumped mass): its
    /// median ms/step, its factorizations, and its estimated critical step.
    #[serde(default)]
    pub explicit: Option<ExplicitTiming>,
    /// The frictional laws of forms/library.toml on the same disc: their time per step over
    /// the frictionless one's, factorizations and low-rank corrections per 1000 steps.
    #[serde(default)]
    pub frictional: Vec<FrictionTiming>,
    /// The finite-strain run of forms/library.toml on the same disc, scheme and Δt: with
    /// Newton's tangent at every iteration, and with chord Newton (`--chord`).
    #[serde(default)]
    pub finite_strain: Vec<FiniteStrainTiming>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct FiniteStrainTiming {
    pub material: String,
    pub contact: String,
    /// Chord Newton (`--chord`).
    pub chord: bool,
    pub ms_per_step: f64,
    pub median_step_ms: f64,
    pub newton_total: usize,
    pub factorizations_per_1000: f64,
    /// `ms_per_step` over the linear run's, and the same per Newton iteration (the step's cost
    /// is its iterations times what each assembles and solves).
    pub over_linear: f64,
    pub over_linear_per_iteration: f64,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct FrictionTiming {
    pub contact: String,
    pub ms_per_step: f64,
    /// `ms_per_step` over the frictionless (default) run's.
    pub over_frictionless: f64,
    pub newton_total: usize,
    pub factorizations_per_1000: f64,
    pub low_rank_updates_per_1000: f64,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ExplicitTiming {
    /// The step: the disc's, or 0.8 Δt_c where that is above Δt_c.
    pub dt: f64,
    pub scheme: String,
    pub mass: String,
    pub ms_per_step: f64,
    pub factorizations: usize,
    pub stable_dt: Option<f64>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Report {
    pub dt: f64,
    pub t_end: f64,
    /// The scheme and contact law timed, and the law's params as run (none in older files).
    #[serde(default)]
    pub scheme: Option<String>,
    #[serde(default)]
    pub contact: Option<String>,
    #[serde(default)]
    pub contact_params: Vec<(String, f64)>,
    pub repeats: usize,
    pub meshes: Vec<DiscTiming>,
}

pub fn disc(meshes: &[PathBuf], repeats: usize, progress: &mut dyn FnMut(&str)) -> Result<Report, CaseError> {
    // The problem of forms/library.toml's `[bench]`.
    let base = Options { problem: crate::settings::get().bench.disc.clone(), ..disc::options() };
    let stream = stream_bandwidth();
    let mut out = Vec::new();
    // The disc's step and end time (its file's) and the methods, as run.
    let (mut dt, mut t_end) = (f64::NAN, f64::NAN);
    let (mut scheme, mut contact, mut contact_params) = (None, None, Vec::new());
    for path in meshes {
        let opts = Options { mesh: Some(path.clone()), ..base.clone() };
        let Timed { per_step: mean, median_step: med, whole, summary: s } = timed(&opts, repeats)?;
        (dt, t_end) = (s.dt, s.t_end);
        contact_params = crate::driver::params::declared_by(&s.params, &s.contact);
        (scheme, contact) = (Some(s.scheme.clone()), Some(s.contact.clone()));
        let per_1000 = |count: usize| 1000.0 * count as f64 / s.steps.max(1) as f64;
        let median_step_ms = median(med);
        let model_bytes = (16 * s.factor_nnz.unwrap_or(0) + 16 * s.matrix_nnz + 24 * s.dofs) as f64;
        let model_ms = 1e3 * model_bytes / stream;
        let cache = triad_bandwidth(model_bytes as usize);
        let cache_model_ms = 1e3 * model_bytes / cache;
        let explicit = explicit_timing(&opts, s.dt, repeats)?;
        let linear_ms = median(mean.clone());
        let frictional = (crate::settings::get().bench.disc_friction.iter())
            .map(|contact| friction_timing(&opts, contact, repeats, linear_ms))
            .collect::<Result<Vec<_>, _>>()?;
        let finite_strain = [false, true]
            .into_iter()
            .map(|chord| finite_strain_timing(&opts, chord, repeats, linear_ms, s.newton_total))
            .collect::<Result<Vec<_>, _>>()?;
        let fastest = mean.iter().copied().fold(f64::INFINITY, f64::min);
        let slowest = mean.iter().copied().fold(0.0, f64::max);
        let ms_per_step = median(mean);
        let t = DiscTiming {
            mesh: path.display().to_string(),
            dofs: s.dofs,
            steps: s.steps,
            newton_total: s.newton_total,
            factorizations: s.factorizations,
            ms_per_step,
            ms_per_step_fastest: fastest,
            ms_per_step_slowest: slowest,
            median_step_ms,
            ms_per_step_with_setup: median(whole),
            factorizations_per_1000: per_1000(s.factorizations),
            low_rank_updates_per_1000: per_1000(s.low_rank_updates),
            matrix_nnz: s.matrix_nnz,
            factor_nnz: s.factor_nnz,
            model_bytes,
            stream_gb_s: stream / 1e9,
            model_ms,
            measured_over_model: ms_per_step / model_ms,
            median_over_model: median_step_ms / model_ms,
            cache_gb_s: cache / 1e9,
            cache_model_ms,
            measured_over_cache_model: ms_per_step / cache_model_ms,
            explicit,
            frictional,
            finite_strain,
        };
        progress(&format!(
            "{}: {} dofs, {} steps, {} Newton iterations, {} factorizations, {} low-rank updates; {:.3} ms/step stepping (runs {:.3}–{:.3}; median step {:.3} ms), {:.3} ms/step whole run; model {:.3} ms ({:.2} MB at STREAM's {:.1} GB/s), measured/model {:.2} (median step/model {:.2}); in cache {:.3} ms (at {:.1} GB/s), measured/model {:.2}",
            t.mesh,
            t.dofs,
            t.steps,
            t.newton_total,
            t.factorizations,
            s.low_rank_updates,
            t.ms_per_step,
            t.ms_per_step_fastest,
            t.ms_per_step_slowest,
            t.median_step_ms,
            t.ms_per_step_with_setup,
            t.model_ms,
            t.model_bytes / 1e6,
            t.stream_gb_s,
            t.measured_over_model,
            t.median_over_model,
            t.cache_model_ms,
            t.cache_gb_s,
            t.measured_over_cache_model
        ));
        if let Some(e) = &t.explicit {
            progress(&format!(
                "{}: {} with {} mass, Δt = {}: {:.3} ms/step stepping, {} factorizations, Δt_c ≈ {}",
                t.mesh,
                e.scheme,
                e.mass,
                e.dt,
                e.ms_per_step,
                e.factorizations,
                e.stable_dt.map_or("—".into(), |d| format!("{d:.4}"))
            ));
        }
        for f in &t.frictional {
            progress(&format!(
                "{}: contact {}: {:.3} ms/step stepping ({:.2}× the frictionless step), {} Newton iterations, per 1000 steps {:.0} factorizations and {:.0} low-rank updates",
                t.mesh,
                f.contact,
                f.ms_per_step,
                f.over_frictionless,
                f.newton_total,
                f.factorizations_per_1000,
                f.low_rank_updates_per_1000
            ));
        }
        for f in &t.finite_strain {
            progress(&format!(
                "{}: {} with {}{}: {:.3} ms/step stepping (median step {:.3} ms), {} Newton iterations, {:.0} factorizations per 1000 steps; {:.2}× the linear step, {:.2}× per Newton iteration",
                t.mesh,
                f.material,
                f.contact,
                if f.chord { ", chord Newton" } else { "" },
                f.ms_per_step,
                f.median_step_ms,
                f.newton_total,
                f.factorizations_per_1000,
                f.over_linear,
                f.over_linear_per_iteration
            ));
        }
        out.push(t);
    }
    Ok(Report { dt, t_end, scheme, contact, contact_params, repeats, meshes: out })
}

/// The explicit run of forms/library.toml on the same mesh at the disc's step `dt` (its summary
/// keys `stable_dt` and `factorizations`).
fn explicit_timing(opts: &Options, dt: f64, repeats: usize) -> Result<Option<ExplicitTiming>, CaseError> {
    let (scheme, mass) = &crate::settings::get().bench.disc_explicit;
    let mass = <crate::simulation::MassChoice as clap::ValueEnum>::from_str(mass, true)
        .map_err(|e| CaseError::Option(format!("forms/library.toml [bench]: {e}")))?;
    let methods = crate::driver::Methods { scheme: scheme.clone(), ..opts.methods.clone() };
    let mut opts = Options { methods, mass, ..opts.clone() };
    // Above its critical step on this mesh: at 0.8 Δt_c (three digits, rounded down), to the
    // same t_end.
    let mut dt = dt;
    if let Err(CaseError::UnstableStep { stable, .. }) =
        disc::run(&Options { dt: Some(dt), t_end: Some(dt), ..opts.clone() })
    {
        let scale = 10f64.powi(stable.log10().floor() as i32 - 2);
        dt = (0.8 * stable / scale).floor() * scale;
    }
    opts.dt = Some(dt);
    let Timed { per_step, summary, .. } = timed(&opts, repeats)?;
    Ok(Some(ExplicitTiming {
        dt,
        scheme: scheme.clone(),
        mass: mass.name().into(),
        ms_per_step: median(per_step),
        factorizations: summary.factorizations,
        stable_dt: summary.stable_dt,
    }))
}

/// A frictional law of forms/library.toml on the same disc, with the default scheme, against
/// the frictionless run's `linear_ms` per step.
fn friction_timing(opts: &Options, contact: &str, repeats: usize, linear_ms: f64) -> Result<FrictionTiming, CaseError> {
    let methods = crate::driver::Methods { contact: contact.to_string(), ..opts.methods.clone() };
    let mut opts = Options { methods, ..opts.clone() };
    opts.chosen.contact = true;
    let Timed { per_step, summary: s, .. } = timed(&opts, repeats)?;
    let per_1000 = |count: usize| 1000.0 * count as f64 / s.steps.max(1) as f64;
    let ms_per_step = median(per_step);
    Ok(FrictionTiming {
        contact: contact.to_string(),
        ms_per_step,
        over_frictionless: ms_per_step / linear_ms,
        newton_total: s.newton_total,
        factorizations_per_1000: per_1000(s.factorizations),
        low_rank_updates_per_1000: per_1000(s.low_rank_updates),
    })
}

/// The finite-strain run of forms/library.toml (material, contact law) on the same disc, with the
/// default scheme and the disc's Δt, with chord Newton or not, against the linear run's `linear_ms` per step and its
/// `linear_newton` iterations.
fn finite_strain_timing(
    opts: &Options,
    chord: bool,
    repeats: usize,
    linear_ms: f64,
    linear_newton: usize,
) -> Result<FiniteStrainTiming, CaseError> {
    let (material, contact) = &crate::settings::get().bench.disc_finite_strain;
    let methods =
        crate::driver::Methods { material: material.clone(), contact: contact.clone(), ..opts.methods.clone() };
    let newton = crate::runtime::nonlinear::newton::NewtonOptions { chord, ..opts.newton };
    let mut opts = Options { methods, newton, ..opts.clone() };
    (opts.chosen.material, opts.chosen.contact) = (true, true);
    let Timed { per_step, median_step: med, summary: s, .. } = timed(&opts, repeats)?;
    let ms_per_step = median(per_step);
    let over_linear = ms_per_step / linear_ms;
    Ok(FiniteStrainTiming {
        material: material.clone(),
        contact: contact.clone(),
        chord,
        ms_per_step,
        median_step_ms: median(med),
        newton_total: s.newton_total,
        factorizations_per_1000: 1000.0 * s.factorizations as f64 / s.steps.max(1) as f64,
        over_linear,
        over_linear_per_iteration: over_linear * linear_newton.max(1) as f64 / s.newton_total.max(1) as f64,
    })
}

/// A disc run's times per step over repeated runs, in ms (the mean over its steps, its median
/// step, and the whole run's mean), and its last run's summary.
struct Timed {
    per_step: Vec<f64>,
    median_step: Vec<f64>,
    whole: Vec<f64>,
    summary: disc::Summary,
}

fn timed(opts: &Options, repeats: usize) -> Result<Timed, CaseError> {
    let (mut per_step, mut median_step, mut whole) = (Vec::new(), Vec::new(), Vec::new());
    let mut last = None;
    for _ in 0..repeats.max(1) {
        let s = disc::run(opts)?.summary;
        let steps = s.steps.max(1) as f64;
        per_step.push(s.stepping_seconds / steps * 1e3);
        median_step.push(s.step_median_seconds * 1e3);
        whole.push(s.seconds_per_step * 1e3);
        last = Some(s);
    }
    Ok(Timed { per_step, median_step, whole, summary: last.expect("at least one run") })
}

/// The last run's `dir/bench_disc.json`, if there is one.
pub fn read(dir: &std::path::Path) -> Option<Result<Report, String>> {
    let path = dir.join("bench_disc.json");
    let text = std::fs::read_to_string(&path).ok()?;
    Some(serde_json::from_str(&text).map_err(|e| format!("{}: {e}", path.display())))
}

/// STREAM's bandwidth, one thread: the triad over arrays of four times the last-level cache
/// each (STREAM's rule for measuring main memory), 64 MiB each at least and 512 MiB at most
/// (three such arrays still exceed a 384 MB cache four times), 128 MiB where the cache's size
/// cannot be read.
pub fn stream_bandwidth() -> f64 {
    let array = last_level_cache_bytes().map_or(128 << 20, |c| (4 * c).clamp(64 << 20, 512 << 20));
    triad_bandwidth(3 * array)
}

/// The largest cache's size, from Linux's sysfs (None elsewhere, or if unreadable).
fn last_level_cache_bytes() -> Option<usize> {
    let dir = std::fs::read_dir("/sys/devices/system/cpu/cpu0/cache").ok()?;
    dir.filter_map(|e| {
        let path = e.ok()?.path();
        let size = std::fs::read_to_string(path.join("size")).ok()?;
        let size = size.trim();
        let (digits, unit) = size.split_at(size.find(|c: char| !c.is_ascii_digit()).unwrap_or(size.len()));
        let scale = match unit {
            "" => 1,
            "K" => 1 << 10,
            "M" => 1 << 20,
            _ => return None,
        };
        Some(digits.parse::<usize>().ok()? * scale)
    })
    .max()
}

/// Bytes per second of the triad a = b + s·c over three arrays of `bytes` in all (at least
/// 64 KiB): the median of 15 timings, each repeating the triad for at least a millisecond. The
/// median, not STREAM's best: the step times it is compared with are medians, and on a shared
/// machine the best is an instant the steps do not see (at 384 MB, three measurements read
/// 25.9–27.6 GB/s at best and 20.6–26.9 at the median).
pub fn triad_bandwidth(bytes: usize) -> f64 {
    let n = (bytes / 24).max(8192);
    let (b, c) = (vec![1.0f64; n], vec![2.0f64; n]);
    let mut a = vec![0.0f64; n];
    let mut triad = |s: f64| {
        a.iter_mut().zip(b.iter().zip(&c)).for_each(|(x, (y, z))| *x = y + s * z);
        std::hint::black_box(&mut a);
    };
    // Repetitions for a millisecond, from a first timing.
    let clock = Instant::now();
    triad(0.5);
    let once = clock.elapsed().as_secs_f64().max(1e-9);
    let reps = ((1e-3 / once).ceil() as usize).max(1);
    let timings: Vec<f64> = (0..15)
        .map(|k| {
            let clock = Instant::now();
            for r in 0..reps {
                triad(1.0 + (k * reps + r) as f64 * 1e-9);
            }
            (24 * n * reps) as f64 / clock.elapsed().as_secs_f64()
        })
        .collect();
    median(timings)
}
