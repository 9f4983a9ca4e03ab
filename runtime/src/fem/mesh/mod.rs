//! Meshes: node coordinates, cells of one element kind (isoparametric: a P2 cell's edge nodes
//! may lie off the straight edges), named boundary regions as lists of (cell, local facet),
//! and named cell groups. Built by the structured generators, the disc generator, or read from
//! Gmsh files.

pub mod ball;
mod boundary;
pub mod disc;
pub mod gmsh;
mod integrity;
pub mod inverted;
mod part;
pub mod structured;
mod validate;

use std::collections::HashMap;

pub use boundary::facet_key;
pub use validate::MeshError;

use crate::fem::element::ElementKind;
use crate::fem::geometry;
use crate::linalg::pattern::Connectivity;

/// A boundary facet: a local facet of a cell.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Facet {
    pub cell: u32,
    pub local: u8,
}

/// A named set of boundary facets (a contact zone, a Dirichlet side, ...).
#[derive(Clone, Debug, PartialEq)]
pub struct Region {
    pub name: String,
    pub facets: Vec<Facet>,
}

/// One body of a problem with several: its cells. A form bound to a body integrates over these
/// and the facets they carry alone, with the body's values of its params.
#[derive(Clone, Debug, PartialEq)]
pub struct Body {
    pub name: String,
    /// Per cell of the mesh, whether it is the body's.
    pub cells: Vec<bool>,
    /// Per node, whether one of the body's cells has it: of the whole mesh's cells, also in one
    /// process's part of it (which keeps every node but only some cells).
    pub nodes: Vec<bool>,
}

/// Moves a point in place (a new boundary node onto the true boundary).
pub type Projection<'a> = dyn Fn(&mut [f64]) + 'a;

#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    pub kind: ElementKind,
    /// `nodes × dim`, row-major.
    pub coords: Vec<f64>,
    /// `cells × kind.nodes()`, row-major, Gmsh node order.
    pub cells: Vec<u32>,
    /// Named boundary regions.
    pub regions: Vec<Region>,
    /// Named groups of cells (Gmsh physical groups of the cell dimension).
    pub cell_groups: Vec<(String, Vec<u32>)>,
    /// Its bodies, when a problem has several (`set_bodies`); none: the mesh is one body.
    pub bodies: Vec<Body>,
    /// What the reader skipped or doubted (e.g. element types it does not use), for the user.
    pub warnings: Vec<String>,
    /// What `h`, the size of the cell carrying a facet, means in the forms (`set_cell_size`).
    cell_size: CellSize,
    /// Per cell, `h` when it is not the diameter (computed once: assembly reads it at every
    /// facet of every Newton iteration).
    sizes: Vec<f64>,
}

/// The size `h` of a cell (in `gamma = gamma0/h`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum CellSize {
    /// The largest distance between two vertices.
    #[default]
    Diameter,
    /// GetFEM's `element_size`: √d times the largest, over the cell's geometric nodes, of the
    /// smallest singular value of the Jacobian of the map from the unit-leg reference simplex
    /// (in 1D, the length). Curved cells included.
    GetFem,
}

impl CellSize {
    /// `diameter` or `getfem`.
    pub fn parse(s: &str) -> Result<CellSize, String> {
        match s {
            "diameter" => Ok(CellSize::Diameter),
            "getfem" => Ok(CellSize::GetFem),
            _ => Err(format!("`{s}` is not a cell size (diameter, getfem)")),
        }
    }
}

impl Mesh {
    /// A mesh of `kind` cells on `coords`, without regions; h is the cell diameter.
    pub fn from_cells(kind: ElementKind, coords: Vec<f64>, cells: Vec<u32>) -> Mesh {
        Mesh {
            kind,
            coords,
            cells,
            regions: Vec::new(),
            cell_groups: Vec::new(),
            bodies: Vec::new(),
            warnings: Vec::new(),
            cell_size: CellSize::Diameter,
            sizes: Vec::new(),
        }
    }

