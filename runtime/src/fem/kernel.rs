//! The interface between compiled forms and the runtime: tabulated basis functions at
//! quadrature points, the per-cell context a kernel reads, case data (`coef`), parameter
//! errors, and the traits every generated form implements.
//!
//! Kernels *add* into their output (the caller zeroes it), so cell and facet contributions
//! of several forms can accumulate in one element array. Vector dofs are node-major:
//! local dof `D*j + k` is component `k` of node `j`.

use std::fmt;
use std::sync::Arc;

use signorini_descriptors::{List, Text};

use crate::fem::element::ElementKind;
use crate::fem::quadrature::{Rule, simplex_rule};

/// Element vector: `[node][component]`.
pub type LocalVector<const D: usize, const N: usize> = [[f64; D]; N];
pub use crate::linalg::pattern::LocalMatrix;

/// Basis functions and reference gradients at the points of a quadrature rule.
#[derive(Clone, Debug)]
pub struct Tabulation<const D: usize, const N: usize> {
    /// Reference weights (for facets: including the reference facet's measure).
    pub weights: Vec<f64>,
    pub phi: Vec<[f64; N]>,
    pub dphi: Vec<[[f64; D]; N]>,
}

/// A tabulation on each local facet of a cell, with the reference outward normals.
#[derive(Clone, Debug)]
pub struct FacetTabulation<const D: usize, const N: usize> {
    pub facets: Vec<(Tabulation<D, N>, [f64; D])>,
}

#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ShapeError(pub String);

impl fmt::Display for ShapeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for ShapeError {}

fn check_kind<const D: usize, const N: usize>(kind: ElementKind) -> Result<(), ShapeError> {
    if kind.dim() != D || kind.nodes() != N {
        return Err(ShapeError(format!(
            "{} has dimension {} and {} nodes, not {D} and {N}",
            kind.name(),
            kind.dim(),
            kind.nodes()
        )));
    }
    Ok(())
}

impl<const D: usize, const N: usize> Tabulation<D, N> {
    /// Tabulates `kind` at the points of a rule on the reference cell.
    pub fn new(kind: ElementKind, rule: &Rule) -> Result<Self, ShapeError> {
        check_kind::<D, N>(kind)?;
        let mut t = Tabulation { weights: rule.weights.clone(), phi: Vec::new(), dphi: Vec::new() };
        for p in &rule.points {
            t.push(kind, p);
        }
        Ok(t)
    }

    /// Tabulates `kind` with the cell rule of at least `degree`.
    pub fn cell(kind: ElementKind, degree: u32) -> Result<Self, ShapeError> {
        Self::new(kind, &simplex_rule(D, degree))
    }

    fn push(&mut self, kind: ElementKind, xi: &[f64]) {
        let phi = kind.basis(xi);
        let grads = kind.basis_gradients(xi);
        self.phi.push(std::array::from_fn(|j| phi[j]));
        self.dphi.push(std::array::from_fn(|j| std::array::from_fn(|k| grads[j][k])));
    }

    pub fn len(&self) -> usize {
        self.weights.len()
    }

    pub fn is_empty(&self) -> bool {
        self.weights.is_empty()
    }
}

impl<const D: usize, const N: usize> FacetTabulation<D, N> {
    /// Volume basis functions and gradients at the points of a facet rule of at least `degree`
    /// (Gauss on edges, a triangle rule on faces, the point itself in 1D), on every local facet.
    pub fn new(kind: ElementKind, degree: u32) -> Result<Self, ShapeError> {
        Self::with_rule(kind, &simplex_rule(D - 1, degree))
    }

