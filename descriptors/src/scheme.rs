//! A time scheme as the compiler lays it out: its states, its stages with their terms, and
//! every term's arguments as combinations of known levels and the stage's unknown, indexing
//! one array of coefficients the scheme evaluates per step.

use crate::slots::SlotUse;
use crate::{List, Text};

/// A vector known when a stage starts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Level {
    /// A state at the start of the step.
    State(usize),
    /// Quantity `.1` of an earlier stage `.0`.
    Stage(usize, usize),
}

/// `c[unknown]·w + Σ c[k]·level` (indices into the coefficient array; `None`: no unknown).
#[derive(Clone, Debug, PartialEq)]
pub struct Combination {
    pub unknown: Option<usize>,
    pub known: List<(Level, usize)>,
}

/// `c[coef] · form(args)` at time `c[time]`.
#[derive(Clone, Debug, PartialEq)]
pub struct TermDesc {
    pub coef: usize,
    pub form: Text,
    pub args: List<Combination>,
    pub time: usize,
}

#[derive(Clone, Debug, PartialEq)]
pub struct StageDesc {
    pub name: Text,
    pub time: usize,
    /// New quantities, the unknown first.
    pub quantities: List<Text>,
    pub values: List<Combination>,
    pub terms: List<TermDesc>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct InitialDesc {
    pub state: usize,
    pub terms: List<TermDesc>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct SchemeDesc {
    pub name: Text,
    /// The slots it applies (`uses`), with where they are declared.
    pub uses: List<SlotUse>,
    pub states: List<Text>,
    pub initial: Option<InitialDesc>,
    pub stages: List<StageDesc>,
    /// The level each state takes at the end of a step.
    pub updates: List<Level>,
    /// The step's local error (`estimate`), over its levels at the step's end (the states at
    /// its start and every stage's quantities); none when the scheme declares none.
    pub estimate: Option<Combination>,
    /// Length of the coefficient array.
    pub coefficients: usize,
}

impl SchemeDesc {
    /// Whether every stage is explicit: only `mass` acts on its unknown, so a step solves with
    /// the mass matrix alone (central differences). A mass with massless dofs (redistributed)
    /// cannot be solved for them.
    pub fn explicit(&self) -> bool {
        !self.stages.is_empty()
            && self.stages.iter().all(|s| {
                s.terms.iter().filter(|t| t.args.iter().any(|c| c.unknown.is_some())).all(|t| t.form == "mass")
            })
    }
}
