//! Contact between two surfaces of the mesh (two bodies): the interface a pair law's kernels
//! implement, pointwise, and the assembly that finds the facing points and contracts the
//! kernels' coefficients with both cells' basis functions.
//!
//! A pair law is evaluated at the quadrature points of its own surface. At each, the facing
//! point is the closest point of the other surface on the deformed configuration
//! ([`crate::fem::facing::Surface`]); the kernel reads both sides' fields there and returns
//! the coefficients of both sides' test functions and of the tangent's four blocks. The facing
//! point moves with both sides' displacements, and the tangent follows it: the closest-point
//! condition's linearization gives the facing point's rate, which the kernel's sliding rates
//! and the facing basis functions' gradients turn into the tangent's third part
//! (docs/mathematics.md, "Two bodies").

pub mod assembly;

use crate::fem::element::ElementKind;
use crate::fem::facing::Surface;
use crate::fem::kernel::Form;
use crate::fem::mesh::{Facet, Mesh};

/// A quadrature point of a pair's own surface that faced the other surface and, at a later
/// evaluation, faces nothing within the pair's reach: its force would vanish without the
/// bodies having parted.
#[derive(Clone, Debug, PartialEq)]
pub struct LostFacing {
    /// The pair law's form.
    pub form: String,
    /// The point on the configuration where it faces nothing.
    pub point: Vec<f64>,
    /// How far the facing surface was when the point last faced it, and the pair's reach.
    pub distance: f64,
    pub reach: f64,
}

impl std::fmt::Display for LostFacing {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let point: Vec<String> = self.point.iter().map(|x| format!("{x:.4}")).collect();
        write!(
            f,
            "contact pair `{}`: the point ({}) of its own surface faced the other surface {:.3e} away and now faces nothing within the pair's reach ({}): it moved by more than half the reach in one Newton iterate, through the other body or past it",
            self.form,
            point.join(", "),
            self.distance,
            self.reach
        )
    }
}

/// A contact pair of a mesh: the surface a pair law integrates over, the surface it faces, and
/// how far a facing point is looked for.
#[derive(Clone, Copy, Debug)]
pub struct Surfaces<'m> {
    pub own: &'m [Facet],
    pub facing: &'m [Facet],
    pub reach: f64,
    pub kind: ElementKind,
    /// Integrated segment by segment (2D, [`PairForm::segmented`]).
    pub segmented: bool,
}

/// A contact pair by its regions' names, as a problem declares it.
#[derive(Clone, Debug, PartialEq)]
pub struct PairRegions {
    pub own: String,
    pub facing: String,
    pub reach: f64,
    /// Integrated segment by segment (2D, [`PairForm::segmented`]), not facet by facet.
    pub segmented: bool,
}

impl PairRegions {
    /// The pair's facets on `mesh` (none for a region it lacks: the problem checked them).
    pub fn on<'m>(&self, mesh: &'m Mesh) -> Surfaces<'m> {
        let facets = |name: &str| mesh.region(name).map(|r| r.facets.as_slice()).unwrap_or(&[]);
        Surfaces {
            own: facets(&self.own),
            facing: facets(&self.facing),
            reach: self.reach,
            kind: mesh.kind,
            segmented: self.segmented,
        }
    }
}

impl Surfaces<'_> {
    /// The node pairs of the two surfaces' cells that may couple: those of facets within
    /// `reach` of each other on the reference configuration (the matrix pattern's couplings).
    pub fn couplings(&self, mesh: &Mesh) -> Vec<(u32, u32)> {
        let surface = Surface::new(mesh, self.facing, &vec![0.0; mesh.num_nodes() * mesh.dim()]);
        let mut out = Vec::new();
        for f in self.own {
            let own_nodes = mesh.cell(f.cell as usize);
            let (mut lower, mut upper) = ([0.0; 3], [0.0; 3]);
            for r in 0..mesh.dim() {
                let along =
                    mesh.kind.facet_nodes(f.local as usize).into_iter().map(|a| mesh.node(own_nodes[a] as usize)[r]);
                let (lo, hi) = along.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)));
                (lower[r], upper[r]) = (lo - self.reach, hi + self.reach);
            }
            let near = surface.within(lower, upper);
            for &k in &near {
                let other = mesh.cell(self.facing[k].cell as usize);
                out.extend(own_nodes.iter().flat_map(|&a| other.iter().map(move |&b| (a, b))));
                // By segments, a cut moves with the facing facets on both of its sides.
                if self.segmented {
                    for &j in &near {
                        let beside = mesh.cell(self.facing[j].cell as usize);
                        out.extend(other.iter().flat_map(|&a| beside.iter().map(move |&b| (a, b))));
                    }
                }
            }
        }
        out.sort_unstable();
        out.dedup();
        out
    }
}

