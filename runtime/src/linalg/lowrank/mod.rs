//! Solves with a matrix that differs from a factored reference on a few dofs, without
//! refactoring (the Woodbury identity). With J = J₀ + U E Uᵀ, U the identity's columns at the
//! dofs D where J − J₀ has entries and E = (J − J₀)[D, D] dense (k×k, symmetric or not):
//!
//! * Cholesky reference in node blocks, J₀ = Pᵀ L Lᵀ P: J = Pᵀ L (I + W E Wᵀ) Lᵀ P with
//!   W = L⁻¹ P U, so with G = Wᵀ W and M = I + G E,
//!
//!   z = L⁻¹ P b,  z ← z − W E M⁻¹ Wᵀ z,  x = Pᵀ L⁻ᵀ z.
//!
//!   A column of W is L⁻¹ times a unit vector: nonzero only on the ancestors of its dof in the
//!   elimination tree (7 % of the unknowns for the disc's contact dofs at 12 490 unknowns), and
//!   computed by visiting those columns of L only. The correction costs 2·nnz(W) per solve,
//!   between the two triangular passes.
//! * Any other factorization: with Z = J₀⁻¹ U (dense columns, one solve each) and G = Uᵀ Z,
//!
//!   x₀ = J₀⁻¹ b,  (I + G E) y = x₀[D],  x = x₀ − Z E y.
//!
//! * Cholesky reference whose change is given as rank-one terms (`element_matrices`): with E = X S Xᵀ,
//!   X k×r (each column on one element's dofs) and S = diag(λ), the same correction with
//!   Ŵ = W X in place of W, S in place of E and the r×r matrix I + XᵀGX S in place of M; r is
//!   the number of switched quadrature points, about k/2.7 on the disc.
//!
//! A contact tangent changes only on the cells of facets whose active set changed, so D stays
//! small while the reference is the operator at an active set near the current one. Columns
//! (and, for W, their Gram matrix) are kept per dof, and the terms' columns Ŵ per term, until
//! the reference changes: a dof that switches again costs nothing.

use faer::Mat;
use faer::linalg::solvers::{PartialPivLu, Solve};

use crate::linalg::block_factor::SparseColumn;
use crate::linalg::element_matrices::{CHANGE_ROUNDOFF, ChangeSplitter, ElementMatrices, RankOneTerms, changed};
use crate::linalg::factorization::Factorization;
use crate::linalg::matrix::{LinalgError, Matrix};
use crate::linalg::pattern::Entries;

mod columns;
use columns::{DenseColumns, correct_sparse, gather, scatter, unscatter};

/// The correction of a factored reference J₀ towards the current matrix.
pub struct LowRank {
    /// J₀'s entries.
    reference: Vec<f64>,
    columns: Columns,
    /// The current correction: D, E (row-major), and the LU factors of I + G E.
    dofs: Vec<usize>,
    e: Vec<f64>,
    lu: Option<PartialPivLu<f64>>,
    /// Stored values of the current correction's columns (the extra reads of a solve).
    column_entries: usize,
    /// The current correction's columns of W, dense over the union of their nodes, when that
    /// is not much larger than their sparse entries; or, for a correction by rank-one terms,
    /// W times their vectors.
    dense: Option<DenseColumns>,
    /// ‖E‖∞ of the current correction.
    change_norm: f64,
    /// Columns of the current correction: the changed dofs, or the rank-one terms.
    terms: usize,
    /// The varying part of J₀ as element matrices, if the problem gives them.
    elements: Option<ChangeSplitter>,
    /// Columns W v of the rank-one terms seen so far, by term id.
    term_columns: TermColumns,
    /// The current correction's rank-one terms' vectors X, `term_size` (position in D, value)
    /// pairs per term (empty for a correction by E).
    term_vectors: Vec<(usize, f64)>,
    term_size: usize,
    /// An update's work vectors, kept between updates in their resting state (`Scratch`).
    scratch: Scratch,
}