    pub fn dim(&self) -> usize {
        self.kind.dim()
    }

    /// Shares the cells out among bodies (name, cells; each cell in one, which the caller
    /// checks).
    pub fn set_bodies(&mut self, bodies: Vec<(String, Vec<u32>)>) {
        let cells = self.num_cells();
        self.bodies = bodies
            .into_iter()
            .map(|(name, list)| {
                let mut mine = vec![false; cells];
                let mut nodes = vec![false; self.num_nodes()];
                for &c in &list {
                    mine[c as usize] = true;
                    self.cell(c as usize).iter().for_each(|&n| nodes[n as usize] = true);
                }
                Body { name, cells: mine, nodes }
            })
            .collect();
    }

    /// The nodes of body `name` (per node, whether one of its cells has it); none if the mesh
    /// has no such body.
    pub fn body_nodes(&self, name: &str) -> Option<Vec<bool>> {
        Some(self.bodies.iter().find(|b| b.name == name)?.nodes.clone())
    }

    /// Places `other`'s nodes and cells after this mesh's (the two share no node): its cells
    /// are numbered from this mesh's count on, its regions and cell groups join those of the
    /// same name. Returns the range of its cells here. Both must be of one element kind.
    pub fn append(&mut self, other: &Mesh) -> std::ops::Range<u32> {
        debug_assert_eq!(self.kind, other.kind, "checked by the caller");
        let (first_node, first_cell) = (self.num_nodes() as u32, self.num_cells() as u32);
        self.coords.extend_from_slice(&other.coords);
        self.cells.extend(other.cells.iter().map(|&n| n + first_node));
        let shifted = |f: &Facet| Facet { cell: f.cell + first_cell, local: f.local };
        for r in &other.regions {
            let facets = r.facets.iter().map(shifted);
            match self.regions.iter_mut().find(|own| own.name == r.name) {
                Some(own) => own.facets.extend(facets),
                None => self.regions.push(Region { name: r.name.clone(), facets: facets.collect() }),
            }
        }
        for (name, group) in &other.cell_groups {
            let cells = group.iter().map(|&c| c + first_cell);
            match self.cell_groups.iter_mut().find(|(own, _)| own == name) {
                Some((_, own)) => own.extend(cells),
                None => self.cell_groups.push((name.clone(), cells.collect())),
            }
        }
        self.warnings.extend(other.warnings.iter().cloned());
        let cell_size = self.cell_size;
        self.set_cell_size(cell_size);
        first_cell..self.num_cells() as u32
    }

    pub fn num_nodes(&self) -> usize {
        self.coords.len() / self.dim()
    }

    pub fn num_cells(&self) -> usize {
        self.cells.len() / self.kind.nodes()
    }

    pub fn cell(&self, c: usize) -> &[u32] {
        let n = self.kind.nodes();
        &self.cells[c * n..(c + 1) * n]
    }

