//! What the stepper asks of a time scheme: its description (laid out by the compiler) and its
//! coefficients for a step size; and the view of a solved stage that observers read.

use signorini_descriptors::{SchemeDesc, Text};

/// A solved stage: its name, its time and its quantities (the unknown first), named as in the
/// scheme's file.
pub struct StageView<'v> {
    pub name: &'v str,
    pub time: f64,
    pub quantities: &'v [Text],
    pub values: &'v [Vec<f64>],
}

impl StageView<'_> {
    /// The stage's value of `state` (u, v, ...): its quantity named after the state, with a
    /// suffix (`um` for `u` in TR-BDF2's `um, vm, am`; `u'` for `u`). The scheme's file names
    /// these; the rule is documented in docs/language.md.
    pub fn value_of(&self, state: &str) -> Option<&[f64]> {
        self.quantities
            .iter()
            .position(|q| q.starts_with(state) && q.len() > state.len())
            .map(|i| self.values[i].as_slice())
    }
}

/// Implemented by every generated scheme, and by schemes interpreted at run time.
pub trait TimeScheme {
    fn desc(&self) -> &SchemeDesc;
    /// Evaluates every coefficient for step size `dt` from time `t`.
    fn coefficients(&self, dt: f64, t: f64, out: &mut [f64]);
}