/// Work vectors of an update, kept at rest between updates: `work` zero (d·n), `position`
/// usize::MAX (n), `seen` false (nodes), `entries` zero (J's entries). An update that ends in
/// an error leaves them reset whole.
#[derive(Default)]
struct Scratch {
    work: Vec<f64>,
    position: Vec<usize>,
    seen: Vec<bool>,
    entries: Vec<f64>,
}

/// Columns kept per rank-one term until the reference changes: a term that persists from one
/// update to the next (an element that stays switched) is not combined again.
#[derive(Default)]
struct TermColumns {
    of_id: std::collections::HashMap<u32, u32>,
    columns: Vec<SparseColumn>,
}

/// The columns computed so far, per dof.
enum Columns {
    /// Not decided until the first update sees the factorization.
    Unknown,
    /// W's columns (factor in node blocks) and their Gram matrix over the cached dofs
    /// (`gram[x][y]` for y ≤ x, NaN until columns x and y are in one correction).
    Sparse { of_dof: Vec<Option<u32>>, columns: Vec<SparseColumn>, gram: Vec<Vec<f64>>, d: usize },
    /// Z's columns (J₀⁻¹ e_d).
    Dense(Vec<Option<Box<[f64]>>>),
}

impl LowRank {
    /// A correction of nothing, for the factored `reference`.
    pub fn new(reference: &Matrix) -> LowRank {
        LowRank {
            reference: reference.values.clone(),
            columns: Columns::Unknown,
            dofs: Vec::new(),
            e: Vec::new(),
            lu: None,
            column_entries: 0,
            dense: None,
            change_norm: 0.0,
            terms: 0,
            elements: None,
            term_columns: TermColumns::default(),
            term_vectors: Vec::new(),
            term_size: 0,
            scratch: Scratch::default(),
        }
    }

    /// Columns computed so far.
    pub fn cached(&self) -> usize {
        match &self.columns {
            Columns::Unknown => 0,
            Columns::Sparse { columns, .. } => columns.len() + self.term_columns.columns.len(),
            Columns::Dense(c) => c.iter().filter(|c| c.is_some()).count(),
        }
    }

    /// How many of `dofs` have no column yet.
    pub fn missing(&self, dofs: &[usize]) -> usize {
        match &self.columns {
            Columns::Unknown => dofs.len(),
            Columns::Sparse { of_dof, .. } => dofs.iter().filter(|&&d| of_dof[d].is_none()).count(),
            Columns::Dense(c) => dofs.iter().filter(|&&d| c[d].is_none()).count(),
        }
    }

    /// Dofs of the current correction.
    pub fn rank(&self) -> usize {
        self.dofs.len()
    }

    /// Columns of the current correction: its rank-one terms if it is made of them, else its
    /// dofs.
    pub fn terms(&self) -> usize {
        self.terms
    }

    /// ‖E‖∞ of the current correction: ‖J‖∞ ≤ ‖J₀‖∞ + ‖E‖∞.
    pub fn change_norm(&self) -> f64 {
        self.change_norm
    }

    /// Gives the varying part of J₀ as element matrices: later updates given the current ones
    /// correct by the rank-one terms of the elements' changes.
    pub fn set_elements(&mut self, elements: Option<ElementMatrices>) {
        self.elements = elements.map(ChangeSplitter::new);
    }

    /// Whether J₀'s element matrices are known.
    pub fn has_elements(&self) -> bool {
        self.elements.is_some()
    }

    /// Values a solve reads beyond the factor's: the current correction's columns.
    pub fn entries(&self) -> usize {
        self.column_entries
    }

    /// The dofs on which `j` differs from the reference by more than round-off (rows and
    /// columns), sorted; only `entries` are compared if given (the only ones that can differ).
    /// The correction leaves J₀'s values where they differ by round-off.
    pub fn changed_dofs(&self, j: &Matrix, entries: Option<&Entries>) -> Vec<usize> {
        let p = &j.pattern;
        let mut differs = vec![false; j.size()];
        let mut compare = |k: usize, col: usize| {
            if changed(self.reference[k], j.values[k]) {
                differs[col] = true;
                differs[p.row_idx[k]] = true;
            }
        };
        match entries {
            Some(e) => e.indices.iter().zip(&e.columns).for_each(|(&k, &col)| compare(k, col as usize)),
            None => (0..j.size()).for_each(|col| (p.col_ptr[col]..p.col_ptr[col + 1]).for_each(|k| compare(k, col))),
        }
        (0..j.size()).filter(|&i| differs[i]).collect()
    }