    /// As `new`, computed once per (kind, degree) and shared: facet loops over a contact region
    /// run at every Newton iteration, and tabulating costs more than a few facets' kernels.
    pub fn shared(kind: ElementKind, degree: u32) -> Result<std::sync::Arc<Self>, ShapeError>
    where
        Self: Send + Sync + 'static,
    {
        use std::any::Any;
        use std::collections::HashMap;
        use std::sync::{Arc, Mutex, OnceLock};
        type Cache = Mutex<HashMap<(ElementKind, u32), Arc<dyn Any + Send + Sync>>>;
        static CACHE: OnceLock<Cache> = OnceLock::new();
        let cache = CACHE.get_or_init(Default::default);
        if let Some(t) = cache.lock().ok().and_then(|c| c.get(&(kind, degree)).cloned())
            && let Ok(t) = t.downcast::<Self>()
        {
            return Ok(t);
        }
        let t = Arc::new(Self::new(kind, degree)?);
        if let Ok(mut c) = cache.lock() {
            c.insert((kind, degree), t.clone());
        }
        Ok(t)
    }

    /// As `new`, with an explicit rule on the reference facet.
    pub fn with_rule(kind: ElementKind, rule: &Rule) -> Result<Self, ShapeError> {
        check_kind::<D, N>(kind)?;
        let facets = (0..kind.facets().len())
            .map(|f| {
                let mut t = Tabulation { weights: Vec::new(), phi: Vec::new(), dphi: Vec::new() };
                for (s, w) in rule.points.iter().zip(&rule.weights) {
                    let (xi, scale) = kind.facet_point(f, s);
                    t.weights.push(w * scale);
                    t.push(kind, &xi);
                }
                let n = kind.reference_normal(f);
                (t, std::array::from_fn(|k| n[k]))
            })
            .collect();
        Ok(FacetTabulation { facets })
    }
}

/// What a cell kernel reads besides the fields.
pub struct CellCtx<'a, const D: usize, const N: usize> {
    pub tab: &'a Tabulation<D, N>,
    pub coords: &'a [[f64; D]; N],
    pub t: f64,
}

/// What a facet kernel reads besides the fields: the tabulation on this facet, its reference
/// normal, and the diameter of the cell carrying it.
pub struct FacetCtx<'a, const D: usize, const N: usize> {
    pub tab: &'a Tabulation<D, N>,
    pub ref_normal: &'a [f64; D],
    pub coords: &'a [[f64; D]; N],
    pub h: f64,
    pub t: f64,
}

/// `f(x, t, out)`: a coef's values at position `x` and time `t`.
pub type CoefFn = Arc<dyn Fn(&[f64], f64, &mut [f64]) + Send + Sync>;

/// `f(x, t, order, out)`: a coef's partial derivatives of `order` (1 or 2) with respect to the
/// position, component-major: `out[c·d + k]` = ∂_k c, `out[(c·d + k)·d + l]` = ∂_k ∂_l c.
pub type CoefDerivativesFn = Arc<dyn Fn(&[f64], f64, usize, &mut [f64]) + Send + Sync>;

/// Case data (`coef` in a .wf file): a constant or a function of position and time.
#[derive(Clone)]
pub enum Coef {
    Constant(Vec<f64>),
    /// `steady`: the function ignores the time. `derivatives`, where known, for a kernel that
    /// reads the coef at a point of its own (`g(x + u)`), whose tangent differentiates it.
    Function {
        components: usize,
        f: CoefFn,
        steady: bool,
        derivatives: Option<CoefDerivativesFn>,
    },
}

impl Coef {
    pub fn scalar(v: f64) -> Self {
        Coef::Constant(vec![v])
    }

    /// A constant vector or (row-major) tensor.
    pub fn constant(v: impl Into<Vec<f64>>) -> Self {
        Coef::Constant(v.into())
    }

    /// `f(x, t, out)` writes the `components` values at position `x` and time `t`.
    pub fn function(components: usize, f: impl Fn(&[f64], f64, &mut [f64]) + Send + Sync + 'static) -> Self {
        Coef::Function { components, f: Arc::new(f), steady: false, derivatives: None }
    }

