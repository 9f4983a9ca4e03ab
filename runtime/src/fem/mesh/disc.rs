//! A curved P2 disc for the bouncing-disc benchmark, so that no Gmsh is needed: concentric
//! rings of 6k vertices at radii kR/m (m = ⌈R/h⌉), zipped into triangles by angle, promoted to
//! P2 with the boundary-edge midpoints moved onto the circle. Regions: `boundary` (all) and
//! `contact` (outward normal with n_y < 0, the lower half).

use super::Mesh;
use crate::fem::element::ElementKind;

/// The disc of `radius` about `center`, with rings about `h` apart.
pub fn disc(radius: f64, center: [f64; 2], h: f64) -> Mesh {
    let m = ((radius / h).ceil() as usize).max(1);
    let mut coords = vec![center[0], center[1]];
    let mut ring_start = vec![0usize];
    for k in 1..=m {
        ring_start.push(coords.len() / 2);
        let r = radius * k as f64 / m as f64;
        let n = 6 * k;
        for j in 0..n {
            let a = std::f64::consts::TAU * j as f64 / n as f64;
            coords.push(center[0] + r * a.cos());
            coords.push(center[1] + r * a.sin());
        }
    }
    let mut cells: Vec<u32> = Vec::with_capacity(3 * 6 * m * m);
    // Innermost ring: a fan around the centre.
    for j in 0..6 {
        cells.extend_from_slice(&[0, (1 + j) as u32, (1 + (j + 1) % 6) as u32]);
    }
    for k in 2..=m {
        let (ni, no) = (6 * (k - 1), 6 * k);
        let inner = |a: usize| (ring_start[k - 1] + a % ni) as u32;
        let outer = |b: usize| (ring_start[k] + b % no) as u32;
        let (mut a, mut b) = (0, 0);
        while a < ni || b < no {
            // Advance on the ring whose next node comes first in angle: (a+1)/ni vs (b+1)/no.
            let outer_first = a == ni || (b < no && (b + 1) * ni <= (a + 1) * no);
            if outer_first {
                cells.extend_from_slice(&[inner(a), outer(b), outer(b + 1)]);
                b += 1;
            } else {
                cells.extend_from_slice(&[inner(a), outer(b), inner(a + 1)]);
                a += 1;
            }
        }
    }
    let p1 = Mesh::from_cells(ElementKind::TriangleP1, coords, cells);
    let onto_circle = |p: &mut [f64]| {
        let (dx, dy) = (p[0] - center[0], p[1] - center[1]);
        let r = (dx * dx + dy * dy).sqrt();
        p[0] = center[0] + dx * radius / r;
        p[1] = center[1] + dy * radius / r;
    };
    let mut mesh = p1.to_p2(Some(&onto_circle));
    mesh.add_region_where("boundary", |_, _| true);
    mesh.add_region_where("contact", |n, _| n[1] < 0.0);
    mesh
}
