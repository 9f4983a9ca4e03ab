//! A pair law's form bound to two surfaces of a mesh: at each quadrature point of its own
//! surface, the facing point on the other surface's deformed configuration, the kernel's
//! coefficients there, and their contraction with the basis functions of both cells into an
//! element of both cells' nodes.

use std::sync::{Arc, Mutex, OnceLock};

use super::{FieldAt, LostFacing, MAX_DIM, PairKernel, PairPoint, SideAt, Surfaces, layout};
use crate::fem::assembly::Assembler;
use crate::fem::assembly::PointValue;
use crate::fem::bound::{BoundForm, BoundFunctional};
use crate::fem::element::ElementKind;
use crate::fem::facing::{Facing, Surface};
use crate::fem::mesh::{Facet, Mesh};
use crate::fem::quadrature::Rule;
use crate::fem::quadrature::simplex_rule;
use crate::fem::search_cost::{Meter, SearchCost};
use crate::linalg::Matrix;
use std::time::Instant;

mod curvature;
mod segments;
mod sliding;

use segments::Cut;

/// The basis of a cell at a reference point: values and reference gradients.
struct Tabulated {
    weight: f64,
    phi: Vec<f64>,
    dref: Vec<Vec<f64>>,
}

/// A local facet's points (weights on the reference facet, times its measure) with the basis
/// there, and its reference normal.
type Points = (Vec<Tabulated>, Vec<f64>);

/// `rule`'s points on each local facet of `kind`'s element.
fn tabulate(kind: ElementKind, rule: &Rule) -> Vec<Points> {
    (0..kind.facets().len())
        .map(|f| {
            let points = rule
                .points
                .iter()
                .zip(&rule.weights)
                .map(|(s, w)| {
                    let (xi, scale) = kind.facet_point(f, s);
                    Tabulated { weight: w * scale, phi: kind.basis(&xi), dref: kind.basis_gradients(&xi) }
                })
                .collect();
            (points, kind.reference_normal(f))
        })
        .collect()
}

/// A quadrature point of the own surface: its facet (index in the own facets), its basis,
/// and what it faces.
struct OwnPoint {
    facet: u32,
    at: At,
    facing: Option<Facing>,
}

/// The own points of an evaluation, and where its facets are cut (by segments).
struct Placed {
    points: Vec<OwnPoint>,
    cuts: Vec<Cut>,
}

/// An own point's basis: a point of the rule on its local facet, or a point of one piece of
/// a segmented facet, tabulated for it.
enum At {
    Rule(u32),
    Piece(Tabulated),
}

/// A pair law's form on a pair of surfaces.
pub struct PairForm<'m> {
    kernel: Box<dyn PairKernel + 'm>,
    /// The index of the law's integral among its facet regions (`meta().facets`).
    region: usize,
    own: &'m [Facet],
    facing: &'m [Facet],
    /// The farthest a facing point is looked for: points with no facet of the other surface
    /// within it face nothing.
    reach: f64,
    /// The quadrature points of each local facet of the element.
    rule: Vec<Points>,
    /// The rule on the reference facet, and whether (2D) each own facet is integrated piece
    /// by piece: cut where its points' facing point crosses an end of a facing facet.
    base: Rule,
    segmented: bool,
    /// Per local facet, its edge vectors e_α in the reference cell (ξ(s) = ξ0 + Σ s_α e_α).
    edges: Vec<Vec<[f64; MAX_DIM]>>,
    /// The reference second derivatives of the element's basis (constant on a cell).
    hessians: Vec<Vec<Vec<f64>>>,
    /// A coupling the matrix pattern lacks, met by the last tangent: the two nodes.
    missing: Mutex<Option<(u32, u32)>>,
    /// What its search and assembly have cost.
    meter: Meter,
    /// The nodes whose displacement moves its facing points: those of the own and the facing
    /// facets' cells (found at the first evaluation).
    moved_by: OnceLock<Vec<u32>>,
    /// The facing points of the last evaluation, per quadrature point of the own surface in
    /// order, with the displacement of `moved_by` they were found at: a tangent or functional
    /// at the residual's state (each Newton iterate's) searches no more.
    found: Mutex<Option<Found>>,
    /// Per quadrature point of the own surface, how far the facing surface was when the point
    /// last faced it (NaN: never), and the first point of the last search that faced it within
    /// half the reach and now faces nothing: lost, not parted.
    seen: Mutex<Vec<f64>>,
    lost: Mutex<Option<LostFacing>>,
}

