//! The nonlinear problem of one stage: its terms' known parts, the constant operator of its
//! linear forms, and the residual and Jacobian Newton iterates on, with the active-set switches
//! that decide when a factorization can be reused.

use std::collections::HashMap;
use std::sync::Arc;

use crate::fem::assembly::Assembler;
use crate::fem::bound::BoundForm;
use crate::linalg::element_matrices::ElementMatrices;
use crate::linalg::lower_half::{HalfPattern, LowerHalf};
use crate::linalg::matrix::SYMMETRY_TOLERANCE;
use crate::linalg::pattern::Entries;
use crate::linalg::{Matrix, Structure};
use crate::nonlinear::problem::NonlinearProblem;
use crate::nonlinear::statics::Constraints;

/// The first element whose tangent entries of `form` are not finite: its nodes' positions
/// (none when the form cannot give its element matrices).
pub(super) fn locate_non_finite(
    asm: &Assembler,
    form: &dyn BoundForm,
    fields: &[&[f64]],
    wrt: usize,
    t: f64,
    name: &str,
) -> NonFiniteTangent {
    let mut elements = ElementMatrices::default();
    let mut nodes = Vec::new();
    if form.tangent_elements(asm, fields, wrt, t, None, &mut elements) && elements.size > 0 {
        let (size, per) = (elements.size, elements.size * elements.size);
        let d = asm.mesh().dim();
        if let Some(e) = elements.values.chunks(per).position(|m| m.iter().any(|v| !v.is_finite())) {
            let mut seen: Vec<usize> = elements.dofs[e * size..(e + 1) * size].iter().map(|dof| dof / d).collect();
            seen.dedup();
            nodes = seen.iter().map(|&node| asm.mesh().node(node).to_vec()).collect();
        }
    }
    NonFiniteTangent { form: name.to_string(), level: wrt, nodes }
}

/// The last active set a stage's terms gave, and what it is a function of: the terms' forms,
/// times (for forms that change with time) and arguments at the support's dofs. A stage whose
/// Newton starts where the last one ended (Newmark's u' = u + δ at δ = 0 is the last iterate,
/// bit for bit) finds its active set here instead of evaluating the contact facets again.
#[derive(Default)]
pub(super) struct SwitchMemo {
    /// The forms, then per term its time, the arguments it is differentiated by, and its
    /// arguments at the support's dofs, as bits.
    pub(super) forms: Vec<String>,
    pub(super) key: Vec<u64>,
    pub(super) set: Vec<bool>,
    /// Whether the tangent depended on the fields only through `set` there.
    pub(super) piecewise: bool,
    /// Scratch for the key being compared.
    pub(super) next: Vec<u64>,
}

/// Largest |Σ c| / Σ |c| of a group of coefficients treated as summing to zero: a few roundings
/// of each coefficient. A sum that is zero in exact arithmetic evaluates to ~1e-16 of Σ |c|;
/// dropping a sum this small that is not exactly zero perturbs the combination by no more than
/// rounding its terms does.
pub(super) const ZERO_SUM: f64 = 64.0 * f64::EPSILON;

/// Partitions coefficients (nonzero) into groups: subsets of at least two whose sum is zero to
/// [`ZERO_SUM`], taken greedily (smallest first, then in index order), and singletons.
/// Beyond 10 coefficients every one is a singleton.
pub(super) fn zero_sum_groups(coefs: &[f64]) -> Vec<Vec<usize>> {
    let n = coefs.len();
    if n > 10 {
        return (0..n).map(|i| vec![i]).collect();
    }
    let members = |mask: u32| (0..n).filter(move |i| mask & (1 << i) != 0);
    let zero_sum = |mask: u32| {
        let (sum, abs) = members(mask).fold((0.0, 0.0), |(s, a), i| (s + coefs[i], a + f64::abs(coefs[i])));
        sum.abs() <= ZERO_SUM * abs
    };
    let mut left: u32 = (1 << n) - 1;
    let mut groups = Vec::new();
    // The smallest zero-sum subset of what is left, the first in index order.
    while let Some(mask) = (2..=left.count_ones())
        .find_map(|size| (1..=left).find(|&m| m & !left == 0 && m.count_ones() == size && zero_sum(m)))
    {
        groups.push(members(mask).collect());
        left &= !mask;
    }
    groups.extend(members(left).map(|i| vec![i]));
    groups
}

