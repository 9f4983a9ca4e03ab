//! The facing point of a point on a surface of the mesh (another body's contact region), on the
//! deformed configuration: the closest point of the surface's facets, curved P2 facets
//! included. A broad phase keeps the facets whose bounding box meets a box about the point
//! (an R-tree of the boxes, `rstar`, rebuilt in O(n log n) whenever the surface moves); a narrow
//! phase projects the point onto each of them. Against bvh's hierarchy (`cargo bench -p
//! signorini-runtime --bench spatial_index`, docs/mathematics.md §9) its queries are slower
//! alone but it builds faster, and the two runs cost the same.
//!
//! A curved facet is a quadratic Bézier curve (a triangular patch in 3D) whose control points
//! are its vertices and, for each edge, 2m − (a + b)/2 with m the edge node: the facet lies in
//! their convex hull, so their box bounds it. The projection minimises |x(s) − p|² over the
//! reference facet by Gauss–Newton steps kept inside it (the closest point of a facet may be
//! on its boundary).
//!
//! A point past the surface's border (its closest point on an end of the surface, reached
//! along a direction that is not the surface's normal there) faces no point of it: the gap
//! along the facing normal would measure a penetration that is not there.

use rstar::primitives::{GeomWithData, Rectangle};
use rstar::{AABB, PointDistance, RTree};

use crate::fem::mesh::{Facet, Mesh};

/// Where a point faces a surface.
#[derive(Clone, Debug, PartialEq)]
pub struct Facing {
    /// The facet's index in the surface's list.
    pub facet: usize,
    /// The point in the reference cell of the facet's cell.
    pub xi: Vec<f64>,
    /// The facing point on the deformed surface.
    pub point: Vec<f64>,
    /// Its distance to the point.
    pub distance: f64,
    /// Whether the point lies past the surface's border: its closest point is on the border
    /// and not straight along the normal there.
    pub beyond: bool,
    /// How far the point lies past the facet's boundary along the facet (the part of p − y
    /// along its tangents; zero where y is inside): of two facets equally near, through their
    /// common end, the point faces the one it overshoots least.
    pub overshoot: f64,
}

/// An end of a facet (2D), for the motion of the line through it normal to the facet.
#[derive(Clone, Debug)]
pub struct End {
    pub point: [f64; 3],
    pub tangent: [f64; 3],
    pub node: u32,
    pub weights: Vec<(u32, f64)>,
}

impl Facing {
    /// Whether it is nearer than `other`; of two equally near (both at their common end, to
    /// round-off), the one the point overshoots least, so that the choice changes on a line
    /// (the bisector of the two facets' ends) and not where a search happens to break a tie.
    fn nearer_than(&self, other: &Facing) -> bool {
        let tie = TIE * self.distance.max(other.distance);
        match self.distance < other.distance - tie {
            true => true,
            false => self.distance <= other.distance + tie && self.overshoot < other.overshoot,
        }
    }
}

/// Distances this close, relative, are equal.
const TIE: f64 = 1e-12;

type Boxed = GeomWithData<Rectangle<[f64; 3]>, u32>;

/// Facets of a mesh on a deformed configuration, indexed for closest-point queries.
pub struct Surface<'m> {
    mesh: &'m Mesh,
    facets: &'m [Facet],
    /// The displacement of the configuration (node-major, the mesh's dimension).
    u: Vec<f64>,
    tree: RTree<Boxed>,
    /// Per local facet of the element: its nodes and its map into the reference cell.
    frames: Vec<Frame>,
    /// The surface's border: in 2D its end nodes (a vertex of one facet), in 3D its edges of
    /// one facet (sorted vertex pairs), sorted for search.
    border: Vec<[u32; 2]>,
}

