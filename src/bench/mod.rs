//! `signorini bench ...`: timings with medians of repeated runs, written as JSON.

pub mod assemble;
pub mod balls;
pub mod bandwidth;
pub mod disc;
pub mod search;
pub mod sphere;

pub use assemble::assemble;
