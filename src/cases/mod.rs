//! Typed views of the library's bar, disc and sphere runs for the report, `verify`, the
//! benchmarks and the tests (the problems themselves are files, run by [`crate::problem::run`]),
//! and case files (`signorini run case.toml`). A view's summary is the keys every run has
//! ([`Common`]) and its problem's own.

/// A view's summary reads the common keys as its own fields (`summary.dt`): `Deref` to its
/// field `common`.
macro_rules! deref_to_common {
    ($summary:ty) => {
        impl std::ops::Deref for $summary {
            type Target = $crate::cases::Common;
            fn deref(&self) -> &$crate::cases::Common {
                &self.common
            }
        }
    };
}

pub mod bar;
pub mod disc;
pub mod file;

use std::collections::BTreeMap;

use serde::Serialize;

use crate::driver::ParamValue;
use crate::error::CaseError;
use crate::problem::outputs::Summary;
use crate::problem::run::Options;
use crate::runtime::fem::mesh::CellSize;
use crate::simulation::MassChoice;

/// The keys the driver writes into every run's summary, typed.
#[derive(Clone, Debug, Serialize)]
pub struct Common {
    /// The problem's name.
    pub case: String,
    pub scheme: String,
    /// The contact law (its file stem).
    pub contact: String,
    /// Files of the run compiled at run time (given by path, not in the library).
    pub interpreted: Vec<String>,
    /// Every param of the scheme and form files, with its value and where it comes from (the
    /// problem's own are the view's).
    pub params: BTreeMap<String, ParamValue>,
    pub mass: MassChoice,
    /// What `h` means in γ = γ0/h.
    pub cell_size: CellSize,
    pub dofs: usize,
    pub dt: f64,
    /// The time reached (the end time, or where the run stopped).
    pub t_end: f64,
    pub steps: usize,
    pub newton_total: usize,
    pub newton_max: usize,
    pub wall_seconds: f64,
    /// Halvings of Δt after a failed Newton (the series has the actual time levels).
    pub step_cuts: usize,
    /// The energy guard's largest growth of E_aug over the energy scale.
    pub energy_growth: f64,
    /// An explicit scheme's estimated critical step.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stable_dt: Option<f64>,
    /// Why the run ended before t_end, if it did (the series stops at the last good step).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stopped: Option<String>,
    /// The checkpoint this run resumed from (its counters and wall time cover the rest only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub resumed: Option<crate::simulation::Resumed>,
    /// Why a summary key of the problem's is absent (undefined on this run).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<String>,
}

impl Common {
    /// The common keys of a run with `opts`, and apart from them the problem's own params
    /// (`NAME.p`).
    fn read(opts: &Options, s: &Summary) -> Result<(Common, BTreeMap<String, ParamValue>), CaseError> {
        let case: String = s.field("case")?;
        let prefix = format!("{case}.");
        let params: BTreeMap<String, ParamValue> = s.field("params")?;
        let (own, params) = params.into_iter().partition(|(k, _)| k.starts_with(&prefix));
        let common = Common {
            case,
            scheme: s.field("scheme")?,
            contact: s.field("contact")?,
            interpreted: s.field("interpreted")?,
            params,
            mass: opts.mass,
            cell_size: opts.cell_size,
            dofs: count(s, "dofs"),
            dt: number(s, "dt"),
            t_end: number(s, "t_end"),
            steps: count(s, "steps"),
            newton_total: count(s, "newton_total"),
            newton_max: count(s, "newton_max"),
            wall_seconds: number(s, "wall_seconds"),
            step_cuts: count(s, "step_cuts"),
            energy_growth: number(s, "energy_growth"),
            stable_dt: s.get("stable_dt").and_then(|v| v.as_f64()),
            stopped: s.get("stopped").and_then(|v| v.as_str()).map(str::to_string),
            resumed: s.field("resumed")?,
            notes: s.field::<Option<Vec<String>>>("notes")?.unwrap_or_default(),
        };
        Ok((common, own))
    }
}

/// A number of the summary; NaN when absent or null.
fn number(s: &Summary, key: &str) -> f64 {
    s.number(key).unwrap_or(f64::NAN)
}

/// A count of the summary; 0 when absent.
fn count(s: &Summary, key: &str) -> usize {
    s.get(key).and_then(|v| v.as_u64()).unwrap_or(0) as usize
}