/// A local facet of the element: its own Lagrange basis on the reference facet (the interval
/// [0, 1] or the triangle), with λ0 = 1 − Σ s_j and λ_{j+1} = s_j its barycentric coordinates,
/// and its map into the reference cell ξ(s) = ξ0 + Σ_j s_j e_j.
struct Frame {
    /// The cell's local nodes at the facet's vertices, in the order of λ.
    vertices: Vec<usize>,
    /// The edge nodes (P2): the local node and the positions in `vertices` of its edge's ends.
    mids: Vec<(usize, usize, usize)>,
    xi0: Vec<f64>,
    edges: Vec<Vec<f64>>,
}

impl Frame {
    fn new(kind: crate::fem::element::ElementKind, facet: usize) -> Frame {
        let d = kind.dim();
        let (xi0, _) = kind.facet_point(facet, &vec![0.0; d - 1]);
        let edges = (0..d - 1)
            .map(|j| {
                let mut s = vec![0.0; d - 1];
                s[j] = 1.0;
                let (xi, _) = kind.facet_point(facet, &s);
                xi.iter().zip(&xi0).map(|(a, b)| a - b).collect()
            })
            .collect();
        let local = kind.facet_nodes(facet);
        let vertices = local[..d].to_vec();
        let reference = kind.reference_nodes();
        let mids = local[d..]
            .iter()
            .map(|&m| {
                let ends: Vec<usize> = (0..d).filter(|&i| is_end(&reference[vertices[i]], &reference[m])).collect();
                (m, ends[0], ends[1])
            })
            .collect();
        Frame { vertices, mids, xi0, edges }
    }

    /// The point x(s) = Σ ψ_b(s) y_b of the facet whose nodes are at `y` (vertices, then
    /// edge nodes), and with `tangents` its derivatives ∂x/∂s_j.
    fn point(&self, y: &[[f64; 3]; 6], s: &[f64], tangents: Option<&mut [[f64; 3]; 2]>) -> [f64; 3] {
        let n = self.vertices.len();
        let mut l = [0.0; 3];
        l[0] = 1.0 - s.iter().sum::<f64>();
        l[1..n].copy_from_slice(s);
        // ∂λ_i/∂s_j: −1 for λ0, δ_{i, j+1} otherwise.
        let dl = |i: usize, j: usize| -> f64 {
            if i == 0 {
                -1.0
            } else if i == j + 1 {
                1.0
            } else {
                0.0
            }
        };
        let quadratic = !self.mids.is_empty();
        let mut x = [0.0; 3];
        let mut t = [[0.0; 3]; 2];
        for i in 0..n {
            let (w, dw) = if quadratic { (l[i] * (2.0 * l[i] - 1.0), 4.0 * l[i] - 1.0) } else { (l[i], 1.0) };
            for r in 0..3 {
                x[r] += w * y[i][r];
                for (j, tj) in t.iter_mut().enumerate().take(n - 1) {
                    tj[r] += dw * dl(i, j) * y[i][r];
                }
            }
        }
        for (k, &(_, a, b)) in self.mids.iter().enumerate() {
            let yk = y[n + k];
            for r in 0..3 {
                x[r] += 4.0 * l[a] * l[b] * yk[r];
                for (j, tj) in t.iter_mut().enumerate().take(n - 1) {
                    tj[r] += 4.0 * (dl(a, j) * l[b] + l[a] * dl(b, j)) * yk[r];
                }
            }
        }
        if let Some(out) = tangents {
            *out = t;
        }
        x
    }
}

