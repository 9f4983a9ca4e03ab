//! The two operations a contact time step spends its time in, once the factorization is
//! reused: a symmetric matrix–vector product (from the whole matrix and from its lower half)
//! and a pair of triangular solves; and the numeric refactorization they avoid. On P2
//! plane-strain patterns the size of the disc's meshes (3 362 and 12 482 unknowns).
//! `cargo bench -p signorini-runtime --bench linalg`.

use criterion::{Criterion, criterion_group, criterion_main};
use signorini_runtime::fem::assembly::Assembler;
use signorini_runtime::linalg::block_factor::BlockFactor;
use std::sync::Arc;

use signorini_runtime::fem::mesh::structured::{Diagonal, rectangle};
use signorini_runtime::fem::test_matrices::diagonally_dominant;
use signorini_runtime::linalg::lower_half::{HalfPattern, LowerHalf};
use signorini_runtime::linalg::{Factorization, Matrix, Structure};

/// A symmetric, strictly diagonally dominant matrix on a P2 plane-strain pattern.
fn spd_matrix(cells: usize) -> Matrix {
    let mesh = rectangle(cells, cells, [0.0, 1.0], [0.0, 1.0], Diagonal::Right, 2);
    diagonally_dominant(&Assembler::new(&mesh))
}

/// `a`'s pattern with blocks that are multiples of the identity (symmetric, as a mass matrix).
fn identity_blocks(a: &Matrix) -> Matrix {
    let mut m = a.clone();
    let (p, d) = (&a.pattern, a.pattern.dim());
    for j in 0..m.size() {
        for k in p.col_ptr[j]..p.col_ptr[j + 1] {
            let i = p.row_idx[k];
            let (lo, hi) = ((i / d).min(j / d), (i / d).max(j / d));
            m.values[k] = if i % d == j % d { 1.0 / (1.0 + ((lo * 7 + hi * 13) % 17) as f64) } else { 0.0 };
        }
    }
    m
}

/// A triangular pass of the factor, in place.
type Pass = fn(&BlockFactor, &mut [f64]);

fn products_and_solves(c: &mut Criterion) {
    for cells in [20, 39] {
        let a = spd_matrix(cells);
        let n = a.size();
        let x: Vec<f64> = (0..n).map(|i| ((i * 31) % 101) as f64 / 101.0).collect();
        let mut y = vec![0.0; n];
        c.bench_function(&format!("symmetric product, {n} unknowns"), |b| b.iter(|| a.mul_vec_transposed(&x, &mut y)));
        let lower = LowerHalf::new(&a, &Arc::new(HalfPattern::new(&a.pattern)));
        c.bench_function(&format!("lower-half product, {n} unknowns"), |b| b.iter(|| lower.mul_vec(&x, &mut y)));
        // Two matrices in one pass (a Newmark stage's M a + K u) against two products above.
        let pair = LowerHalf::fused(&[&a, &a], &Arc::new(HalfPattern::new(&a.pattern)));
        let terms = [(1.0, x.as_slice()), (0.5, x.as_slice())];
        c.bench_function(&format!("fused lower-half product of two, {n} unknowns"), |b| {
            b.iter(|| pair.mul_sum(&terms, &mut y))
        });
        // A mass matrix's blocks are multiples of the identity, stored by one value each.
        let mass = identity_blocks(&a);
        let pair = LowerHalf::fused(&[&mass, &a], &Arc::new(HalfPattern::new(&a.pattern)));
        c.bench_function(&format!("fused lower-half product of a mass and one, {n} unknowns"), |b| {
            b.iter(|| pair.mul_sum(&terms, &mut y))
        });
        let mut f = Factorization::new(Structure::SymmetricPositiveDefinite);
        f.factor(&a).unwrap();
        // The symbolic analysis is kept: this is the refactorization a time step may need.
        c.bench_function(&format!("numeric factorization, {n} unknowns"), |b| b.iter(|| f.factor(&a).unwrap()));
        c.bench_function(&format!("solve pair, {n} unknowns"), |b| {
            b.iter(|| {
                y.copy_from_slice(&x);
                f.solve_in_place(&mut y).unwrap()
            })
        });
        // The two passes apart: the forward pass waits on each column's diagonal solve, the
        // backward pass on each column's sum.
        let bf = f.block().expect("a Cholesky factor in node blocks");
        c.bench_function(&format!("forward pass, {n} unknowns"), |b| {
            b.iter(|| {
                y.copy_from_slice(&x);
                bf.forward(&mut y)
            })
        });
        // The passes with the factor out of the caches (64 MB written in between, untimed), as
        // the forward pass meets it in a step when the step's other data has pushed it out.
        let mut flush = vec![0.0f64; 8 << 20];
        let passes: [(&str, Pass); 2] = [("forward", BlockFactor::forward), ("backward", BlockFactor::backward)];
        for (name, pass) in passes {
            c.bench_function(&format!("{name} pass from memory, {n} unknowns"), |b| {
                b.iter_batched(
                    || {
                        flush.iter_mut().for_each(|v| *v += 1.0);
                        std::hint::black_box(&flush);
                    },
                    |_| {
                        y.copy_from_slice(&x);
                        pass(bf, &mut y)
                    },
                    criterion::BatchSize::PerIteration,
                )
            });
        }
        c.bench_function(&format!("backward pass, {n} unknowns"), |b| {
            b.iter(|| {
                y.copy_from_slice(&x);
                bf.backward(&mut y)
            })
        });
    }
}

criterion_group!(benches, products_and_solves);
criterion_main!(benches);