    /// The cells' nodes, for the sparsity pattern of a vector field on this mesh.
    pub fn connectivity(&self) -> Connectivity<'_> {
        Connectivity {
            dim: self.dim(),
            num_nodes: self.num_nodes(),
            nodes_per_cell: self.kind.nodes(),
            cells: &self.cells,
        }
    }

    pub fn node(&self, i: usize) -> &[f64] {
        let d = self.dim();
        &self.coords[i * d..(i + 1) * d]
    }

    /// The coordinates of a cell's nodes as a fixed-size array (D and N must match the kind).
    pub fn cell_coords<const D: usize, const N: usize>(&self, c: usize) -> [[f64; D]; N] {
        let nodes = self.cell(c);
        std::array::from_fn(|j| std::array::from_fn(|k| self.coords[nodes[j] as usize * D + k]))
    }

    /// Diameter of a cell (largest distance between two vertices).
    /// The size `h` of cell `c`, as `set_cell_size` chose.
    pub fn cell_size(&self, c: usize) -> f64 {
        match self.cell_size {
            CellSize::Diameter => self.cell_diameter(c),
            CellSize::GetFem => self.sizes[c],
        }
    }

    /// The smallest cell's size (infinite for a mesh without cells).
    pub fn smallest_cell(&self) -> f64 {
        (0..self.num_cells()).map(|c| self.cell_size(c)).fold(f64::INFINITY, f64::min)
    }

    /// Chooses what `h` means, and computes it for every cell.
    pub fn set_cell_size(&mut self, rule: CellSize) {
        self.cell_size = rule;
        self.sizes = match rule {
            CellSize::Diameter => Vec::new(),
            CellSize::GetFem => (0..self.num_cells())
                .map(|c| {
                    let nodes: Vec<&[f64]> = self.cell(c).iter().map(|&n| self.node(n as usize)).collect();
                    crate::fem::geometry::getfem_size(self.kind, &nodes)
                })
                .collect(),
        };
    }

    /// What `h` means.
    pub fn cell_size_rule(&self) -> CellSize {
        self.cell_size
    }

    pub fn cell_diameter(&self, c: usize) -> f64 {
        let d = self.dim();
        let nodes = self.cell(c);
        let nv = self.kind.vertices();
        let mut h2: f64 = 0.0;
        for a in 0..nv {
            for b in a + 1..nv {
                let (pa, pb) = (self.node(nodes[a] as usize), self.node(nodes[b] as usize));
                h2 = h2.max((0..d).map(|k| (pa[k] - pb[k]).powi(2)).sum());
            }
        }
        h2.sqrt()
    }

    /// Largest cell diameter.
    pub fn max_diameter(&self) -> f64 {
        (0..self.num_cells()).map(|c| self.cell_diameter(c)).fold(0.0, f64::max)
    }

    /// Every boundary facet (facets belonging to one cell only), sorted by (cell, local).
    pub fn boundary_facets(&self) -> Vec<Facet> {
        boundary::boundary_facets(self)
    }

    /// The region `name`, which must have facets of positive total measure (a contact zone
    /// or Dirichlet side of measure zero would silently do nothing).
    pub fn region(&self, name: &str) -> Result<&Region, MeshError> {
        let region = self.regions.iter().find(|r| r.name == name).ok_or_else(|| MeshError::NoSuchRegion {
            name: name.to_string(),
            known: self.regions.iter().map(|r| r.name.clone()).collect(),
        })?;
        let empty = |reason: &str| MeshError::EmptyRegion { name: name.to_string(), reason: reason.to_string() };
        if region.facets.is_empty() {
            return Err(empty("has no facets"));
        }
        if let Some(f) = region
            .facets
            .iter()
            .find(|f| f.cell as usize >= self.num_cells() || f.local as usize >= self.kind.vertices())
        {
            return Err(empty(&format!("names facet {} of cell {}, which the mesh does not have", f.local, f.cell)));
        }
        // Measure of the straight (vertex) facets, against the scale of their cells.
        let (measure, scale) = region.facets.iter().fold((0.0, 0.0), |(m, s), f| {
            let h = self.cell_diameter(f.cell as usize);
            (m + self.straight_facet_measure(*f), s + h.powi(self.dim() as i32 - 1))
        });
        if measure.is_nan() || measure <= 1e-12 * scale {
            return Err(empty(&format!("has measure {measure:e} over {} facets", region.facets.len())));
        }
        Ok(region)
    }

    /// Whether a region of that name exists (empty or not).
    pub fn has_region(&self, name: &str) -> bool {
        self.regions.iter().any(|r| r.name == name)
    }

    /// The measure of a facet's vertex simplex (a point counts 1).
    fn straight_facet_measure(&self, f: Facet) -> f64 {
        let cell = self.cell(f.cell as usize);
        let verts = &self.kind.info().facets[f.local as usize];
        let p = |i: usize| self.node(cell[verts[i]] as usize);
        match self.dim() {
            1 => 1.0,
            2 => (0..2).map(|k| (p(1)[k] - p(0)[k]).powi(2)).sum::<f64>().sqrt(),
            _ => {
                let (a, b, o) = (p(1), p(2), p(0));
                let u = [a[0] - o[0], a[1] - o[1], a[2] - o[2]];
                let v = [b[0] - o[0], b[1] - o[1], b[2] - o[2]];
                let n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
                0.5 * (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt()
            }
        }
    }

    /// Adds (or replaces) a region made of the boundary facets whose outward unit normal and
    /// centroid satisfy `pred(normal, centroid)`.
    pub fn add_region_where(&mut self, name: &str, pred: impl Fn(&[f64], &[f64]) -> bool) -> &Region {
        let facets = self.boundary_facets().into_iter().filter(|f| {
            let (n, x) = self.facet_normal_and_centroid(*f);
            pred(&n, &x)
        });
        let region = Region { name: name.to_string(), facets: facets.collect() };
        self.regions.retain(|r| r.name != name);
        self.regions.push(region);
        self.regions.last().expect("just pushed")
    }

    /// Outward unit normal and position at the centre of a facet (reference-facet centroid).
    pub fn facet_normal_and_centroid(&self, f: Facet) -> (Vec<f64>, Vec<f64>) {
        let d = self.dim();
        let s = vec![1.0 / d as f64; d - 1];
        let (xi, _) = self.kind.facet_point(f.local as usize, &s);
        let grads = self.kind.basis_gradients(&xi);
        let phi = self.kind.basis(&xi);
        let nodes = self.cell(f.cell as usize);
        let mut j = vec![vec![0.0; d]; d];
        let mut x = vec![0.0; d];
        for (a, &node) in nodes.iter().enumerate() {
            let p = self.node(node as usize);
            for r in 0..d {
                x[r] += phi[a] * p[r];
                for c in 0..d {
                    j[r][c] += p[r] * grads[a][c];
                }
            }
        }
        let n_ref = self.kind.reference_normal(f.local as usize);
        let n = match d {
            1 => vec![n_ref[0] / j[0][0]],
            2 => {
                let m = [[j[0][0], j[0][1]], [j[1][0], j[1][1]]];
                let (_, inv) = geometry::invert(&m);
                (0..2).map(|l| (0..2).map(|b| inv[b][l] * n_ref[b]).sum()).collect()
            }
            _ => {
                let m = [[j[0][0], j[0][1], j[0][2]], [j[1][0], j[1][1], j[1][2]], [j[2][0], j[2][1], j[2][2]]];
                let (_, inv) = geometry::invert(&m);
                (0..3).map(|l| (0..3).map(|b| inv[b][l] * n_ref[b]).sum()).collect()
            }
        };
        let norm = n.iter().map(|v: &f64| v * v).sum::<f64>().sqrt();
        (n.iter().map(|v| v / norm).collect(), x)
    }

    /// Nodes lying on the facets of a region (vertices and, for P2, edge nodes), sorted.
    pub fn region_nodes(&self, region: &Region) -> Vec<u32> {
        let mut nodes: Vec<u32> = region
            .facets
            .iter()
            .flat_map(|f| {
                let cell = self.cell(f.cell as usize);
                self.kind.facet_nodes(f.local as usize).into_iter().map(move |i| cell[i])
            })
            .collect();
        nodes.sort_unstable();
        nodes.dedup();
        nodes
    }

    /// Total measure (length, area, volume), integrated with the isoparametric map.
    pub fn measure(&self) -> f64 {
        let d = self.dim();
        let rule = crate::fem::quadrature::simplex_rule(d, 2 * d as u32);
        let tab: Vec<Vec<Vec<f64>>> = rule.points.iter().map(|p| self.kind.basis_gradients(p)).collect();
        let mut total = 0.0;
        for c in 0..self.num_cells() {
            let nodes = self.cell(c);
            for (g, w) in tab.iter().zip(&rule.weights) {
                let mut j = [[0.0; 3]; 3];
                for (a, &node) in nodes.iter().enumerate() {
                    let p = self.node(node as usize);
                    for r in 0..d {
                        for s in 0..d {
                            j[r][s] += p[r] * g[a][s];
                        }
                    }
                }
                total += w * det(&j, d).abs();
            }
        }
        total
    }

    /// Promotes a P1 mesh to P2 by adding edge midpoints (straight edges), keeping regions.
    /// `project` may move each new boundary-edge midpoint (e.g. onto a circle).
    pub fn to_p2(&self, project: Option<&Projection<'_>>) -> Mesh {
        let (kind, edges) = match self.kind.info().p2 {
            Some(p2) if self.kind.degree() == 1 => (p2, p2.info().edge_nodes),
            _ => return self.clone(),
        };
        let d = self.dim();
        let boundary_edges: std::collections::HashSet<(u32, u32)> = if project.is_some() {
            self.boundary_facets()
                .iter()
                .flat_map(|f| {
                    let cell = self.cell(f.cell as usize);
                    let verts: Vec<u32> = self.kind.facets()[f.local as usize].iter().map(|&v| cell[v]).collect();
                    let mut pairs = Vec::new();
                    for a in 0..verts.len() {
                        for b in a + 1..verts.len() {
                            pairs.push((verts[a].min(verts[b]), verts[a].max(verts[b])));
                        }
                    }
                    pairs
                })
                .collect()
        } else {
            Default::default()
        };
        let mut coords = self.coords.clone();
        let mut midpoint: HashMap<(u32, u32), u32> = HashMap::new();
        let nn = kind.nodes();
        let mut cells = Vec::with_capacity(self.num_cells() * nn);
        for c in 0..self.num_cells() {
            let cell = self.cell(c).to_vec();
            cells.extend_from_slice(&cell);
            for &[a, b] in edges {
                let key = (cell[a].min(cell[b]), cell[a].max(cell[b]));
                let id = *midpoint.entry(key).or_insert_with(|| {
                    let id = (coords.len() / d) as u32;
                    let mut m: Vec<f64> = (0..d)
                        .map(|k| 0.5 * (self.node(cell[a] as usize)[k] + self.node(cell[b] as usize)[k]))
                        .collect();
                    if let Some(p) = project
                        && boundary_edges.contains(&key)
                    {
                        p(&mut m);
                    }
                    coords.extend_from_slice(&m);
                    id
                });
                cells.push(id);
            }
        }
        let mut p2 = Mesh {
            kind,
            coords,
            cells,
            regions: self.regions.clone(),
            cell_groups: self.cell_groups.clone(),
            bodies: self.bodies.clone(),
            warnings: self.warnings.clone(),
            cell_size: CellSize::Diameter,
            sizes: Vec::new(),
        };
        p2.set_cell_size(self.cell_size);
        p2
    }
}

/// A mesh as the graph `linalg` reads (its cells' nodes): what `linalg::ownership` partitions,
/// the conversion kept here so that the bottom layer knows nothing of meshes.
impl<'m> From<&'m Mesh> for Connectivity<'m> {
    fn from(mesh: &'m Mesh) -> Self {
        mesh.connectivity()
    }
}

fn det(j: &[[f64; 3]; 3], d: usize) -> f64 {
    match d {
        1 => j[0][0],
        2 => j[0][0] * j[1][1] - j[0][1] * j[1][0],
        _ => {
            j[0][0] * (j[1][1] * j[2][2] - j[1][2] * j[2][1]) - j[0][1] * (j[1][0] * j[2][2] - j[1][2] * j[2][0])
                + j[0][2] * (j[1][0] * j[2][1] - j[1][1] * j[2][0])
        }
    }
}
