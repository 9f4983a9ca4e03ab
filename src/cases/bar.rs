//! `signorini run bar`: the compressed bar of docs/mathematics.md §6 with any compiled scheme, Nitsche or
//! penalty contact, against its exact solution.

use std::path::PathBuf;
use std::time::Instant;

use serde::{Deserialize, Serialize};

use super::CaseError;
use super::exact;
use crate::checkpoint::Control;
use crate::driver::{Active, ParamValue, Setup};
use crate::runtime::assembly::{Assembler, Quadrature};
use crate::runtime::kernel::Coef;
use crate::runtime::mesh::{CellSize, Mesh, structured};
use crate::runtime::newton::NewtonOptions;
use crate::runtime::problem::Constraints;
use crate::simulation::{Problem, Simulation, Tools};

/// The bar's material is the form files' default (E = ρ = 1, ν = 0): no overrides.
pub const OVERRIDES: &[(&str, f64)] = &[];

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum MassChoice {
    Consistent,
    /// Mass redistribution (docs/mathematics.md §4): no inertia at the contact node.
    Redistributed,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Options {
    /// Scheme, contact law, extra forms and params.
    pub setup: Setup,
    pub elements: usize,
    pub dt: f64,
    pub t_end: f64,
    pub mass: MassChoice,
    /// What `h` means in γ = γ0/h.
    pub cell_size: CellSize,
    pub newton: NewtonOptions,
    pub out: Option<PathBuf>,
    /// Show a progress bar on long runs (when stdout is a terminal).
    pub progress: bool,
    /// Write `out`/checkpoint.bin after every this many steps (0: only on an interrupt).
    pub checkpoint_every: usize,
    /// Continue from `out`/checkpoint.bin.
    pub resume: bool,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            setup: Setup::default(),
            elements: 20,
            dt: 0.01,
            t_end: 12.0,
            mass: MassChoice::Consistent,
            cell_size: CellSize::Diameter,
            newton: NewtonOptions::default(),
            out: None,
            checkpoint_every: 0,
            resume: false,
            progress: false,
        }
    }
}

/// One row of `series.csv`.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Row {
    pub t: f64,
    pub u_c: f64,
    pub v_c: f64,
    pub lambda: f64,
    /// λ at t − Δt/2 from (u(t − Δt) + u(t))/2, where midpoint and hybrid impose contact
    /// (NaN at t = 0).
    pub lambda_half: f64,
    pub energy: f64,
    pub energy_aug: f64,
    pub penetration: f64,
    pub newton: usize,
    /// The contact law's `contact_trial` at the contact point: P_{1,γ}(u) before the projection
    /// (Nitsche), −ε (u_N − g) (penalty).
    #[serde(skip)]
    pub p1: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    pub case: &'static str,
    pub scheme: String,
    /// The contact law (its file stem).
    pub contact: String,
    /// Files of the run compiled at run time (given by path, not in the library).
    pub interpreted: Vec<String>,
    /// Every param of the scheme and form files, with its value and where it comes from.
    pub params: std::collections::BTreeMap<String, ParamValue>,
    pub mass: MassChoice,
    pub cell_size: CellSize,
    pub elements: usize,
    pub dt: f64,
    pub t_end: f64,
    pub dofs: usize,
    pub steps: usize,
    /// max_n ‖u_h − I_h u‖_M / max_n ‖I_h u‖_M.
    pub err_linf_l2_u: f64,
    /// (Σ (λⁿ − σ_ex(0, tⁿ))²)^½ / (Σ σ_ex(0, tⁿ)²)^½; absent (see `notes`) when the exact
    /// contact stress is zero on [0, t_end].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub err_l2_lambda: Option<f64>,
    /// The same with λ evaluated at u^{n+½} = (uⁿ + uⁿ⁺¹)/2 against σ_ex(0, t^{n+½}): where the
    /// midpoint and hybrid schemes impose contact (docs/mathematics.md §6 [P]; with redistributed mass their
    /// contact node oscillates with period 2 at integer steps).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub err_l2_lambda_half: Option<f64>,
    pub energy_initial: f64,
    pub energy_final: f64,
    pub energy_aug_initial: f64,
    pub energy_aug_final: f64,
    /// (E_Θ(T) − E_Θ(0)) / E_Θ(0).
    pub energy_aug_drift_final: f64,
    /// max_n |E_Θⁿ − E_Θ(0)| / E_Θ(0).
    pub energy_aug_drift_max: f64,
    pub max_penetration: f64,
    pub newton_total: usize,
    pub newton_max: usize,
    pub wall_seconds: f64,
    /// Halvings of Δt after a failed Newton (the series has the actual time levels).
    pub step_cuts: usize,
    /// Why the run ended before t_end, if it did (the series stops at the last good step).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stopped: Option<String>,
    /// The checkpoint this run resumed from (its counters and wall time cover the rest only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub resumed: Option<crate::simulation::Resumed>,
    /// Why a metric is absent.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<String>,
}

