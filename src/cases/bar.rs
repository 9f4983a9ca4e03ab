//! The compressed bar as the report, `verify` and the tests read it: the problem itself is data
//! (`forms/problems/bar.wf`, run by the one driver, [`crate::problem::run`], against the
//! reference [`crate::references::bar`]); this module gives its rows and summary typed fields.
//! Its runs take the driver's [`Options`]; the number of elements is the problem's param `ne`.

use serde::{Deserialize, Serialize};

use super::{Common, number};
use crate::error::CaseError;
use crate::problem::run::{Chosen, Options};

/// The bar's run with its file's mesh and times and a run's defaults: the problem of
/// forms/library.toml's `cases.bar`, with the methods as given (no `bind` line replaces them).
pub fn options() -> Options {
    Options { chosen: Chosen::all(), ..Options::new(&crate::settings::get().cases.bar) }
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

/// The bar's summary: the keys of every run ([`Common`], read through `Deref`) and the bar's own.
#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    #[serde(flatten)]
    pub common: Common,
    /// The number of elements (the problem's param `ne`).
    pub elements: usize,
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
}

deref_to_common!(Summary);

pub struct Run {
    pub summary: Summary,
    pub series: Vec<Row>,
}

/// Runs the bar; writes series.csv and summary.json into `opts.out` if set.
pub fn run(opts: &Options) -> Result<Run, CaseError> {
    from_problem(opts, &crate::problem::run::run(opts)?)
}

fn from_problem(opts: &Options, run: &crate::problem::run::Run) -> Result<Run, CaseError> {
    let s = &run.summary;
    let (common, own) = Common::read(opts, s)?;
    let names = ["u_c", "v_c", "lambda", "lambda_half", "energy", "energy_aug", "penetration", "newton", "p1"];
    let index = run.indices(&names, &common.case)?;
    let series = run
        .rows
        .iter()
        .map(|(t, v)| Row {
            t: *t,
            u_c: v[index[0]],
            v_c: v[index[1]],
            lambda: v[index[2]],
            lambda_half: v[index[3]],
            energy: v[index[4]],
            energy_aug: v[index[5]],
            penetration: v[index[6]],
            newton: v[index[7]] as usize,
            p1: v[index[8]],
        })
        .collect::<Vec<_>>();
    let summary = Summary {
        elements: own.get(&format!("{}.ne", common.case)).map_or(0, |p| p.value as usize),
        err_linf_l2_u: number(s, "err_linf_l2_u"),
        err_l2_lambda: s.number("err_l2_lambda"),
        err_l2_lambda_half: s.number("err_l2_lambda_half"),
        energy_initial: number(s, "energy_initial"),
        energy_final: number(s, "energy_final"),
        energy_aug_initial: number(s, "energy_aug_initial"),
        energy_aug_final: number(s, "energy_aug_final"),
        energy_aug_drift_final: number(s, "energy_aug_drift_final"),
        energy_aug_drift_max: number(s, "energy_aug_drift_max"),
        max_penetration: number(s, "max_penetration"),
        common,
    };
    Ok(Run { summary, series })
}