impl<'m> Surface<'m> {
    /// The facets on the configuration x + u.
    pub fn new(mesh: &'m Mesh, facets: &'m [Facet], u: &[f64]) -> Surface<'m> {
        let frames: Vec<Frame> = (0..mesh.kind.facets().len()).map(|facet| Frame::new(mesh.kind, facet)).collect();
        let border = border(mesh, facets, &frames);
        let mut surface = Surface { mesh, facets, u: u.to_vec(), tree: RTree::new(), frames, border };
        let boxes = (0..facets.len()).map(|k| surface.bounding_box(k)).collect();
        surface.tree = RTree::bulk_load(boxes);
        surface
    }

    /// The displaced position of a node.
    fn position(&self, node: usize) -> [f64; 3] {
        let d = self.mesh.dim();
        let mut y = [0.0; 3];
        for (k, y) in y.iter_mut().enumerate().take(d) {
            *y = self.mesh.node(node)[k] + self.u[node * d + k];
        }
        y
    }

    /// The box of facet `k`'s Bézier control points.
    fn bounding_box(&self, k: usize) -> Boxed {
        let f = self.facets[k];
        let frame = &self.frames[f.local as usize];
        let cell = self.mesh.cell(f.cell as usize);
        let mut points: Vec<[f64; 3]> = frame.vertices.iter().map(|&a| self.position(cell[a] as usize)).collect();
        // Edge nodes (P2): the control point 2m − (a + b)/2 of their edge.
        for &(m, a, b) in &frame.mids {
            let (m, a, b) = (self.position(cell[m] as usize), points[a], points[b]);
            points.push(std::array::from_fn(|r| 2.0 * m[r] - 0.5 * (a[r] + b[r])));
        }
        let lower = std::array::from_fn(|r| points.iter().map(|p| p[r]).fold(f64::INFINITY, f64::min));
        let upper = std::array::from_fn(|r| points.iter().map(|p| p[r]).fold(f64::NEG_INFINITY, f64::max));
        GeomWithData::new(Rectangle::from_corners(lower, upper), k as u32)
    }

    /// The closest point of the surface to `p` within `radius` (none: no facet within it, or
    /// the point is past the border of an open surface).
    pub fn closest(&self, p: &[f64], radius: f64) -> Option<Facing> {
        self.nearest(p, radius).filter(|b| !b.beyond)
    }

    /// The closest point of the surface to `p` within `radius`, past the border or not.
    pub fn nearest(&self, p: &[f64], radius: f64) -> Option<Facing> {
        let at: [f64; 3] = std::array::from_fn(|r| p.get(r).copied().unwrap_or(0.0));
        let around =
            AABB::from_corners(std::array::from_fn(|r| at[r] - radius), std::array::from_fn(|r| at[r] + radius));
        // Nearest boxes first: a facet whose box is further than the best point found so far
        // cannot hold a closer one.
        let mut candidates: Vec<(f64, usize)> = self
            .tree
            .locate_in_envelope_intersecting(around)
            .map(|c| (c.geom().distance_2(&at), c.data as usize))
            .collect();
        candidates.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut best: Option<Facing> = None;
        for (box_distance_2, k) in candidates {
            // (With a margin: a facet through the best point's end ties with it.)
            if best.as_ref().is_some_and(|b| box_distance_2 > b.distance * b.distance * (1.0 + 4.0 * TIE)) {
                break;
            }
            let facing = self.project(k, p);
            if facing.distance <= radius && best.as_ref().is_none_or(|b| facing.nearer_than(b)) {
                best = Some(facing);
            }
        }
        best
    }

    /// The facets whose boxes meet the box from `lower` to `upper` (coordinates past the mesh's
    /// dimension are 0).
    pub fn within(&self, lower: [f64; 3], upper: [f64; 3]) -> Vec<usize> {
        self.tree.locate_in_envelope_intersecting(AABB::from_corners(lower, upper)).map(|c| c.data as usize).collect()
    }

    /// The closest point of the surface to `p` by trying every facet (for checks).
    pub fn closest_by_every_facet(&self, p: &[f64]) -> Option<Facing> {
        (0..self.facets.len()).map(|k| self.project(k, p)).min_by(|a, b| a.distance.total_cmp(&b.distance))
    }

    /// The closest point of facet `k` to `p`.
    pub fn project(&self, k: usize, p: &[f64]) -> Facing {
        let (mesh, f) = (self.mesh, self.facets[k]);
        let d = mesh.dim();
        let frame = &self.frames[f.local as usize];
        let cell = mesh.cell(f.cell as usize);
        // The facet's nodes on the configuration: vertices, then edge nodes (P2).
        let mut y = [[0.0; 3]; 6];
        for (slot, &a) in y.iter_mut().zip(frame.vertices.iter().chain(frame.mids.iter().map(|(m, _, _)| m))) {
            *slot = self.position(cell[a] as usize);
        }
        let at: [f64; 3] = std::array::from_fn(|r| p.get(r).copied().unwrap_or(0.0));
        let mut s = [1.0 / d as f64; 2];
        for _ in 0..MAX_STEPS {
            let mut tangents = [[0.0; 3]; 2];
            let x = frame.point(&y, &s[..d - 1], Some(&mut tangents));
            let residual: [f64; 3] = std::array::from_fn(|r| at[r] - x[r]);
            let step = gauss_newton_step(&tangents[..d - 1], &residual);
            let before = s;
            for (sj, dj) in s.iter_mut().zip(&step[..d - 1]) {
                *sj += dj;
            }
            keep_in_facet(&mut s[..d - 1]);
            let moved = s.iter().zip(&before).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
            if moved < 1e-14 {
                break;
            }
        }
        // The point and its tangents where the steps ended.
        let mut tangents = [[0.0; 3]; 2];
        let x = frame.point(&y, &s[..d - 1], Some(&mut tangents));
        let xi = (0..d).map(|r| frame.xi0[r] + (0..d - 1).map(|j| frame.edges[j][r] * s[j]).sum::<f64>()).collect();
        let distance = (0..d).map(|r| (at[r] - x[r]).powi(2)).sum::<f64>().sqrt();
        // The residual's part along the facet, T (TᵀT)⁻¹ Tᵀ r: zero where r is normal.
        let residual: [f64; 3] = std::array::from_fn(|r| at[r] - x[r]);
        let step = gauss_newton_step(&tangents[..d - 1], &residual);
        let along: f64 =
            (0..3).map(|r| (0..d - 1).map(|j| tangents[j][r] * step[j]).sum::<f64>().powi(2)).sum::<f64>().sqrt();
        let beyond = self.on_border(frame, cell, &s[..d - 1]) && along > ALONG_TOLERANCE * distance;
        Facing { facet: k, xi, point: x[..d].to_vec(), distance, beyond, overshoot: along }
    }

    /// Whether the facet point at `s` lies on the surface's border: the vertices it does not
    /// weigh span a border node (2D) or lie on a border edge (3D).
    fn on_border(&self, frame: &Frame, cell: &[u32], s: &[f64]) -> bool {
        let n = frame.vertices.len();
        let mut l = [0.0; 3];
        l[0] = 1.0 - s.iter().sum::<f64>();
        l[1..n].copy_from_slice(s);
        // The vertices it weighs (at most three), without allocating: this runs per projection.
        let (mut held, mut count) = ([0u32; 3], 0);
        for i in (0..n).filter(|&i| l[i] > 0.0) {
            held[count] = cell[frame.vertices[i]];
            count += 1;
        }
        let is_border = |e: [u32; 2]| self.border.binary_search(&e).is_ok();
        match (n, &held[..count]) {
            (2, &[a]) => is_border([a, a]),
            (3, &[a, b]) => is_border([a.min(b), a.max(b)]),
            (3, &[a]) => self.border.iter().any(|e| e.contains(&a)),
            _ => false,
        }
    }

    /// In 2D, facet `k`'s two ends on the configuration, each with the facet's tangent ∂x/∂s
    /// there (s from its first vertex to its second): a point's closest point leaves the facet
    /// at an end where the point crosses the line through it normal to that tangent.
    pub fn ends(&self, k: usize) -> [([f64; 3], [f64; 3]); 2] {
        let f = self.facets[k];
        let frame = &self.frames[f.local as usize];
        let cell = self.mesh.cell(f.cell as usize);
        let mut y = [[0.0; 3]; 6];
        for (slot, &a) in y.iter_mut().zip(frame.vertices.iter().chain(frame.mids.iter().map(|(m, _, _)| m))) {
            *slot = self.position(cell[a] as usize);
        }
        [0.0, 1.0].map(|s| {
            let mut tangents = [[0.0; 3]; 2];
            let x = frame.point(&y, &[s], Some(&mut tangents));
            (x, tangents[0])
        })
    }

    /// In 2D, facet `k`'s end `end` (0: its first vertex, 1: its second) on the configuration:
    /// its point, the facet's tangent t = ∂x/∂s there, the vertex's node, and t's weights on
    /// the facet's nodes (t = Σ_b w_b y_b over their positions y_b), for how t moves with them.
    pub fn end(&self, k: usize, end: usize) -> End {
        let f = self.facets[k];
        let frame = &self.frames[f.local as usize];
        let cell = self.mesh.cell(f.cell as usize);
        let locals: Vec<usize> = frame.vertices.iter().copied().chain(frame.mids.iter().map(|(m, _, _)| *m)).collect();
        let s = [end as f64];
        let weights = (0..locals.len())
            .map(|b| {
                let mut unit = [[0.0; 3]; 6];
                unit[b][0] = 1.0;
                let mut tangents = [[0.0; 3]; 2];
                frame.point(&unit, &s, Some(&mut tangents));
                (cell[locals[b]], tangents[0][0])
            })
            .collect();
        let (point, tangent) = self.ends(k)[end];
        End { point, tangent, node: cell[frame.vertices[end]], weights }
    }

    /// The facets, as given.
    pub fn facets(&self) -> &'m [Facet] {
        self.facets
    }
}

