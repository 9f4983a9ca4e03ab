//! Compiled forms and functionals bound to a mesh: a kernel with its quadrature and the mesh
//! facets of the boundary regions it integrates over, behind object-safe traits so that the
//! forms of one scheme or problem may differ in type.

use crate::fem::assembly::{Assembler, CellIntegral, FacetIntegral, Functional, Kernel, PointValue, Quadrature};
use crate::fem::mesh::Facet;
use crate::fem::quadrature::Rule;
use crate::linalg::Matrix;
use crate::linalg::element_matrices::ElementMatrices;

/// A compiled form bound to a mesh: its kernel, the mesh facets of each boundary region it
/// integrates over, and quadrature degrees. Object-safe, so a scheme's forms may differ in type.
pub trait BoundForm {
    fn name(&self) -> &str;
    fn fields(&self) -> usize;
    /// Whether it reads the displacement at the previous time level (`prev`): then every call
    /// passes it after the `fields()` arguments (see [`with_previous`]).
    fn previous(&self) -> bool {
        false
    }
    fn linear(&self) -> bool;
    /// The tangent depends on the fields only through the switches, everywhere (see
    /// `switches` for where it does at an iterate).
    fn piecewise(&self) -> bool;
    fn residual(&self, asm: &Assembler, fields: &[&[f64]], t: f64, out: &mut [f64]);
    fn tangent(&self, asm: &Assembler, fields: &[&[f64]], wrt: usize, t: f64, m: &mut Matrix);
    /// Appends the active-set switches of the tangent with respect to field `wrt` at `fields`;
    /// whether the tangent depends on the fields only through them there (always where
    /// `piecewise`; for a Coulomb law, where its friction radius is zero on every facet).
    fn switches(&self, asm: &Assembler, fields: &[&[f64]], wrt: usize, t: f64, out: &mut Vec<bool>) -> bool;
    /// The cells whose element matrices the tangent adds to, if not all of them (a form that
    /// integrates over boundary facets only): the Jacobian changes nowhere else.
    fn support(&self) -> Option<Vec<u32>> {
        None
    }
    /// Appends the tangent's element matrices (unscaled, as `tangent` adds them) if the form
    /// integrates over facets only, and with `m` also adds them into `m` as `tangent` does (one
    /// evaluation for both); false, with nothing done, if it cannot.
    fn tangent_elements(
        &self,
        _asm: &Assembler,
        _fields: &[&[f64]],
        _wrt: usize,
        _t: f64,
        _m: Option<&mut Matrix>,
        _out: &mut ElementMatrices,
    ) -> bool {
        false
    }
    /// Whether the form changes with time other than through its fields.
    fn time_dependent(&self) -> bool {
        true
    }
    /// False where the tangent is known to be unsymmetric where it matters, though it may not
    /// be at a probe's random states (a contact pair's, zero until the bodies touch); true
    /// otherwise, the probe deciding.
    fn may_be_symmetric(&self) -> bool {
        true
    }
    /// What its contact pairs' search and assembly have cost so far (none for other forms).
    fn search_cost(&self) -> crate::fem::search_cost::SearchCost {
        Default::default()
    }
    /// Whether it searches for facing points (a contact pair's form): then [`Self::lost_facing`]
    /// is asked after each stage's Newton.
    fn searches(&self) -> bool {
        false
    }
    /// A point that faced the other surface and faces nothing at the last evaluation, if any.
    fn lost_facing(&self) -> Option<crate::fem::pair::LostFacing> {
        None
    }
}

/// `fields`, with `previous` after them when the form reads the previous time level (`reads`):
/// the arguments of a form that may read it.
pub fn with_previous<'a>(reads: bool, fields: &[&'a [f64]], previous: &'a [f64]) -> Vec<&'a [f64]> {
    let mut all = fields.to_vec();
    if reads {
        all.push(previous);
    }
    all
}

/// A kernel with its integration data.
pub struct Bound<'m, K: Kernel> {
    pub kernel: K,
    pub quadrature: Quadrature,
    /// For each boundary region of the form (by its name in the .wf file), the mesh facets.
    pub regions: Vec<(String, &'m [Facet])>,
    /// The cells of its volume integral, if not all of them (a body's: per cell, whether it is
    /// one).
    pub cells: Option<&'m [bool]>,
}

impl<K: Kernel> Bound<'_, K> {
    /// The form's integral over `region` on `facets`.
    fn on<'a>(&'a self, region: &'a str, facets: &'a [Facet]) -> FacetIntegral<'a, K> {
        FacetIntegral { kernel: &self.kernel, region, facets, quadrature: self.quadrature, cells: self.cells }
    }

    /// Its volume integral.
    fn over_cells(&self) -> CellIntegral<'_, K> {
        CellIntegral { kernel: &self.kernel, quadrature: self.quadrature, cells: self.cells }
    }
}

