//! The cost of a mesh's integrity checks (`Mesh::validate`, run on every mesh read) on the
//! largest built-in ball of `bench sphere` (985k unknowns), against one quadrature pass over
//! its cells (`Mesh::measure`, a lower bound for an assembly).
//! `cargo bench -p signorini-runtime --bench mesh`.

use criterion::{Criterion, criterion_group, criterion_main};
use signorini_runtime::fem::mesh::ball::ball;

fn checks_against_a_pass(c: &mut Criterion) {
    let mesh = ball(10.0, [0.0, 0.0, 12.0], 10.0 / 17.0);
    let name = format!("{} cells, {} unknowns", mesh.num_cells(), 3 * mesh.num_nodes());
    let mut group = c.benchmark_group("large ball");
    group.sample_size(10);
    group.bench_function(format!("validate, {name}"), |b| b.iter(|| mesh.validate().unwrap()));
    group.bench_function(format!("one quadrature pass, {name}"), |b| b.iter(|| mesh.measure()));
    group.finish();
}

criterion_group!(benches, checks_against_a_pass);
criterion_main!(benches);
