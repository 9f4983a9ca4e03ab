//! A slot that several files provide: the sum of their forms (a material's body load and a
//! problem's boundary tractions both add to `load`). Residuals and tangents add into the same
//! vector and matrix, so the sum is each form's contribution in the files' order.

use super::assembly::Assembler;
use super::bound::{BoundForm, with_previous};
use crate::linalg::Matrix;

/// The forms of one slot, summed; they take the same number of time levels.
pub struct Summed<'m> {
    name: String,
    parts: Vec<Box<dyn BoundForm + 'm>>,
}

impl<'m> Summed<'m> {
    /// `parts` take the same number of time levels (the caller checks it).
    pub fn new(parts: Vec<Box<dyn BoundForm + 'm>>) -> Summed<'m> {
        let names: Vec<&str> = parts.iter().map(|p| p.name()).collect();
        Summed { name: names.join(" + "), parts }
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

// `tangent_elements` keeps the trait's default (none): a sum's Jacobian is assembled whole; the
// summed slots are loads and other linear terms, whose matrices are constant.
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
    fn time_dependent(&self) -> bool {
        self.parts.iter().any(|p| p.time_dependent())
    }
}
