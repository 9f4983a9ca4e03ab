//! Friction through the whole driver, on the library's `sliding_block` (settled on the plane
//! at the start), with the library's Coulomb laws and the tests' penalty law
//! (`tests/problems/coulomb_penalty.wf`, run by path): a stiff block launched along the ground
//! decelerates at F g and stops at t* = v0/(F g) after v0²/(2 F g), the rigid-body limit, within
//! 2 % for F = 0.2, 0.3, 0.5 (the stop is found on the grid of Δt = 0.005), and friction takes its kinetic energy (within 2 %); on a slope it
//! stays at rest below the friction angle and accelerates at g (sin α − F cos α) above it (within
//! 2 %); without friction (F = 0) it slides on at v0. A frictional law's
//! active points are its contact points, not the regimes of its projection: the disc first
//! touches at the frictionless law's time.

use std::path::Path;
use std::process::Command;

const BIN: &str = env!("CARGO_BIN_EXE_signorini");
const ROOT: &str = env!("CARGO_MANIFEST_DIR");

/// The summary of `signorini ARGS`, run in a directory of its own named `name`.
fn summary(name: &str, args: &[&str]) -> serde_json::Value {
    let dir = std::env::temp_dir().join(format!("signorini-friction-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let out = Command::new(BIN).args(args).arg("--out").arg(&dir).output().expect("the binary runs");
    assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    let summary = std::fs::read_to_string(Path::new(&dir).join("summary.json")).expect("a summary");
    let _ = std::fs::remove_dir_all(&dir);
    serde_json::from_str(&summary).expect("JSON")
}

fn law() -> String {
    format!("{ROOT}/tests/problems/coulomb_penalty.wf")
}

/// The library's frictional laws, each with the scheme and params its rigid-body limits are
/// checked with: the penalty law (the tests' file and the library's), Nitsche–Coulomb θ = 1
/// (γ0 above the block's stiffness) and θ = −1, under HHT (whose damping of the high modes
/// keeps the stiff Nitsche contact from chattering).
fn laws() -> Vec<(String, Vec<&'static str>)> {
    vec![
        (law(), vec![]),
        ("penalty-coulomb".into(), vec![]),
        ("nitsche-coulomb".into(), vec!["--scheme", "hht", "--param", "gamma0=1e5"]),
        ("nitsche-coulomb".into(), vec!["--scheme", "hht", "--param", "gamma0=1e4", "--param", "theta=-1"]),
    ]
}

/// The library's sliding block with friction coefficient `f`, law `law` and `extra` arguments.
fn block(name: &str, law: &str, f: f64, extra: &[&str]) -> serde_json::Value {
    let coefficient = format!("F={f}");
    let args = [&["run", "sliding_block", "--contact", law, "--param", &coefficient][..], extra].concat();
    summary(name, &args)
}

#[test]
fn a_sliding_block_stops_where_and_when_a_rigid_body_would() {
    let (v0, g) = (0.3, 1.0);
    for (k, (law, extra)) in laws().iter().enumerate() {
        for f in [0.2, 0.3, 0.5] {
            let s = block(&format!("block-{k}-{f}"), law, f, extra);
            let (stop, distance) = (s["stop_time"].as_f64().expect("it stops"), s["distance"].as_f64().unwrap());
            let (t_star, d_star) = (v0 / (f * g), v0 * v0 / (2.0 * f * g));
            assert!(
                (stop / t_star - 1.0).abs() < 0.02,
                "{law} {extra:?}, F = {f}: stops at {stop}, the rigid body at {t_star}"
            );
            assert!(
                (distance / d_star - 1.0).abs() < 0.02,
                "{law} {extra:?}, F = {f}: slides {distance}, the rigid body {d_star}"
            );
            // Friction took the kinetic energy ½ m v0² (m = 0.5) the block was launched with.
            let work = s["work_of_friction"].as_f64().unwrap();
            let launched = 0.5 * 0.5 * v0 * v0;
            assert!(
                (work / launched - 1.0).abs() < 0.02,
                "{law} {extra:?}, F = {f}: friction took {work} of {launched}"
            );
        }
    }
}

#[test]
fn on_a_slope_the_block_stays_below_the_friction_angle_and_slides_above_it() {
    let (f, g) = (0.3, 1.0);
    // Nitsche's stick is exact; the penalty law's creeps (docs/problems.md).
    let extra = ["--scheme", "hht", "--param", "gamma0=1e5", "--param", "v0=0", "--t-end", "1"];
    for slope in [0.2, 0.25, 0.4, 1.0] {
        let slope_arg = format!("slope={slope}");
        let args = [&extra[..], &["--param", &slope_arg]].concat();
        let s = block(&format!("slope-{slope}"), "nitsche-coulomb", f, &args);
        let a = s["acceleration"].as_f64().unwrap();
        let (sin, cos) = (slope / f64::hypot(1.0, slope), 1.0 / f64::hypot(1.0, slope));
        if slope < f {
            assert!(a.abs() < 0.02 * g * sin, "tan α = {slope} < F: at rest, yet a = {a}");
        } else {
            let rigid = g * (sin - f * cos);
            assert!((a / rigid - 1.0).abs() < 0.02, "tan α = {slope}: a = {a}, the rigid body's {rigid}");
        }
    }
}

#[test]
fn without_friction_the_block_slides_on() {
    let s = block("block-free", &law(), 0.0, &[]);
    assert!(s.get("stop_time").is_none_or(|v| v.is_null()), "it does not stop: {s}");
    let distance = s["distance"].as_f64().unwrap();
    assert!((distance / (0.3 * 1.6) - 1.0).abs() < 1e-3, "v0 t_end = 0.48, slid {distance}");
}

#[test]
fn a_frictional_laws_active_points_are_its_contact_points() {
    let run = ["run", "disc", "--h", "2", "--t-start", "5.5", "--t-end", "6.6", "--scheme", "hht", "--contact"];
    let first =
        |law: &str| summary(law.rsplit('/').next().unwrap(), &[&run[..], &[law]].concat())["first_contact"].as_f64();
    let frictionless = first("penalty").expect("the disc touches");
    assert_eq!(first(&law()), Some(frictionless), "the same first contact as the frictionless law");
}