/// The own points and their facing points, with the displacement they were found at.
type Found = (Vec<f64>, Arc<Placed>);

/// A facing point overshoots its facet by more than this, relative to its distance, where it
/// is held at the facet's end (round-off leaves about 1e-16 where it is inside).
const HELD: f64 = 1e-8;

/// The field whose displacement places both surfaces, so that the facing points and the
/// tangent's sliding part follow it: the law's first (`u` of `contact(u; v)`, the step's end u
/// of `friction_work(u, w)`).
const CONFIGURATION: usize = 0;

/// Where a quadrature point's facing point is, and both cells' basis functions there.
struct PairElement {
    point: PairPoint,
    /// The quadrature weight times the own facet's measure ratio.
    weight: f64,
    /// The own cell's nodes, then the facing cell's.
    nodes: Vec<u32>,
    phi: Vec<f64>,
    /// Physical gradients, per node.
    dphi: Vec<[f64; MAX_DIM]>,
    /// The facing facet's tangents T_α = ∂y/∂s_α on the reference configuration.
    tangents: Vec<[f64; MAX_DIM]>,
    /// Whether the facing point slides as the bodies move: not where it is held at a facet's
    /// end (the point overshoots the facet, in the wedge between two facets' normals there).
    slides: bool,
    /// The facing side's second-order data (P2 cells).
    curvature: Option<curvature::Curvature>,
}

impl<'m> PairForm<'m> {
    /// The law's integral over region `region` of its facets, on the facets `own`, facing
    /// `facing`, with quadrature `degree` on the own facets.
    pub fn new(
        kernel: Box<dyn PairKernel + 'm>,
        region: usize,
        kind: ElementKind,
        own: &'m [Facet],
        facing: &'m [Facet],
        degree: u32,
        reach: f64,
    ) -> Self {
        let d = kind.dim();
        let base = simplex_rule(d - 1, degree);
        let rule = tabulate(kind, &base);
        let edges = (0..kind.facets().len())
            .map(|f| {
                let (xi0, _) = kind.facet_point(f, &vec![0.0; d - 1]);
                (0..d - 1)
                    .map(|a| {
                        let mut s = vec![0.0; d - 1];
                        s[a] = 1.0;
                        let (xi, _) = kind.facet_point(f, &s);
                        std::array::from_fn(|r| if r < d { xi[r] - xi0[r] } else { 0.0 })
                    })
                    .collect()
            })
            .collect();
        PairForm {
            kernel,
            region,
            own,
            facing,
            reach,
            rule,
            base,
            segmented: false,
            edges,
            hessians: kind.basis_hessians(),
            missing: Mutex::new(None),
            meter: Meter::default(),
            moved_by: OnceLock::new(),
            found: Mutex::new(None),
            seen: Mutex::new(Vec::new()),
            lost: Mutex::new(None),
        }
    }

    /// Integrated segment by segment when `on` (2D; 3D facets are integrated whole): each own
    /// facet cut where its points' facing point crosses an end of a facing facet, where the
    /// integrand has a kink (the facing basis) or a jump (the facing normal), the rule on each
    /// piece. Non-matching meshes then pass the contact patch test.
    pub fn segmented(mut self, on: bool) -> Self {
        self.segmented = on && self.base.points.first().is_some_and(|p| p.len() == 1);
        self
    }

    /// The node pairs its tangent may couple ([`Surfaces::couplings`]).
    pub fn couplings(&self, mesh: &Mesh) -> Vec<(u32, u32)> {
        let segmented = self.segmented;
        Surfaces { own: self.own, facing: self.facing, reach: self.reach, kind: mesh.kind, segmented }.couplings(mesh)
    }

