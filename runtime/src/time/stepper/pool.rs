//! Spare vectors of the problem's size, so that a step allocates none once the first has run.

/// Spare vectors, reused.
#[derive(Default)]
pub(super) struct Pool(Vec<Vec<f64>>);

impl Pool {
    /// A vector of length `n`, contents unspecified.
    pub(super) fn take(&mut self, n: usize) -> Vec<f64> {
        let mut v = self.0.pop().unwrap_or_default();
        v.resize(n, 0.0);
        v
    }

    /// A vector of `n` zeros.
    pub(super) fn zeros(&mut self, n: usize) -> Vec<f64> {
        let mut v = self.take(n);
        v.fill(0.0);
        v
    }

    /// A copy of `x`.
    pub(super) fn copy(&mut self, x: &[f64]) -> Vec<f64> {
        let mut v = self.take(x.len());
        v.copy_from_slice(x);
        v
    }

    pub(super) fn give(&mut self, v: Vec<f64>) {
        // Bounded, should a scheme give back more than it takes.
        if v.capacity() > 0 && self.0.len() < 64 {
            self.0.push(v);
        }
    }
}