pub struct Run {
    pub summary: Summary,
    pub series: Vec<Row>,
}

/// Runs the bar; writes series.csv and summary.json into `opts.out` if set.
pub fn run(opts: &Options) -> Result<Run, CaseError> {
    if opts.elements == 0 || opts.elements > 100_000 {
        return Err(CaseError::Option(format!("--ne must be in 1..=100000, not {}", opts.elements)));
    }
    let positive = |x: f64| x > 0.0 && x.is_finite();
    if !positive(opts.dt) || !positive(opts.t_end) {
        return Err(CaseError::Option("--dt and --t-end must be positive".into()));
    }
    if opts.t_end / opts.dt > 1e7 {
        return Err(CaseError::Option(format!(
            "--dt {} and --t-end {} make {:.1e} steps, more than 10⁷",
            opts.dt,
            opts.t_end,
            opts.t_end / opts.dt
        )));
    }
    let active = Active::resolve(&opts.setup, OVERRIDES)?;
    simulate(opts, &active)
}

/// Case data: no body force; gap g = x; obstacle normal −1 at x = 0.
fn coefs(name: &str) -> Option<Coef> {
    match name {
        "f" => Some(Coef::constant(vec![0.0])),
        "g" => Some(Coef::of_position(1, |x, out| out[0] = x[0])),
        "nc" => Some(Coef::constant(vec![-1.0])),
        _ => None,
    }
}

