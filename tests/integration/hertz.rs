//! The Hertz cases against the closed forms (docs/mathematics.md §6): static contact of a
//! cylinder (2D) and a ball (3D) under a body force, by Nitsche and by penalty, and the
//! low-velocity impact of a ball. The tolerances are what the committed meshes reach, with a
//! margin; the report's refinement study shows the rates.

use signorini::driver::Methods;
use signorini::problem::run::{Options, run};
use signorini::references::hertz::profile;
use signorini::runtime::fem::assembly::{Assembler, Quadrature};
use signorini::runtime::fem::kernel::Coef;
use signorini::runtime::fem::quadrature::simplex_rule;
use signorini::runtime::library::Binding;

/// The library's Hertz problem (`hertz_cylinder` or `hertz_ball`) at a mesh level: its summary.
fn pressed(problem: &str, contact: &str, level: usize) -> signorini::problem::outputs::Summary {
    let mut o = Options::new(problem);
    o.methods = Methods { contact: contact.into(), ..Methods::default() }.set("level", level as f64);
    o.chosen.contact = true;
    run(&o).unwrap_or_else(|e| panic!("{problem} {contact} level {level}: {e}")).summary
}

fn number(s: &signorini::problem::outputs::Summary, key: &str) -> f64 {
    s.number(key).unwrap_or_else(|| panic!("no `{key}` in the summary"))
}

#[test]
fn the_pressed_cylinder_has_hertz_half_width_peak_pressure_and_profile() {
    for contact in ["nitsche", "penalty"] {
        let s = pressed("hertz_cylinder", contact, 1);
        // Equilibrium: the contact force carries the weight (the mesh's measure is exact to 1e-6).
        let (force, load) = (number(&s, "contact_force"), number(&s, "load"));
        assert!((force / load - 1.0).abs() < 1e-5, "{contact}: force {force} vs {load}");
        let (a, p0) = (number(&s, "half_width_error"), number(&s, "peak_pressure_error"));
        assert!(a.abs() < 0.02, "{contact}: half-width error {a}");
        assert!(p0.abs() < 0.01, "{contact}: peak pressure error {p0}");
        let profile = number(&s, "profile_l2_error");
        assert!(profile < 0.03, "{contact}: profile error {profile}");
        // The default force makes Hertz's half-width R/10 = 1.
        assert!((number(&s, "hertz_half_width") - 1.0).abs() < 1e-12);
    }
}

#[test]
fn the_cylinder_profile_error_decreases_under_refinement() {
    // The pointwise pressure's oscillation at the edge of the zone keeps the decrease uneven
    // from level to level (report: 4.9 %, 1.44 %, 1.44 %, 0.92 %); over two levels it is clear.
    let coarse = number(&pressed("hertz_cylinder", "nitsche", 0), "profile_l2_error");
    let fine = number(&pressed("hertz_cylinder", "nitsche", 2), "profile_l2_error");
    assert!(fine < 0.5 * coarse, "{coarse} → {fine}");
}

#[test]
fn the_pressed_ball_has_hertz_contact_radius_and_peak_pressure() {
    for contact in ["nitsche", "penalty"] {
        let s = pressed("hertz_ball", contact, 0);
        let (force, load) = (number(&s, "contact_force"), number(&s, "load"));
        assert!((force / load - 1.0).abs() < 1e-4, "{contact}: force {force} vs {load}");
        // The coarsest ball has 4 cells across the contact radius: its zone is 4 % short.
        let (a, p0) = (number(&s, "contact_radius_error"), number(&s, "peak_pressure_error"));
        assert!(a.abs() < 0.05, "{contact}: radius error {a}");
        assert!(p0.abs() < 0.02, "{contact}: peak pressure error {p0}");
    }
}

#[test]
fn the_impact_lasts_hertz_contact_time_and_reaches_hertz_peak_force() {
    // 50 steps per contact time (the default is 200; the figures move by < 1 %).
    let mut o = Options::new("hertz_impact");
    o.methods = Methods::default().set("steps", 50.0);
    let r = run(&o).unwrap();
    let s = &r.summary;
    assert!(number(s, "indentation_ratio") <= 0.02 && number(s, "contact_time_over_wave_time") >= 10.0);
    let (duration, peak) = (number(s, "contact_duration_error"), number(s, "peak_force_error"));
    assert!(duration.abs() < 0.03, "contact time error {duration}");
    assert!(peak.abs() < 0.03, "peak force error {peak}");
    // Crank–Nicolson with Nitsche θ = 1: the ball leaves with its speed (the waves left in it
    // take 10⁻⁴ of the energy), and free flight before contact is exact.
    let restitution = number(s, "restitution");
    assert!((restitution - 1.0).abs() < 1e-3, "restitution {restitution}");
    let speed = 0.0025;
    let (force, active, velocity) =
        (r.column("fz_contact").unwrap(), r.column("active_points").unwrap(), r.column("vz_mean").unwrap());
    for k in 0..2 {
        // σ(u) of a translation is round-off: so is the −θ/γ σ_N(u) σ_N(v) term.
        assert!(force[k].abs() < 1e-20 && active[k] == 0.0, "force before contact {}", force[k]);
        assert!((velocity[k] + speed).abs() < 1e-12);
    }
}

