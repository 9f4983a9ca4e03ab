//! The facing point of a point on a surface of the mesh (another body's contact region), on the
//! deformed configuration: the closest point of the surface's facets, curved P2 facets
//! included. A broad phase keeps the facets whose bounding box meets a box about the point
//! (an R-tree of the boxes, `rstar`, rebuilt in O(n log n) whenever the surface moves); a narrow
//! phase projects the point onto each of them.
//!
//! A curved facet is a quadratic Bézier curve (a triangular patch in 3D) whose control points
//! are its vertices and, for each edge, 2m − (a + b)/2 with m the edge node: the facet lies in
//! their convex hull, so their box bounds it. The projection minimises |x(s) − p|² over the
//! reference facet by Gauss–Newton steps kept inside it (the closest point of a facet may be
//! on its boundary).

use rstar::primitives::{GeomWithData, Rectangle};
use rstar::{AABB, RTree};

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
}

type Boxed = GeomWithData<Rectangle<[f64; 3]>, u32>;

/// Facets of a mesh on a deformed configuration, indexed for closest-point queries.
pub struct Surface<'m> {
    mesh: &'m Mesh,
    facets: &'m [Facet],
    /// The displacement of the configuration (node-major, the mesh's dimension).
    u: Vec<f64>,
    tree: RTree<Boxed>,
}

impl<'m> Surface<'m> {
    /// The facets on the configuration x + u.
    pub fn new(mesh: &'m Mesh, facets: &'m [Facet], u: &[f64]) -> Surface<'m> {
        let mut surface = Surface { mesh, facets, u: u.to_vec(), tree: RTree::new() };
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
        let kind = self.mesh.kind;
        let cell = self.mesh.cell(f.cell as usize);
        let local = kind.facet_nodes(f.local as usize);
        let vertices = kind.dim();
        let mut points: Vec<[f64; 3]> = local[..vertices].iter().map(|&a| self.position(cell[a] as usize)).collect();
        // Edge nodes (P2): the control point 2m − (a + b)/2 of their edge.
        let reference = kind.reference_nodes();
        for &e in &local[vertices..] {
            let m = self.position(cell[e] as usize);
            let ends: Vec<usize> =
                local[..vertices].iter().copied().filter(|&a| is_end(&reference[a], &reference[e])).collect();
            let (a, b) = (self.position(cell[ends[0]] as usize), self.position(cell[ends[1]] as usize));
            points.push(std::array::from_fn(|r| 2.0 * m[r] - 0.5 * (a[r] + b[r])));
        }
        let lower = std::array::from_fn(|r| points.iter().map(|p| p[r]).fold(f64::INFINITY, f64::min));
        let upper = std::array::from_fn(|r| points.iter().map(|p| p[r]).fold(f64::NEG_INFINITY, f64::max));
        GeomWithData::new(Rectangle::from_corners(lower, upper), k as u32)
    }

    /// The closest point of the surface to `p` within `radius` (none: no facet within it).
    pub fn closest(&self, p: &[f64], radius: f64) -> Option<Facing> {
        let at: [f64; 3] = std::array::from_fn(|r| p.get(r).copied().unwrap_or(0.0));
        let around =
            AABB::from_corners(std::array::from_fn(|r| at[r] - radius), std::array::from_fn(|r| at[r] + radius));
        let mut best: Option<Facing> = None;
        for candidate in self.tree.locate_in_envelope_intersecting(&around) {
            let facing = self.project(candidate.data as usize, p);
            if facing.distance <= radius && best.as_ref().is_none_or(|b| facing.distance < b.distance) {
                best = Some(facing);
            }
        }
        best
    }

    /// The closest point of the surface to `p` by trying every facet (for checks).
    pub fn closest_by_every_facet(&self, p: &[f64]) -> Option<Facing> {
        (0..self.facets.len()).map(|k| self.project(k, p)).min_by(|a, b| a.distance.total_cmp(&b.distance))
    }

    /// The closest point of facet `k` to `p`.
    pub fn project(&self, k: usize, p: &[f64]) -> Facing {
        let (mesh, f) = (self.mesh, self.facets[k]);
        let (kind, d) = (mesh.kind, mesh.dim());
        let cell: Vec<[f64; 3]> = mesh.cell(f.cell as usize).iter().map(|&n| self.position(n as usize)).collect();
        // ξ(s) = ξ0 + E s on the reference facet; x(s) = Σ φ_a(ξ) y_a.
        let facet = f.local as usize;
        let (xi0, _) = kind.facet_point(facet, &vec![0.0; d - 1]);
        let edges: Vec<Vec<f64>> = (0..d - 1)
            .map(|j| {
                let mut s = vec![0.0; d - 1];
                s[j] = 1.0;
                let (xi, _) = kind.facet_point(facet, &s);
                xi.iter().zip(&xi0).map(|(a, b)| a - b).collect()
            })
            .collect();
        let xi_at = |s: &[f64]| -> Vec<f64> {
            (0..d).map(|r| xi0[r] + (0..d - 1).map(|j| edges[j][r] * s[j]).sum::<f64>()).collect()
        };
        let x_at = |xi: &[f64]| -> [f64; 3] {
            let phi = kind.basis(xi);
            std::array::from_fn(|r| phi.iter().zip(&cell).map(|(w, y)| w * y[r]).sum())
        };
        let mut s = vec![1.0 / d as f64; d - 1];
        for _ in 0..MAX_STEPS {
            let xi = xi_at(&s);
            let x = x_at(&xi);
            let grads = kind.basis_gradients(&xi);
            // T = ∂x/∂s (d × (d − 1)): the tangents of the facet at s.
            let tangents: Vec<[f64; 3]> = (0..d - 1)
                .map(|j| {
                    std::array::from_fn(|r| {
                        grads
                            .iter()
                            .zip(&cell)
                            .map(|(g, y)| y[r] * (0..d).map(|c| g[c] * edges[j][c]).sum::<f64>())
                            .sum()
                    })
                })
                .collect();
            let residual: [f64; 3] = std::array::from_fn(|r| p.get(r).copied().unwrap_or(0.0) - x[r]);
            let step = gauss_newton_step(&tangents, &residual);
            let before = s.clone();
            for (sj, dj) in s.iter_mut().zip(&step) {
                *sj += dj;
            }
            keep_in_facet(&mut s);
            let moved = s.iter().zip(&before).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
            if moved < 1e-14 {
                break;
            }
        }
        let xi = xi_at(&s);
        let x = x_at(&xi);
        let distance = (0..d).map(|r| (p[r] - x[r]).powi(2)).sum::<f64>().sqrt();
        Facing { facet: k, xi, point: x[..d].to_vec(), distance }
    }

    /// The facets, as given.
    pub fn facets(&self) -> &'m [Facet] {
        self.facets
    }
}

