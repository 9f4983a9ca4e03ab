//! The resources of a run: the memory it will need, checked before the mesh is built (a mesh
//! size that cannot fit is an error that says what fits, instead of an allocation failure, an
//! abort, minutes later); the memory it used (its peak) and the median of its timings, which
//! summaries and benchmarks report.

use crate::error::CaseError;

/// The median of some timings (NaN of none).
pub fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 { v[n / 2] } else { 0.5 * (v[n / 2 - 1] + v[n / 2]) }
}

/// The process's peak resident memory in bytes (Linux: VmHWM of /proc/self/status).
pub fn peak_memory() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// Peak bytes per unknown, measured: the 3D P2 ball with the iterative solver needs 9.6–9.8 kB
/// per unknown from 108k to 986k unknowns (bench sphere); 2D P2 (about 25 stored entries per
/// row, five matrices, a Cholesky factor of about 60 entries per column) about 2.5 kB; the
/// 1D bar far less.
const BYTES_PER_DOF: [f64; 3] = [500.0, 2_500.0, 10_000.0];

/// The memory the system can still give (Linux: MemAvailable), if known.
pub fn available_bytes() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024.0)
}

/// Errs when `dofs` unknowns in dimension `dim` need more memory than is available. `h`, the
/// mesh size that gave them, lets the message say which size fits (unknowns ∝ h^−dim).
pub fn check(case: &str, dofs: f64, dim: usize, h: Option<f64>) -> Result<(), CaseError> {
    let Some(available) = available_bytes() else { return Ok(()) };
    check_against(case, dofs, dim, h, available)
}

fn check_against(case: &str, dofs: f64, dim: usize, h: Option<f64>, available: f64) -> Result<(), CaseError> {
    let need = dofs * BYTES_PER_DOF[dim.clamp(1, 3) - 1];
    if need <= 0.9 * available {
        return Ok(());
    }
    let gb = |b: f64| b / 1e9;
    let fits = h.map_or(String::new(), |h| {
        format!("; --h {:.3} or coarser fits", h * (need / (0.9 * available)).powf(1.0 / dim as f64))
    });
    Err(CaseError::Option(format!(
        "{case}: about {dofs:.2e} unknowns need about {:.1} GB of memory, and {:.1} GB are available{fits}",
        gb(need),
        gb(available)
    )))
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_message_says_which_size_fits() {
        // 1e9 unknowns in 3D against 24 GB: h must grow by (1e13 / 21.6e9)^(1/3) ≈ 7.7 (0.0077).
        let e = super::check_against("static-block", 1e9, 3, Some(0.001), 24e9).unwrap_err().to_string();
        assert!(
            e.contains("1.00e9 unknowns need about 10000.0 GB of memory") && e.contains("--h 0.008 or coarser"),
            "{e}"
        );
        assert!(super::check_against("a-case", 12_490.0, 2, Some(0.5), 24e9).is_ok());
    }
}