/// Cholesky if every form's tangent is symmetric, LU otherwise. Nonlinear tangents are probed at
/// pseudo-random states ±s, larger than the mesh, so that a switched term (a contact law's
/// active set) is active at each point in one of them, and at states a thousandth of the mesh's
/// cells in size, where a finite-strain material is defined (J = det F > 0; at the large states
/// its ln J is NaN), and at a large rigid translation plus such a small state, where a contact
/// law that reads the material's stress (Nitsche's at finite strain) is both defined and
/// active. A tangent that is not finite says nothing and is passed over; a form with no
/// finite probe at all is taken as nonsymmetric. In a split run every process probes its cells,
/// and one nonsymmetric part decides for all.
pub(super) fn probe_structure(
    asm: &Assembler,
    forms: &HashMap<String, Box<dyn BoundForm + '_>>,
    matrices: &HashMap<String, Vec<Matrix>>,
) -> Structure {
    let here = probe_here(asm, forms, matrices);
    match asm.pattern().ownership() {
        Some(o) if o.any(here == Structure::General) => Structure::General,
        Some(_) => Structure::SymmetricPositiveDefinite,
        None => here,
    }
}

fn probe_here(
    asm: &Assembler,
    forms: &HashMap<String, Box<dyn BoundForm + '_>>,
    matrices: &HashMap<String, Vec<Matrix>>,
) -> Structure {
    if matrices.values().flatten().any(|m| !m.is_symmetric(SYMMETRY_TOLERANCE)) {
        return Structure::General;
    }
    let n = asm.size();
    let large = 10.0 * asm.mesh().max_diameter() * asm.mesh().num_cells().max(1) as f64;
    let small = 1e-3 * asm.mesh().max_diameter();
    let mut seed = 0x9E37_79B9_7F4A_7C15u64;
    let mut random = |scale: f64| {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        scale * ((seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5)
    };
    let mut names: Vec<&String> = forms.keys().filter(|k| !matrices.contains_key(*k)).collect();
    names.sort();
    for name in names {
        let form = &forms[name];
        if form.fields() == 0 {
            continue;
        }
        if !form.may_be_symmetric() {
            return Structure::General;
        }
        let mut finite = false;
        let d = asm.mesh().dim();
        for (scale, translated) in [(large, false), (large, false), (small, false), (small, true)] {
            // The fields, and the previous time level when the form reads it; dofs node by node.
            let count = form.fields() + usize::from(form.previous());
            let shift: Vec<f64> = (0..d).map(|_| if translated { random(large) } else { 0.0 }).collect();
            let state: Vec<Vec<f64>> =
                (0..count).map(|_| (0..n).map(|i| shift[i % d] + random(scale)).collect()).collect();
            for sign in [1.0, -1.0] {
                let fields: Vec<Vec<f64>> = state.iter().map(|f| f.iter().map(|x| sign * x).collect()).collect();
                let refs: Vec<&[f64]> = fields.iter().map(Vec::as_slice).collect();
                for wrt in 0..form.fields() {
                    let mut m = asm.zero_matrix();
                    form.tangent(asm, &refs, wrt, 0.0, &mut m);
                    if m.values.iter().any(|v| !v.is_finite()) {
                        continue;
                    }
                    finite = true;
                    if !m.is_symmetric(SYMMETRY_TOLERANCE) {
                        return Structure::General;
                    }
                }
            }
        }
        if !finite {
            return Structure::General;
        }
    }
    Structure::SymmetricPositiveDefinite
}

/// A stage matrix; a symmetric one (under Cholesky) also as its lower half, whose products
/// read half the values.
pub(super) struct Linear {
    pub(super) matrix: Matrix,
    pub(super) half: Option<LowerHalf>,
}

impl Linear {
    pub(super) fn new(matrix: Matrix, half_pattern: Option<&Arc<HalfPattern>>) -> Linear {
        let half = half_pattern.map(|h| LowerHalf::new(&matrix, h));
        Linear { matrix, half }
    }

    /// `y = A x`.
    pub(super) fn mul(&self, x: &[f64], y: &mut [f64]) {
        match &self.half {
            Some(h) => h.mul_vec(x, y),
            None => self.matrix.mul_vec(x, y),
        }
    }
}

/// A part of a combination: a·x, or a·(x − y).
pub(super) type Part<'v> = (f64, &'v [f64], Option<&'v [f64]>);

/// A nonlinear term of a stage: coef·form(α₁w + b₁, ...).
pub(super) struct ActiveTerm<'d> {
    pub(super) form: &'d str,
    pub(super) coef: f64,
    pub(super) alphas: Vec<f64>,
    pub(super) bases: Vec<Vec<f64>>,
    pub(super) t: f64,
}