/// Gauss–Newton iterations of a projection: enough for a P2 facet from its centre (each step
/// gains digits quadratically once near, for a point near the facet).
const MAX_STEPS: usize = 40;

/// Whether reference vertex `a` is an end of the edge whose midpoint is `m`: its mirror
/// 2m − a is a reference vertex too.
fn is_end(a: &[f64], m: &[f64]) -> bool {
    let other: Vec<f64> = a.iter().zip(m).map(|(a, m)| 2.0 * m - a).collect();
    let vertex = |x: &[f64]| x.iter().all(|c| *c == 0.0 || *c == 1.0) && x.iter().sum::<f64>() <= 1.0;
    vertex(&other) && other.as_slice() != a
}

/// δ solving (TᵀT) δ = Tᵀ r for one or two tangents.
fn gauss_newton_step(t: &[[f64; 3]], r: &[f64; 3]) -> Vec<f64> {
    let dot = |a: &[f64; 3], b: &[f64; 3]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    match t {
        [t0] => vec![dot(t0, r) / dot(t0, t0)],
        [t0, t1] => {
            let (a, b, c) = (dot(t0, t0), dot(t0, t1), dot(t1, t1));
            let (f, g) = (dot(t0, r), dot(t1, r));
            let det = a * c - b * b;
            vec![(c * f - b * g) / det, (a * g - b * f) / det]
        }
        _ => Vec::new(),
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
