//! Element matrices kept apart rather than assembled: the varying part of a Jacobian (a
//! contact tangent) as a list of small matrices over their cells' dofs. A change of active set
//! switches quadrature points on some facets; the change of each such facet's matrix has the
//! rank of its switched points, where the assembled change has the rank of all the dofs it
//! touches (for the disc, up to 82 switched points against 222 dofs). `lowrank` corrects a
//! factorization by these rank-one terms.

use faer::{Mat, Side};

/// Element matrices of one size, each with its dofs: `dofs[e·size..]` and `values[e·size²..]`
/// (row-major).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ElementMatrices {
    pub size: usize,
    pub dofs: Vec<usize>,
    pub values: Vec<f64>,
}

/// Symmetric rank-one terms λ v vᵀ, each v over `size` dofs: `dofs[t·size..]`, `vectors[t·size..]`;
/// `ids` tell the same term (the same vector on the same dofs) at two updates.
#[derive(Clone, Debug, Default)]
pub struct RankOneTerms {
    pub size: usize,
    pub dofs: Vec<usize>,
    pub vectors: Vec<f64>,
    pub lambdas: Vec<f64>,
    pub ids: Vec<u32>,
}

impl ElementMatrices {
    pub fn len(&self) -> usize {
        self.dofs.len().checked_div(self.size).unwrap_or(0)
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Scales the elements from index `from` on.
    pub fn scale_from(&mut self, from: usize, c: f64) {
        let start = from * self.size * self.size;
        self.values[start..].iter_mut().for_each(|v| *v *= c);
    }

    /// Zeroes the rows and columns of the `fixed` dofs (where a constrained Jacobian is the
    /// identity, whatever the elements say).
    pub fn zero_fixed(&mut self, fixed: &[bool]) {
        let s = self.size;
        if s == 0 {
            return;
        }
        for (dofs, values) in self.dofs.chunks_exact(s).zip(self.values.chunks_exact_mut(s * s)) {
            for (a, &dof) in dofs.iter().enumerate() {
                if fixed[dof] {
                    (0..s).for_each(|b| {
                        values[a * s + b] = 0.0;
                        values[b * s + a] = 0.0;
                    });
                }
            }
        }
    }
}

/// Eigenvalues of an element's change below this fraction of its largest are round-off: the
/// two matrices sum the same quadrature points in the same order except those switched.
const ROUNDOFF: f64 = 1e-12;

/// A change of a tangent's entry (of J, or of an element matrix) below this fraction of the
/// entry's size is round-off, not a change: a law whose tangent is constant in exact arithmetic
/// while its arguments move changes by such amounts at every step (Tresca's while sliding in
/// 2D, (s/|x|)(I − x̂x̂ᵀ) applied to a tangential vector: 1e-16 to 1e-15 of the entry on the
/// disc, where the changes of a switched point are 1e-10 and more). Newton's tangent needs
/// nothing near this accuracy; a correction that counted them would cover all of a sliding Γ_C.
pub const CHANGE_ROUNDOFF: f64 = 1e-13;

/// Whether `after` differs from `before` by more than round-off ([`CHANGE_ROUNDOFF`]).
pub fn changed(before: f64, after: f64) -> bool {
    (after - before).abs() > CHANGE_ROUNDOFF * after.abs().max(before.abs())
}

/// Whether an element matrix changed by more than round-off, measured against its largest
/// entry (an entry of an element can be small by cancellation where J's is not).
fn changed_element(before: &[f64], after: &[f64]) -> bool {
    let size = before.iter().chain(after).fold(0.0f64, |m, v| m.max(v.abs()));
    before.iter().zip(after).any(|(b, a)| (a - b).abs() > CHANGE_ROUNDOFF * size)
}

/// Splits the changes of element matrices from a reference into rank-one terms, remembering
/// each element's split while its matrix stays the same (an element switched at one update
/// usually is at the next ones too: only newly switched ones are decomposed).
#[derive(Clone, Debug)]
pub struct ChangeSplitter {
    reference: ElementMatrices,
    /// Per element: the matrix last split and its terms (eigenvalues, eigenvectors).
    splits: Vec<Option<Split>>,
    /// The id of the next split's first term.
    next_id: u32,
}

#[derive(Clone, Debug)]
struct Split {
    matrix: Vec<f64>,
    lambdas: Vec<f64>,
    vectors: Vec<f64>,
    /// Its first term's id (the others follow).
    id: u32,
}

impl ChangeSplitter {
    pub fn new(reference: ElementMatrices) -> ChangeSplitter {
        let splits = vec![None; reference.len()];
        ChangeSplitter { reference, splits, next_id: 0 }
    }

