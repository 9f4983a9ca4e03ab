//! Friction through the whole driver, with the penalty Coulomb law of the tests
//! (`tests/problems/coulomb_penalty.wf`, run by path): a stiff block launched along the ground
//! decelerates at F g and stops at t* = v0/(F g) after v0²/(2 F g), the rigid-body limit, within
//! 1 % for F = 0.2, 0.3, 0.5; without friction (F = 0) it slides on at v0. A frictional law's
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

/// The sliding block's summary with friction coefficient `f`.
fn slide(f: f64) -> serde_json::Value {
    let problem = format!("{ROOT}/tests/problems/sliding_block.wf");
    summary(&format!("block-{f}"), &["run", &problem, "--contact", &law(), "--param", &format!("F={f}")])
}

#[test]
fn a_sliding_block_stops_where_and_when_a_rigid_body_would() {
    let (v0, g) = (0.3, 1.0);
    for f in [0.2, 0.3, 0.5] {
        let s = slide(f);
        let (stop, distance) = (s["stop_time"].as_f64().expect("it stops"), s["distance"].as_f64().unwrap());
        let (t_star, d_star) = (v0 / (f * g), v0 * v0 / (2.0 * f * g));
        assert!((stop / t_star - 1.0).abs() < 0.01, "F = {f}: stops at {stop}, the rigid body at {t_star}");
        assert!((distance / d_star - 1.0).abs() < 0.01, "F = {f}: slides {distance}, the rigid body {d_star}");
    }
}

#[test]
fn without_friction_the_block_slides_on() {
    let s = slide(0.0);
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
