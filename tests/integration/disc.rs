//! The bouncing disc (spec §6.2): before the first contact every scheme reproduces free fall
//! exactly, u_y = −½ 0.1 t² and E = 0, and the first contact happens in the step containing t* = √40.

use signorini::cases::disc;
use signorini::driver::{self, Methods};
use signorini::problem::run::Options;

fn scheme(name: &str) -> Methods {
    Methods { scheme: name.into(), ..Methods::default() }
}

/// The gravity of a library problem, read from its file: its body force `coef f` (a force
/// density) over the density `material.rho` it sets, vertically. Until the first contact the body falls
/// freely, u = −g t²/2.
pub(crate) fn gravity(problem: &str) -> f64 {
    use signorini::compiler::check::const_value;
    use signorini::compiler::syntax::ast::{Defined, ExprKind};
    let pf = signorini::problem::load(problem).unwrap();
    let p = pf.problem();
    let value = |items: &[Defined], name: &str| {
        let d = items.iter().find(|d| d.name.name == name).unwrap_or_else(|| panic!("{problem} sets no `{name}`"));
        d.value.clone()
    };
    let ExprKind::Vector(f) = value(&p.coefs, "f").kind else { panic!("{problem}: `coef f` is not a vector") };
    // The material's density: `set material.rho = ...` (`rho` alone would be ambiguous).
    let rho = const_value(&value(&p.sets, "material.rho")).expect("a constant ρ");
    -const_value(f.last().expect("a component")).expect("a constant force") / rho
}

#[test]
fn free_fall_is_exact_and_contact_starts_in_the_right_step() {
    let g = gravity("disc");
    let t_star = (2.0 * 2.0 / g).sqrt();
    for scheme in driver::all_schemes() {
        let opts = Options { methods: self::scheme(scheme).set("h", 2.0), t_end: Some(6.5), ..disc::options() };
        let r = disc::run(&opts).unwrap_or_else(|e| panic!("{scheme:?}: {e}"));
        for row in r.series.iter().filter(|row| row.t < t_star - 0.05) {
            let exact = -0.5 * g * row.t * row.t;
            assert!(
                (row.u_vertical_mean - exact).abs() < 1e-12,
                "{scheme:?} t = {}: mean {} vs {exact}",
                row.t,
                row.u_vertical_mean
            );
            // E = 0 exactly. Round-off only (≤ 5e-12 of a kinetic energy ~56 at t = 6): the
            // stepper evaluates every scheme in increments (runtime/src/time/stage.rs). Before, it
            // was 4e-11 (Newmark) to 4e-10 (TR-BDF2).
            assert!(row.energy.abs() < 2e-11, "{scheme:?} t = {}: E = {:e}", row.t, row.energy);
            assert!((row.u_vertical_mean_nodal - exact).abs() < 1e-10, "{scheme:?} t = {}: nodal mean", row.t);
            assert!(
                (row.u_vertical_lowest - exact).abs() < 1e-10,
                "{scheme:?} t = {}: lowest {} vs {exact}",
                row.t,
                row.u_vertical_lowest
            );
            assert_eq!(row.active_points, 0);
            // The centre of mass falls at v_y = −g t.
            assert!(
                (row.v_vertical_mean + g * row.t).abs() < 1e-10,
                "{scheme:?} t = {}: v {}",
                row.t,
                row.v_vertical_mean
            );
        }
        // A multi-stage scheme reports each intermediate stage, which is exact in free fall too.
        // TR-BDF2's trapezoidal stage ends at t + (2 − √2)Δt.
        let expected = if scheme == "trbdf2" { r.summary.steps } else { 0 };
        assert_eq!(r.stages.len(), expected, "{scheme:?}");
        for (k, s) in r.stages.iter().enumerate() {
            let t = (k as f64 + 2.0 - 2f64.sqrt()) * r.summary.dt;
            assert!((s.row.t - t).abs() < 1e-12, "{scheme:?} stage {k} at t = {}, expected {t}", s.row.t);
        }
        for s in r.stages.iter().filter(|s| s.row.t < t_star - 0.05) {
            let exact = -0.5 * g * s.row.t * s.row.t;
            assert!((s.row.u_vertical_mean - exact).abs() < 1e-10, "{scheme:?} stage {} at t = {}", s.stage, s.row.t);
            assert!(
                (s.row.v_vertical_mean + g * s.row.t).abs() < 1e-10,
                "{scheme:?} stage {} at t = {}",
                s.stage,
                s.row.t
            );
        }
        let first = r.summary.first_contact.expect("the disc reaches the ground");
        assert!(
            first - r.summary.dt < t_star && t_star <= first,
            "{scheme:?}: first contact at {first}, t* = {t_star}"
        );
    }
}