/// Where one surface's node lies deepest inside the other body.
#[derive(Clone, Debug, PartialEq)]
pub struct Overlap {
    /// The node's position on the configuration.
    pub point: Vec<f64>,
    /// How far inside the other body, along its outward normal at the facing point.
    pub depth: f64,
    /// The size of the node's cell.
    pub cell_size: f64,
}

impl Surfaces<'_> {
    /// The own surface's node deepest inside the facing body on the configuration x + `u`,
    /// measured along the facing facet's outward normal (none: no node is inside).
    pub fn deepest_overlap(&self, mesh: &Mesh, u: &[f64]) -> Option<Overlap> {
        let d = mesh.dim();
        let surface = Surface::new(mesh, self.facing, u);
        let mut deepest: Option<Overlap> = None;
        for f in self.own {
            let cell = mesh.cell(f.cell as usize);
            for a in mesh.kind.facet_nodes(f.local as usize) {
                let node = cell[a] as usize;
                let p: Vec<f64> = (0..d).map(|r| mesh.node(node)[r] + u[node * d + r]).collect();
                let Some(facing) = surface.closest(&p, self.reach) else { continue };
                let (normal, _) = mesh.facet_normal_and_centroid(self.facing[facing.facet]);
                let depth = -(0..d).map(|r| (p[r] - facing.point[r]) * normal[r]).sum::<f64>();
                if depth > 0.0 && deepest.as_ref().is_none_or(|o| depth > o.depth) {
                    deepest = Some(Overlap { point: p, depth, cell_size: mesh.cell_size(f.cell as usize) });
                }
            }
        }
        deepest
    }
}

/// The most space dimensions a pair point holds.
pub const MAX_DIM: usize = 3;

/// A field's value, gradient and (on the facing side of a P2 pair) second derivatives at a
/// point.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FieldAt {
    pub value: [f64; MAX_DIM],
    /// `grad[k][l]` = ∂_l u_k.
    pub grad: [[f64; MAX_DIM]; MAX_DIM],
    /// `hess[k][l][m]` = ∂_l ∂_m u_k: the gradient's rate as the facing point slides.
    pub hess: [[[f64; MAX_DIM]; MAX_DIM]; MAX_DIM],
}

/// One side of a pair at a point: its reference position, the outward unit normal of its body
/// there, the diameter of the cell carrying the facet, and the fields (the form's arguments,
/// then the previous level if it reads it).
#[derive(Clone, Debug, Default)]
pub struct SideAt {
    pub x: [f64; MAX_DIM],
    pub normal: [f64; MAX_DIM],
    /// `normal_rate[k][r]` = ∂_r n_k along the surface (the facing side's curvature on curved
    /// P2 facets; zero across the surface): the normal's rate as the facing point slides.
    pub normal_rate: [[f64; MAX_DIM]; MAX_DIM],
    pub h: f64,
    pub fields: Vec<FieldAt>,
}

/// A quadrature point of a pair's own surface and the point facing it.
#[derive(Clone, Debug, Default)]
pub struct PairPoint {
    pub dim: usize,
    pub t: f64,
    pub own: SideAt,
    pub facing: SideAt,
}

/// Sizes of a kernel's outputs in dimension `d`.
pub mod layout {
    /// The residual's coefficients: f0 (d), f1 (d²) of the own test function, then h0, h1 of
    /// the facing one (`IntegralIr` and `PairIr` conventions of the compiler).
    pub fn residual(d: usize) -> usize {
        2 * (d + d * d)
    }

    /// One tangent block: c00 (d²), c01 (d³), c10 (d³), c11 (d⁴).
    pub fn block(d: usize) -> usize {
        d * d + 2 * d * d * d + d * d * d * d
    }

    /// The tangent's four blocks, (own test, own trial), (own, facing), (facing, own),
    /// (facing, facing), one after the other; then the residual's coefficients, and their rates
    /// as the facing point slides along each axis (`[c·d + r]`), for the part of the tangent
    /// through the facing point's motion.
    pub fn tangent(d: usize) -> usize {
        4 * block(d) + residual(d) * (1 + d)
    }
}

/// The kernels of a pair law's form: pointwise coefficients, which the assembly weights and
/// contracts. `region` indexes `meta().facets`.
pub trait PairKernel: Form + Send + Sync {
    /// Whether the law integrates over each surface of its pair in turn (the facing one as its
    /// own, with the facing body's params), not over the pair's own surface only.
    fn both_sides(&self) -> bool {
        false
    }
    /// Writes the residual's coefficients ([`layout::residual`]); false if the form has no
    /// residual on `region` (a functional, or an integrand that is zero).
    fn residual_at(&self, region: usize, p: &PairPoint, out: &mut [f64]) -> bool;
    /// Writes the tangent's blocks with respect to field `wrt` ([`layout::tangent`]).
    fn tangent_at(&self, region: usize, p: &PairPoint, wrt: usize, out: &mut [f64]) -> bool;
    /// A functional's integrand.
    fn value_at(&self, region: usize, p: &PairPoint) -> f64;
}