    /// `f(x, out)` writes the `components` values at position `x`, at every time (loads made
    /// of steady coefs are assembled once, not at every step).
    pub fn of_position(components: usize, f: impl Fn(&[f64], &mut [f64]) + Send + Sync + 'static) -> Self {
        Coef::Function { components, f: Arc::new(move |x, _, out| f(x, out)), steady: true, derivatives: None }
    }

    /// With its first and second derivatives with respect to the position (see
    /// [`CoefDerivativesFn`]); a constant has them already.
    pub fn with_derivatives(self, d: impl Fn(&[f64], f64, usize, &mut [f64]) + Send + Sync + 'static) -> Self {
        match self {
            Coef::Function { components, f, steady, .. } => {
                Coef::Function { components, f, steady, derivatives: Some(Arc::new(d)) }
            }
            c => c,
        }
    }

    /// Component `comp` at the point `y` (a kernel's own, `g(x + u)`), or its partial derivative
    /// along the coordinates `dirs` (at most two; sorted or not). NaN where the coef has no
    /// derivatives (a function made in Rust without [`Coef::with_derivatives`]), or past the
    /// second: the run stops at a non-finite residual or tangent, never on a wrong one.
    #[inline]
    pub fn at(&self, y: &[f64], t: f64, comp: usize, dirs: &[u8]) -> f64 {
        let d = y.len();
        match (self, dirs) {
            (Coef::Constant(v), []) => v.get(comp).copied().unwrap_or(f64::NAN),
            (Coef::Constant(_), _) => 0.0,
            (Coef::Function { f, components, .. }, []) => {
                let mut out = [0.0; 9];
                f(y, t, &mut out[..(*components).min(9)]);
                out.get(comp).copied().unwrap_or(f64::NAN)
            }
            (Coef::Function { derivatives: Some(df), components, .. }, [k]) => {
                let mut out = [0.0; 27];
                df(y, t, 1, &mut out[..(components * d).min(27)]);
                out.get(comp * d + *k as usize).copied().unwrap_or(f64::NAN)
            }
            (Coef::Function { derivatives: Some(df), components, .. }, [k, l]) => {
                let mut out = [0.0; 81];
                df(y, t, 2, &mut out[..(components * d * d).min(81)]);
                out.get((comp * d + *k as usize) * d + *l as usize).copied().unwrap_or(f64::NAN)
            }
            _ => f64::NAN,
        }
    }

    /// Whether the values may change with time.
    pub fn time_dependent(&self) -> bool {
        matches!(self, Coef::Function { steady: false, .. })
    }

    pub fn components(&self) -> usize {
        match self {
            Coef::Constant(v) => v.len(),
            Coef::Function { components, .. } => *components,
        }
    }

    #[inline]
    pub fn eval(&self, x: &[f64], t: f64, out: &mut [f64]) {
        match self {
            Coef::Constant(v) => {
                let n = v.len().min(out.len());
                out[..n].copy_from_slice(&v[..n]);
            }
            Coef::Function { f, .. } => f(x, t, out),
        }
    }
}

impl fmt::Debug for Coef {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Coef::Constant(v) => write!(f, "Coef::Constant({v:?})"),
            Coef::Function { components, .. } => {
                write!(f, "Coef::Function({components} components)")
            }
        }
    }
}

/// Checks that a coef has the number of components its declared shape needs in dimension `dim`.
pub fn check_coef(name: &str, coef: &Coef, shape_rank: u32, dim: usize) -> Result<(), ShapeError> {
    let want = dim.pow(shape_rank);
    if coef.components() != want {
        return Err(ShapeError(format!(
            "coef `{name}` has {} components; it needs {want} in dimension {dim}",
            coef.components()
        )));
    }
    Ok(())
}