    /// Makes the correction the one from the reference to `j`, whose differing dofs are `dofs`
    /// (from [`LowRank::changed_dofs`]); `reference` is J₀'s factorization. Given `elements`,
    /// the varying part of `j` as element matrices (see [`LowRank::set_elements`]), a Cholesky
    /// reference is corrected by the rank-one terms of their change, if those make up J − J₀.
    /// Returns false, making no correction, if its small system would have more than
    /// `max_system` rows (k for a correction by E, the terms' count r for one by terms): that
    /// system's factorization, and its Gram matrix's products, would cost more than J's. After
    /// a refusal or an error, the correction is updated again before it is solved with.
    pub fn update(
        &mut self,
        j: &Matrix,
        dofs: Vec<usize>,
        reference: &mut Factorization,
        elements: Option<&ElementMatrices>,
        max_system: usize,
    ) -> Result<bool, LinalgError> {
        let n = j.size();
        let mut scratch = std::mem::take(&mut self.scratch);
        let d = reference.block().map_or(1, |b| b.dim());
        if scratch.position.len() != n || scratch.work.len() < d * n || scratch.seen.len() < n / d {
            scratch = Scratch {
                work: vec![0.0; d * n],
                position: vec![usize::MAX; n],
                seen: vec![false; n / d],
                entries: Vec::new(),
            };
        }
        let result = self.update_with(j, dofs, reference, elements, max_system, &mut scratch);
        match result {
            Ok(true) => self.dofs.iter().for_each(|&i| scratch.position[i] = usize::MAX),
            Ok(false) | Err(_) => {
                scratch.work.fill(0.0);
                scratch.position.fill(usize::MAX);
                scratch.seen.fill(false);
                scratch.entries.fill(0.0);
            }
        }
        self.scratch = scratch;
        result
    }