    /// The coupling the pattern lacked at the last tangent, if any: a facing point farther on
    /// the reference configuration than the pair's reach.
    pub fn missing_coupling(&self) -> Option<(u32, u32)> {
        self.missing.lock().ok().and_then(|m| *m)
    }

    /// Calls `each` at every quadrature point of the own surface that faces the other one.
    /// With `curved`, each element carries the facing side's second-order data (a tangent's
    /// sliding part on P2 reads it; a residual or a value does not).
    fn each_point(&self, mesh: &Mesh, fields: &[&[f64]], t: f64, curved: bool, each: impl FnMut(&PairElement)) {
        self.each_point_of(&self.rule, mesh, fields, t, curved, each);
    }

    /// [`PairForm::each_point`] at the points of `rule` (per local facet: the points, and the
    /// reference normal); the facing points are kept for the form's own rule only.
    fn each_point_of(
        &self,
        rule: &[Points],
        mesh: &Mesh,
        fields: &[&[f64]],
        t: f64,
        curved: bool,
        mut each: impl FnMut(&PairElement),
    ) {
        // Bound to a body that does not own the pair: no point, so no search to build.
        if self.own.is_empty() {
            return;
        }
        let started = Instant::now();
        let moving = fields.get(CONFIGURATION).copied().unwrap_or(&[]);
        let placed = self.facing_points(rule, mesh, moving);
        for point in &placed.points {
            let Some(facing) = &point.facing else { continue };
            let f = self.own[point.facet as usize];
            let (points, ref_normal) = &rule[f.local as usize];
            let q = match &point.at {
                At::Rule(i) => &points[*i as usize],
                At::Piece(q) => q,
            };
            each(&self.element(mesh, f, q, ref_normal, facing, fields, t, curved));
        }
        self.meter.evaluated(started);
    }

    /// The element of own point `q` of facet `f` (reference normal `ref_normal`) facing
    /// `facing`; with `curved`, its facing side's second-order data on P2 cells.
    #[allow(clippy::too_many_arguments)]
    fn element(
        &self,
        mesh: &Mesh,
        f: Facet,
        q: &Tabulated,
        ref_normal: &[f64],
        facing: &Facing,
        fields: &[&[f64]],
        t: f64,
        curved: bool,
    ) -> PairElement {
        let d = mesh.dim();
        let own = side(mesh, f.cell as usize, &q.phi, &q.dref, ref_normal, fields);
        let g = self.facing[facing.facet];
        let kind = mesh.kind;
        let (phi, dref) = (kind.basis(&facing.xi), kind.basis_gradients(&facing.xi));
        let facing_normal = kind.reference_normal(g.local as usize);
        let mut other = side(mesh, g.cell as usize, &phi, &dref, &facing_normal, fields);
        let edges = &self.edges[g.local as usize];
        let curvature = (curved && kind.degree() > 1).then(|| {
            curvature::curvature(mesh, g.cell as usize, &self.hessians, &mut other, &facing_normal, edges, fields)
        });
        let tangents =
            edges.iter().map(|e| std::array::from_fn(|r| (0..d).map(|c| other.jacobian[r][c] * e[c]).sum())).collect();
        let nodes = mesh.cell(f.cell as usize).iter().chain(mesh.cell(g.cell as usize)).copied().collect();
        PairElement {
            weight: q.weight * own.scale,
            nodes,
            phi: q.phi.iter().chain(&phi).copied().collect(),
            dphi: own.dphi.into_iter().chain(other.dphi).collect(),
            tangents,
            slides: facing.overshoot <= HELD * facing.distance,
            curvature,
            point: PairPoint { dim: d, t, own: own.side, facing: other.side },
        }
    }

    /// The weighted residual of element `e` from the kernel's coefficients `r`, per node of the
    /// element and component (`each(a, k, value)`).
    fn contract(e: &PairElement, r: &[f64], d: usize, mut each: impl FnMut(usize, usize, f64)) {
        let half = e.nodes.len() / 2;
        for a in 0..e.nodes.len() {
            let off = if a < half { 0 } else { d + d * d };
            for k in 0..d {
                let mut v = r[off + k] * e.phi[a];
                for l in 0..d {
                    v += r[off + d + k * d + l] * e.dphi[a][l];
                }
                each(a, k, e.weight * v);
            }
        }
    }
}

