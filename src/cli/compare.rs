//! `signorini compare A B`: column by column, how far two runs' `series.csv` are apart.

use std::path::Path;
use std::process::ExitCode;

use super::fail;

/// Prints the comparison; fails when `tol` is given and a column differs by more.
pub(super) fn command(a: &Path, b: &Path, tol: Option<f64>) -> ExitCode {
    match compare(a, b) {
        Ok((text, worst)) => {
            print!("{text}");
            match tol {
                Some(t) if worst > t => fail(format!("the runs differ by {worst:e} > {t:e}")),
                _ => ExitCode::SUCCESS,
            }
        }
        Err(e) => fail(e),
    }
}

/// A CSV of numbers with a header line.
fn read(path: &Path) -> Result<(Vec<String>, Vec<Vec<f64>>), String> {
    let file = if path.is_dir() { path.join("series.csv") } else { path.to_path_buf() };
    let text = std::fs::read_to_string(&file).map_err(|e| format!("cannot read {}: {e}", file.display()))?;
    let mut lines = text.lines();
    let header: Vec<String> = lines.next().unwrap_or_default().split(',').map(str::to_string).collect();
    let mut rows = Vec::new();
    for (i, line) in lines.enumerate() {
        let row: Result<Vec<f64>, _> = line.split(',').map(str::parse::<f64>).collect();
        rows.push(row.map_err(|_| format!("{}:{}: not a row of numbers", file.display(), i + 2))?);
    }
    Ok((header, rows))
}

/// The comparison as text, and the largest relative difference over the columns.
pub fn compare(a: &Path, b: &Path) -> Result<(String, f64), String> {
    let ((ha, ra), (hb, rb)) = (read(a)?, read(b)?);
    if ra.len() != rb.len() {
        return Err(format!("{} has {} rows, {} has {}", a.display(), ra.len(), b.display(), rb.len()));
    }
    let mut out = format!("{:<14} {:>14} {:>14}\n", "column", "max |a − b|", "relative");
    let mut worst = 0.0f64;
    for (i, name) in ha.iter().enumerate() {
        let Some(j) = hb.iter().position(|h| h == name) else { continue };
        let (mut diff, mut scale) = (0.0f64, 0.0f64);
        for (x, y) in ra.iter().zip(&rb) {
            let (p, q) = (x.get(i).copied().unwrap_or(f64::NAN), y.get(j).copied().unwrap_or(f64::NAN));
            if p.is_nan() && q.is_nan() {
                continue;
            }
            diff = diff.max((p - q).abs());
            scale = scale.max(p.abs());
        }
        let rel = if scale > 0.0 { diff / scale } else { diff };
        worst = worst.max(rel);
        out.push_str(&format!("{name:<14} {diff:>14.3e} {rel:>14.3e}\n"));
    }
    Ok((out, worst))
}
