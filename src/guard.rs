//! The step guard: when a failed step may be retried with Δt halved, how much energy a run may
//! gain before it is stopped, and whether an explicit scheme may step beyond its critical step;
//! with their defaults, which the command line and case files read from here.

/// Most halvings of a step (`--max-step-cuts`, `max_step_cuts`): Δt/2⁴⁰ is below any use, and
/// the step's progress is counted in units of Δt/2^cuts.
pub const MAX_STEP_CUTS: usize = 40;

/// When a step may fail and how much energy a run may gain (`--max-step-cuts`,
/// `--energy-tolerance`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Guard {
    pub max_step_cuts: usize,
    /// Run an explicit scheme above its estimated critical step (`--allow-unstable-dt`).
    pub allow_unstable_dt: bool,
    /// The growth of E_aug beyond E_aug(0) + the work of the loads that stops a run, as a
    /// fraction of the energy scale; 0 turns the check off.
    pub energy_tolerance: f64,
}

/// `--energy-tolerance`'s default: 5 % of the problem's energy scale.
pub const ENERGY_TOLERANCE: f64 = 0.05;

impl Default for Guard {
    fn default() -> Self {
        Guard { max_step_cuts: 6, allow_unstable_dt: false, energy_tolerance: ENERGY_TOLERANCE }
    }
}

/// A number of step cuts (`--max-step-cuts`, a case file's `max_step_cuts`), checked against
/// [`MAX_STEP_CUTS`].
pub fn step_cuts(n: i64) -> Result<usize, String> {
    usize::try_from(n).ok().filter(|&n| n <= MAX_STEP_CUTS).ok_or_else(|| format!("{n} is not in 0..={MAX_STEP_CUTS}"))
}