/// One side's data at a point of a cell, its basis' physical gradients, and the facet measure
/// ratio (Nanson).
struct Side {
    side: SideAt,
    dphi: Vec<[f64; MAX_DIM]>,
    scale: f64,
    /// J = ∂x/∂ξ on the reference configuration.
    jacobian: [[f64; MAX_DIM]; MAX_DIM],
}

fn side(mesh: &Mesh, cell: usize, phi: &[f64], dref: &[Vec<f64>], ref_normal: &[f64], fields: &[&[f64]]) -> Side {
    let d = mesh.dim();
    let nodes = mesh.cell(cell);
    let mut j = [[0.0; MAX_DIM]; MAX_DIM];
    let mut x = [0.0; MAX_DIM];
    for (a, &n) in nodes.iter().enumerate() {
        let p = mesh.node(n as usize);
        for r in 0..d {
            x[r] += phi[a] * p[r];
            for c in 0..d {
                j[r][c] += p[r] * dref[a][c];
            }
        }
    }
    let (det, inv) = invert(&j, d);
    // ∇φ = J⁻ᵀ ∇_ξ φ; n ∝ J⁻ᵀ N.
    let dphi: Vec<[f64; MAX_DIM]> = dref
        .iter()
        .map(|g| std::array::from_fn(|l| if l < d { (0..d).map(|b| inv[b][l] * g[b]).sum() } else { 0.0 }))
        .collect();
    let mut normal: [f64; MAX_DIM] =
        std::array::from_fn(|l| if l < d { (0..d).map(|b| inv[b][l] * ref_normal[b]).sum() } else { 0.0 });
    let size = normal.iter().map(|v| v * v).sum::<f64>().sqrt();
    normal.iter_mut().for_each(|v| *v /= size);
    let fields = fields
        .iter()
        .map(|u| {
            let mut at = FieldAt::default();
            for (a, &n) in nodes.iter().enumerate() {
                for k in 0..d {
                    let ua = u.get(n as usize * d + k).copied().unwrap_or(f64::NAN);
                    at.value[k] += phi[a] * ua;
                    for l in 0..d {
                        at.grad[k][l] += dphi[a][l] * ua;
                    }
                }
            }
            at
        })
        .collect();
    let side = SideAt { x, normal, normal_rate: [[0.0; MAX_DIM]; MAX_DIM], h: mesh.cell_size(cell), fields };
    Side { side, dphi, scale: size * det.abs(), jacobian: j }
}

/// The determinant and inverse of the leading d×d block.
fn invert(j: &[[f64; MAX_DIM]; MAX_DIM], d: usize) -> (f64, [[f64; MAX_DIM]; MAX_DIM]) {
    let mut inv = [[0.0; MAX_DIM]; MAX_DIM];
    match d {
        1 => {
            inv[0][0] = 1.0 / j[0][0];
            (j[0][0], inv)
        }
        2 => {
            let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
            inv[0][0] = j[1][1] / det;
            inv[0][1] = -j[0][1] / det;
            inv[1][0] = -j[1][0] / det;
            inv[1][1] = j[0][0] / det;
            (det, inv)
        }
        _ => {
            let c = |r: usize, s: usize| {
                let (r1, r2, s1, s2) = ((r + 1) % 3, (r + 2) % 3, (s + 1) % 3, (s + 2) % 3);
                j[r1][s1] * j[r2][s2] - j[r1][s2] * j[r2][s1]
            };
            let det = (0..3).map(|s| j[0][s] * c(0, s)).sum::<f64>();
            for r in 0..3 {
                for s in 0..3 {
                    inv[s][r] = c(r, s) / det;
                }
            }
            (det, inv)
        }
    }
}

