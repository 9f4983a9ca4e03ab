//! `signorini bench ...`: timings with medians of repeated runs, written as JSON.

pub mod assemble;
pub mod disc;

pub use assemble::assemble;

pub fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 { v[n / 2] } else { 0.5 * (v[n / 2 - 1] + v[n / 2]) }
}
