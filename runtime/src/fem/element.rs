//! The element catalogue: reference cells, Lagrange P1/P2 basis functions and their
//! gradients, local facets with their reference outward normals, and the catalogue
//! [`ELEMENTS`] of every kind's facts (sizes, Gmsh and VTK codes and orders). Node order is Gmsh's.
//!
//! Reference cells: interval [0, 1]; triangle (0,0), (1,0), (0,1); tetrahedron (0,0,0),
//! (1,0,0), (0,1,0), (0,0,1). P2 edge nodes: triangle 3:(0,1) 4:(1,2) 5:(2,0); tetrahedron
//! 4:(0,1) 5:(1,2) 6:(0,2) 7:(0,3) 8:(2,3) 9:(1,3).

/// The element types of the catalogue. Geometry is isoparametric: a P2 cell is curved.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ElementKind {
    IntervalP1,
    TriangleP1,
    TriangleP2,
    TetrahedronP1,
    TetrahedronP2,
}

/// Everything the code knows about one element kind, in one row of [`ELEMENTS`]: the
/// dispatch, the Gmsh reader, the VTU writer and P2 promotion all read it from here.
#[derive(Debug)]
pub struct ElementInfo {
    pub kind: ElementKind,
    pub name: &'static str,
    pub dim: usize,
    /// Polynomial degree of the basis (and of the isoparametric geometry).
    pub degree: u32,
    /// Nodes per cell (scalar basis functions).
    pub nodes: usize,
    /// Local facets as lists of local vertex indices.
    pub facets: &'static [&'static [usize]],
    /// Vertex pairs of the edge nodes, which follow the vertices (empty for P1).
    pub edge_nodes: &'static [[usize; 2]],
    /// Gmsh's element type number (node order: Gmsh's, which is ours).
    pub gmsh: u32,
    /// VTK's cell type, and for each VTK node position the local node of ours it shows.
    pub vtk: u8,
    pub vtk_order: &'static [usize],
    /// The P2 kind on the same cell, for promotion (`Mesh::to_p2`).
    pub p2: Option<ElementKind>,
}

/// Vertex pairs of the P2 triangle's edge nodes 3..6.
const TRIANGLE_EDGES: [[usize; 2]; 3] = [[0, 1], [1, 2], [2, 0]];
/// Vertex pairs of the P2 tetrahedron's edge nodes 4..10 (Gmsh's order).
const TET_EDGES: [[usize; 2]; 6] = [[0, 1], [1, 2], [0, 2], [0, 3], [2, 3], [1, 3]];
const INTERVAL_FACETS: &[&[usize]] = &[&[0], &[1]];
const TRIANGLE_FACETS: &[&[usize]] = &[&[0, 1], &[1, 2], &[2, 0]];
const TET_FACETS: &[&[usize]] = &[&[0, 1, 2], &[0, 1, 3], &[0, 2, 3], &[1, 2, 3]];

/// The catalogue, indexed by `ElementKind as usize`.
pub const ELEMENTS: [ElementInfo; 5] = [
    ElementInfo {
        kind: ElementKind::IntervalP1,
        name: "P1 interval",
        dim: 1,
        degree: 1,
        nodes: 2,
        facets: INTERVAL_FACETS,
        edge_nodes: &[],
        gmsh: 1,
        vtk: 3,
        vtk_order: &[0, 1],
        p2: None,
    },
    ElementInfo {
        kind: ElementKind::TriangleP1,
        name: "P1 triangle",
        dim: 2,
        degree: 1,
        nodes: 3,
        facets: TRIANGLE_FACETS,
        edge_nodes: &[],
        gmsh: 2,
        vtk: 5,
        vtk_order: &[0, 1, 2],
        p2: Some(ElementKind::TriangleP2),
    },
    ElementInfo {
        kind: ElementKind::TriangleP2,
        name: "P2 triangle",
        dim: 2,
        degree: 2,
        nodes: 6,
        facets: TRIANGLE_FACETS,
        edge_nodes: &TRIANGLE_EDGES,
        gmsh: 9,
        vtk: 22,
        vtk_order: &[0, 1, 2, 3, 4, 5],
        p2: Some(ElementKind::TriangleP2),
    },
    ElementInfo {
        kind: ElementKind::TetrahedronP1,
        name: "P1 tetrahedron",
        dim: 3,
        degree: 1,
        nodes: 4,
        facets: TET_FACETS,
        edge_nodes: &[],
        gmsh: 4,
        vtk: 10,
        vtk_order: &[0, 1, 2, 3],
        p2: Some(ElementKind::TetrahedronP2),
    },
    ElementInfo {
        kind: ElementKind::TetrahedronP2,
        name: "P2 tetrahedron",
        dim: 3,
        degree: 2,
        nodes: 10,
        facets: TET_FACETS,
        edge_nodes: &TET_EDGES,
        gmsh: 11,
        // VTK_QUADRATIC_TETRA's edges 8 and 9 are (1,3) and (2,3): Gmsh's 9 and 8.
        vtk: 24,
        vtk_order: &[0, 1, 2, 3, 4, 5, 6, 7, 9, 8],
        p2: Some(ElementKind::TetrahedronP2),
    },
];

