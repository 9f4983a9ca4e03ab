//! A curved P2 ball, so that the 3D benchmark needs no Gmsh: the cube [−1, 1]³ with `n`
//! cells per side, each cut into six tetrahedra along its diagonal from the corner nearest the
//! centre (Kuhn's subdivision reflected into each octant, so still conforming), mapped onto
//! the ball by the smooth cube-to-sphere map x′ = x √(1 − y²/2 − z²/2 + y²z²/3) (and cyclic),
//! which sends the cube's surface onto the sphere; then promoted to P2 with the boundary-edge
//! midpoints moved onto the sphere. Every tetrahedron holds its cell's corner nearest the
//! centre, which is inside, so none has all four vertices on the sphere (such slivers invert
//! once curved). Regions: `boundary` (all) and `contact` (outward normal with n_z < 0).

use super::Mesh;
use super::structured::{kuhn, orient_positively};
use crate::fem::element::ElementKind;

/// The ball of `radius` about `center`, with about `radius/h` cells along each half axis.
pub fn ball(radius: f64, center: [f64; 3], h: f64) -> Mesh {
    let half = ((radius / h).round() as usize).max(1);
    let n = 2 * half;
    let v = |i: usize, j: usize, k: usize| ((k * (n + 1) + j) * (n + 1) + i) as u32;
    let mut coords = Vec::with_capacity(3 * (n + 1).pow(3));
    for k in 0..=n {
        for j in 0..=n {
            for i in 0..=n {
                let [x, y, z] = [i, j, k].map(|a| a as f64 / half as f64 - 1.0);
                let (x2, y2, z2) = (x * x, y * y, z * z);
                let q = [
                    x * (1.0 - y2 / 2.0 - z2 / 2.0 + y2 * z2 / 3.0).sqrt(),
                    y * (1.0 - z2 / 2.0 - x2 / 2.0 + z2 * x2 / 3.0).sqrt(),
                    z * (1.0 - x2 / 2.0 - y2 / 2.0 + x2 * y2 / 3.0).sqrt(),
                ];
                coords.extend((0..3).map(|a| center[a] + radius * q[a]));
            }
        }
    }
    let mut cells = Vec::with_capacity(24 * n * n * n);
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                // From the corner nearest the centre, away from it.
                let cell = [i, j, k];
                let start = cell.map(|a| if a < half { a + 1 } else { a });
                kuhn(start, cell.map(|a| a >= half), &|p| v(p[0], p[1], p[2]), &mut cells);
            }
        }
    }
    let mut mesh = Mesh::from_cells(ElementKind::TetrahedronP1, coords, cells);
    orient_positively(&mut mesh);
    let onto_sphere = |p: &mut [f64]| {
        let r = (0..3).map(|k| (p[k] - center[k]).powi(2)).sum::<f64>().sqrt();
        for k in 0..3 {
            p[k] = center[k] + (p[k] - center[k]) * radius / r;
        }
    };
    let mut mesh = mesh.to_p2(Some(&onto_sphere));
    mesh.add_region_where("boundary", |_, _| true);
    mesh.add_region_where("contact", |n, _| n[2] < 0.0);
    mesh
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_ball_is_curved_and_converges_to_its_volume() {
        let exact = 4.0 / 3.0 * std::f64::consts::PI * 1000.0;
        let mut errors = Vec::new();
        for h in [5.0, 2.5, 1.25] {
            let mesh = ball(10.0, [0.0, 0.0, 12.0], h);
            assert_eq!(mesh.kind, crate::fem::element::ElementKind::TetrahedronP2);
            mesh.validate().unwrap();
            // Shape: no cell much thinner than it is long (radius ratio of the straight tets).
            let worst = (0..mesh.num_cells()).map(|c| mesh.cell_size(c)).fold(0.0f64, f64::max);
            assert!(worst < 2.5 * h, "largest cell {worst} for h = {h}");
            // Every boundary node (vertices and edge midpoints) lies on the sphere.
            let boundary = mesh.region_nodes(mesh.region("boundary").unwrap());
            for &i in &boundary {
                let p = mesh.node(i as usize);
                let r = (p[0] * p[0] + p[1] * p[1] + (p[2] - 12.0).powi(2)).sqrt();
                assert!((r - 10.0).abs() < 1e-12, "node {i} at radius {r}");
            }
            // The lower half is the contact zone.
            let contact = mesh.region_nodes(mesh.region("contact").unwrap());
            assert!(contact.iter().all(|&i| mesh.node(i as usize)[2] <= 12.0 + 1e-12));
            assert!(contact.len() * 2 >= boundary.len() - boundary.len() / 10);
            errors.push((mesh.measure() - exact).abs() / exact);
        }
        // Isoparametric P2 with the sphere interpolated quadratically: the volume error falls
        // like h⁴ (measured ratios ≈ 15.6 and 15.9).
        for w in errors.windows(2) {
            assert!(w[0] / w[1] > 12.0, "volume errors {errors:?}");
        }
    }
}
