//! `--solver petsc` (feature `petsc`) against the direct solver: the disc through its first
//! impact, with Nitsche's θ = 1 (symmetric tangents: CG) and θ = −1 (GMRES), and the sphere;
//! every column of the series agrees to 1e-8 of its scale (`assert_agree`). The user's
//! `-ksp_rtol` and `-pc_type` stand; a static stiffness turns block Jacobi into GAMG. Bad PETSc
//! options are an error with PETSc's message.

use std::path::Path;
use std::process::Command;

const BIN: &str = env!("CARGO_BIN_EXE_signorini");

/// The series of `run ARGS --solver SOLVER`, as its header and rows.
fn series(args: &[&str], solver: &str, dir: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let out = Command::new(BIN)
        .args(["run"])
        .args(args)
        .args(["--solver", solver, "--force", "--out"])
        .arg(dir)
        .output()
        .expect("the binary runs");
    assert!(out.status.success(), "{args:?} --solver {solver}: {}", String::from_utf8_lossy(&out.stderr));
    read_series(dir)
}

/// `dir/series.csv` as its header and rows (NaN where a value is empty).
pub(super) fn read_series(dir: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(dir.join("series.csv")).expect("a series");
    let mut lines = text.lines();
    let header = lines.next().expect("a header").split(',').map(str::to_string).collect();
    let rows = lines.map(|l| l.split(',').map(|v| v.parse().unwrap_or(f64::NAN)).collect()).collect();
    (header, rows)
}

/// The energy scale of the run in `dir`: its summary's `kinetic_energy_max` (the disc's and the
/// sphere's problem files declare it so; their energy is 0 at the start).
pub(super) fn energy_scale(dir: &Path) -> f64 {
    read_summary(dir)["kinetic_energy_max"].as_f64().expect("kinetic_energy_max in the summary")
}

/// `dir/summary.json`.
fn read_summary(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).expect("a summary")).expect("JSON")
}

/// Every column of `rows` equals `reference`'s to 1e-8 of the column's largest value (NaN where
/// it is NaN), as many rows; but `newton`, the count of Newton's iterations, which an iterative
/// solver's loose solves raise by design (inexact Newton) where the direct solver's need none.
/// The energy columns (`energy…`) are sums of kinetic, elastic and gravity's energies that
/// cancel to a thousandth of them: their scale is the run's `energy` scale, the size of those
/// terms (on the disc at θ = −1, block-Jacobi GMRES at a fixed 1e-12 left 4e-8 of the column's
/// own largest value with the velocities agreeing to 2e-11, which is 4e-11 of this scale), and
/// to 1e-6 of their own.
pub(super) fn assert_agree(what: &str, header: &[String], reference: &[Vec<f64>], rows: &[Vec<f64>], energy: f64) {
    assert_eq!(reference.len(), rows.len(), "{what}: as many rows");
    for (c, column) in header.iter().enumerate().filter(|(_, name)| *name != "newton") {
        let own = reference.iter().map(|r| r[c].abs()).filter(|v| v.is_finite()).fold(0.0, f64::max);
        // An energy column is also held to 1e-6 of its own scale, so that a drift of its own
        // does not hide behind the energy's.
        let (scale, own_tolerance) = if column.starts_with("energy") { (own.max(energy), 1e-6) } else { (own, 1e-8) };
        for (d, p) in reference.iter().zip(rows) {
            let (d, p) = (d[c], p[c]);
            let tolerance = (1e-8 * scale).min(own_tolerance * own).max(f64::MIN_POSITIVE);
            assert!(
                (d.is_nan() && p.is_nan()) || (d - p).abs() <= tolerance,
                "{what}: {column} {p} against {d} (scale {scale:e}, own {own:e})"
            );
        }
    }
}

fn agree(args: &[&str], name: &str) {
    let tmp = std::env::temp_dir().join(format!("signorini-petsc-{name}-{}", std::process::id()));
    let (header, direct) = series(args, "direct", &tmp.join("direct"));
    let (_, petsc) = series(args, "petsc", &tmp.join("petsc"));
    assert_agree(name, &header, &direct, &petsc, energy_scale(&tmp.join("direct")));
    let _ = std::fs::remove_dir_all(&tmp);
}

#[test]
fn the_disc_through_impact_agrees_with_the_direct_solver() {
    agree(&["disc", "--t-start", "6", "--t-end", "8"], "disc");
    agree(&["disc", "--t-start", "6", "--t-end", "8", "--param", "theta=-1"], "disc-unsymmetric");
}

#[test]
fn the_sphere_through_impact_agrees_with_the_direct_solver() {
    agree(&["sphere", "--t-start", "6.3", "--t-end", "6.45"], "sphere");
}

