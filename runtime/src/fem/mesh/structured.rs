//! Structured meshes: uniform intervals, rectangles cut into triangles along either diagonal,
//! boxes cut into six tetrahedra per cube (Kuhn), as P1 or (straight) P2. Sides are named
//! regions: `left`/`right` (x), `bottom`/`top` (y in 2D, z in 3D), `front`/`back` (y in 3D).

use super::{Facet, Mesh, Region};
use crate::fem::element::ElementKind;

/// Which diagonal cuts each square of a rectangle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Diagonal {
    /// From (i, j) to (i+1, j+1).
    Right,
    /// From (i+1, j) to (i, j+1).
    Left,
}

/// `n` P1 elements on [a, b]; regions `left` (x = a) and `right` (x = b).
pub fn interval(n: usize, a: f64, b: f64) -> Mesh {
    let n = n.max(1);
    let coords = (0..=n).map(|i| a + (b - a) * i as f64 / n as f64).collect();
    let cells = (0..n as u32).flat_map(|i| [i, i + 1]).collect();
    let regions = vec![
        Region { name: "left".into(), facets: vec![Facet { cell: 0, local: 0 }] },
        Region { name: "right".into(), facets: vec![Facet { cell: n as u32 - 1, local: 1 }] },
    ];
    Mesh { regions, ..Mesh::from_cells(ElementKind::IntervalP1, coords, cells) }
}

/// `nx × ny` squares of [x0, x1] × [y0, y1], two triangles each, P1 or P2 (`degree`).
pub fn rectangle(nx: usize, ny: usize, x: [f64; 2], y: [f64; 2], diagonal: Diagonal, degree: u32) -> Mesh {
    let (nx, ny) = (nx.max(1), ny.max(1));
    let mut coords = Vec::with_capacity(2 * (nx + 1) * (ny + 1));
    for j in 0..=ny {
        for i in 0..=nx {
            coords.push(x[0] + (x[1] - x[0]) * i as f64 / nx as f64);
            coords.push(y[0] + (y[1] - y[0]) * j as f64 / ny as f64);
        }
    }
    let v = |i: usize, j: usize| (j * (nx + 1) + i) as u32;
    let mut cells = Vec::with_capacity(6 * nx * ny);
    for j in 0..ny {
        for i in 0..nx {
            let (a, b, c, d) = (v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1));
            match diagonal {
                Diagonal::Right => cells.extend_from_slice(&[a, b, c, a, c, d]),
                Diagonal::Left => cells.extend_from_slice(&[a, b, d, b, c, d]),
            }
        }
    }
    let mesh = Mesh::from_cells(ElementKind::TriangleP1, coords, cells);
    let mut mesh = if degree >= 2 { mesh.to_p2(None) } else { mesh };
    name_sides(&mut mesh, &[("left", 0, -1.0), ("right", 0, 1.0), ("bottom", 1, -1.0), ("top", 1, 1.0)]);
    mesh
}

/// `nx × ny × nz` cubes of a box, six tetrahedra each around the main diagonal, P1 or P2.
pub fn cuboid(n: [usize; 3], x: [f64; 2], y: [f64; 2], z: [f64; 2], degree: u32) -> Mesh {
    let [nx, ny, nz] = n.map(|k| k.max(1));
    let mut coords = Vec::with_capacity(3 * (nx + 1) * (ny + 1) * (nz + 1));
    for k in 0..=nz {
        for j in 0..=ny {
            for i in 0..=nx {
                coords.push(x[0] + (x[1] - x[0]) * i as f64 / nx as f64);
                coords.push(y[0] + (y[1] - y[0]) * j as f64 / ny as f64);
                coords.push(z[0] + (z[1] - z[0]) * k as f64 / nz as f64);
            }
        }
    }
    let v = |i: usize, j: usize, k: usize| ((k * (ny + 1) + j) * (nx + 1) + i) as u32;
    let mut cells = Vec::with_capacity(24 * nx * ny * nz);
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                kuhn([i, j, k], [true; 3], &|p| v(p[0], p[1], p[2]), &mut cells);
            }
        }
    }
    let mut mesh = Mesh::from_cells(ElementKind::TetrahedronP1, coords, cells);
    orient_positively(&mut mesh);
    let mut mesh = if degree >= 2 { mesh.to_p2(None) } else { mesh };
    name_sides(
        &mut mesh,
        &[
            ("left", 0, -1.0),
            ("right", 0, 1.0),
            ("front", 1, -1.0),
            ("back", 1, 1.0),
            ("bottom", 2, -1.0),
            ("top", 2, 1.0),
        ],
    );
    mesh
}

/// The six Kuhn tetrahedra of a grid cube: each follows one monotone path from the cube's corner
/// `from` to the opposite one, stepping up (`true`) or down along each axis. Cubes cut from
/// corresponding corners (here: all from their lowest, or all from the one nearest a centre)
/// fit together conformingly.
pub(super) fn kuhn(from: [usize; 3], up: [bool; 3], vertex: &dyn Fn([usize; 3]) -> u32, cells: &mut Vec<u32>) {
    const PATHS: [[usize; 3]; 6] = [[0, 1, 2], [0, 2, 1], [1, 0, 2], [1, 2, 0], [2, 0, 1], [2, 1, 0]];
    for path in PATHS {
        let mut p = from;
        let mut tet = [vertex(p); 4];
        for (s, &axis) in path.iter().enumerate() {
            p[axis] = if up[axis] { p[axis] + 1 } else { p[axis] - 1 };
            tet[s + 1] = vertex(p);
        }
        cells.extend_from_slice(&tet);
    }
}

/// Swaps two vertices of every P1 cell with a negative Jacobian determinant.
pub(super) fn orient_positively(mesh: &mut Mesh) {
    let d = mesh.dim();
    let nn = mesh.kind.nodes();
    for c in 0..mesh.num_cells() {
        let cell = &mesh.cells[c * nn..(c + 1) * nn];
        let p: Vec<&[f64]> = cell.iter().map(|&i| &mesh.coords[i as usize * d..(i as usize + 1) * d]).collect();
        let e: Vec<Vec<f64>> = (1..=d).map(|a| (0..d).map(|k| p[a][k] - p[0][k]).collect()).collect();
        let det = e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) - e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0])
            + e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]);
        if det < 0.0 {
            mesh.cells.swap(c * nn + 1, c * nn + 2);
        }
    }
}

/// Names the boundary facets whose outward normal points along ±axis.
fn name_sides(mesh: &mut Mesh, sides: &[(&str, usize, f64)]) {
    for &(name, axis, sign) in sides {
        mesh.add_region_where(name, |n, _| n[axis] * sign > 0.5);
    }
}