/// The pointwise integrand of a boundary functional, summed with the weights of the rule it was
/// sampled at, is the functional integrated with that rule.
#[test]
fn point_values_integrate_to_the_functional() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/meshes/hertz_cylinder_0.msh");
    let mut mesh = signorini::runtime::fem::mesh::gmsh::read(&path).unwrap();
    mesh.add_region_where("Gamma_C", |n, _| n[1] < 0.0);
    let asm = Assembler::new(&mesh);
    let material = [("E", 50.0), ("nu", 0.25), ("rho", 1.0), ("gamma0", 5000.0)];
    let forms = signorini::driver::FilesInUse::resolve_forms(&Methods::default(), &material).unwrap();
    let facets = asm.region("Gamma_C").unwrap();
    let degree = 7;
    let binding =
        Binding::new(Quadrature { cell: None, facet: Some(degree) }, vec![("Gamma_C".to_string(), facets)], 2);
    let coefs = |name: &str| match name {
        "g" => Some(Coef::function(1, |x, _, out| out[0] = x[1])),
        "nc" => Some(Coef::constant(vec![0.0, -1.0])),
        "f" => Some(Coef::constant(vec![0.0, 0.0])),
        _ => None,
    };
    let pressure = forms.instantiate(&coefs, &binding).unwrap().take_functional("contact_pressure").unwrap();
    // Pushed 0.05 into the plane: a zone of half-width about √(2R·0.05) = 1.
    let u: Vec<f64> = (0..asm.size()).map(|i| if i % 2 == 1 { -0.05 } else { 0.0 }).collect();
    let points = pressure.facet_point_values(&asm, &simplex_rule(1, degree), &[&u], 0.0);
    let sum: f64 = points.iter().map(|p| p.weight * p.value).sum();
    let value = pressure.value(&asm, &[&u], 0.0);
    assert!(value < 0.0 && (sum - value).abs() < 1e-12 * value.abs(), "{sum} vs {value}");
    // And the profile reads them as pressures on the part facing the plane.
    let samples = profile::sample(&asm, pressure.as_ref(), &u);
    assert!(samples.iter().all(|s| s.p >= 0.0) && samples.iter().any(|s| s.p > 0.0));
    // Rigidly pushed, the zone is where the circle is below 0.05: |x| < √(2R·0.05 − 0.05²).
    let zone = profile::zone(2, 2.0, &samples, 1.0).unwrap();
    let exact = (2.0 * 10.0 * 0.05 - 0.05f64.powi(2)).sqrt();
    assert!((zone.size - exact).abs() < 5e-3, "zone {} vs {exact}", zone.size);
}

/// `at_max(radius_measured, fz_contact)` measures its column only where the force reaches a new
/// maximum; plotting the column makes it measured at every row. The summary is the same.
#[test]
fn a_column_only_at_max_reads_is_measured_at_the_new_maxima_only() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(root.join("forms/problems/hertz_impact.wf")).unwrap();
    let meshes = format!("\"{}/", root.join("assets/meshes").display());
    let every_row = text.replace("\"../../assets/meshes/", &meshes).replace(
        "plot \"centre of mass velocity\": vz_mean",
        "plot \"centre of mass velocity\": vz_mean, radius_measured",
    );
    let dir = std::env::temp_dir().join(format!("signorini-at-max-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("every_row.wf");
    std::fs::write(&file, every_row).unwrap();
    let short = |problem: &str| {
        let mut o = Options::new(problem);
        o.methods = Methods::default().set("steps", 10.0);
        run(&o).unwrap()
    };
    let (deferred, every) = (short("hertz_impact"), short(file.to_str().unwrap()));
    let radius = |r: &signorini::problem::run::Run| r.summary.number("contact_radius").unwrap();
    assert_eq!(radius(&deferred).to_bits(), radius(&every).to_bits());
    // Deferred, the column is measured at fewer rows (NaN at the others; measured at every row it
    // is NaN only where there is no contact), with the same values where it is.
    let (a, b) = (deferred.column("radius_measured").unwrap(), every.column("radius_measured").unwrap());
    let measured = |c: &[f64]| c.iter().filter(|x| !x.is_nan()).count();
    assert!(measured(&a) < measured(&b), "{} rows of {} measured", measured(&a), measured(&b));
    assert!(a.iter().zip(&b).all(|(x, y)| x.is_nan() || x.to_bits() == y.to_bits()));
    std::fs::remove_dir_all(&dir).unwrap();
}