impl ActiveTerm<'_> {
    /// Writes the arguments α w + b into `out` (resized, reused across calls): at `dofs` only,
    /// if given (the rest is never read).
    pub(super) fn args_into(&self, w: &[f64], out: &mut Vec<Vec<f64>>, dofs: Option<&[usize]>) {
        out.resize_with(self.alphas.len(), Vec::new);
        for ((o, a), b) in out.iter_mut().zip(&self.alphas).zip(&self.bases) {
            match dofs {
                Some(dofs) => {
                    o.resize(w.len(), 0.0);
                    dofs.iter().for_each(|&i| o[i] = b[i] + a * w[i]);
                }
                None => {
                    o.clear();
                    o.extend(b.iter().zip(w).map(|(bi, wi)| bi + a * wi));
                }
            }
        }
    }
}

pub(super) struct StageProblem<'p, 'a> {
    pub(super) asm: &'p Assembler<'a>,
    pub(super) forms: &'p HashMap<String, Box<dyn BoundForm + 'a>>,
    pub(super) constant: &'p Linear,
    pub(super) rhs: Vec<f64>,
    pub(super) terms: Vec<ActiveTerm<'p>>,
    pub(super) constraints: &'p Constraints,
    pub(super) structure: Structure,
    /// Every form's tangent depends on the fields only through the switches, everywhere.
    pub(super) piecewise: bool,
    /// Where the nonlinear terms' residuals and tangents can be nonzero, if known.
    pub(super) support: Option<&'p Support>,
    /// Reused for the nonlinear terms' tangents, arguments and residuals.
    pub(super) scratch: &'p mut Option<Matrix>,
    pub(super) args: Vec<Vec<f64>>,
    pub(super) term: Vec<f64>,
    pub(super) switches: &'p mut SwitchMemo,
    /// The largest term of the last residual.
    pub(super) magnitude: f64,
    pub(super) recorded: RecordedTangent,
    /// The first non-finite entry of a nonlinear term's tangent: where it is.
    pub(super) non_finite: Option<NonFiniteTangent>,
}

/// Where a tangent is not finite: the form, the time level it is differentiated by, and the
/// nodes of the first element (cell or facet) with a non-finite entry.
#[derive(Clone, Debug)]
pub struct NonFiniteTangent {
    pub form: String,
    pub level: usize,
    pub nodes: Vec<Vec<f64>>,
}

impl std::fmt::Display for NonFiniteTangent {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let at: Vec<String> = self
            .nodes
            .iter()
            .map(|x| format!("({})", x.iter().map(|c| format!("{c:.6}")).collect::<Vec<_>>().join(", ")))
            .collect();
        write!(f, "the tangent of form `{}` (by its field {}) is not finite", self.form, self.level + 1)?;
        if at.is_empty() { Ok(()) } else { write!(f, " on the element with nodes at {}", at.join(", ")) }
    }
}

/// The nonlinear terms' tangent as element matrices, recorded by the last Jacobian assembly
/// (unscaled, with each term's first element and scale) at the arguments it had (`key`, their
/// bits at the support's dofs): `tangent_elements` at the same arguments reads them rather
/// than evaluating the kernels a second time.
#[derive(Default)]
pub(super) struct RecordedTangent {
    pub(super) valid: bool,
    pub(super) key: Vec<u64>,
    pub(super) parts: Vec<(usize, f64)>,
    pub(super) elements: ElementMatrices,
}

