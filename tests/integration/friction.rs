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
    run(name, args).0
}

/// The summary and the series (by column name) of `signorini ARGS`.
fn run(name: &str, args: &[&str]) -> (serde_json::Value, Series) {
    let dir = std::env::temp_dir().join(format!("signorini-friction-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let out = Command::new(BIN).args(args).arg("--out").arg(&dir).output().expect("the binary runs");
    assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    let summary = std::fs::read_to_string(Path::new(&dir).join("summary.json")).expect("a summary");
    let csv = std::fs::read_to_string(Path::new(&dir).join("series.csv")).expect("a series");
    let _ = std::fs::remove_dir_all(&dir);
    (serde_json::from_str(&summary).expect("JSON"), Series::parse(&csv))
}

/// A series.csv: its header and rows.
struct Series {
    names: Vec<String>,
    rows: Vec<Vec<f64>>,
}

impl Series {
    fn parse(csv: &str) -> Series {
        let mut lines = csv.lines();
        let names = lines.next().expect("a header").split(',').map(str::to_string).collect();
        let rows = lines.map(|l| l.split(',').map(|x| x.parse().expect("a number")).collect()).collect();
        Series { names, rows }
    }

    /// Column `name` over the rows.
    fn column(&self, name: &str) -> Vec<f64> {
        let k = self.names.iter().position(|n| n == name).unwrap_or_else(|| panic!("no column {name}"));
        self.rows.iter().map(|r| r[k]).collect()
    }
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
    let coefficient = format!("mu={f}");
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

/// With F = 0 a Coulomb law is its frictionless law: the same residual and tangent bits
/// (tests/integration/friction_laws.rs), and, its friction radius zero at every point, a
/// tangent that the active set decides, so that Newton takes the frictionless law's path: the
/// same series, byte for byte, under every scheme.
#[test]
fn without_friction_the_coulomb_laws_give_the_frictionless_laws_series_bit_for_bit() {
    let window = ["run", "disc", "--h", "2", "--t-start", "5.5", "--t-end", "7.5", "--scheme"];
    let series = |name: String, args: Vec<&str>| {
        let dir = std::env::temp_dir().join(format!("signorini-friction-f0-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let out = Command::new(BIN).args(&args).arg("--out").arg(&dir).output().expect("the binary runs");
        assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
        let csv = std::fs::read(dir.join("series.csv")).expect("a series");
        let _ = std::fs::remove_dir_all(&dir);
        csv
    };
    let pairs = [("nitsche-traction", "nitsche-coulomb", "theta=-1"), ("penalty", "penalty-coulomb", "gamma0=1000")];
    for scheme in ["hht", "newmark", "midpoint", "trbdf2", "hybrid"] {
        for (frictionless, coulomb, param) in pairs {
            let free = [&window[..], &[scheme, "--contact", frictionless, "--param", param]].concat();
            let zero = [&window[..], &[scheme, "--contact", coulomb, "--param", param, "--param", "F=0"]].concat();
            assert!(
                series(format!("{scheme}-{frictionless}"), free) == series(format!("{scheme}-{coulomb}"), zero),
                "{scheme}: {coulomb} with F = 0 differs from {frictionless}"
            );
        }
    }
}

#[test]
fn a_frictional_laws_active_points_are_its_contact_points() {
    let run = ["run", "disc", "--h", "2", "--t-start", "5.5", "--t-end", "6.6", "--scheme", "hht", "--contact"];
    let first =
        |law: &str| summary(law.rsplit('/').next().unwrap(), &[&run[..], &[law]].concat())["first_contact"].as_f64();
    let frictionless = first("penalty").expect("the disc touches");
    assert_eq!(first(&law()), Some(frictionless), "the same first contact as the frictionless law");
}

/// The library's `rolling_disc`: settled on the plane and launched at v0 without spin, a stiff
/// disc slides, then rolls from t* = v0/(3 μ g) at 2 v0/3 (a rigid uniform disc), within 3 %,
/// under HHT with Nitsche–Coulomb θ = −1 (the file's) and with the penalty law.
#[test]
fn a_disc_launched_without_spin_rolls_from_where_a_rigid_disc_would() {
    for (k, law) in ["nitsche-coulomb", "penalty-coulomb"].iter().enumerate() {
        let s = summary(&format!("rolling-{k}"), &["run", "rolling_disc", "--contact", law]);
        let (v0, mu, g) = (0.2, 0.3, 1.0);
        let t_star = v0 / (3.0 * mu * g);
        let time = s["rolling_time"].as_f64().expect("it rolls");
        let speed = s["rolling_speed"].as_f64().unwrap();
        let spin = s["rolling_spin"].as_f64().unwrap();
        assert!((time / t_star - 1.0).abs() < 0.03, "{law}: rolls from {time}, the rigid disc from {t_star}");
        assert!((speed / (2.0 * v0 / 3.0) - 1.0).abs() < 0.03, "{law}: rolls at {speed}, the rigid disc at 2 v0/3");
        // Rolling: the spin times R = 1 is the speed (the slip below 1 % of v0).
        assert!((spin - speed).abs() < 0.01 * v0, "{law}: spin {spin}, speed {speed}");
    }
}

/// The library's `shear_block`: pressed by its weight N = 1 and sheared from the top, the
/// block's tangential reaction T stays ≤ F N at every row (pointwise |λ_t| ≤ F |λ_N|
/// integrated) and equals F N within 1 % once it slides; under Tresca it stays ≤ s |Γ_C| and
/// saturates there. Each law's stick or slip is decided at the quadrature points: the bound
/// holds to round-off. The same without inertia, under the examples' quasi-static scheme.
#[test]
fn a_sheared_block_s_reaction_saturates_at_the_friction_limit() {
    // Without inertia too: the quasi-static scheme of the examples.
    let quasistatic = format!("{ROOT}/examples/problems/quasistatic.wf");
    let laws: [(&str, &[&str]); 6] = [
        ("nitsche-coulomb", &[]),
        ("nitsche-coulomb", &["--param", "theta=-1"]),
        ("nitsche-coulomb", &["--param", "mu=0.5"]),
        ("nitsche-coulomb", &["--scheme", &quasistatic]),
        ("penalty-coulomb", &[]),
        ("nitsche-tresca", &["--param", "s=0.1"]),
    ];
    for (k, (law, extra)) in laws.iter().enumerate() {
        let args = [&["run", "shear_block", "--contact", law][..], extra].concat();
        let (s, series) = run(&format!("shear-{k}"), &args);
        let (t, tangential, normal) = (series.column("t"), series.column("tangential"), series.column("normal"));
        // The limit and what it is compared with: F N, or s |Γ_C| (|Γ_C| = 2).
        let limit = |i: usize| match *law {
            "nitsche-tresca" => 2.0 * 0.1,
            _ => normal[i] * if extra.contains(&"mu=0.5") { 0.5 } else { 0.3 },
        };
        for i in 0..t.len() {
            assert!(
                tangential[i] <= limit(i) * (1.0 + 1e-9),
                "{law} {extra:?} at t = {}: T = {} > {}",
                t[i],
                tangential[i],
                limit(i)
            );
        }
        let onset = s["onset"].as_f64().expect("it slides");
        assert!(onset < 1.0, "{law} {extra:?}: slides from {onset}");
        // Once the drive's ramp and the block's swing have passed (t ≥ 2: the block slides at
        // the drive's speed).
        let sliding: Vec<usize> = (0..t.len()).filter(|&i| t[i] >= 2.0).collect();
        assert!(sliding.len() > 20);
        for &i in &sliding {
            assert!(
                (tangential[i] / limit(i) - 1.0).abs() < 0.01,
                "{law} {extra:?} at t = {}: T = {}, the limit {}",
                t[i],
                tangential[i],
                limit(i)
            );
        }
    }
}

/// The library's `oblique_disc` (μ = 0.3, thrown at vx = 0.5) through its first impact:
/// `cumulative` sums the frictional work of the steps and `initial` reads the first row, so
/// the balance column is E_aug + W_fric − E_aug(0) on every row; friction takes energy (W_fric
/// grows, and slows and spins the disc); and the balance is what Crank–Nicolson's trapezoidal
/// friction leaves over the law's end-of-step work: it closes at first order in Δt.
#[test]
fn an_oblique_impact_s_frictional_work_closes_the_energy_balance_at_first_order() {
    let window = ["run", "oblique_disc", "--h", "2", "--t-start", "5.5", "--t-end", "8.5"];
    let mut defects = Vec::new();
    for dt in ["0.02", "0.01"] {
        let (s, series) = run(&format!("oblique-{dt}"), &[&window[..], &["--dt", dt]].concat());
        let (work, total) = (series.column("dissipated"), series.column("friction_total"));
        let (energy, balance) = (series.column("energy_aug"), series.column("balance"));
        let mut sum = 0.0;
        for i in 0..work.len() {
            if !work[i].is_nan() {
                sum += work[i];
            }
            assert_eq!(total[i], sum, "row {i}: cumulative(dissipated)");
            let expected = energy[i] + total[i] - energy[0];
            assert!((balance[i] - expected).abs() <= 1e-12 * energy[0], "row {i}: balance {} ≠ {expected}", balance[i]);
        }
        assert!(sum > 0.02 * energy[0], "friction took {sum} of E_aug(0) = {}", energy[0]);
        assert!(s["vx_final"].as_f64().unwrap() < 0.5 && s["spin_final"].as_f64().unwrap() > 0.0, "{s}");
        defects.push(s["balance_max"].as_f64().unwrap());
    }
    let ratio = defects[1] / defects[0];
    assert!(
        (0.35..0.65).contains(&ratio),
        "halving Δt took the balance's defect from {} to {}",
        defects[0],
        defects[1]
    );
}

/// Crank–Nicolson's energy law with friction, on the library's `oblique_disc` (its default
/// Newmark β = ¼, γ = ½): E_aug changes over each step by minus the `dissipation` column (the
/// trapezoidal work of the contact force, `work(contact)`, less the change of the contact
/// energy), to round-off, with every frictional law; for the penalty law, whose stick force
/// goes with the slip, the dissipation is ≥ 0 on every step that keeps the contact status.
#[test]
fn crank_nicolson_s_energy_law_closes_with_the_frictional_dissipation() {
    let window = ["run", "oblique_disc", "--h", "2", "--t-start", "5.5", "--t-end", "10"];
    for law in ["nitsche-coulomb", "nitsche-tresca", "penalty-coulomb"] {
        let (s, series) = run(&format!("cn-{law}"), &[&window[..], &["--contact", law]].concat());
        let (energy, dissipation) = (series.column("energy_aug"), series.column("dissipation"));
        let scale = energy.iter().fold(0.0f64, |m, e| m.max(e.abs()));
        for i in 1..energy.len() {
            let defect = energy[i] - energy[i - 1] + dissipation[i];
            assert!(defect.abs() < 1e-10 * scale, "{law}, row {i}: ΔE_aug + D = {defect:e} (scale {scale})");
        }
        let cn = s["expected"].as_array().unwrap().iter().find(|x| x["key"] == "cn_balance_max").unwrap();
        assert_eq!(cn["met"], true, "{law}: {cn}");
        if law == "penalty-coulomb" {
            let negative = s["dissipation_negative"].as_f64().unwrap();
            assert!(negative <= 1e-12 * scale, "{law}: a kept-status step gave back {negative}");
        }
    }
}

/// `settled` takes the loads at the start time: started at t = 0.5, where the slope's load
/// along the plane is on (`H(t)`), a block on a slope steeper than the friction angle has no
/// equilibrium to settle in (an error that says so); below the angle it settles and stays.
#[test]
fn settling_takes_the_loads_at_the_start_time() {
    let run = |slope: &str| {
        let dir = std::env::temp_dir().join(format!("signorini-friction-settle-{slope}-{}", std::process::id()));
        let out = Command::new(BIN)
            .args(["run", "sliding_block", "--param", "v0=0", "--param", &format!("slope={slope}")])
            .args(["--t-start", "0.5", "--t-end", "0.7", "--out"])
            .arg(&dir)
            .output()
            .expect("the binary runs");
        let _ = std::fs::remove_dir_all(&dir);
        out
    };
    let steep = run("0.4");
    assert!(!steep.status.success(), "tan α = 0.4 > F = 0.3 settled");
    assert!(String::from_utf8_lossy(&steep.stderr).contains("did not settle"), "{steep:?}");
    let gentle = run("0.2");
    assert!(gentle.status.success(), "{}", String::from_utf8_lossy(&gentle.stderr));
}