impl<K: Kernel> BoundForm for Bound<'_, K> {
    fn name(&self) -> &str {
        &self.kernel.meta().name
    }
    fn fields(&self) -> usize {
        self.kernel.meta().fields.len()
    }
    fn previous(&self) -> bool {
        self.kernel.meta().previous
    }
    fn linear(&self) -> bool {
        self.kernel.meta().linear
    }
    fn piecewise(&self) -> bool {
        self.kernel.meta().piecewise
    }
    fn residual(&self, asm: &Assembler, fields: &[&[f64]], t: f64, out: &mut [f64]) {
        if self.kernel.meta().cell_degree.is_some() {
            asm.cell_residual(self.over_cells(), fields, t, out);
        }
        for (region, facets) in &self.regions {
            asm.facet_residual(self.on(region, facets), fields, t, out);
        }
    }
    fn tangent(&self, asm: &Assembler, fields: &[&[f64]], wrt: usize, t: f64, m: &mut Matrix) {
        if self.kernel.meta().cell_degree.is_some() {
            asm.cell_tangent(self.over_cells(), fields, wrt, t, m);
        }
        for (region, facets) in &self.regions {
            asm.facet_tangent(self.on(region, facets), fields, wrt, t, m);
        }
    }
    fn switches(&self, asm: &Assembler, fields: &[&[f64]], wrt: usize, t: f64, out: &mut Vec<bool>) -> bool {
        let meta = self.kernel.meta();
        // A volume integral's switches are not evaluated: its tangent counts as piecewise only
        // where the form is.
        let mut piecewise = meta.piecewise || meta.cell_degree.is_none();
        for (region, facets) in &self.regions {
            piecewise &= asm.facet_switches(self.on(region, facets), fields, wrt, t, out);
        }
        piecewise
    }
    fn support(&self) -> Option<Vec<u32>> {
        if self.kernel.meta().cell_degree.is_some() {
            return None;
        }
        let mine = |c: &u32| self.cells.is_none_or(|cells| cells[*c as usize]);
        Some(self.regions.iter().flat_map(|(_, facets)| facets.iter().map(|f| f.cell)).filter(mine).collect())
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
        if self.kernel.meta().cell_degree.is_some() {
            return false;
        }
        for (region, facets) in &self.regions {
            asm.facet_tangent_elements(self.on(region, facets), fields, wrt, t, m.as_deref_mut(), out);
        }
        true
    }
    fn time_dependent(&self) -> bool {
        self.kernel.time_dependent()
    }
}

/// A linear form given by its matrix (e.g. a redistributed mass matrix).
pub struct MatrixForm {
    pub name: String,
    pub matrix: Matrix,
}

impl BoundForm for MatrixForm {
    fn name(&self) -> &str {
        &self.name
    }
    fn fields(&self) -> usize {
        1
    }
    fn linear(&self) -> bool {
        true
    }
    fn piecewise(&self) -> bool {
        true
    }
    fn residual(&self, _asm: &Assembler, fields: &[&[f64]], _t: f64, out: &mut [f64]) {
        let mut y = vec![0.0; out.len()];
        self.matrix.mul_vec(fields[0], &mut y);
        out.iter_mut().zip(&y).for_each(|(o, v)| *o += v);
    }
    fn tangent(&self, _asm: &Assembler, _fields: &[&[f64]], _wrt: usize, _t: f64, m: &mut Matrix) {
        m.add_scaled(1.0, &self.matrix);
    }
    fn switches(&self, _asm: &Assembler, _fields: &[&[f64]], _wrt: usize, _t: f64, _out: &mut Vec<bool>) -> bool {
        true
    }
    fn time_dependent(&self) -> bool {
        false
    }
}

/// A functional bound to a mesh: its integral, or its integral per cell.
pub trait BoundFunctional {
    fn name(&self) -> &str;
    fn fields(&self) -> usize;
    /// The integral over the cells (if it has a volume part) and its boundary regions.
    fn value(&self, asm: &Assembler, fields: &[&[f64]], t: f64) -> f64;
    /// The volume integral on each cell.
    fn cell_values(&self, asm: &Assembler, fields: &[&[f64]], t: f64) -> Vec<f64>;
    /// The integrand of its boundary regions at the points of `rule` on each facet
    /// ([`Assembler::facet_point_values`]).
    fn facet_point_values(&self, asm: &Assembler, rule: &Rule, fields: &[&[f64]], t: f64) -> Vec<PointValue>;
}

/// A functional kernel with its integration data.
pub struct BoundValue<'m, K: Functional> {
    pub kernel: K,
    pub quadrature: Quadrature,
    pub regions: Vec<(String, &'m [Facet])>,
    /// As [`Bound::cells`].
    pub cells: Option<&'m [bool]>,
}

impl<K: Functional> BoundValue<'_, K> {
    fn on<'a>(&'a self, region: &'a str, facets: &'a [Facet]) -> FacetIntegral<'a, K> {
        FacetIntegral { kernel: &self.kernel, region, facets, quadrature: self.quadrature, cells: self.cells }
    }

    fn over_cells(&self) -> CellIntegral<'_, K> {
        CellIntegral { kernel: &self.kernel, quadrature: self.quadrature, cells: self.cells }
    }
}

impl<K: Functional> BoundFunctional for BoundValue<'_, K> {
    fn name(&self) -> &str {
        &self.kernel.meta().name
    }
    fn fields(&self) -> usize {
        self.kernel.meta().fields.len()
    }
    fn value(&self, asm: &Assembler, fields: &[&[f64]], t: f64) -> f64 {
        let mut v = 0.0;
        if self.kernel.meta().cell_degree.is_some() {
            v += asm.cell_value(self.over_cells(), fields, t);
        }
        for (region, facets) in &self.regions {
            v += asm.facet_value(self.on(region, facets), fields, t);
        }
        v
    }
    fn cell_values(&self, asm: &Assembler, fields: &[&[f64]], t: f64) -> Vec<f64> {
        asm.cell_values(self.over_cells(), fields, t)
    }
    fn facet_point_values(&self, asm: &Assembler, rule: &Rule, fields: &[&[f64]], t: f64) -> Vec<PointValue> {
        let mut out = Vec::new();
        for (region, facets) in &self.regions {
            out.extend(asm.facet_point_values(self.on(region, facets), rule, fields, t));
        }
        out
    }
}