    fn update_with(
        &mut self,
        j: &Matrix,
        dofs: Vec<usize>,
        reference: &mut Factorization,
        elements: Option<&ElementMatrices>,
        max_system: usize,
        scratch: &mut Scratch,
    ) -> Result<bool, LinalgError> {
        let n = j.size();
        if matches!(self.columns, Columns::Unknown) {
            self.columns = match reference.block() {
                Some(b) => Columns::Sparse { of_dof: vec![None; n], columns: Vec::new(), gram: Vec::new(), d: b.dim() },
                None => Columns::Dense(vec![None; n]),
            };
        }
        let k = dofs.len();
        let by_terms = elements.is_some() && self.elements.is_some() && matches!(self.columns, Columns::Sparse { .. });
        if k > max_system && !by_terms {
            return Ok(false);
        }
        // The previous correction's dense columns' memory, reused for the new ones.
        let mut spare = self.dense.take().map(|d| d.values).unwrap_or_default();
        // E's nonzero entries (row and column in D, value), from J's pattern among D: a
        // correction by rank-one terms needs no k×k matrix.
        let mut e_entries: Vec<EEntry> = Vec::new();
        let position = &mut scratch.position;
        dofs.iter().enumerate().for_each(|(a, &d)| position[d] = a);
        let p = &j.pattern;
        for (b, &col) in dofs.iter().enumerate() {
            for idx in p.col_ptr[col]..p.col_ptr[col + 1] {
                let a = position[p.row_idx[idx]];
                let change = j.values[idx] - self.reference[idx];
                if a != usize::MAX && change != 0.0 {
                    e_entries.push(EEntry { row: a, column: b, value: change, index: idx });
                }
            }
        }
        // W's or Z's columns for the dofs that have none yet.
        match &mut self.columns {
            Columns::Unknown => unreachable!("decided above"),
            Columns::Sparse { of_dof, columns, gram, d } => {
                let block = reference.block().ok_or(LinalgError::NotFactored)?;
                // A node's new dofs together: their columns share the node's ancestors.
                let work = &mut scratch.work;
                let new_dofs: Vec<usize> = dofs.iter().copied().filter(|&dof| of_dof[dof].is_none()).collect();
                for group in new_dofs.chunk_by(|&a, &b| block.position(a) / *d == block.position(b) / *d) {
                    let positions: Vec<usize> = group.iter().map(|&dof| block.position(dof)).collect();
                    for (&dof, w) in group.iter().zip(block.forward_units(&positions, work)) {
                        of_dof[dof] = Some(columns.len() as u32);
                        columns.push(w);
                        gram.push(vec![f64::NAN; columns.len()]);
                    }
                }
                // The products among this correction's columns not computed yet (NaN): a
                // column's products with columns of other corrections wait until they meet.
                let mut slots: Vec<usize> =
                    dofs.iter().map(|&dof| of_dof[dof].expect("computed above") as usize).collect();
                slots.sort_unstable();
                let mut missing = Vec::new();
                for (i, &x) in slots.iter().enumerate() {
                    missing.clear();
                    missing.extend(slots[..=i].iter().copied().filter(|&y| gram[x][y].is_nan()));
                    if missing.is_empty() {
                        continue;
                    }
                    scatter(&columns[x], *d, work);
                    for &y in &missing {
                        gram[x][y] = gather(&columns[y], *d, work);
                    }
                    unscatter(&columns[x], *d, work);
                }
            }
            Columns::Dense(columns) => {
                let missing: Vec<usize> = dofs.iter().copied().filter(|&d| columns[d].is_none()).collect();
                if !missing.is_empty() {
                    let mut block = vec![0.0; n * missing.len()];
                    for (c, &d) in missing.iter().enumerate() {
                        block[c * n + d] = 1.0;
                    }
                    reference.solve_many_in_place(&mut block, missing.len())?;
                    for (c, &d) in missing.iter().enumerate() {
                        columns[d] = Some(block[c * n..(c + 1) * n].into());
                    }
                }
            }
        }
        let mut row_sums = vec![0.0; k];
        e_entries.iter().for_each(|x| row_sums[x.row] += x.value.abs());
        self.change_norm = row_sums.iter().copied().fold(0.0, f64::max);
        let terms = match (elements, &mut self.elements) {
            (Some(now), Some(splitter)) if k > 0 => splitter.split(now),
            _ => None,
        };
        if let Some(terms) = terms.filter(|t| t.len() <= max_system)
            && let Some(factored) = self.factored(j, &dofs, scratch, &e_entries, &terms, &mut spare)
        {
            self.column_entries = factored.dense.values.len();
            (self.dense, self.e, self.lu) = (Some(factored.dense), factored.s, Some(factored.lu));
            (self.term_vectors, self.term_size) = (factored.x, terms.size);
            self.terms = terms.len();
            self.dofs = dofs;
            return Ok(true);
        }
        if k > max_system {
            return Ok(false);
        }
        let mut e = Mat::<f64>::zeros(k, k);
        e_entries.iter().for_each(|x| e[(x.row, x.column)] = x.value);
        // G, k×k: Wᵀ W or Uᵀ Z.
        let g = match &self.columns {
            Columns::Unknown => unreachable!("decided above"),
            Columns::Sparse { of_dof, gram, .. } => {
                let slots: Vec<usize> = dofs.iter().map(|&dof| of_dof[dof].expect("computed above") as usize).collect();
                Mat::from_fn(k, k, |a, c| gram_entry(gram, slots[a], slots[c]))
            }
            Columns::Dense(columns) => {
                Mat::from_fn(k, k, |a, c| columns[dofs[c]].as_ref().expect("computed above")[dofs[a]])
            }
        };
        let m = Mat::<f64>::identity(k, k) + &g * &e;
        let lu = m.partial_piv_lu();
        let u = lu.U();
        let scale = (0..k).map(|i| u[(i, i)].abs()).fold(0.0f64, f64::max);
        // A vanishing or NaN pivot.
        if (0..k).any(|i| u[(i, i)].abs().partial_cmp(&(1e-14 * scale)) != Some(std::cmp::Ordering::Greater)) {
            return Err(LinalgError::Singular { index: None });
        }
        self.column_entries = match &self.columns {
            Columns::Sparse { of_dof, columns, .. } => {
                dofs.iter().map(|&d| columns[of_dof[d].expect("computed") as usize].values.len()).sum()
            }
            _ => k * n,
        };
        self.dense = match &self.columns {
            Columns::Sparse { of_dof, columns, d, .. } if k > 0 => {
                let cols: Vec<&SparseColumn> =
                    dofs.iter().map(|&dof| &columns[of_dof[dof].expect("computed") as usize]).collect();
                DenseColumns::new(&cols, *d, n / *d, self.column_entries, &mut spare)
            }
            _ => None,
        };
        self.lu = (k > 0).then_some(lu);
        self.e = (0..k * k).map(|i| e[(i / k, i % k)]).collect();
        (self.term_vectors, self.term_size) = (Vec::new(), 0);
        self.terms = k;
        self.dofs = dofs;
        Ok(true)
    }