impl BoundForm for PairForm<'_> {
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
        false
    }
    fn piecewise(&self) -> bool {
        false
    }
    /// The facing point's motion (and a master–slave law's one-sided test functions) make the
    /// tangent unsymmetric once the bodies touch.
    fn may_be_symmetric(&self) -> bool {
        false
    }
    fn search_cost(&self) -> SearchCost {
        self.meter.cost()
    }
    fn searches(&self) -> bool {
        true
    }
    fn lost_facing(&self) -> Option<LostFacing> {
        self.lost.lock().ok().and_then(|l| l.clone())
    }

    fn residual(&self, asm: &Assembler, fields: &[&[f64]], t: f64, out: &mut [f64]) {
        let mesh = asm.mesh();
        let d = mesh.dim();
        let mut r = vec![0.0; layout::residual(d)];
        self.each_point(mesh, fields, t, false, |e| {
            r.fill(0.0);
            if !self.kernel.residual_at(self.region, &e.point, &mut r) {
                return;
            }
            Self::contract(e, &r, d, |a, k, v| out[e.nodes[a] as usize * d + k] += v);
        });
    }

    fn tangent(&self, asm: &Assembler, fields: &[&[f64]], wrt: usize, t: f64, m: &mut Matrix) {
        let mesh = asm.mesh();
        let d = mesh.dim();
        let mut c = vec![0.0; layout::tangent(d)];
        let block = layout::block(d);
        let mut missing = None;
        let pattern = m.pattern.clone();
        let moving = CONFIGURATION;
        let mut ke = Vec::new();
        self.each_point(mesh, fields, t, wrt == moving, |e| {
            c.fill(0.0);
            if !self.kernel.tangent_at(self.region, &e.point, wrt, &mut c) {
                return;
            }
            let (n, half) = (e.nodes.len(), e.nodes.len() / 2);
            ke.clear();
            ke.resize(n * d * n * d, 0.0);
            // Per block (own/facing test × own/facing trial), which of its gradient parts are
            // not zero: a law that reads no gradient on a side skips their products (adding
            // zeros changes no sum).
            let parts: [[bool; 2]; 4] = std::array::from_fn(|blk| {
                let at = blk * block;
                let nonzero = |r: std::ops::Range<usize>| c[r].iter().any(|v| *v != 0.0);
                [nonzero(at + d * d..at + d * d + d * d * d), nonzero(at + d * d + d * d * d..at + block)]
            });
            // By stages: each test function's coefficients against a trial value and gradient
            // (p, q), then against each trial function: O(n d⁴ + n² d³), not O(n² d⁴).
            for a in 0..n {
                let (pa, ga) = (e.weight * e.phi[a], e.dphi[a].map(|g| e.weight * g));
                for trial_side in 0..2 {
                    let blk = 2 * usize::from(a >= half) + trial_side;
                    let at = blk * block;
                    let [trial_gradient, test_gradient] = parts[blk];
                    let (c00, c01) = (&c[at..], &c[at + d * d..]);
                    let (c10, c11) = (&c[at + d * d + d * d * d..], &c[at + d * d + 2 * d * d * d..]);
                    let mut p = [[0.0; MAX_DIM]; MAX_DIM];
                    let mut q = [[[0.0; MAX_DIM]; MAX_DIM]; MAX_DIM];
                    for k in 0..d {
                        for mm in 0..d {
                            let mut v = c00[k * d + mm] * pa;
                            if test_gradient {
                                for l in 0..d {
                                    v += c10[(k * d + l) * d + mm] * ga[l];
                                }
                            }
                            p[k][mm] = v;
                            if trial_gradient || test_gradient {
                                for nn in 0..d {
                                    let mut w = c01[(k * d + mm) * d + nn] * pa;
                                    if test_gradient {
                                        for l in 0..d {
                                            w += c11[((k * d + l) * d + mm) * d + nn] * ga[l];
                                        }
                                    }
                                    q[k][mm][nn] = w;
                                }
                            }
                        }
                    }
                    let gradients = trial_gradient || test_gradient;
                    for b in trial_side * half..(trial_side + 1) * half {
                        let (pb, gb) = (e.phi[b], &e.dphi[b]);
                        for k in 0..d {
                            let row = &mut ke[(a * d + k) * n * d + b * d..][..d];
                            for (mm, slot) in row.iter_mut().enumerate() {
                                let mut v = p[k][mm] * pb;
                                if gradients {
                                    for nn in 0..d {
                                        v += q[k][mm][nn] * gb[nn];
                                    }
                                }
                                *slot += v;
                            }
                        }
                    }
                }
            }
            if wrt == moving {
                self.add_sliding(e, &c[4 * block..], d, &mut ke);
            }
            // Points apart (a zero element) need no coupling.
            if ke.iter().all(|v| *v == 0.0) {
                return;
            }
            if let Err(pair) = pattern.scatter_nodes(&e.nodes, &ke, |pos, v| m.values[pos] += v) {
                missing = Some(pair);
            }
        });
        if wrt == moving && self.segmented && !self.own.is_empty() {
            let placed = self.facing_points(&self.rule, mesh, fields[moving]);
            if let Some(pair) = self.add_cuts(mesh, &placed.cuts, fields, t, m) {
                missing = Some(pair);
            }
        }
        if let Some((a, b)) = missing {
            // The residual stays exact: Newton converges to the same state with this Jacobian,
            // only more slowly, as it does in a step's first, far-off iterates.
            tracing::warn!(
                "contact pair `{}`: nodes {a} and {b} face each other but were farther apart than the pair's reach ({}) on the reference configuration, so the Jacobian leaves out their coupling (Newton may converge slowly): raise `within` on the problem's `contact` line",
                self.kernel.meta().name,
                self.reach
            );
        }
        if let Ok(mut slot) = self.missing.lock() {
            *slot = missing;
        }
    }

    /// The facing points move with the fields: the tangent is never decided by switches.
    fn switches(&self, _: &Assembler, _: &[&[f64]], _: usize, _: f64, _: &mut Vec<bool>) -> bool {
        false
    }
}