/// Spec §4.5: the hybrid scheme with θ = 1 never increases E_Θ (to 1e-9 of the energy scale).
#[test]
fn hybrid_never_increases_the_augmented_energy() {
    let r =
        disc::run(&Options { methods: scheme("hybrid").set("h", 2.0), t_end: Some(20.0), ..disc::options() }).unwrap();
    let scale = r.series.iter().map(|row| row.energy_aug.abs()).fold(0.0, f64::max);
    assert!(scale > 1e-3);
    // The Jacobian is refactored only when the active set changes: through the whole contact
    // phase far fewer factorizations than Newton iterations.
    let s = &r.summary;
    assert!(
        s.factorizations * 4 < s.newton_total,
        "{} factorizations, {} iterations",
        s.factorizations,
        s.newton_total
    );
    for w in r.series.windows(2) {
        assert!(
            w[1].energy_aug <= w[0].energy_aug + 1e-9 * scale,
            "t = {}: {} → {}",
            w[1].t,
            w[0].energy_aug,
            w[1].energy_aug
        );
    }
}

/// Penetration decreases when γ0 grows (Nitsche) and when ε = γ0/h grows (penalty).
#[test]
fn penetration_decreases_with_the_contact_parameter() {
    for contact in ["nitsche", "penalty"] {
        // θ = 1 needs γ0 ≳ 20E (E = 50) for coercivity: start there.
        let p: Vec<f64> = [1000.0, 3000.0, 10000.0]
            .iter()
            .map(|&gamma0| {
                let methods = Methods { scheme: "hybrid".into(), contact: contact.into(), ..Methods::default() };
                let methods = methods.set("gamma0", gamma0).set("h", 2.0);
                let o = Options { methods, t_end: Some(12.0), ..disc::options() };
                disc::run(&o).unwrap().summary.max_penetration
            })
            .collect();
        assert!(p[0] > p[1] && p[1] > p[2], "{contact:?}: {p:?}");
    }
}

/// The reference Gmsh mesh and the built-in generator at the same h give the same physics:
/// impact, deepest descent and rebound of the centre of mass, release time.
#[test]
fn gmsh_mesh_and_built_in_generator_agree() {
    let shared = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/meshes/disc_r10_h1_v22.msh");
    assert!(shared.exists(), "{} is missing: the reference meshes live in assets/meshes", shared.display());
    let summary = |mesh: Option<std::path::PathBuf>| {
        let r = disc::run(&Options { methods: scheme("hybrid"), mesh, t_end: Some(26.0), ..disc::options() }).unwrap();
        let release = r.series.iter().filter(|row| row.active_points > 0).map(|row| row.t).fold(0.0, f64::max);
        let rebound = r
            .series
            .iter()
            .filter(|row| row.t > release)
            .map(|row| row.u_vertical_mean)
            .fold(f64::NEG_INFINITY, f64::max);
        (r.summary.first_contact.unwrap(), r.summary.min_u_vertical_mean, release, rebound)
    };
    let (a, b) = (summary(None), summary(Some(shared)));
    assert_eq!(a.0, b.0, "impact");
    assert!((a.1 - b.1).abs() < 0.01, "deepest mean displacement {} vs {}", a.1, b.1);
    assert!((a.2 - b.2).abs() < 0.2, "release {} vs {}", a.2, b.2);
    assert!((a.3 - b.3).abs() < 0.02, "rebound {} vs {}", a.3, b.3);
}

#[test]
fn an_unstable_setting_fails_with_a_clear_error() {
    // Nitsche θ = 1 with γ0 = 2E is not coercive: the free fall already diverges while E_aug
    // is kept, its potential part going negative, and the energy guard stops it within the
    // first second, long before the values overflow.
    let methods = Methods::default().set("gamma0", 100.0).set("h", 2.0);
    let o = Options { methods, t_end: Some(20.0), ..disc::options() };
    let e = disc::run(&o).err().expect("diverges").to_string();
    assert!(e.contains("not coercive") && e.contains("gamma0 = 100"), "{e}");
    let t: f64 = e.trim_start_matches("stopped at t = ").split(':').next().unwrap().parse().unwrap();
    assert!(t < 2.0, "stopped at {t}");
}

/// With Newton held to two iterations, Δt = 0.1 cannot follow the first impact: those steps
/// are retried with Δt halved, the step size returns to 0.1 afterwards, and the run reaches
/// t_end on the nominal time levels with the cuts counted.
#[test]
fn steps_cut_at_impact_return_to_the_nominal_step() {
    let mut o = Options { t_end: Some(9.0), dt: Some(0.1), ..disc::options() };
    o.newton.max_iterations = 2;
    let r = disc::run(&o).unwrap();
    let s = &r.summary;
    assert!(s.step_cuts > 0, "no cut at Δt = 0.1");
    let times: Vec<f64> = r.series.iter().map(|row| row.t).collect();
    let short = times.windows(2).filter(|w| w[1] - w[0] < 0.99 * s.dt).count();
    assert!(short >= 2, "{short} short steps for {} cuts", s.step_cuts);
    assert!((times.last().unwrap() - 9.0).abs() < 1e-12, "ends at {}", times.last().unwrap());
    // After the cuts the steps are whole again.
    let tail = &times[times.len() - 10..];
    assert!(tail.windows(2).all(|w| (w[1] - w[0] - s.dt).abs() < 1e-9), "{tail:?}");
}