    /// The change from the reference to `current` (the same elements, at other arguments) as
    /// rank-one terms: the eigenpairs of each differing element's change, those above
    /// round-off (an element whose entries differ by round-off only has none; one that differs
    /// so from its last split keeps that split's terms). None if the lists do not match or a
    /// change is not symmetric.
    pub fn split(&mut self, current: &ElementMatrices) -> Option<RankOneTerms> {
        let s = self.reference.size;
        if current.size != s || current.dofs != self.reference.dofs || s == 0 {
            return None;
        }
        let mut terms = RankOneTerms { size: s, ..Default::default() };
        let pairs = self.reference.values.chunks_exact(s * s).zip(current.values.chunks_exact(s * s));
        for (e, (before, after)) in pairs.enumerate() {
            if !changed_element(before, after) {
                continue;
            }
            if self.splits[e].as_ref().is_none_or(|split| changed_element(&split.matrix, after)) {
                let mut split = split_change(before, after, s)?;
                split.id = self.next_id;
                self.next_id += split.lambdas.len() as u32;
                self.splits[e] = Some(split);
            }
            let split = self.splits[e].as_ref().expect("split above");
            for (i, &lambda) in split.lambdas.iter().enumerate() {
                terms.dofs.extend_from_slice(&current.dofs[e * s..(e + 1) * s]);
                terms.vectors.extend_from_slice(&split.vectors[i * s..(i + 1) * s]);
                terms.lambdas.push(lambda);
                terms.ids.push(split.id + i as u32);
            }
        }
        Some(terms)
    }
}

/// The eigenpairs of `after − before` above round-off; None if it is not symmetric.
fn split_change(before: &[f64], after: &[f64], s: usize) -> Option<Split> {
    let change = Mat::from_fn(s, s, |a, b| after[a * s + b] - before[a * s + b]);
    let scale = (0..s * s).map(|i| change[(i / s, i % s)].abs()).fold(0.0f64, f64::max);
    if (0..s).any(|a| (0..a).any(|b| (change[(a, b)] - change[(b, a)]).abs() > 1e-14 * scale)) {
        return None;
    }
    let eigen = change.self_adjoint_eigen(Side::Lower).ok()?;
    let (values, vectors) = (eigen.S(), eigen.U());
    let largest = (0..s).map(|i| values[i].abs()).fold(0.0f64, f64::max);
    let kept: Vec<usize> = (0..s).filter(|&i| values[i].abs() > ROUNDOFF * largest).collect();
    Some(Split {
        matrix: after.to_vec(),
        lambdas: kept.iter().map(|&i| values[i]).collect(),
        id: 0,
        vectors: kept.iter().flat_map(|&i| (0..s).map(move |a| vectors[(a, i)])).collect(),
    })
}

impl RankOneTerms {
    pub fn len(&self) -> usize {
        self.lambdas.len()
    }

    pub fn is_empty(&self) -> bool {
        self.lambdas.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_change_splits_into_the_rank_one_terms_that_make_it() {
        // Two 3×3 elements; the second changes by 2 a aᵀ − 0.5 b bᵀ.
        let base = [4.0, 1.0, 0.5, 1.0, 3.0, 0.2, 0.5, 0.2, 2.0];
        let reference = ElementMatrices {
            size: 3,
            dofs: vec![0, 1, 2, 2, 3, 4],
            values: base.iter().chain(base.iter()).copied().collect(),
        };
        let (a, b) = ([1.0, -2.0, 0.5], [0.3, 0.1, 1.0]);
        let mut current = reference.clone();
        for i in 0..3 {
            for j in 0..3 {
                current.values[9 + i * 3 + j] += 2.0 * a[i] * a[j] - 0.5 * b[i] * b[j];
            }
        }
        let mut splitter = ChangeSplitter::new(reference.clone());
        let terms = splitter.split(&current).expect("symmetric");
        assert_eq!(terms.len(), 2, "rank two");
        assert!(terms.dofs.iter().all(|d| [2, 3, 4].contains(d)), "on the second element's dofs");
        for i in 0..3 {
            for j in 0..3 {
                let sum: f64 =
                    (0..2).map(|t| terms.lambdas[t] * terms.vectors[t * 3 + i] * terms.vectors[t * 3 + j]).sum();
                let change = current.values[9 + i * 3 + j] - reference.values[9 + i * 3 + j];
                assert!((sum - change).abs() < 1e-14, "({i}, {j}): {sum} against {change}");
            }
        }
        // The same change again: the remembered split, the same ids.
        let again = splitter.split(&current).expect("symmetric");
        assert_eq!((again.lambdas, again.ids), (terms.lambdas.clone(), terms.ids.clone()));
        // An element whose entries differ by round-off only, nonsymmetrically, adds no term.
        let mut noisy = current.clone();
        noisy.values[1] *= 1.0 + 2.0 * f64::EPSILON;
        noisy.values[5] *= 1.0 - 3.0 * f64::EPSILON;
        let split = splitter.split(&noisy).expect("round-off is no change");
        assert_eq!(split.ids, terms.ids, "the second element's terms only");
        // A nonsymmetric change is not split.
        current.values[9 + 1] += 1.0;
        assert!(splitter.split(&current).is_none());
    }
}
