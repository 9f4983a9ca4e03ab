//! What the contact pairs' search and assembly cost a run: counted by each pair form as it
//! works, summed over a stepper's forms for the run's summary.

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

/// The searches for facing points and the pair assembly they serve, so far.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SearchCost {
    /// Spatial indexes built (one per residual, tangent or functional evaluated).
    pub builds: u64,
    /// Facing points looked for (one per quadrature point of an own surface, per evaluation).
    pub queries: u64,
    /// Time building the indexes and answering the queries.
    pub search_seconds: f64,
    /// Time in the pair forms' residuals, tangents and functionals, the search included.
    pub assembly_seconds: f64,
}

impl std::ops::Add for SearchCost {
    type Output = SearchCost;
    fn add(self, o: SearchCost) -> SearchCost {
        SearchCost {
            builds: self.builds + o.builds,
            queries: self.queries + o.queries,
            search_seconds: self.search_seconds + o.search_seconds,
            assembly_seconds: self.assembly_seconds + o.assembly_seconds,
        }
    }
}

/// A pair form's running counts, shared by the threads that evaluate it.
#[derive(Debug, Default)]
pub struct Meter {
    builds: AtomicU64,
    queries: AtomicU64,
    search_nanos: AtomicU64,
    assembly_nanos: AtomicU64,
}

impl Meter {
    /// Counts an index built since `start`.
    pub fn built(&self, start: Instant) {
        self.builds.fetch_add(1, Ordering::Relaxed);
        self.search_nanos.fetch_add(nanos(start), Ordering::Relaxed);
    }

    /// Counts a query answered since `start`.
    pub fn queried(&self, start: Instant) {
        self.queries.fetch_add(1, Ordering::Relaxed);
        self.search_nanos.fetch_add(nanos(start), Ordering::Relaxed);
    }

    /// Counts an evaluation (residual, tangent or functional) since `start`.
    pub fn evaluated(&self, start: Instant) {
        self.assembly_nanos.fetch_add(nanos(start), Ordering::Relaxed);
    }

    pub fn cost(&self) -> SearchCost {
        SearchCost {
            builds: self.builds.load(Ordering::Relaxed),
            queries: self.queries.load(Ordering::Relaxed),
            search_seconds: self.search_nanos.load(Ordering::Relaxed) as f64 * 1e-9,
            assembly_seconds: self.assembly_nanos.load(Ordering::Relaxed) as f64 * 1e-9,
        }
    }
}

fn nanos(start: Instant) -> u64 {
    u64::try_from(start.elapsed().as_nanos()).unwrap_or(u64::MAX)
}