impl ElementKind {
    pub const ALL: [ElementKind; 5] = [
        ElementKind::IntervalP1,
        ElementKind::TriangleP1,
        ElementKind::TriangleP2,
        ElementKind::TetrahedronP1,
        ElementKind::TetrahedronP2,
    ];

    /// This kind's row of the catalogue.
    pub fn info(self) -> &'static ElementInfo {
        &ELEMENTS[self as usize]
    }

    /// The kind of a Gmsh element type number, if it is one of ours.
    pub fn from_gmsh(code: u32) -> Option<ElementKind> {
        ELEMENTS.iter().find(|e| e.gmsh == code).map(|e| e.kind)
    }

    pub fn dim(self) -> usize {
        self.info().dim
    }

    pub fn degree(self) -> u32 {
        self.info().degree
    }

    /// Number of nodes (scalar basis functions).
    pub fn nodes(self) -> usize {
        self.info().nodes
    }

    pub fn vertices(self) -> usize {
        self.dim() + 1
    }

    pub fn name(self) -> &'static str {
        self.info().name
    }

    /// Reference coordinates of the vertices.
    pub fn reference_vertices(self) -> Vec<Vec<f64>> {
        match self.dim() {
            1 => vec![vec![0.0], vec![1.0]],
            2 => vec![vec![0.0, 0.0], vec![1.0, 0.0], vec![0.0, 1.0]],
            _ => vec![vec![0.0, 0.0, 0.0], vec![1.0, 0.0, 0.0], vec![0.0, 1.0, 0.0], vec![0.0, 0.0, 1.0]],
        }
    }

    /// Reference coordinates of all nodes, in node order.
    pub fn reference_nodes(self) -> Vec<Vec<f64>> {
        let v = self.reference_vertices();
        let mid = |a: usize, b: usize| v[a].iter().zip(&v[b]).map(|(x, y)| 0.5 * (x + y)).collect::<Vec<f64>>();
        let mut nodes = v.clone();
        nodes.extend(self.info().edge_nodes.iter().map(|e| mid(e[0], e[1])));
        nodes
    }

    /// Local facets as lists of local vertex indices.
    pub fn facets(self) -> Vec<Vec<usize>> {
        self.info().facets.iter().map(|f| f.to_vec()).collect()
    }

    /// Local nodes lying on each facet (vertices, then edge nodes for P2).
    pub fn facet_nodes(self, facet: usize) -> Vec<usize> {
        let verts = &self.facets()[facet];
        let mut nodes = verts.clone();
        let edges = self.info().edge_nodes;
        let offset = self.vertices();
        for (e, pair) in edges.iter().enumerate() {
            if verts.contains(&pair[0]) && verts.contains(&pair[1]) {
                nodes.push(offset + e);
            }
        }
        nodes
    }

    /// Outward unit normal of a reference facet.
    pub fn reference_normal(self, facet: usize) -> Vec<f64> {
        let s2 = std::f64::consts::FRAC_1_SQRT_2;
        let s3 = 1.0 / 3f64.sqrt();
        match (self.dim(), facet) {
            (1, 0) => vec![-1.0],
            (1, _) => vec![1.0],
            (2, 0) => vec![0.0, -1.0],
            (2, 1) => vec![s2, s2],
            (2, _) => vec![-1.0, 0.0],
            (_, 0) => vec![0.0, 0.0, -1.0],
            (_, 1) => vec![0.0, -1.0, 0.0],
            (_, 2) => vec![-1.0, 0.0, 0.0],
            _ => vec![s3, s3, s3],
        }
    }

    /// Values of all basis functions at a reference point.
    pub fn basis(self, xi: &[f64]) -> Vec<f64> {
        let l = barycentric(xi);
        match self.degree() {
            1 => l,
            _ => p2(&l, self.info().edge_nodes),
        }
    }

    /// Reference gradients of all basis functions at a reference point: `[node][direction]`.
    pub fn basis_gradients(self, xi: &[f64]) -> Vec<Vec<f64>> {
        let d = self.dim();
        let l = barycentric(xi);
        let dl = barycentric_gradients(d);
        match self.degree() {
            1 => dl,
            _ => {
                let edges = self.info().edge_nodes;
                let mut g: Vec<Vec<f64>> =
                    (0..=d).map(|i| dl[i].iter().map(|x| (4.0 * l[i] - 1.0) * x).collect()).collect();
                for &[a, b] in edges {
                    g.push((0..d).map(|k| 4.0 * (dl[a][k] * l[b] + l[a] * dl[b][k])).collect());
                }
                g
            }
        }
    }

    /// Reference second derivatives of all basis functions (constant on a cell: P1's are zero,
    /// P2's quadratics have constant Hessians): `[node][b][c]` = ∂²φ/∂ξ_b∂ξ_c.
    pub fn basis_hessians(self) -> Vec<Vec<Vec<f64>>> {
        let d = self.dim();
        let dl = barycentric_gradients(d);
        match self.degree() {
            1 => vec![vec![vec![0.0; d]; d]; d + 1],
            _ => {
                // (λ_i(2λ_i − 1))'' = 4 ∇λ_i ⊗ ∇λ_i; (4 λ_a λ_b)'' = 4 (∇λ_a ⊗ ∇λ_b + ∇λ_b ⊗ ∇λ_a).
                let twice = |a: usize, b: usize, scale: f64| -> Vec<Vec<f64>> {
                    (0..d)
                        .map(|r| (0..d).map(|c| scale * (dl[a][r] * dl[b][c] + dl[b][r] * dl[a][c])).collect())
                        .collect()
                };
                let vertices = (0..=d).map(|i| twice(i, i, 2.0));
                vertices.chain(self.info().edge_nodes.iter().map(|&[a, b]| twice(a, b, 4.0))).collect()
            }
        }
    }

    /// Maps a point of the reference facet (the interval \[0, 1\] or the triangle) into the reference cell,
    /// and returns it with the facet's measure scaling (reference facet → cell facet).
    pub fn facet_point(self, facet: usize, s: &[f64]) -> (Vec<f64>, f64) {
        let v = self.reference_vertices();
        let f = &self.facets()[facet];
        match self.dim() {
            1 => (v[f[0]].clone(), 1.0),
            2 => {
                let (a, b) = (&v[f[0]], &v[f[1]]);
                let p = (0..2).map(|k| a[k] + s[0] * (b[k] - a[k])).collect();
                let len = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
                (p, len)
            }
            _ => {
                let (a, b, c) = (&v[f[0]], &v[f[1]], &v[f[2]]);
                let p = (0..3).map(|k| a[k] + s[0] * (b[k] - a[k]) + s[1] * (c[k] - a[k])).collect();
                let e1: Vec<f64> = (0..3).map(|k| b[k] - a[k]).collect();
                let e2: Vec<f64> = (0..3).map(|k| c[k] - a[k]).collect();
                let cross =
                    [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]];
                (p, cross.iter().map(|x| x * x).sum::<f64>().sqrt())
            }
        }
    }
}