/// Static description of a compiled form: constant in generated code, built by a form
/// interpreted at run time.
#[derive(Debug, Clone, PartialEq)]
pub struct FormMeta {
    pub name: Text,
    pub fields: List<Text>,
    pub test: Text,
    /// The tangent does not depend on the fields: assemble it once.
    pub linear: bool,
    /// The tangent depends on the fields only through the switches (the active set).
    pub piecewise: bool,
    /// The form reads the displacement at the previous time level (`prev` in its file): its
    /// kernels take it after the fields, as one more field that no tangent differentiates.
    pub previous: bool,
    /// Suggested cell quadrature degree for P1 and P2, if the form has a volume integral.
    pub cell_degree: Option<[u32; 2]>,
    /// Boundary regions with suggested facet quadrature degrees for P1 and P2.
    pub facets: List<(Text, [u32; 2])>,
    /// Where each of `facets` is named in the source (`file.wf:line:col` of `int(NAME)`), for
    /// errors when a case does not define the region.
    pub facet_sites: List<Text>,
    /// Where the form first takes a `tangential` part (`file.wf:line:col`): a 1D mesh has no
    /// tangent space, and binding the form there is an error at this site.
    pub tangential: Option<Text>,
}

/// Implemented by every generated form.
pub trait Form {
    /// Generated forms return their `META` constant; interpreted forms, what they were built with.
    fn meta(&self) -> &FormMeta;

    /// Whether the integrands may change with time (they read `t`, or a coef that does) other
    /// than through the fields. A load that does not is assembled once.
    fn time_dependent(&self) -> bool {
        true
    }
}

/// Element kernels of a form for cells of dimension D with N nodes. Each method adds its
/// contribution to `out`. Every method defaults to adding nothing, so a form implements only
/// what it has: one without a volume (facet) integral leaves the cell (facet) methods out, and
/// one without active-set switches the `*_switches` methods.
#[allow(unused_variables)]
pub trait FormKernel<const D: usize, const N: usize>: Form {
    fn cell_residual(&self, ctx: &CellCtx<'_, D, N>, fields: &[&LocalVector<D, N>], out: &mut LocalVector<D, N>) {}
    /// Derivative with respect to field argument `wrt`.
    fn cell_tangent(
        &self,
        ctx: &CellCtx<'_, D, N>,
        fields: &[&LocalVector<D, N>],
        wrt: usize,
        out: &mut LocalMatrix<D, N>,
    ) {
    }
    /// Pushes, at every quadrature point, the sign (`a > 0`) of each active-set switch H(a) of
    /// the tangent with respect to field `wrt`. For a `piecewise` form, equal switches mean
    /// an equal tangent. Returns whether the tangent depends on the fields only through these
    /// switches at these points: always for a `piecewise` form, and for one that is not where
    /// its gates are off (a Coulomb law where the friction radius is zero).
    fn cell_switches(
        &self,
        ctx: &CellCtx<'_, D, N>,
        fields: &[&LocalVector<D, N>],
        wrt: usize,
        out: &mut Vec<bool>,
    ) -> bool {
        true
    }
    /// `region` indexes `META.facets`.
    fn facet_residual(
        &self,
        region: usize,
        ctx: &FacetCtx<'_, D, N>,
        fields: &[&LocalVector<D, N>],
        out: &mut LocalVector<D, N>,
    ) {
    }
    fn facet_tangent(
        &self,
        region: usize,
        ctx: &FacetCtx<'_, D, N>,
        fields: &[&LocalVector<D, N>],
        wrt: usize,
        out: &mut LocalMatrix<D, N>,
    ) {
    }
    fn facet_switches(
        &self,
        region: usize,
        ctx: &FacetCtx<'_, D, N>,
        fields: &[&LocalVector<D, N>],
        wrt: usize,
        out: &mut Vec<bool>,
    ) -> bool {
        true
    }
}

/// Kernels of a functional (a form without a test function): the integral over one cell or
/// one facet of region `region`. Both default to 0 (no volume, no facet integral).
#[allow(unused_variables)]
pub trait FunctionalKernel<const D: usize, const N: usize>: Form {
    fn cell_value(&self, ctx: &CellCtx<'_, D, N>, fields: &[&LocalVector<D, N>]) -> f64 {
        0.0
    }
    fn facet_value(&self, region: usize, ctx: &FacetCtx<'_, D, N>, fields: &[&LocalVector<D, N>]) -> f64 {
        0.0
    }
}

/// H(a) = 1 if a > 0, else 0 (so H(0) = 0).
#[inline(always)]
pub fn heaviside(a: f64) -> f64 {
    if a > 0.0 { 1.0 } else { 0.0 }
}

/// Element residual of a form's volume integral on one cell (a fresh array, for tests and
/// element-level checks; assembly reuses its buffers instead).
pub fn cell_vector<const D: usize, const N: usize, K: FormKernel<D, N>>(
    k: &K,
    tab: &Tabulation<D, N>,
    coords: &[[f64; D]; N],
    fields: &[&LocalVector<D, N>],
    t: f64,
) -> LocalVector<D, N> {
    let mut out = [[0.0; D]; N];
    k.cell_residual(&CellCtx { tab, coords, t }, fields, &mut out);
    out
}

/// Element tangent of a form's volume integral on one cell, as a row-major (N·D)×(N·D) matrix.
pub fn cell_matrix<const D: usize, const N: usize, K: FormKernel<D, N>>(
    k: &K,
    tab: &Tabulation<D, N>,
    coords: &[[f64; D]; N],
    fields: &[&LocalVector<D, N>],
    wrt: usize,
    t: f64,
) -> Vec<Vec<f64>> {
    let mut out = Box::new([[[[0.0; D]; N]; D]; N]);
    k.cell_tangent(&CellCtx { tab, coords, t }, fields, wrt, &mut out);
    flatten(&out)
}

/// Which facet term is evaluated where: the form's region, the cell's local facet, and the
/// cell's size h (Nitsche's and the penalty's scale).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OnFacet {
    pub region: usize,
    pub facet: usize,
    pub h: f64,
}