fn simulate(opts: &Options, active: &Active) -> Result<Run, CaseError> {
    let start = Instant::now();
    let ne = opts.elements;
    let mut mesh = structured::interval(ne, 0.0, 1.0);
    mesh.set_cell_size(opts.cell_size);
    let asm = Assembler::new(&mesh);
    let n = asm.size();
    let mut constraints = Constraints::none(n);
    constraints.fix(ne); // u(1) = 0
    let problem = Problem {
        coefs: &coefs,
        quadrature: Quadrature::default(),
        contact: "left",
        regions: &[],
        constraints,
        mass: opts.mass,
        newton: opts.newton,
    };
    let identity = crate::checkpoint::identity(
        "bar",
        active,
        &mesh,
        &[
            ("mass", format!("{:?}", opts.mass)),
            ("cell size", format!("{:?}", opts.cell_size)),
            ("dt", format!("{:?}", opts.dt)),
            ("t_end", format!("{:?}", opts.t_end)),
            ("Newton options", format!("{:?}", opts.newton)),
            ("checkpoint period", opts.checkpoint_every.to_string()),
        ],
    );
    let mut control = Control::new(opts.checkpoint_every, opts.out.clone(), identity, opts.resume)?;
    let mut sim = Simulation::new(&asm, problem, active)?;
    let redistributed = opts.mass == MassChoice::Redistributed;
    // Initial state: u₀ = (1 − x)/2, v₀ = 0, a₀ from the scheme's initial problem.
    sim.initialize((0..n).map(|i| 0.5 * (1.0 - mesh.node(i)[0])).collect())?;
    let steps = (opts.t_end / opts.dt).round() as usize;
    let mut series = Vec::with_capacity(steps + 1);
    // λ and P at the contact point (docs/mathematics.md §2), from the contact law's functionals: in 1D the
    // integral over Γ_C is the value at x = 0. NaN when the law does not provide them.
    let contact_stress = |tools: &Tools, u: &[f64]| -> (f64, f64) {
        (tools.value(&tools.contact_pressure, u), tools.value(&tools.contact_trial, u))
    };
    let measure = |tools: &Tools, u: &[f64], v: Option<&[f64]>, newton: usize, t: f64| -> Row {
        let u0 = u[0];
        let (lambda, p1) = contact_stress(tools, u);
        let energy = tools.energy(u, v);
        Row {
            t,
            u_c: u0,
            v_c: v.map_or(f64::NAN, |v| v[0]),
            lambda,
            lambda_half: f64::NAN,
            energy,
            energy_aug: energy + tools.value(&tools.contact_energy, u),
            penetration: (-u0).max(0.0),
            newton,
            p1,
        }
    };
    series.push(measure(&sim.tools, &sim.states[0], sim.velocity(), 0, 0.0));
    let mut errors = Errors::default();
    errors.track(&sim.tools, &mesh, &sim.states[0], &series[0]);
    let mut t = 0.0;
    // Rows the checkpoints so far hold (each records the rows new since the one before).
    let mut saved_rows = 0;
    if let Some(records) = control.observer() {
        series.clear();
        for bytes in records {
            let record: Record = postcard::from_bytes(bytes)
                .map_err(|e| CaseError::Option(format!("the checkpoint's record of the run is damaged ({e})")))?;
            series.extend(record.series.into_iter().map(|(row, p1)| Row { p1, ..row }));
            errors = record.errors;
        }
        t = series.last().map_or(0.0, |r| r.t);
        saved_rows = series.len();
    }
    let v_index = sim.v_index;
    let outcome =
        sim.run(0.0, opts.dt, steps, opts.progress, &mut control, &mut |_, _, _| {}, &mut |tools, step, record| {
            t = step.t;
            let mut row = measure(
                tools,
                &step.states[0],
                v_index.map(|i| step.states[i].as_slice()),
                step.report.iterations(),
                t,
            );
            if redistributed {
                // The massless contact node's velocity is not meaningful: report its mean velocity.
                row.v_c = (step.states[0][0] - step.before[0]) / step.dt;
            }
            let half: Vec<f64> = step.before.iter().zip(&step.states[0]).map(|(a, b)| 0.5 * (a + b)).collect();
            let s = exact::contact_stress(t - 0.5 * step.dt);
            row.lambda_half = contact_stress(tools, &half).0;
            errors.half_err += (row.lambda_half - s).powi(2);
            errors.half_norm += s * s;
            errors.track(tools, &mesh, &step.states[0], &row);
            series.push(row);
            if let Some(record) = record {
                *record = postcard::to_stdvec(&Record {
                    series: series[saved_rows..].iter().map(|r| (r.clone(), r.p1)).collect(),
                    errors: errors.clone(),
                })
                .map_err(|e| CaseError::Option(format!("cannot encode the checkpoint: {e}")))?;
                saved_rows = series.len();
            }
            Ok(())
        })?;
    let Errors { err_max, exact_max, lam_err, lam_norm, half_err, half_norm } = errors;
    let first = &series[0];
    let last = series.last().expect("at least the initial row");
    let e0 = first.energy_aug;
    let summary = Summary {
        case: "bar",
        scheme: active.scheme_name().to_string(),
        contact: active.forms.contact_name().to_string(),
        interpreted: active.interpreted(),
        params: active.forms.params.values(),
        mass: opts.mass,
        cell_size: opts.cell_size,
        elements: ne,
        dt: opts.dt,
        t_end: t,
        dofs: n,
        steps,
        err_linf_l2_u: err_max / exact_max,
        err_l2_lambda: relative(lam_err, lam_norm),
        err_l2_lambda_half: relative(half_err, half_norm),
        energy_initial: first.energy,
        energy_final: last.energy,
        energy_aug_initial: e0,
        energy_aug_final: last.energy_aug,
        energy_aug_drift_final: (last.energy_aug - e0) / e0,
        energy_aug_drift_max: series.iter().map(|r| (r.energy_aug - e0).abs()).fold(0.0, f64::max) / e0,
        max_penetration: series.iter().map(|r| r.penetration).fold(0.0, f64::max),
        newton_total: series.iter().map(|r| r.newton).sum(),
        newton_max: series.iter().map(|r| r.newton).max().unwrap_or(0),
        wall_seconds: start.elapsed().as_secs_f64(),
        step_cuts: outcome.cuts,
        stopped: outcome.stopped.as_ref().map(ToString::to_string),
        resumed: outcome.resumed,
        notes: Vec::new(),
    };
    let mut summary = summary;
    if summary.err_l2_lambda.is_none() {
        summary.notes.push(format!(
            "err_l2_lambda and err_l2_lambda_half omitted: the exact contact stress is zero on [0, {}] (first contact at t = 1)",
            summary.t_end
        ));
    }
    if let Some(dir) = &opts.out {
        write_outputs(dir, &summary, &series)?;
    }
    if let Some(e) = outcome.stopped {
        return Err(e);
    }
    Ok(Run { summary, series })
}

