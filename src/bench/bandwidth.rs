//! The memory bandwidth a sparse matrix product can draw on: STREAM's triad (a = b + s·c) over
//! arrays far larger than the caches, the best of several passes. A product with a matrix of
//! B bytes that does not fit the caches takes at least B over this bandwidth: the cost model
//! of `bench sphere`'s Krylov solves.

use rayon::prelude::*;

/// Unknowns of each array: 3 × 128 MB.
const LEN: usize = 1 << 24;
const PASSES: usize = 5;

/// The triad's bandwidth in bytes per second on `threads` threads (each pass reads b and c and
/// writes a: 24 bytes per entry, as STREAM counts).
pub fn triad(threads: usize) -> f64 {
    let run = || {
        let (mut a, b, c) = (vec![0.0f64; LEN], vec![1.0f64; LEN], vec![2.0f64; LEN]);
        let chunk = LEN / threads.max(1) / 8;
        let mut best = f64::INFINITY;
        for pass in 0..PASSES {
            let s = 0.5 + pass as f64;
            let clock = std::time::Instant::now();
            a.par_chunks_mut(chunk.max(1)).zip(b.par_chunks(chunk.max(1))).zip(c.par_chunks(chunk.max(1))).for_each(
                |((a, b), c)| {
                    for ((a, b), c) in a.iter_mut().zip(b).zip(c) {
                        *a = b + s * c;
                    }
                },
            );
            best = best.min(clock.elapsed().as_secs_f64());
        }
        // The result is read, so that the passes are not optimized away.
        std::hint::black_box(&a);
        24.0 * LEN as f64 / best
    };
    match rayon::ThreadPoolBuilder::new().num_threads(threads.max(1)).build() {
        Ok(pool) => pool.install(run),
        Err(_) => run(),
    }
}