impl StageProblem<'_, '_> {
    /// Adds the nonlinear terms at w to `r` (on the support only, if known).
    pub(super) fn add_terms(&mut self, w: &[f64], r: &mut [f64]) {
        use crate::linalg::norms::norm_inf;
        let dofs = self.support.map(|s| s.dofs.as_slice());
        for term in &self.terms {
            term.args_into(w, &mut self.args, dofs);
            let refs: Vec<&[f64]> = self.args.iter().map(Vec::as_slice).collect();
            // The term is nonzero at the support's dofs only, if there is one.
            match dofs {
                Some(dofs) => {
                    self.term.resize(r.len(), 0.0);
                    dofs.iter().for_each(|&i| self.term[i] = 0.0);
                }
                None => {
                    self.term.clear();
                    self.term.resize(r.len(), 0.0);
                }
            }
            self.forms[term.form].residual(self.asm, &refs, term.t, &mut self.term);
            let largest = match dofs {
                // A NaN reaches r, where Newton sees it; the magnitude only sets a floor.
                Some(dofs) => dofs.iter().map(|&i| self.term[i].abs()).fold(0.0, f64::max),
                None => norm_inf(&self.term),
            };
            self.magnitude = self.magnitude.max(term.coef.abs() * largest);
            match dofs {
                Some(dofs) => dofs.iter().for_each(|&i| r[i] += term.coef * self.term[i]),
                None => r.iter_mut().zip(&self.term).for_each(|(ri, x)| *ri += term.coef * x),
            }
        }
    }

    /// Adds the nonlinear terms' tangents at w to `j` (on the support only, if known).
    pub(super) fn add_tangents(&mut self, w: &[f64], j: &mut Matrix) {
        let dofs = self.support.map(|s| s.dofs.as_slice());
        let rec = &mut self.recorded;
        rec.valid = true;
        rec.key.clear();
        rec.parts.clear();
        rec.elements.dofs.clear();
        rec.elements.values.clear();
        for term in &self.terms {
            term.args_into(w, &mut self.args, dofs);
            push_key(&self.args, dofs, &mut rec.key);
            let refs: Vec<&[f64]> = self.args.iter().map(Vec::as_slice).collect();
            for (k, a) in term.alphas.iter().enumerate() {
                if *a != 0.0 {
                    // Kernels add unscaled: assemble into the scratch matrix, then scale in
                    // (only where the tangent can be nonzero, when that is known).
                    let m = self.scratch.get_or_insert_with(|| self.asm.zero_matrix());
                    match self.support {
                        Some(s) => s.entries.indices.iter().for_each(|&i| m.values[i] = 0.0),
                        None => m.values.iter_mut().for_each(|v| *v = 0.0),
                    }
                    let c = term.coef * a;
                    let form = &self.forms[term.form];
                    rec.parts.push((rec.elements.len(), c));
                    rec.valid = rec.valid
                        && form.tangent_elements(self.asm, &refs, k, term.t, Some(&mut *m), &mut rec.elements);
                    if !rec.valid {
                        form.tangent(self.asm, &refs, k, term.t, m);
                    }
                    if self.non_finite.is_none() && m.values.iter().any(|v| !v.is_finite()) {
                        self.non_finite = Some(locate_non_finite(self.asm, &**form, &refs, k, term.t, term.form));
                    }
                    match self.support {
                        Some(s) => s.entries.indices.iter().for_each(|&i| j.values[i] += c * m.values[i]),
                        None => j.add_scaled(c, m),
                    }
                }
            }
        }
    }
}

impl NonlinearProblem for StageProblem<'_, '_> {
    fn node_coordinates(&self) -> Option<std::sync::Arc<[f64]>> {
        Some(self.asm.mesh().coords.as_slice().into())
    }
    fn residual(&mut self, w: &[f64], r: &mut [f64]) {
        use crate::linalg::norms::norm_inf;
        // Newton starts from δ = 0 unless a constraint moves: no product then.
        self.magnitude = norm_inf(&self.rhs);
        if w.iter().all(|x| *x == 0.0) {
            r.copy_from_slice(&self.rhs);
        } else {
            self.constant.mul(w, r);
            self.magnitude = self.magnitude.max(norm_inf(r));
            r.iter_mut().zip(&self.rhs).for_each(|(ri, c)| *ri += c);
        }
        self.add_terms(w, r);
        self.constraints.zero(r);
    }