/// The error sums over the steps.
#[derive(Clone, Default, Serialize, Deserialize)]
struct Errors {
    err_max: f64,
    exact_max: f64,
    lam_err: f64,
    lam_norm: f64,
    half_err: f64,
    half_norm: f64,
}

impl Errors {
    /// The error in the norm of the mass the scheme steps with, and λ's against the exact one.
    fn track(&mut self, tools: &Tools, mesh: &Mesh, u: &[f64], row: &Row) {
        let interp: Vec<f64> = (0..u.len()).map(|i| exact::displacement(mesh.node(i)[0], row.t)).collect();
        let diff: Vec<f64> = u.iter().zip(&interp).map(|(a, b)| a - b).collect();
        self.err_max = self.err_max.max(Tools::quad(&tools.scheme_mass, &diff, &diff).sqrt());
        self.exact_max = self.exact_max.max(Tools::quad(&tools.scheme_mass, &interp, &interp).sqrt());
        let s = exact::contact_stress(row.t);
        self.lam_err += (row.lambda - s).powi(2);
        self.lam_norm += s * s;
    }
}

/// The bar's record in a checkpoint: the rows new since the checkpoint before (with P, which
/// series.csv leaves out) and the error sums so far.
#[derive(Serialize, Deserialize)]
struct Record {
    series: Vec<(Row, f64)>,
    errors: Errors,
}

/// (err/norm)^½, undefined when the exact quantity is zero.
fn relative(err: f64, norm: f64) -> Option<f64> {
    (norm > 0.0).then(|| (err / norm).sqrt()).filter(|e| e.is_finite())
}

fn write_outputs(dir: &std::path::Path, summary: &Summary, series: &[Row]) -> Result<(), CaseError> {
    let mut csv = String::from("t,u_c,v_c,lambda,lambda_half,energy,energy_aug,penetration,newton\n");
    for r in series {
        csv.push_str(&format!(
            "{},{},{},{},{},{},{},{},{}\n",
            r.t, r.u_c, r.v_c, r.lambda, r.lambda_half, r.energy, r.energy_aug, r.penetration, r.newton
        ));
    }
    let write = |name: &str, bytes: &[u8]| {
        let path = dir.join(name);
        crate::output::write_atomic(&path, bytes)
            .map_err(|source| CaseError::Write { path: path.display().to_string(), source })
    };
    write("series.csv", csv.as_bytes())?;
    let pts = |f: &dyn Fn(&Row) -> f64| series.iter().map(|r| (r.t, f(r))).collect::<Vec<_>>();
    let dense: Vec<f64> = (0..=2400).map(|k| k as f64 * summary.t_end / 2400.0).collect();
    let exact_u: Vec<(f64, f64)> = dense.iter().map(|&t| (t, exact::displacement(0.0, t))).collect();
    let exact_s: Vec<(f64, f64)> = dense.iter().map(|&t| (t, exact::contact_stress(t))).collect();
    use crate::plot::Curve;
    let plot_err = |e: String| CaseError::Write { path: dir.display().to_string(), source: std::io::Error::other(e) };
    crate::plot::panels(
        &dir.join("contact.png"),
        "t",
        &[
            (
                "displacement of the contact point",
                "u(0, t)",
                vec![
                    Curve { label: "computed", points: pts(&|r| r.u_c), dashed: false },
                    Curve { label: "exact", points: exact_u, dashed: true },
                ],
            ),
            (
                "contact stress",
                "λ",
                vec![
                    Curve { label: "computed", points: pts(&|r| r.lambda), dashed: false },
                    Curve { label: "exact", points: exact_s, dashed: true },
                ],
            ),
        ],
    )
    .map_err(plot_err)?;
    crate::plot::panels(
        &dir.join("energy.png"),
        "t",
        &[(
            "energies",
            "energy",
            vec![
                Curve { label: "E", points: pts(&|r| r.energy), dashed: false },
                Curve { label: "E + contact energy", points: pts(&|r| r.energy_aug), dashed: false },
            ],
        )],
    )
    .map_err(plot_err)?;
    let path = dir.join("summary.json");
    crate::output::write_json(&path, summary)
        .map_err(|source| CaseError::Write { path: path.display().to_string(), source })
}