/// Gauss–Newton iterations of a projection: enough for a P2 facet from its centre (each step
/// gains digits quadratically once near, for a point near the facet).
const MAX_STEPS: usize = 40;

/// The part of the residual along the facet, relative to its length, past which a point on the
/// border is off the surface: round-off leaves about 1e-16 where the residual is normal.
const ALONG_TOLERANCE: f64 = 1e-8;

/// The border of the surface of `facets`: in 2D its nodes of one facet, as `[a, a]`; in 3D its
/// edges of one facet, as sorted `[a, b]`.
fn border(mesh: &Mesh, facets: &[Facet], frames: &[Frame]) -> Vec<[u32; 2]> {
    let mut pieces: Vec<[u32; 2]> = Vec::new();
    for f in facets {
        let cell = mesh.cell(f.cell as usize);
        let v: Vec<u32> = frames[f.local as usize].vertices.iter().map(|&a| cell[a]).collect();
        match *v.as_slice() {
            [a, b] => pieces.extend([[a, a], [b, b]]),
            [a, b, c] => pieces.extend([[a, b], [b, c], [a, c]].map(|[p, q]| [p.min(q), p.max(q)])),
            _ => {}
        }
    }
    pieces.sort_unstable();
    let mut out = Vec::new();
    let mut i = 0;
    while i < pieces.len() {
        let j = (i..pieces.len()).find(|&j| pieces[j] != pieces[i]).unwrap_or(pieces.len());
        if j - i == 1 {
            out.push(pieces[i]);
        }
        i = j;
    }
    out
}