    fn residual_on_support(&mut self, w: &[f64], r: &mut [f64]) -> bool {
        // (A w)ᵢ from A's lower triangle, as `residual`'s lower-half product reads it (A is
        // symmetric where it has one, to round-off: its two triangles may differ in their
        // last bits).
        let Some(support) = self.support.filter(|_| self.constant.half.is_some()) else { return false };
        let a = &self.constant.matrix;
        let p = &a.pattern;
        r.fill(0.0);
        for (&i, left) in support.dofs.iter().zip(&support.lower_rows) {
            let below = p.col_ptr[i]..p.col_ptr[i + 1];
            let mut aw: f64 = left.iter().map(|&(k, j)| a.values[k] * w[j]).sum();
            for (v, &j) in a.values[below.clone()].iter().zip(&p.row_idx[below]) {
                if j > i {
                    aw += v * w[j];
                }
            }
            r[i] = aw;
        }
        // A split run's other rows are partial here: their owners' values replace them.
        p.complete(r);
        let mut largest = 0.0f64;
        for &i in &support.dofs {
            largest = largest.max(r[i].abs());
            r[i] += self.rhs[i];
        }
        self.magnitude = self.magnitude.max(largest);
        self.add_terms(w, r);
        self.constraints.zero(r);
        // Test builds check it against the whole residual there, to round-off.
        if cfg!(debug_assertions) {
            let magnitude = self.magnitude;
            let mut full = vec![0.0; r.len()];
            self.residual(w, &mut full);
            self.magnitude = magnitude;
            let scale = a.norm_inf() * crate::linalg::norms::norm_inf(w) + magnitude;
            for &i in &support.dofs {
                let err = (full[i] - r[i]).abs();
                assert!(err <= 64.0 * f64::EPSILON * scale, "residual_on_support differs at {i} by {err:e}");
            }
        }
        true
    }

    fn magnitude(&self) -> f64 {
        self.magnitude
    }

    fn active_set(&mut self, w: &[f64], out: &mut Vec<bool>) -> bool {
        let dofs = self.support.map(|s| s.dofs.as_slice());
        // The set is a function of the forms, times and arguments at the support's dofs: the
        // last one evaluated is reused if those are the same bits.
        let memo = &mut *self.switches;
        if let Some(dofs) = dofs {
            memo.next.clear();
            for term in &self.terms {
                term.args_into(w, &mut self.args, Some(dofs));
                // A steady form's set does not depend on the time.
                let steady = !self.forms[term.form].time_dependent();
                memo.next.push(if steady { u64::MAX } else { term.t.to_bits() });
                memo.next.extend(term.alphas.iter().map(|a| u64::from(*a != 0.0)));
                push_key(&self.args, Some(dofs), &mut memo.next);
            }
            if memo.key == memo.next && memo.forms.iter().map(String::as_str).eq(self.terms.iter().map(|t| t.form)) {
                out.extend_from_slice(&memo.set);
                // (A memo never filled, of no terms, holds the default `false`.)
                return self.piecewise || memo.piecewise;
            }
        }
        let start = out.len();
        // Where not every form is piecewise, the set may still decide the tangent at this
        // iterate (a Coulomb law's gates off: no friction radius). Not in a split run, whose
        // processes see their own facets' gates and must take the same Newton steps.
        let mut here = self.asm.pattern().ownership().is_none();
        for term in &self.terms {
            term.args_into(w, &mut self.args, dofs);
            let refs: Vec<&[f64]> = self.args.iter().map(Vec::as_slice).collect();
            for (k, a) in term.alphas.iter().enumerate() {
                if *a != 0.0 {
                    here &= self.forms[term.form].switches(self.asm, &refs, k, term.t, out);
                }
            }
        }
        let piecewise = self.piecewise || here;
        if dofs.is_some() {
            std::mem::swap(&mut memo.key, &mut memo.next);
            if !memo.forms.iter().map(String::as_str).eq(self.terms.iter().map(|t| t.form)) {
                memo.forms = self.terms.iter().map(|t| t.form.to_string()).collect();
            }
            memo.set.clear();
            memo.set.extend_from_slice(&out[start..]);
            memo.piecewise = piecewise;
        }
        piecewise
    }

    fn jacobian(&mut self, w: &[f64], j: &mut Matrix) {
        j.values.copy_from_slice(&self.constant.matrix.values);
        self.add_tangents(w, j);
        self.constraints.apply(j);
    }

    fn update_jacobian(&mut self, w: &[f64], j: &mut Matrix) -> bool {
        // Outside the support, J is the constant part (with the constraints) at every w.
        let Some(s) = self.support else { return false };
        s.entries.indices.iter().for_each(|&i| j.values[i] = self.constant.matrix.values[i]);
        self.add_tangents(w, j);
        self.constraints.apply(j);
        true
    }