    /// The correction by rank-one terms λ v vᵀ that make up E on `dofs` (with G = Wᵀ W there):
    /// with X the terms' vectors (k×r, a few dofs each) and S = diag(λ), J = Pᵀ L (I + Ŵ S Ŵᵀ)
    /// Lᵀ P for Ŵ = W X, and the solve's correction is Ŵ S M̃⁻¹ Ŵᵀ with M̃ = I + Xᵀ G X S,
    /// r×r. Returns Ŵ (dense), S and M̃'s factors; None if the terms do not make up
    /// E to round-off, or Ŵ would be too large (the correction by E is used then).
    /// `scratch.position[dof]` is the dof's index in `dofs` (usize::MAX if it is not one of
    /// them), for each of the n dofs; `spare` is memory for Ŵ.
    fn factored(
        &mut self,
        j: &Matrix,
        dofs: &[usize],
        scratch: &mut Scratch,
        e: &[EEntry],
        terms: &RankOneTerms,
        spare: &mut Vec<f64>,
    ) -> Option<Factored> {
        let Scratch { work, position, seen, entries } = scratch;
        let n = position.len();
        let Columns::Sparse { of_dof, columns, gram, d } = &self.columns else { return None };
        let d = *d;
        let (r, s) = (terms.len(), terms.size);
        // X as (position in D, value) per term; a term reaching outside D does not make up E,
        // unless only by round-off (D leaves out dofs whose entries changed by no more: the
        // unit vector's component is then of that order, and the sum is checked below).
        let mut x: Vec<(usize, f64)> = Vec::with_capacity(r * s);
        for (&dof, &v) in terms.dofs.iter().zip(&terms.vectors) {
            match position[dof] {
                usize::MAX if v.abs() > CHANGE_ROUNDOFF => return None,
                usize::MAX => x.push((0, 0.0)),
                a => x.push((a, v)),
            }
        }
        let term = |t: usize| &x[t * s..(t + 1) * s];
        // Σ λ v vᵀ − E, summed in J's entries (`entries`, zero at rest).
        if entries.len() != j.values.len() {
            *entries = vec![0.0; j.values.len()];
        }
        let p = &j.pattern;
        let mut touched: Vec<usize> = e.iter().map(|x| x.index).collect();
        e.iter().for_each(|x| entries[x.index] -= x.value);
        let mut outside = false;
        for t in 0..r {
            for &(b, vb) in term(t).iter().filter(|(_, v)| *v != 0.0) {
                let col = dofs[b];
                let rows = &p.row_idx[p.col_ptr[col]..p.col_ptr[col + 1]];
                for &(a, va) in term(t).iter().filter(|(_, v)| *v != 0.0) {
                    match rows.binary_search(&dofs[a]) {
                        Ok(at) => {
                            let idx = p.col_ptr[col] + at;
                            entries[idx] += terms.lambdas[t] * va * vb;
                            touched.push(idx);
                        }
                        Err(_) => outside = true,
                    }
                }
            }
        }
        let scale = e.iter().fold(0.0f64, |m, x| m.max(x.value.abs()));
        let (mut error, mut nan) = (0.0f64, false);
        for &idx in &touched {
            error = error.max(entries[idx].abs());
            nan |= entries[idx].is_nan();
            entries[idx] = 0.0;
        }
        if outside || nan || error > TERMS_ACCURACY * scale {
            return None;
        }
        // M̃ = I + Xᵀ G X S, through H = G X on the terms' support (rows) only, r columns;
        // G's entries Wᵀ W from the Gram matrix, by the support's and the terms' column slots.
        let slot = |a: usize| of_dof[dofs[a]].expect("computed") as usize;
        let mut row_of = vec![usize::MAX; dofs.len()];
        let mut support = Vec::new();
        for &(a, v) in &x {
            if v != 0.0 && row_of[a] == usize::MAX {
                row_of[a] = support.len();
                support.push(slot(a));
            }
        }
        let u = support.len();
        let mut h = vec![0.0; u * r];
        for (t, ht) in h.chunks_exact_mut(u).enumerate() {
            for &(b, v) in term(t).iter().filter(|(_, v)| *v != 0.0) {
                let q = slot(b);
                for (hi, &p) in ht.iter_mut().zip(&support) {
                    *hi += v * gram_entry(gram, p, q);
                }
            }
        }
        let m = Mat::from_fn(r, r, |p, q| {
            let gpq: f64 = term(p).iter().filter(|(_, v)| *v != 0.0).map(|&(a, v)| v * h[q * u + row_of[a]]).sum();
            f64::from(u8::from(p == q)) + gpq * terms.lambdas[q]
        });
        // Each new term's column W v = Σ v_i W e_i, over the union of its dofs' columns' nodes.
        let cache = &mut self.term_columns;
        for (t, &id) in terms.ids.iter().enumerate() {
            if cache.of_id.contains_key(&id) {
                continue;
            }
            let mut nodes: Vec<u32> = Vec::new();
            for &(a, v) in term(t).iter().filter(|(_, v)| *v != 0.0) {
                let col = &columns[of_dof[dofs[a]].expect("computed") as usize];
                for (&node, w) in col.nodes.iter().zip(col.values.chunks_exact(d)) {
                    if !seen[node as usize] {
                        seen[node as usize] = true;
                        nodes.push(node);
                    }
                    work[node as usize * d..][..d].iter_mut().zip(w).for_each(|(x, wi)| *x += v * wi);
                }
            }
            nodes.sort_unstable();
            let mut values = Vec::with_capacity(nodes.len() * d);
            for &node in &nodes {
                seen[node as usize] = false;
                let at = &mut work[node as usize * d..][..d];
                values.extend_from_slice(at);
                at.iter_mut().for_each(|x| *x = 0.0);
            }
            cache.of_id.insert(id, cache.columns.len() as u32);
            cache.columns.push(SparseColumn { nodes, values });
        }
        let lu = m.partial_piv_lu();
        let u = lu.U();
        let largest = (0..r).map(|i| u[(i, i)].abs()).fold(0.0f64, f64::max);
        if (0..r).any(|i| u[(i, i)].abs().partial_cmp(&(1e-14 * largest)) != Some(std::cmp::Ordering::Greater)) {
            return None;
        }
        let cols: Vec<&SparseColumn> = terms.ids.iter().map(|id| &cache.columns[cache.of_id[id] as usize]).collect();
        let dense = DenseColumns::new(&cols, d, n / d, usize::MAX, spare)?;
        let sd = (0..r * r).map(|i| if i / r == i % r { terms.lambdas[i / r] } else { 0.0 }).collect();
        Some(Factored { dense, s: sd, lu, x })
    }