/// Whether reference vertex `a` is an end of the edge whose midpoint is `m`: its mirror
/// 2m − a is a reference vertex too.
fn is_end(a: &[f64], m: &[f64]) -> bool {
    let other: Vec<f64> = a.iter().zip(m).map(|(a, m)| 2.0 * m - a).collect();
    let vertex = |x: &[f64]| x.iter().all(|c| *c == 0.0 || *c == 1.0) && x.iter().sum::<f64>() <= 1.0;
    vertex(&other) && other.as_slice() != a
}

/// δ solving (TᵀT) δ = Tᵀ r for one or two tangents.
fn gauss_newton_step(t: &[[f64; 3]], r: &[f64; 3]) -> [f64; 2] {
    let dot = |a: &[f64; 3], b: &[f64; 3]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    match t {
        [t0] => [dot(t0, r) / dot(t0, t0), 0.0],
        [t0, t1] => {
            let (a, b, c) = (dot(t0, t0), dot(t0, t1), dot(t1, t1));
            let (f, g) = (dot(t0, r), dot(t1, r));
            let det = a * c - b * b;
            [(c * f - b * g) / det, (a * g - b * f) / det]
        }
        _ => [0.0; 2],
    }
}

/// The point of the reference facet (the interval [0, 1], or the triangle s ≥ 0, s0 + s1 ≤ 1)
/// nearest to `s`.
fn keep_in_facet(s: &mut [f64]) {
    match s {
        [a] => *a = a.clamp(0.0, 1.0),
        [a, b] => {
            *a = a.max(0.0);
            *b = b.max(0.0);
            let over = *a + *b - 1.0;
            if over > 0.0 {
                *a -= over / 2.0;
                *b -= over / 2.0;
                if *a < 0.0 {
                    (*a, *b) = (0.0, 1.0);
                } else if *b < 0.0 {
                    (*a, *b) = (1.0, 0.0);
                }
            }
        }
        _ => {}
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::mesh::disc::disc;

    /// Points about a curved P2 disc of radius 10: the R-tree finds the facet every facet's
    /// projection finds, and the distance to the surface is |p| − R to the P2 boundary's
    /// geometric error.
    #[test]
    fn the_closest_point_is_every_facet_s_closest_and_lies_on_the_circle() {
        let mesh = disc(10.0, [0.0, 0.0], 1.0);
        let facets = mesh.boundary_facets();
        let u = vec![0.0; mesh.num_nodes() * 2];
        let surface = Surface::new(&mesh, &facets, &u);
        for k in 0..200 {
            let angle = k as f64 * 0.0731;
            let r = 10.0 + 0.3 * ((k % 7) as f64 - 3.0) / 3.0;
            let p = [r * angle.cos(), r * angle.sin()];
            let found = surface.closest(&p, 1.0).expect("within 1 of the surface");
            let every = surface.closest_by_every_facet(&p).unwrap();
            assert_eq!(found.facet, every.facet, "at {p:?}");
            assert!((found.distance - every.distance).abs() < 1e-14);
            // The P2 boundary is within about 1.3e-6 of the circle at h = 1.
            let exact = (r - 10.0).abs();
            assert!((found.distance - exact).abs() < 1e-5, "{} against {exact}", found.distance);
        }
        // Nothing within a radius that reaches no facet.
        assert!(surface.closest(&[0.0, 0.0], 5.0).is_none());
    }

    /// The same on a curved P2 ball: its boundary triangles are quadratic patches.
    #[test]
    fn the_closest_point_of_a_curved_ball_lies_on_the_sphere() {
        let mesh = crate::fem::mesh::ball::ball(1.0, [0.0, 0.0, 0.0], 0.5);
        let facets = mesh.boundary_facets();
        let u = vec![0.0; mesh.num_nodes() * 3];
        let surface = Surface::new(&mesh, &facets, &u);
        let mut worst: f64 = 0.0;
        for k in 0..100 {
            let (theta, phi) = (0.37 * k as f64, 0.11 + 0.029 * k as f64);
            let r = 1.0 + 0.05 * ((k % 5) as f64 - 2.0);
            let p = [r * phi.sin() * theta.cos(), r * phi.sin() * theta.sin(), r * phi.cos()];
            let found = surface.closest(&p, 0.5).expect("within 0.5 of the surface");
            let every = surface.closest_by_every_facet(&p).unwrap();
            assert!((found.distance - every.distance).abs() < 1e-14, "at {p:?}");
            worst = worst.max((found.distance - (r - 1.0).abs()).abs());
        }
        // P2 patches of a unit sphere at h = 0.5 lie within about 3e-4 of it.
        assert!(worst < 1e-3, "{worst}");
    }

    /// On a displaced configuration the facing point moves with the surface, and a straight
    /// facet's projection is exact.
    #[test]
    fn the_search_reads_the_deformed_configuration() {
        let mesh = crate::fem::mesh::structured::rectangle(
            4,
            2,
            [0.0, 1.0],
            [0.0, 0.5],
            crate::fem::mesh::structured::Diagonal::Right,
            1,
        );
        let facets = mesh.boundary_facets();
        let lift = 0.25;
        let u: Vec<f64> = (0..mesh.num_nodes() * 2).map(|i| if i % 2 == 1 { lift } else { 0.0 }).collect();
        let surface = Surface::new(&mesh, &facets, &u);
        // Below the displaced bottom (y = 0.25): the facing point is straight above.
        let found = surface.closest(&[0.3, 0.1], 0.5).unwrap();
        assert!((found.point[0] - 0.3).abs() < 1e-15 && (found.point[1] - lift).abs() < 1e-15, "{found:?}");
        assert!((found.distance - 0.15).abs() < 1e-15);
        // Off a corner: the corner itself.
        let corner = surface.closest(&[1.2, 0.0], 0.5).unwrap();
        assert!((corner.point[0] - 1.0).abs() < 1e-15 && (corner.point[1] - lift).abs() < 1e-15, "{corner:?}");
    }

    /// An open surface (a rectangle's top, P1 and P2, and a box's top in 3D): a point beyond
    /// its end faces nothing, a point straight above or below its end faces the end, and a
    /// point inside faces the point above it.
    #[test]
    fn a_point_past_the_border_faces_nothing() {
        use crate::fem::mesh::structured::{Diagonal, rectangle};
        for degree in [1, 2] {
            let mesh = rectangle(4, 2, [0.0, 1.0], [0.0, 0.5], Diagonal::Right, degree);
            let top: Vec<Facet> =
                mesh.boundary_facets().into_iter().filter(|&f| mesh.facet_normal_and_centroid(f).0[1] > 0.5).collect();
            let surface = Surface::new(&mesh, &top, &vec![0.0; mesh.num_nodes() * 2]);
            assert!(surface.closest(&[1.2, 0.49], 0.5).is_none(), "degree {degree}: past the right end");
            assert!(surface.closest(&[-0.1, 0.55], 0.5).is_none(), "degree {degree}: past the left end");
            let end = surface.closest(&[1.0, 0.45], 0.5).expect("below the end");
            assert!((end.point[0] - 1.0).abs() < 1e-15 && (end.distance - 0.05).abs() < 1e-15);
            let inside = surface.closest(&[0.3, 0.45], 0.5).expect("inside");
            assert!(!inside.beyond && (inside.point[0] - 0.3).abs() < 1e-14);
        }
        let mesh = crate::fem::mesh::structured::cuboid([2, 2, 1], [0.0, 1.0], [0.0, 1.0], [0.0, 0.5], 1);
        let top: Vec<Facet> =
            mesh.boundary_facets().into_iter().filter(|&f| mesh.facet_normal_and_centroid(f).0[2] > 0.5).collect();
        let surface = Surface::new(&mesh, &top, &vec![0.0; mesh.num_nodes() * 3]);
        assert!(surface.closest(&[1.1, 0.5, 0.45], 0.5).is_none(), "past an edge");
        assert!(surface.closest(&[1.1, 1.1, 0.45], 0.5).is_none(), "past a corner");
        let inside = surface.closest(&[0.7, 0.4, 0.45], 0.5).expect("inside");
        assert!((inside.distance - 0.05).abs() < 1e-14, "{inside:?}");
    }

    #[test]
    fn a_point_is_kept_in_the_reference_triangle() {
        let mut s = [0.9, 0.5];
        keep_in_facet(&mut s);
        assert!((s[0] - 0.7).abs() < 1e-15 && (s[1] - 0.3).abs() < 1e-15);
        let mut s = [-0.2, 1.4];
        keep_in_facet(&mut s);
        assert_eq!(s, [0.0, 1.0]);
    }
}