    fn jacobian_product(&mut self, j: &Matrix, x: &[f64], y: &mut [f64]) -> bool {
        // J = P (A + T) P + I_c: A the constant part (its lower half), T the tangents on the
        // support's entries (J − A there), P zeroing the constrained dofs.
        let (Some(s), Some(_)) = (self.support, self.constant.half.as_ref()) else { return false };
        let constrained = self.constraints.fixed.iter().any(|f| *f);
        // x with its constrained entries zeroed, in the terms' residual buffer: with a support,
        // `residual` zeroes and reads that buffer at the support's dofs only, so what this
        // leaves elsewhere is never read (and no vector is allocated per check).
        let x_free = if constrained {
            self.term.clear();
            self.term.extend_from_slice(x);
            self.constraints.zero(&mut self.term);
            self.term.as_slice()
        } else {
            x
        };
        self.constant.mul(x_free, y);
        let (a, rows) = (&self.constant.matrix.values, &j.pattern.row_idx);
        for (&k, &col) in s.entries.indices.iter().zip(&s.entries.columns) {
            y[rows[k]] += (j.values[k] - a[k]) * x_free[col as usize];
        }
        // In a split run J − A is exact only at this process's rows (elsewhere both are partial,
        // and their difference rounds otherwise): the owners' rows replace the others.
        j.pattern.complete(y);
        if constrained {
            y.iter_mut().zip(x).zip(&self.constraints.fixed).filter(|(_, f)| **f).for_each(|((y, x), _)| *y = *x);
        }
        true
    }

    fn jacobian_matrix(&self) -> Matrix {
        self.asm.zero_matrix()
    }

    fn structure(&self) -> Structure {
        self.structure
    }

    fn varying_entries(&self) -> Option<&Entries> {
        self.support.map(|s| &s.entries)
    }

    fn tangent_elements(&mut self, w: &[f64]) -> Option<ElementMatrices> {
        let Some(recorded) = self.recorded_elements(w) else { return self.evaluate_elements(w) };
        // Test builds check the recording against an evaluation, bit for bit (NaN included: a
        // tangent that is not finite is reported by the assembly, not here).
        if cfg!(debug_assertions) {
            let evaluated = self.evaluate_elements(w);
            let bits = |m: &ElementMatrices| {
                (m.size, m.dofs.clone(), m.values.iter().map(|v| v.to_bits()).collect::<Vec<_>>())
            };
            assert_eq!(evaluated.as_ref().map(bits), Some(bits(&recorded)), "recorded tangent elements");
        }
        Some(recorded)
    }
}

impl StageProblem<'_, '_> {
    /// The elements the last Jacobian assembly recorded, scaled as `evaluate_elements` scales
    /// them, if it was at w's arguments.
    pub(super) fn recorded_elements(&mut self, w: &[f64]) -> Option<ElementMatrices> {
        if !self.recorded.valid {
            return None;
        }
        let dofs = self.support.map(|s| s.dofs.as_slice());
        let mut key = Vec::with_capacity(self.recorded.key.len());
        for term in &self.terms {
            term.args_into(w, &mut self.args, dofs);
            push_key(&self.args, dofs, &mut key);
        }
        let rec = &self.recorded;
        if key != rec.key {
            return None;
        }
        let mut out = rec.elements.clone();
        let size = out.size * out.size;
        for (p, &(from, c)) in rec.parts.iter().enumerate() {
            let to = rec.parts.get(p + 1).map_or(out.len(), |next| next.0);
            out.values[from * size..to * size].iter_mut().for_each(|v| *v *= c);
        }
        out.zero_fixed(&self.constraints.fixed);
        Some(out)
    }

    /// The nonlinear terms' tangent at w as element matrices, each term's scaled by its
    /// coefficient; None if a form cannot give them.
    pub(super) fn evaluate_elements(&mut self, w: &[f64]) -> Option<ElementMatrices> {
        let dofs = self.support.map(|s| s.dofs.as_slice());
        let mut out = ElementMatrices::default();
        for term in &self.terms {
            term.args_into(w, &mut self.args, dofs);
            let refs: Vec<&[f64]> = self.args.iter().map(Vec::as_slice).collect();
            for (k, a) in term.alphas.iter().enumerate() {
                if *a != 0.0 {
                    let from = out.len();
                    if !self.forms[term.form].tangent_elements(self.asm, &refs, k, term.t, None, &mut out) {
                        return None;
                    }
                    out.scale_from(from, term.coef * a);
                }
            }
        }
        out.zero_fixed(&self.constraints.fixed);
        Some(out)
    }
}

