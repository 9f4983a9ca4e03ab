//! The levels a stage reads (the step's states, the stages solved so far) and the
//! combinations of them its arguments and values are: `c_w·w + Σ c·level`, in increments.

use signorini_descriptors::{Combination, Level, TermDesc};

use super::Stepper;
use crate::time::stage::{Part, zero_sum_groups};

/// What a stage's combinations read: the states at the step's start, each solved stage's
/// quantities, and the level Newton's increment is taken from (the state the unknown updates).
#[derive(Clone, Copy)]
pub(super) struct Levels<'l> {
    pub(super) states: &'l [Vec<f64>],
    pub(super) quantities: &'l [Vec<Vec<f64>>],
    pub(super) reference: Level,
}

impl<'l> Levels<'l> {
    pub(super) fn get(&self, l: Level) -> &'l [f64] {
        match l {
            Level::State(i) => &self.states[i],
            Level::Stage(s, q) => &self.quantities[s][q],
        }
    }
}

impl Stepper<'_> {
    /// `c_w·w + Σ c·level` with the unknown w = reference + δ (δ = 0 if `delta` is `None`):
    /// `c_w·δ`, plus the levels (the reference with c_w added to its coefficient) grouped by
    /// [`zero_sum_groups`], each group as Σ c·(level − its reference level), each other level as
    /// c·level.
    pub(super) fn combine(&self, c: &Combination, levels: &Levels, delta: Option<&[f64]>, out: &mut [f64]) {
        let (level, reference) = (|l: Level| levels.get(l), levels.reference);
        let mut terms: Vec<(Level, f64)> = Vec::with_capacity(c.known.len() + 1);
        let mut add = |l: Level, a: f64| match terms.iter_mut().find(|(m, _)| *m == l) {
            Some((_, b)) => *b += a,
            None => terms.push((l, a)),
        };
        // The sum's parts in order: out += a·x, or out += a·(x − y).
        let mut parts: Vec<Part> = Vec::new();
        if let Some(k) = c.unknown {
            let a = self.coefs[k];
            if let Some(d) = delta {
                parts.push((a, d, None));
            }
            add(reference, a);
        }
        for &(l, k) in c.known.iter() {
            add(l, self.coefs[k]);
        }
        terms.retain(|(_, a)| *a != 0.0);
        let coefs: Vec<f64> = terms.iter().map(|(_, a)| *a).collect();
        for group in zero_sum_groups(&coefs) {
            if group.len() == 1 {
                let (l, a) = terms[group[0]];
                parts.push((a, level(l), None));
                continue;
            }
            let r = group.iter().copied().find(|&i| terms[i].0 == reference).unwrap_or(group[0]);
            let x0 = level(terms[r].0);
            for &i in group.iter().filter(|&&i| i != r) {
                let (l, a) = terms[i];
                parts.push((a, level(l), Some(x0)));
            }
        }
        // Strip by strip, each part in turn: one pass over memory, the same sums as part by part.
        const STRIP: usize = 512;
        for (k, o) in out.chunks_mut(STRIP).enumerate() {
            let range = k * STRIP..k * STRIP + o.len();
            o.fill(0.0);
            for &(a, x, y) in &parts {
                match y {
                    None => o.iter_mut().zip(&x[range.clone()]).for_each(|(o, x)| *o += a * x),
                    Some(y) => o
                        .iter_mut()
                        .zip(&x[range.clone()])
                        .zip(&y[range.clone()])
                        .for_each(|((o, x), y)| *o += a * (x - y)),
                }
            }
        }
    }

    /// The displacement a term's `prev` reads. A term of the accepted level u alone (HHT's
    /// `α·contact(u)`, an explicit `contact(u)`, the initial problem's) is that level's law,
    /// which reads the level before it: u at the start of the previous step (u⁰ at the first
    /// and in the initial problem). Any other term is a new level's (u', um, (u + u')/2), which
    /// reads the level the stage starts from: u for the first stage, the previous stage's
    /// displacement (TR-BDF2's um) for a later one.
    pub(super) fn previous_level<'s>(&'s self, term: &TermDesc, levels: &Levels<'s>) -> &'s [f64] {
        let Levels { states, quantities, .. } = *levels;
        let accepted = |c: &Combination| {
            c.unknown.is_none() && matches!(&*c.known, [(Level::State(0), k)] if self.coefs[*k] == 1.0)
        };
        if term.args.iter().all(accepted) {
            return self.previous.as_deref().unwrap_or(&states[0]);
        }
        let Some(last) = quantities.len().checked_sub(1) else { return &states[0] };
        match self.displacement(&self.desc.stages[last]) {
            Some(q) => &quantities[last][q],
            None => &states[0],
        }
    }
}
