//! `forms/library.toml`: the library's defaults and the runs the report, `verify` and the
//! benchmarks make, as data (no scheme, law or problem name is written in Rust).

use std::sync::OnceLock;

use serde::Deserialize;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Settings {
    pub defaults: Defaults,
    pub cases: Cases,
    pub report: Report,
    pub verify: Verify,
    pub bench: Bench,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Bench {
    /// `bench disc`: the problem timed.
    pub disc: String,
    /// `bench disc`: the explicit run timed beside the default one, (scheme, mass matrix).
    pub disc_explicit: (String, String),
    /// `bench disc`: the frictional contact laws timed beside the default one (their cost
    /// over the frictionless step, factorizations and low-rank updates per 1000 steps: an
    /// unsymmetric tangent that turns with the slip).
    pub disc_friction: Vec<String>,
    /// `bench disc`: the finite-strain run timed beside the default one, (material, contact
    /// law): same mesh, scheme and Δt, and its cost per step over the linear one's.
    pub disc_finite_strain: (String, String),
    /// `bench assemble`: the finite-strain material whose stiffness (residual and tangent at a
    /// small random state) is timed per cell, and the quadrature degrees it is timed at.
    pub assemble_material: String,
    pub assemble_degrees: Vec<u32>,
    /// Its params set for the timing (the others at their defaults).
    pub assemble_params: std::collections::BTreeMap<String, f64>,
    /// `bench sphere`: the problem timed against its size, and the options of each run.
    pub sphere: String,
    pub sphere_options: Vec<String>,
    /// `bench balls`: the two-body problem timed against its size, and the options of each run.
    pub balls: String,
    pub balls_options: Vec<String>,
    /// `bench adaptive`: problems run with fixed and with adaptive steps side by side.
    pub adaptive: Vec<AdaptiveBench>,
}

/// One problem of `bench adaptive`: the adaptive run's tolerance, the options of every run, the
/// summary keys compared, and either a reference run's options (fine fixed steps: its values
/// stand for the exact ones, so each run's difference from it is its time discretization's
/// error) or the fixed run taken at the adaptive run's number of steps (keys that are errors
/// against an exact solution already).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AdaptiveBench {
    pub problem: String,
    pub tolerance: f64,
    #[serde(default)]
    pub options: Vec<String>,
    pub compare: Vec<String>,
    #[serde(default)]
    pub reference: Option<Vec<String>>,
    #[serde(default)]
    pub same_steps: bool,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Defaults {
    pub scheme: String,
    pub contact: String,
    /// The contact law of a problem with contact pairs (a law of `forms/pairs/`).
    pub pair: String,
    pub material: String,
}

/// The problems `cases::bar` and `cases::disc` run unless told otherwise.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Cases {
    pub bar: String,
    pub disc: String,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Report {
    pub bar: Vec<BarRuns>,
    /// §5: the static Hertz problems and the impact problem.
    pub hertz: Vec<HertzStatic>,
    pub hertz_impact: String,
    /// §6: friction problems, and the one every scheme × frictional law runs.
    pub friction: Vec<FrictionRun>,
    pub friction_table: FrictionTable,
    /// §9: the sources of the methods.
    pub references: Vec<Citation>,
}

/// A source of the methods, and what it is behind (schemes, laws, problems, sections).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Citation {
    pub cite: String,
    pub behind: Vec<String>,
}

/// A friction problem of the report: run with `contact` (the problem's own when empty) and
/// `params`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrictionRun {
    pub problem: String,
    pub label: String,
    #[serde(default)]
    pub contact: String,
    #[serde(default)]
    pub params: std::collections::BTreeMap<String, f64>,
}

/// The problem the report runs with every scheme × frictional law.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrictionTable {
    pub problem: String,
    #[serde(default)]
    pub params: std::collections::BTreeMap<String, f64>,
    pub t_start: Option<f64>,
    /// The summary keys of its table.
    pub keys: Vec<String>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HertzStatic {
    pub problem: String,
    /// The summary key of the contact size (`KEY` and `KEY_error`).
    pub size: String,
    /// The finest mesh level solved.
    pub finest: usize,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BarRuns {
    /// (scheme, contact law, mass matrix).
    pub runs: Vec<(String, String, String)>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Verify {
    pub contacts: Vec<String>,
    /// `verify --scheme`: the library's schemes every report compares with.
    pub references: Vec<String>,
    /// `verify --scheme`: the slot a scheme applies to the velocity for a damping term; a scheme
    /// that uses it is also measured on the damped oscillator.
    pub damping_slot: String,
}

/// The parsed file (compiled in; `tests/settings` checks that it parses and names library
/// files only).
pub fn get() -> &'static Settings {
    static SETTINGS: OnceLock<Settings> = OnceLock::new();
    SETTINGS.get_or_init(|| {
        toml::from_str(include_str!("../forms/library.toml")).expect("forms/library.toml is checked by its test")
    })
}