/// Facet residual of region `at.region` on local facet `at.facet`.
pub fn facet_vector<const D: usize, const N: usize, K: FormKernel<D, N>>(
    k: &K,
    tab: &FacetTabulation<D, N>,
    at: OnFacet,
    coords: &[[f64; D]; N],
    fields: &[&LocalVector<D, N>],
    t: f64,
) -> LocalVector<D, N> {
    let OnFacet { region, facet, h } = at;
    let (ftab, normal) = &tab.facets[facet];
    let mut out = [[0.0; D]; N];
    k.facet_residual(region, &FacetCtx { tab: ftab, ref_normal: normal, coords, h, t }, fields, &mut out);
    out
}

/// Facet tangent of region `at.region` on local facet `at.facet`, row-major.
pub fn facet_matrix<const D: usize, const N: usize, K: FormKernel<D, N>>(
    k: &K,
    tab: &FacetTabulation<D, N>,
    at: OnFacet,
    coords: &[[f64; D]; N],
    fields: &[&LocalVector<D, N>],
    wrt: usize,
    t: f64,
) -> Vec<Vec<f64>> {
    let OnFacet { region, facet, h } = at;
    let (ftab, normal) = &tab.facets[facet];
    let mut out = Box::new([[[[0.0; D]; N]; D]; N]);
    k.facet_tangent(region, &FacetCtx { tab: ftab, ref_normal: normal, coords, h, t }, fields, wrt, &mut out);
    flatten(&out)
}

fn flatten<const D: usize, const N: usize>(m: &LocalMatrix<D, N>) -> Vec<Vec<f64>> {
    let mut rows = Vec::with_capacity(N * D);
    for row_node in m.iter() {
        for row in row_node.iter() {
            rows.push(row.iter().flat_map(|col| col.iter().copied()).collect());
        }
    }
    rows
}