impl PairForm<'_> {
    /// The quadrature points of the own surface, in order, each with its facing point on the
    /// configuration x + `moving`: the last evaluation's if the displacement that moves them
    /// is the same, else placed and searched anew.
    fn facing_points(&self, rule: &[Points], mesh: &Mesh, moving: &[f64]) -> Arc<Placed> {
        let own_rule = std::ptr::eq(rule, self.rule.as_slice());
        let d = mesh.dim();
        let moved_by = self.moved_by.get_or_init(|| {
            let mut nodes: Vec<u32> =
                self.own.iter().chain(self.facing).flat_map(|f| mesh.cell(f.cell as usize)).copied().collect();
            nodes.sort_unstable();
            nodes.dedup();
            nodes
        });
        let at = |n: u32, k: usize| moving.get(n as usize * d + k).copied().unwrap_or(0.0);
        let key: Vec<f64> = moved_by.iter().flat_map(|&n| (0..d).map(move |k| at(n, k))).collect();
        let mut last = self.found.lock().unwrap_or_else(|e| e.into_inner());
        if own_rule
            && let Some((k, found)) = last.as_ref()
            && k.iter().zip(&key).all(|(a, b)| a.to_bits() == b.to_bits())
        {
            return found.clone();
        }
        let started = Instant::now();
        let surface = Surface::new(mesh, self.facing, moving);
        self.meter.built(started);
        let mut placed = Vec::new();
        let mut cuts = Vec::new();
        let mut seen = self.seen.lock().unwrap_or_else(|e| e.into_inner());
        if own_rule {
            seen.resize(self.own.len(), f64::NAN);
        }
        let mut lost = None;
        // Per point of the facet at hand: where it is, and how far it faces the surface (none:
        // nothing within the reach).
        let mut distances: Vec<([f64; MAX_DIM], Option<f64>)> = Vec::new();
        for (i, f) in self.own.iter().enumerate() {
            let cell = mesh.cell(f.cell as usize);
            // A point of the facet on the configuration, x + u summed as `side` sums them.
            let position = |phi: &[f64]| -> [f64; MAX_DIM] {
                let mut p = [0.0; MAX_DIM];
                for (a, &n) in cell.iter().enumerate() {
                    for (k, pk) in p.iter_mut().enumerate().take(d) {
                        *pk += phi[a] * (mesh.node(n as usize)[k] + at(n, k));
                    }
                }
                p
            };
            distances.clear();
            let mut place = |at: At, phi: &[f64]| {
                let p = position(phi);
                let asked = Instant::now();
                let nearest = surface.nearest(&p[..d], self.reach);
                self.meter.queried(asked);
                distances.push((p, nearest.as_ref().map(|b| b.distance)));
                placed.push(OwnPoint { facet: i as u32, at, facing: nearest.filter(|b| !b.beyond) });
            };
            if own_rule && self.segmented {
                let (pieces, facet_cuts) = self.pieces(i as u32, *f, mesh, &position, &surface);
                cuts.extend(facet_cuts);
                for (a, b) in pieces {
                    for (s, w) in self.base.points.iter().zip(&self.base.weights) {
                        let (xi, scale) = mesh.kind.facet_point(f.local as usize, &[a + (b - a) * s[0]]);
                        let q = Tabulated {
                            weight: w * (b - a) * scale,
                            phi: mesh.kind.basis(&xi),
                            dref: mesh.kind.basis_gradients(&xi),
                        };
                        let phi = q.phi.clone();
                        place(At::Piece(q), &phi);
                    }
                }
            } else {
                for (k, q) in rule[f.local as usize].0.iter().enumerate() {
                    place(At::Rule(k as u32), &q.phi);
                }
            }
            if own_rule {
                // Lost: every point of the facet faced the surface within half the reach, and
                // one of them now faces nothing.
                if lost.is_none()
                    && seen[i] <= 0.5 * self.reach
                    && let Some((p, _)) = distances.iter().find(|(_, r)| r.is_none())
                {
                    lost = Some(LostFacing {
                        form: self.kernel.meta().name.to_string(),
                        point: p[..d].to_vec(),
                        distance: seen[i],
                        reach: self.reach,
                    });
                }
                seen[i] =
                    distances.iter().try_fold(0.0, |most: f64, (_, r)| r.map(|r| most.max(r))).unwrap_or(f64::NAN);
            }
        }
        let placed = Arc::new(Placed { points: placed, cuts });
        if own_rule {
            *last = Some((key, placed.clone()));
            *self.lost.lock().unwrap_or_else(|e| e.into_inner()) = lost;
        }
        placed
    }
}