    /// Solves J x = b in place (b on entry) with the reference factorization `f` and this
    /// correction. With `defect`, also returns ‖J x − b‖∞ as the correction leaves it (the
    /// residual were the triangular passes exact): with the correction's small system solved
    /// to y, ρ = Wᵀz' − y for the corrected z' = L⁻¹Pb − W E y, and J x − b = U E ρ (U X S ρ
    /// for rank-one terms), on the dofs D only. None if not asked or not known (columns of
    /// J₀⁻¹, for a reference other than a Cholesky factor in node blocks).
    pub fn solve(&self, f: &mut Factorization, b: &mut [f64], defect: bool) -> Result<Option<f64>, LinalgError> {
        let Some(lu) = self.lu.as_ref() else {
            f.solve_in_place(b)?;
            return Ok(defect.then_some(0.0));
        };
        let k = self.dofs.len();
        let mut rho = defect.then(Vec::new);
        match &self.columns {
            Columns::Sparse { of_dof, columns, d, .. } => {
                if let Some(dense) = &self.dense {
                    f.solve_split_in_place(b, |z| dense.correct(z, *d, lu, &self.e, rho.as_mut()))?;
                } else {
                    let cols: Vec<&SparseColumn> =
                        self.dofs.iter().map(|&dof| &columns[of_dof[dof].expect("computed") as usize]).collect();
                    f.solve_split_in_place(b, |z| correct_sparse(&cols, *d, lu, &self.e, z, rho.as_mut()))?;
                }
                Ok(rho.map(|rho| self.defect(&rho)))
            }
            Columns::Dense(columns) => {
                f.solve_in_place(b)?;
                let mut y = Mat::from_fn(k, 1, |a, _| b[self.dofs[a]]);
                lu.solve_in_place(y.as_mut());
                // x −= Z (E y).
                for (c, &dof) in self.dofs.iter().enumerate() {
                    let ey: f64 = (0..k).map(|x| self.e[c * k + x] * y[(x, 0)]).sum();
                    if ey != 0.0 {
                        let z = columns[dof].as_ref().expect("computed in update");
                        b.iter_mut().zip(z.iter()).for_each(|(xi, zi)| *xi -= ey * zi);
                    }
                }
                Ok(None)
            }
            Columns::Unknown => {
                f.solve_in_place(b)?;
                Ok(defect.then_some(0.0))
            }
        }
    }

