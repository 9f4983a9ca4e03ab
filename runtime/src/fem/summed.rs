//! A slot that several files provide: the sum of their forms (a material's body load and a
//! problem's boundary tractions both add to `load`). Residuals and tangents add into the same
//! vector and matrix, so the sum is each form's contribution in the files' order. A problem of
//! several bodies binds each file's forms and functionals to each body: a slot is then the sum
//! over the bodies of one form (or functional), each on its own cells.

use super::assembly::{Assembler, PointValue};
use super::bound::{BoundForm, BoundFunctional, with_previous};
use super::quadrature::Rule;
use crate::linalg::Matrix;
use crate::linalg::element_matrices::ElementMatrices;

/// The forms of one slot, summed; they take the same number of time levels.
pub struct Summed<'m> {
    name: String,
    parts: Vec<Box<dyn BoundForm + 'm>>,
    /// The parts are one form bound to several bodies: each gives its element matrices if the
    /// first does.
    bodies: bool,
}

impl<'m> Summed<'m> {
    /// `parts` take the same number of time levels (the caller checks it).
    pub fn new(parts: Vec<Box<dyn BoundForm + 'm>>) -> Summed<'m> {
        let names: Vec<&str> = parts.iter().map(|p| p.name()).collect();
        Summed { name: names.join(" + "), parts, bodies: false }
    }

    /// One form bound to each of several bodies (their cells disjoint).
    pub fn over_bodies(parts: Vec<Box<dyn BoundForm + 'm>>) -> Summed<'m> {
        Summed { name: parts[0].name().to_string(), parts, bodies: true }
    }

    /// The arguments of part `p`: the levels, and the previous one where it reads it.
    fn args<'a>(&self, p: &dyn BoundForm, fields: &[&'a [f64]]) -> Vec<&'a [f64]> {
        let levels = &fields[..p.fields().min(fields.len())];
        match (self.previous(), fields.get(p.fields())) {
            (true, Some(previous)) => with_previous(p.previous(), levels, previous),
            _ => levels.to_vec(),
        }
    }
}

// `tangent_elements` of files' sums keeps the trait's default (none): such a Jacobian is
// assembled whole; those slots are loads and other linear terms, whose matrices are constant.
// One form over bodies gives its parts' element matrices.
impl BoundForm for Summed<'_> {
    fn name(&self) -> &str {
        &self.name
    }
    fn fields(&self) -> usize {
        self.parts[0].fields()
    }
    fn previous(&self) -> bool {
        self.parts.iter().any(|p| p.previous())
    }
    fn linear(&self) -> bool {
        self.parts.iter().all(|p| p.linear())
    }
    fn piecewise(&self) -> bool {
        self.parts.iter().all(|p| p.piecewise())
    }
    fn may_be_symmetric(&self) -> bool {
        self.parts.iter().all(|p| p.may_be_symmetric())
    }
    fn search_cost(&self) -> crate::fem::search_cost::SearchCost {
        self.parts.iter().map(|p| p.search_cost()).fold(Default::default(), |a, c| a + c)
    }
    fn residual(&self, asm: &Assembler, fields: &[&[f64]], t: f64, out: &mut [f64]) {
        for p in &self.parts {
            p.residual(asm, &self.args(p.as_ref(), fields), t, out);
        }
    }
    fn tangent(&self, asm: &Assembler, fields: &[&[f64]], wrt: usize, t: f64, m: &mut Matrix) {
        for p in &self.parts {
            p.tangent(asm, &self.args(p.as_ref(), fields), wrt, t, m);
        }
    }
    fn switches(&self, asm: &Assembler, fields: &[&[f64]], wrt: usize, t: f64, out: &mut Vec<bool>) -> bool {
        let mut decided = true;
        for p in &self.parts {
            decided &= p.switches(asm, &self.args(p.as_ref(), fields), wrt, t, out);
        }
        decided
    }
    fn support(&self) -> Option<Vec<u32>> {
        let mut cells = Vec::new();
        for p in &self.parts {
            cells.extend(p.support()?);
        }
        Some(cells)
    }
    fn tangent_elements(
        &self,
        asm: &Assembler,
        fields: &[&[f64]],
        wrt: usize,
        t: f64,
        mut m: Option<&mut Matrix>,
        out: &mut ElementMatrices,
    ) -> bool {
        // One form's parts all give them or none does (nothing done): asking the first decides.
        if !self.bodies {
            return false;
        }
        for p in &self.parts {
            if !p.tangent_elements(asm, &self.args(p.as_ref(), fields), wrt, t, m.as_deref_mut(), out) {
                return false;
            }
        }
        true
    }
    fn time_dependent(&self) -> bool {
        self.parts.iter().any(|p| p.time_dependent())
    }
}

/// One functional bound to each of several bodies, or the functionals of one name of several
/// contact laws (an obstacle's and a pair's `contact_energy`): its value is the sum of theirs.
pub struct SummedFunctional<'m> {
    parts: Vec<Box<dyn BoundFunctional + 'm>>,
}

impl<'m> SummedFunctional<'m> {
    /// `parts` take the same number of time levels (the caller checks it).
    pub fn new(parts: Vec<Box<dyn BoundFunctional + 'm>>) -> SummedFunctional<'m> {
        SummedFunctional { parts }
    }

    pub fn over_bodies(parts: Vec<Box<dyn BoundFunctional + 'm>>) -> SummedFunctional<'m> {
        SummedFunctional { parts }
    }
}

impl BoundFunctional for SummedFunctional<'_> {
    fn name(&self) -> &str {
        self.parts[0].name()
    }
    fn fields(&self) -> usize {
        self.parts[0].fields()
    }
    fn value(&self, asm: &Assembler, fields: &[&[f64]], t: f64) -> f64 {
        self.parts.iter().map(|p| p.value(asm, fields, t)).sum()
    }
    fn cell_values(&self, asm: &Assembler, fields: &[&[f64]], t: f64) -> Vec<f64> {
        // Each part is zero off its body's cells.
        let mut sum = self.parts[0].cell_values(asm, fields, t);
        for p in &self.parts[1..] {
            sum.iter_mut().zip(p.cell_values(asm, fields, t)).for_each(|(s, v)| *s += v);
        }
        sum
    }
    fn facet_point_values(&self, asm: &Assembler, rule: &Rule, fields: &[&[f64]], t: f64) -> Vec<PointValue> {
        self.parts.iter().flat_map(|p| p.facet_point_values(asm, rule, fields, t)).collect()
    }
}