/// Barycentric coordinates (λ0 = 1 − Σ ξ, λk = ξk).
fn barycentric(xi: &[f64]) -> Vec<f64> {
    let mut l = vec![1.0 - xi.iter().sum::<f64>()];
    l.extend_from_slice(xi);
    l
}

fn barycentric_gradients(d: usize) -> Vec<Vec<f64>> {
    let mut g = vec![vec![-1.0; d]];
    for k in 0..d {
        g.push((0..d).map(|j| if j == k { 1.0 } else { 0.0 }).collect());
    }
    g
}

fn p2(l: &[f64], edges: &[[usize; 2]]) -> Vec<f64> {
    let mut v: Vec<f64> = l.iter().map(|x| x * (2.0 * x - 1.0)).collect();
    v.extend(edges.iter().map(|&[a, b]| 4.0 * l[a] * l[b]));
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_catalogue_is_indexed_by_kind_and_agrees_with_the_dispatch() {
        fn shape<const D: usize, const N: usize>() -> (usize, usize) {
            (D, N)
        }
        for (i, e) in ELEMENTS.iter().enumerate() {
            assert_eq!(e.kind as usize, i);
            assert_eq!(e.kind.info().kind, e.kind);
            assert_eq!(dispatch!(e.kind, shape()), (e.dim, e.nodes), "{}", e.name);
            assert_eq!(e.nodes, e.dim + 1 + e.edge_nodes.len(), "{}", e.name);
            assert_eq!(ElementKind::from_gmsh(e.gmsh), Some(e.kind));
            let mut order = e.vtk_order.to_vec();
            order.sort_unstable();
            assert_eq!(order, (0..e.nodes).collect::<Vec<_>>(), "{}: VTK order is a permutation", e.name);
            if let Some(p2) = e.p2 {
                assert_eq!((p2.dim(), p2.degree()), (e.dim, 2));
            }
        }
    }

    #[test]
    fn basis_is_nodal_and_a_partition_of_unity() {
        for kind in ElementKind::ALL {
            let nodes = kind.reference_nodes();
            assert_eq!(nodes.len(), kind.nodes());
            for (i, xi) in nodes.iter().enumerate() {
                let phi = kind.basis(xi);
                for (j, p) in phi.iter().enumerate() {
                    assert!((p - f64::from(i == j)).abs() < 1e-14, "{kind:?} node {i} basis {j}");
                }
                let grads = kind.basis_gradients(xi);
                for k in 0..kind.dim() {
                    assert!(grads.iter().map(|g| g[k]).sum::<f64>().abs() < 1e-13);
                }
            }
        }
    }

    #[test]
    fn hessians_match_finite_differences_of_the_gradients() {
        for kind in ElementKind::ALL {
            let d = kind.dim();
            let xi: Vec<f64> = (0..d).map(|k| 0.21 + 0.04 * k as f64).collect();
            let h = kind.basis_hessians();
            for c in 0..d {
                let (mut p, mut m) = (xi.clone(), xi.clone());
                p[c] += 1e-6;
                m[c] -= 1e-6;
                let (gp, gm) = (kind.basis_gradients(&p), kind.basis_gradients(&m));
                for j in 0..kind.nodes() {
                    for b in 0..d {
                        let fd = (gp[j][b] - gm[j][b]) / 2e-6;
                        assert!((fd - h[j][b][c]).abs() < 1e-7, "{kind:?} node {j}: {fd} against {}", h[j][b][c]);
                    }
                }
            }
        }
    }

    #[test]
    fn gradients_match_finite_differences() {
        for kind in ElementKind::ALL {
            let d = kind.dim();
            let xi: Vec<f64> = (0..d).map(|k| 0.17 + 0.05 * k as f64).collect();
            let g = kind.basis_gradients(&xi);
            for k in 0..d {
                let (mut p, mut m) = (xi.clone(), xi.clone());
                p[k] += 1e-6;
                m[k] -= 1e-6;
                let (bp, bm) = (kind.basis(&p), kind.basis(&m));
                for j in 0..kind.nodes() {
                    assert!(((bp[j] - bm[j]) / 2e-6 - g[j][k]).abs() < 1e-8);
                }
            }
        }
    }

    #[test]
    fn facet_nodes_lie_on_their_facet() {
        for kind in ElementKind::ALL {
            let nodes = kind.reference_nodes();
            for f in 0..kind.facets().len() {
                let n = kind.reference_normal(f);
                let v0 = &nodes[kind.facets()[f][0]];
                for &i in &kind.facet_nodes(f) {
                    let dist: f64 = nodes[i].iter().zip(v0).zip(&n).map(|((x, y), nn)| (x - y) * nn).sum();
                    assert!(dist.abs() < 1e-14);
                }
                assert_eq!(kind.facet_nodes(f).len(), if kind.degree() == 1 { kind.dim() } else { 3 * kind.dim() - 3 });
            }
        }
    }
}
