//! `signorini bench search`: the facing-point search of contact between bodies
//! (`runtime::fem::facing`) against the number of facets. A strip's bottom (2D, curved P2
//! facets) and a slab's (3D, triangles) are bent by a wave, the configuration the search reads,
//! and each facet is faced by a point a little below its middle, as another body's surface
//! would face it. Timed, as medians over repeated runs: building the index (the R-tree of the
//! facets' boxes, redone whenever the surface moves) and the queries (broad phase and the
//! projections onto the candidates), per facet and against n log₂ n.

use std::time::Instant;

use serde::{Deserialize, Serialize};

use crate::resources::median;
use crate::runtime::fem::facing::Surface;
use crate::runtime::fem::mesh::{Facet, Mesh, structured};

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SearchTiming {
    pub dim: usize,
    pub facets: usize,
    /// Median over runs: building the index, and all the queries (one per facet).
    pub build_ms: f64,
    pub queries_ms: f64,
    /// The same per facet and per n log₂ n (ns): flat with n when the cost is n log n.
    pub build_ns_per_n_log_n: f64,
    pub query_ns_per_n_log_n: f64,
    /// Queries that found their facet (all of them, on this geometry).
    pub found: usize,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SearchReport {
    pub repeats: usize,
    pub timings: Vec<SearchTiming>,
}

/// The facet counts timed: about 10³, 10⁴ and 10⁵ in each dimension.
const SIZES_2D: [usize; 3] = [1_000, 10_000, 100_000];
const SIDES_3D: [usize; 3] = [22, 71, 224];

pub fn search(repeats: usize, log: &mut dyn FnMut(String)) -> SearchReport {
    let mut timings = Vec::new();
    let strips = SIZES_2D
        .map(|n| structured::rectangle(n, 1, [0.0, 0.1 * n as f64], [0.0, 0.1], structured::Diagonal::Right, 2));
    let slabs = SIDES_3D.map(|m| {
        let side = 0.1 * m as f64;
        structured::cuboid([m, m, 1], [0.0, side], [0.0, side], [0.0, 0.1], 1)
    });
    for mesh in strips.iter().chain(&slabs) {
        let t = time(mesh, repeats.max(1));
        log(format!(
            "{}D, {} facets: build {:.3} ms, queries {:.3} ms ({:.1} and {:.1} ns per n log2 n), {} found",
            t.dim, t.facets, t.build_ms, t.queries_ms, t.build_ns_per_n_log_n, t.query_ns_per_n_log_n, t.found
        ));
        timings.push(t);
    }
    SearchReport { repeats, timings }
}

/// The mesh's bottom facets bent by a wave, each faced from 0.03 below its middle.
fn time(mesh: &Mesh, repeats: usize) -> SearchTiming {
    let d = mesh.dim();
    let bottom: Vec<Facet> =
        mesh.boundary_facets().into_iter().filter(|&f| mesh.facet_normal_and_centroid(f).0[d - 1] < -0.5).collect();
    let wave = |x: &[f64]| 0.02 * (std::f64::consts::TAU * x[0]).sin() * (1.0 + x[d - 2]).cos();
    let u: Vec<f64> = (0..mesh.num_nodes())
        .flat_map(|i| (0..d).map(move |k| (i, k)))
        .map(|(i, k)| if k == d - 1 { wave(mesh.node(i)) } else { 0.0 })
        .collect();
    let points: Vec<Vec<f64>> = bottom
        .iter()
        .map(|&f| {
            let (_, mut x) = mesh.facet_normal_and_centroid(f);
            x[d - 1] += wave(&x) - 0.03;
            x
        })
        .collect();
    let (mut builds, mut queries, mut found) = (Vec::new(), Vec::new(), 0);
    for _ in 0..repeats {
        let start = Instant::now();
        let surface = Surface::new(mesh, &bottom, &u);
        builds.push(start.elapsed().as_secs_f64());
        let start = Instant::now();
        found = points.iter().filter(|p| surface.closest(p, 0.2).is_some()).count();
        queries.push(start.elapsed().as_secs_f64());
    }
    let n = bottom.len() as f64;
    let (build, query) = (median(builds), median(queries));
    SearchTiming {
        dim: d,
        facets: bottom.len(),
        build_ms: build * 1e3,
        queries_ms: query * 1e3,
        build_ns_per_n_log_n: build * 1e9 / (n * n.log2()),
        query_ns_per_n_log_n: query * 1e9 / (n * n.log2()),
        found,
    }
}