/// Appends the bits of `args` at `dofs` (everywhere if None).
pub(super) fn push_key(args: &[Vec<f64>], dofs: Option<&[usize]>, key: &mut Vec<u64>) {
    for arg in args {
        match dofs {
            Some(dofs) => key.extend(dofs.iter().map(|&i| arg[i].to_bits())),
            None => key.extend(arg.iter().map(|x| x.to_bits())),
        }
    }
}

/// The entries the stage's nonlinear terms' tangents add to: those coupling the nodes of the
/// cells of their supports (None if one of them has none).
pub(super) fn tangent_support(
    asm: &Assembler,
    forms: &HashMap<String, Box<dyn BoundForm + '_>>,
    terms: &[ActiveTerm],
) -> Option<Support> {
    let mut nodes = vec![false; asm.mesh().num_nodes()];
    for term in terms {
        for cell in forms[term.form].support()? {
            asm.mesh().cell(cell as usize).iter().for_each(|&n| nodes[n as usize] = true);
        }
    }
    let d = asm.pattern().dim();
    let dofs: Vec<usize> = (0..nodes.len()).filter(|&j| nodes[j]).flat_map(|j| j * d..(j + 1) * d).collect();
    let p = asm.pattern();
    let lower_rows = dofs
        .iter()
        .map(|&i| {
            // The pattern is symmetric: row i's columns are column i's rows.
            let columns = &p.row_idx[p.col_ptr[i]..p.col_ptr[i + 1]];
            columns
                .iter()
                .filter(|&&j| j <= i)
                .map(|&j| {
                    let rows = &p.row_idx[p.col_ptr[j]..p.col_ptr[j + 1]];
                    let k = rows.binary_search(&i).expect("a symmetric pattern");
                    (p.col_ptr[j] + k, j)
                })
                .collect()
        })
        .collect();
    Some(Support { entries: asm.pattern().entries_among(&nodes), dofs, lower_rows })
}

/// Where a stage's nonlinear terms live when they integrate over facets only: the dofs of
/// their cells (the only ones their residuals touch and their arguments are read at) and the
/// entries coupling them (the only ones their tangents add to).
pub(super) struct Support {
    pub(super) entries: Entries,
    pub(super) dofs: Vec<usize>,
    /// For each of `dofs` (row i), where the pattern's lower triangle holds row i left of and
    /// on the diagonal: (entry index, column j ≤ i). With column i below the diagonal, these
    /// read row i of a symmetric matrix from its lower triangle alone, as its lower-half
    /// products do (`residual_on_support`).
    pub(super) lower_rows: Vec<Vec<(usize, usize)>>,
}

#[cfg(test)]
mod tests {
    use super::zero_sum_groups;

    #[test]
    fn zero_sum_groups_of_trbdf2_and_newmark() {
        // TR-BDF2's a' at Δt = 0.02 (u', u, v, um, vm): the displacement levels sum to 7e-12.
        let a = [29142.13562373094, 6035.533905932739, 35.355339059327385, -35177.669529663675, -206.06601717798208];
        assert_eq!(zero_sum_groups(&a), vec![vec![0, 1, 3], vec![2], vec![4]]);
        // Newmark's v' (u' merged into u, v, a): no group.
        assert_eq!(zero_sum_groups(&[1.0, -1.0 / 3.0, 0.01]), vec![vec![0], vec![1], vec![2]]);
        // Two groups, the smaller first.
        assert_eq!(zero_sum_groups(&[1.0, 2.0, -3.0, 0.5, -0.5]), vec![vec![3, 4], vec![0, 1, 2]]);
        assert_eq!(zero_sum_groups(&[]), Vec::<Vec<usize>>::new());
        // Too many to search: singletons.
        let many = [1.0, -1.0, 2.0, -2.0, 3.0, -3.0, 4.0, -4.0, 5.0, -5.0, 6.0];
        assert_eq!(zero_sum_groups(&many), (0..11).map(|i| vec![i]).collect::<Vec<_>>());
    }
}