impl BoundFunctional for PairForm<'_> {
    fn name(&self) -> &str {
        &self.kernel.meta().name
    }
    fn fields(&self) -> usize {
        self.kernel.meta().fields.len()
    }
    fn value(&self, asm: &Assembler, fields: &[&[f64]], t: f64) -> f64 {
        pair_value(self, asm.mesh(), fields, t)
    }
    /// A pair law has no volume integral.
    fn cell_values(&self, asm: &Assembler, _: &[&[f64]], _: f64) -> Vec<f64> {
        vec![0.0; asm.mesh().num_cells()]
    }
    /// The integrand at the points of `rule` on the own surface's facets that face the other
    /// surface (a point facing nothing is left out), at their reference positions.
    fn facet_point_values(&self, asm: &Assembler, rule: &Rule, fields: &[&[f64]], t: f64) -> Vec<PointValue> {
        let mesh = asm.mesh();
        let d = mesh.dim();
        let mut out = Vec::new();
        self.each_point_of(&tabulate(mesh.kind, rule), mesh, fields, t, false, |e| {
            out.push(PointValue {
                x: e.point.own.x[..d].to_vec(),
                normal: e.point.own.normal[..d].to_vec(),
                weight: e.weight,
                value: self.kernel.value_at(self.region, &e.point),
            })
        });
        out
    }
}

/// The integral of a pair law's functional over its own surface.
pub fn pair_value(form: &PairForm<'_>, mesh: &Mesh, fields: &[&[f64]], t: f64) -> f64 {
    let mut sum = 0.0;
    form.each_point(mesh, fields, t, false, |e| sum += e.weight * form.kernel.value_at(form.region, &e.point));
    sum
}