/// A user's `-ksp_rtol` replaces Newton's per-solve tolerances: at 1e-14 no solve is loose, so
/// Newton takes the direct solver's iterations, step by step (with Newton's own tolerances
/// the disc at θ = −1 takes 132 against 119).
#[test]
fn the_users_ksp_rtol_stands() {
    let tmp = std::env::temp_dir().join(format!("signorini-petsc-rtol-{}", std::process::id()));
    let args = ["disc", "--t-start", "6", "--t-end", "8", "--param", "theta=-1"];
    let (header, direct) = series(&args, "direct", &tmp.join("direct"));
    let with: Vec<&str> = [&args[..], &["--petsc-options", "-ksp_rtol 1e-14"]].concat();
    let (_, petsc) = series(&with, "petsc", &tmp.join("petsc"));
    let newton = header.iter().position(|c| c == "newton").expect("a newton column");
    let iterations = |rows: &[Vec<f64>]| rows.iter().map(|r| r[newton]).collect::<Vec<_>>();
    assert_eq!(iterations(&petsc), iterations(&direct), "Newton's iterations, step by step");
    assert_agree("disc with -ksp_rtol", &header, &direct, &petsc, energy_scale(&tmp.join("direct")));
    let _ = std::fs::remove_dir_all(&tmp);
}

/// The static block: block Jacobi does not serve a stiffness alone, so the solver turns to
/// GAMG (and logs it); a user's `-pc_type` is kept as given. Both agree with the direct solver.
#[test]
fn a_static_stiffness_turns_to_multigrid_unless_the_user_chose() {
    let tmp = std::env::temp_dir().join(format!("signorini-petsc-static-{}", std::process::id()));
    series(&["static_block"], "direct", &tmp.join("direct"));
    let direct = read_summary(&tmp.join("direct"));
    let run = |options: &[&str], name: &str| {
        let dir = tmp.join(name);
        let out = Command::new(BIN)
            .args(["run", "static_block", "--solver", "petsc", "--force", "--out"])
            .arg(&dir)
            .args(options)
            .env("RUST_LOG", "signorini_runtime=info")
            .output()
            .expect("the binary runs");
        let log = String::from_utf8_lossy(&out.stderr).to_string();
        assert!(out.status.success(), "{name}: {log}");
        let answer = read_summary(&dir);
        for key in ["contact_force", "max_penetration", "active_points"] {
            let (d, p) = (direct[key].as_f64().expect(key), answer[key].as_f64().expect(key));
            assert!((d - p).abs() <= 1e-8 * d.abs(), "{name}: {key} {p} against {d}");
        }
        log.contains("GAMG from now on")
    };
    assert!(run(&[], "switched"), "block Jacobi gave way to GAMG");
    assert!(!run(&["--petsc-options", "-pc_type bjacobi"], "chosen"), "the user's block Jacobi stays");
    let _ = std::fs::remove_dir_all(&tmp);
}

/// A factorization through PETSc (`-ksp_type preonly`) is the solve itself: it is set up
/// again for every new tangent, never kept like a Krylov method's preconditioner (kept, the
/// Hertz ball's second Newton iteration solved with its first tangent and failed).
#[test]
fn a_factorization_through_petsc_is_never_kept_for_a_new_tangent() {
    let tmp = std::env::temp_dir().join(format!("signorini-petsc-preonly-{}", std::process::id()));
    let args = ["hertz_ball", "--param", "level=0"];
    series(&args, "direct", &tmp.join("direct"));
    let with: Vec<&str> = [&args[..], &["--petsc-options", "-ksp_type preonly -pc_type lu"]].concat();
    series(&with, "petsc", &tmp.join("petsc"));
    let (direct, petsc) = (read_summary(&tmp.join("direct")), read_summary(&tmp.join("petsc")));
    for key in ["contact_radius", "peak_pressure", "contact_force"] {
        let (d, p) = (direct[key].as_f64().expect(key), petsc[key].as_f64().expect(key));
        assert!((d - p).abs() <= 1e-10 * d.abs(), "{key}: {p} against {d}");
    }
    let _ = std::fs::remove_dir_all(&tmp);
}

#[test]
fn bad_petsc_options_are_an_error_with_petscs_message() {
    let out = Command::new(BIN)
        .args(["run", "disc", "--t-start", "6", "--t-end", "6.2", "--solver", "petsc"])
        .args(["--petsc-options", "-ksp_type no_such_method"])
        .output()
        .expect("the binary runs");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(stderr.contains("PETSc") && stderr.contains("no_such_method"), "{stderr}");
}
