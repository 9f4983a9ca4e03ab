//! The facing-point search's broad phase with two spatial-index crates on the same boxes:
//! rstar's R-tree (bulk-loaded), which `fem::facing` uses, and bvh's binary BVH (built by the
//! surface area heuristic). The boxes are those of a surface of triangles bent by a wave, as
//! `signorini bench search`'s slab; each query asks for the boxes that meet a cube around a
//! point a little below a triangle's centroid, as a quadrature point of the other body's
//! surface would, and orders them by distance, as `Surface::closest` does. Timed: building the
//! index, and all the queries, at about 10⁴ and 10⁵ triangles.

use std::hint::black_box;

use bvh::aabb::{Aabb, Bounded};
use bvh::bounding_hierarchy::BHShape;
use bvh::bvh::Bvh;
use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::Point3;
use rstar::primitives::{GeomWithData, Rectangle};
use rstar::{AABB, PointDistance, RTree};

/// A triangle's box, as bvh wants it (with its node in the hierarchy).
struct Boxed {
    lower: [f64; 3],
    upper: [f64; 3],
    node: usize,
}

impl Bounded<f64, 3> for Boxed {
    fn aabb(&self) -> Aabb<f64, 3> {
        Aabb::with_bounds(Point3::from(self.lower), Point3::from(self.upper))
    }
}

impl BHShape<f64, 3> for Boxed {
    fn set_bh_node_index(&mut self, index: usize) {
        self.node = index;
    }
    fn bh_node_index(&self) -> usize {
        self.node
    }
}

/// A box: its lower and upper corners.
type Corners = ([f64; 3], [f64; 3]);

/// The boxes of the 2 m² triangles of [0, 0.1 m]² bent by a wave, and one query point per
/// triangle, 0.03 below its centroid.
fn surface(m: usize) -> (Vec<Corners>, Vec<[f64; 3]>) {
    let wave = |x: f64, y: f64| 0.02 * (std::f64::consts::TAU * x).sin() * (1.0 + y).cos();
    let at = |i: usize, j: usize| {
        let (x, y) = (0.1 * i as f64, 0.1 * j as f64);
        [x, y, wave(x, y)]
    };
    let (mut boxes, mut points) = (Vec::new(), Vec::new());
    for i in 0..m {
        for j in 0..m {
            for corners in [[at(i, j), at(i + 1, j), at(i + 1, j + 1)], [at(i, j), at(i + 1, j + 1), at(i, j + 1)]] {
                let lower = std::array::from_fn(|r| corners.iter().map(|c| c[r]).fold(f64::INFINITY, f64::min));
                let upper = std::array::from_fn(|r| corners.iter().map(|c| c[r]).fold(f64::NEG_INFINITY, f64::max));
                boxes.push((lower, upper));
                let mut centroid: [f64; 3] = std::array::from_fn(|r| corners.iter().map(|c| c[r]).sum::<f64>() / 3.0);
                centroid[2] -= 0.03;
                points.push(centroid);
            }
        }
    }
    (boxes, points)
}

/// The half side of the query's cube: about two triangles.
const REACH: f64 = 0.2;

fn rtree(boxes: &[Corners]) -> RTree<GeomWithData<Rectangle<[f64; 3]>, u32>> {
    RTree::bulk_load(
        boxes
            .iter()
            .enumerate()
            .map(|(k, (lo, hi))| GeomWithData::new(Rectangle::from_corners(*lo, *hi), k as u32))
            .collect(),
    )
}

fn bvh_of(boxes: &[Corners]) -> (Bvh<f64, 3>, Vec<Boxed>) {
    let mut shapes: Vec<Boxed> =
        boxes.iter().map(|(lower, upper)| Boxed { lower: *lower, upper: *upper, node: 0 }).collect();
    let bvh = Bvh::build(&mut shapes);
    (bvh, shapes)
}

/// The distance² from `p` to a box.
fn distance_2(lower: &[f64; 3], upper: &[f64; 3], p: &[f64; 3]) -> f64 {
    (0..3).map(|r| (lower[r] - p[r]).max(p[r] - upper[r]).max(0.0).powi(2)).sum()
}

fn cube(p: &[f64; 3]) -> Corners {
    (std::array::from_fn(|r| p[r] - REACH), std::array::from_fn(|r| p[r] + REACH))
}

fn bench(c: &mut Criterion) {
    for m in [71, 224] {
        let (boxes, points) = surface(m);
        let n = boxes.len();
        let mut group = c.benchmark_group(format!("spatial_index/{n}_boxes"));
        group.sample_size(10);
        group.bench_function("rstar_build", |b| b.iter(|| black_box(rtree(&boxes))));
        group.bench_function("bvh_build", |b| b.iter(|| black_box(bvh_of(&boxes))));
        let tree = rtree(&boxes);
        let (bvh, shapes) = bvh_of(&boxes);
        // Both find the same candidates for every query.
        for p in points.iter().step_by(97) {
            let (lo, hi) = cube(p);
            let mut a: Vec<u32> =
                tree.locate_in_envelope_intersecting(AABB::from_corners(lo, hi)).map(|g| g.data).collect();
            let query = Aabb::with_bounds(Point3::from(lo), Point3::from(hi));
            let mut b: Vec<u32> = bvh
                .traverse(&query, &shapes)
                .into_iter()
                .map(|s| shapes.iter().position(|t| std::ptr::eq(t, s)).unwrap() as u32)
                .collect();
            a.sort_unstable();
            b.sort_unstable();
            assert_eq!(a, b, "the two indexes disagree at {p:?}");
        }
        group.bench_function("rstar_queries", |b| {
            b.iter(|| {
                let mut found = 0;
                for p in &points {
                    let (lo, hi) = cube(p);
                    let mut near: Vec<(f64, u32)> = tree
                        .locate_in_envelope_intersecting(AABB::from_corners(lo, hi))
                        .map(|g| (g.geom().distance_2(p), g.data))
                        .collect();
                    near.sort_by(|a, b| a.0.total_cmp(&b.0));
                    found += near.len();
                }
                black_box(found)
            })
        });
        group.bench_function("bvh_queries", |b| {
            b.iter(|| {
                let mut found = 0;
                for p in &points {
                    let (lo, hi) = cube(p);
                    let query = Aabb::with_bounds(Point3::from(lo), Point3::from(hi));
                    let mut near: Vec<(f64, &Boxed)> = bvh
                        .traverse_iterator(&query, &shapes)
                        .map(|s| (distance_2(&s.lower, &s.upper, p), s))
                        .collect();
                    near.sort_by(|a, b| a.0.total_cmp(&b.0));
                    found += near.len();
                }
                black_box(found)
            })
        });
        group.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