    /// ‖U E ρ‖∞, or ‖U X S ρ‖∞ for a correction by rank-one terms (see [`LowRank::solve`]);
    /// NaN if any entry is.
    fn defect(&self, rho: &[f64]) -> f64 {
        let k = self.dofs.len();
        let mut v = vec![0.0; k];
        if self.term_size > 0 {
            let (r, s) = (rho.len(), self.term_size);
            for (t, x) in self.term_vectors.chunks_exact(s).enumerate() {
                let c = self.e[t * r + t] * rho[t];
                x.iter().for_each(|&(a, xa)| v[a] += xa * c);
            }
        } else {
            for (c, vc) in v.iter_mut().enumerate() {
                *vc = (0..k).map(|x| self.e[c * k + x] * rho[x]).sum();
            }
        }
        crate::linalg::norms::norm_inf(&v)
    }
}

/// A correction by rank-one terms: Ŵ (dense), S (r×r, row-major) and M̃'s factors.
struct Factored {
    dense: DenseColumns,
    s: Vec<f64>,
    lu: PartialPivLu<f64>,
    x: Vec<(usize, f64)>,
}

/// Rank-one terms must make up the change of J to this fraction of its largest entry.
const TERMS_ACCURACY: f64 = 1e-12;

/// A nonzero entry of E = J − J₀ among the correction's dofs D: its row and column in D, its
/// value, and its index among J's values.
#[derive(Clone, Copy, Debug)]
struct EEntry {
    row: usize,
    column: usize,
    value: f64,
    index: usize,
}

/// Entry (x, y) of the symmetric Gram matrix of the columns, stored as its lower triangle.
fn gram_entry(gram: &[Vec<f64>], x: usize, y: usize) -> f64 {
    gram[x.max(y)][x.min(y)]
}

#[cfg(test)]
mod tests;
