//! Problems posed in files: a library problem copied elsewhere runs by path with the same bits;
//! a user coef (a graded density) is supplied by the problem and the free fall it poses stays
//! exact; an interpreted contact law agrees with the compiled one on a library problem; a
//! problem's transcendental functions of its params fold to numbers.

use std::path::{Path, PathBuf};

use signorini::driver::Setting;
use signorini::problem::run::{Options, Run, run};

fn temp_dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("signorini-problems-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn short(problem: &str) -> Options {
    let mut o = Options::new(problem);
    o.t_end = Some(7.0);
    o.methods.params.push(Setting { name: "h".into(), value: 2.0, origin: "test".into() });
    o
}

fn bits(r: &Run) -> Vec<(u64, Vec<u64>)> {
    r.rows.iter().map(|(t, v)| (t.to_bits(), v.iter().map(|x| x.to_bits()).collect())).collect()
}

#[test]
fn a_library_problem_copied_elsewhere_runs_by_path_with_the_same_bits() {
    let dir = temp_dir("copy");
    let file = dir.join("my_disc.wf");
    std::fs::copy(Path::new(env!("CARGO_MANIFEST_DIR")).join("forms/problems/disc.wf"), &file).unwrap();
    let library = run(&short("disc")).unwrap();
    let by_path = run(&short(file.to_str().unwrap())).unwrap();
    assert_eq!(library.columns, by_path.columns);
    assert!(library.rows.len() > 300);
    assert_eq!(bits(&library), bits(&by_path), "the same problem, by name and by path");
    // The impact is in the run: the comparison covers contact, not only the free fall.
    assert!(library.column("active_points").unwrap().iter().any(|&a| a > 0.0));
}

#[test]
fn a_user_coef_set_by_the_problem_reaches_the_forms() {
    let here = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/problems");
    // The problem binds its material file (graded_material.wf, beside it).
    let r = run(&Options::new(here.join("graded_density.wf").to_str().unwrap())).unwrap();
    // Mass ρζ and load ρζg: the free fall is a rigid translation, u = −g t²/2 at every node.
    let t_star = 40f64.sqrt();
    let (mean, lowest) = (r.column("uy_mean").unwrap(), r.column("uy_lowest").unwrap());
    let mut checked = 0;
    for (i, (t, _)) in r.rows.iter().enumerate() {
        if *t < t_star - 0.1 {
            let exact = -0.05 * t * t;
            assert!((mean[i] - exact).abs() < 1e-11, "t = {t}: mean {} vs {exact}", mean[i]);
            assert!((lowest[i] - exact).abs() < 1e-11, "t = {t}: lowest {} vs {exact}", lowest[i]);
            checked += 1;
        }
    }
    assert!(checked > 100);
    // The graded density is in the forms: the contact then differs from the uniform disc's.
    // The user's choice wins over the problem's bind: the library's uniform material.
    let mut uniform = Options::new(here.join("graded_density.wf").to_str().unwrap());
    uniform.chosen.material = true;
    let u = run(&uniform).unwrap();
    let (a, b) = (r.column("uy_mean").unwrap(), u.column("uy_mean").unwrap());
    assert!((a.last().unwrap() - b.last().unwrap()).abs() > 1e-6, "zeta changed nothing after impact");
}

#[test]
fn an_interpreted_contact_law_agrees_with_the_compiled_one() {
    let dir = temp_dir("law");
    let law = dir.join("my_nitsche.wf");
    std::fs::copy(Path::new(env!("CARGO_MANIFEST_DIR")).join("forms/contact_nitsche.wf"), &law).unwrap();
    let compiled = run(&short("disc")).unwrap();
    let mut o = short("disc");
    o.methods.contact = law.display().to_string();
    let interpreted = run(&o).unwrap();
    let scale = compiled.column("uy_mean").unwrap().iter().fold(0.0f64, |m, x| m.max(x.abs()));
    for name in ["uy_mean", "uy_lowest", "fy_contact", "energy_aug"] {
        let (a, b) = (compiled.column(name).unwrap(), interpreted.column(name).unwrap());
        let worst = a.iter().zip(&b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
        let size = a.iter().fold(scale, |m, x| m.max(x.abs()));
        assert!(worst <= 1e-10 * size, "{name}: {worst:e}");
    }
}

/// A rigid ball of radius R under the disc, its top at the ground's height: its gap differs
/// from the plane's by |x_⊥|²/(2R) + O(R⁻²), so the run tends to the disc's on the ground at
/// order 1 in 1/R (the differences shrink tenfold per decade of R).
#[test]
fn a_ball_obstacle_tends_to_the_plane_as_its_radius_grows() {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/problems/disc_on_ball.wf");
    let plane = run(&short("disc")).unwrap();
    let on_ball = |r: f64| {
        let mut o = short(file.to_str().unwrap());
        o.methods.params.push(Setting { name: "R".into(), value: r, origin: "test".into() });
        let b = run(&o).unwrap();
        let (x, y) = (b.column("uy_mean").unwrap(), plane.column("uy_mean").unwrap());
        assert_eq!(x.len(), y.len());
        x.iter().zip(&y).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max)
    };
    let d: Vec<f64> = [200.0, 2000.0, 20000.0].iter().map(|&r| on_ball(r)).collect();
    for w in d.windows(2) {
        let ratio = w[0] / w[1];
        assert!((8.0..12.0).contains(&ratio), "differences {d:?}: ratio {ratio}");
    }
    assert!(d[2] < 1e-5, "{d:?}");
}

/// Dirichlet conditions: the compressed bar posed as a problem (held at x = 1) reproduces the
/// built-in bar's columns bit for bit, and the elastic force at the held end at t = 0 is that of
/// u₀ = (1 − x)/2: E u₀' = −1/2, so −(K u₀) at x = 1 is +1/2.
#[test]
fn the_bar_posed_with_a_dirichlet_condition_is_the_built_in_bar() {
    use signorini::cases::bar;
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/problems/bar.wf");
    let mut o = Options::new(file.to_str().unwrap());
    o.t_end = Some(3.0);
    let posed = run(&o).unwrap();
    let built_in = bar::run(&Options { t_end: Some(3.0), ..bar::options() }).unwrap();
    assert_eq!(posed.rows.len(), built_in.series.len());
    let col = |name: &str| posed.column(name).unwrap();
    type Of = fn(&bar::Row) -> f64;
    let pairs: [(&str, Of); 6] = [
        ("u_c", |r| r.u_c),
        ("v_c", |r| r.v_c),
        ("lambda", |r| r.lambda),
        ("energy", |r| r.energy),
        ("energy_aug", |r| r.energy_aug),
        ("penetration", |r| r.penetration),
    ];
    for (name, of) in pairs {
        let a = col(name);
        for (i, r) in built_in.series.iter().enumerate() {
            assert_eq!(a[i].to_bits(), of(r).to_bits(), "{name} at t = {}: {} vs {}", r.t, a[i], of(r));
        }
    }
    let wall = col("wall_force");
    assert!((wall[0] - 0.5).abs() < 1e-12, "{}", wall[0]);
    // Contact happened: the comparison covers the impact.
    assert!(col("lambda").iter().any(|l| *l < 0.0));
}

/// A time-dependent traction (a user coef on a region of the problem, read by a material file
/// of the user's): the bar pulled at its end by p t follows d'Alembert's u(1, t) = p t²/2 until
/// the wave reflected at the free end comes back at t = 2, with the error of the end
/// displacement falling at order 2 under refinement at a fixed Courant number.
#[test]
fn a_traction_on_a_region_of_the_problem_follows_d_alembert() {
    let here = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/problems");
    let error = |ne: usize| {
        let mut o = Options::new(here.join("traction_bar.wf").to_str().unwrap());
        o.methods.params.push(Setting { name: "ne".into(), value: ne as f64, origin: "test".into() });
        o.dt = Some(0.5 / ne as f64);
        let r = run(&o).unwrap();
        assert!(r.column("active_points").unwrap().iter().all(|a| *a == 0.0), "the bar reached the obstacle");
        let (t, u) = (r.rows.last().unwrap().0, r.column("u_end").unwrap());
        assert!((t - 1.9).abs() < 1e-12 && *u.last().unwrap() > 0.18, "t = {t}");
        r.column("error").unwrap().iter().fold(0.0f64, |m, e| m.max(e.abs()))
    };
    let e: Vec<f64> = [80, 160, 320].iter().map(|&ne| error(ne)).collect();
    for w in e.windows(2) {
        let order = (w[0] / w[1]).log2();
        assert!((1.8..3.0).contains(&order), "errors {e:?}: order {order}");
    }
    // About 1e-6 of u(1, 1.9) = 0.1805 on the finest mesh.
    assert!(e[2] < 2e-6 * 0.1805, "{e:?}");
}

/// The ring of examples/problems (a Gmsh annulus with physical groups) thrown with a spin onto
/// an inclined plane: before it lands, its centre of mass follows the parabola exactly, its
/// momentum changes by the gravity impulse, and its linearized angular momentum about the
/// centre is conserved to round-off (K annihilates an infinitesimal rotation and gravity has no
/// moment about the centre of mass); after, Newmark with Nitsche θ = 1 keeps E_aug on every step
/// whose active set is unchanged.
#[test]
fn the_thrown_ring_flies_exactly_and_keeps_its_energy_law_after_landing() {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/problems/ring.wf");
    let r = run(&Options::new(file.to_str().unwrap())).unwrap();
    let (v0, g) = (0.5, 0.1);
    let col = |name: &str| r.column(name).unwrap();
    let (ux, uy, vy, l) = (col("ux_cm"), col("uy_cm"), col("vy_cm"), col("angular_momentum"));
    let first = r.summary.number("first_contact").expect("the ring lands");
    let mut flight = 0;
    for (i, (t, _)) in r.rows.iter().enumerate().take_while(|(_, (t, _))| *t < first - 1e-9) {
        assert!((ux[i] - v0 * t).abs() < 1e-10, "t = {t}: x {} vs {}", ux[i], v0 * t);
        assert!((uy[i] + 0.5 * g * t * t).abs() < 1e-10, "t = {t}: y {}", uy[i]);
        assert!((vy[i] + g * t).abs() < 1e-10, "t = {t}: vy {}", vy[i]);
        assert!((l[i] - l[0]).abs() < 1e-12 * l[0].abs(), "t = {t}: L {} vs {}", l[i], l[0]);
        flight += 1;
    }
    assert!(flight > 100 && l[0].abs() > 1.0, "{flight} rows of flight, L = {}", l[0]);
    // After landing: the contact's moment changes L, and E_aug is kept while the set is.
    assert!((l.last().unwrap() - l[0]).abs() > 1e-3 * l[0].abs());
    let e = col("energy_aug");
    let (mut kept, mut changed) = (0, 0);
    for i in 1..r.rows.len() {
        if r.rows[i].0 < first {
            continue;
        }
        if r.switches[i] == r.switches[i - 1] {
            kept += 1;
            assert!((e[i] - e[i - 1]).abs() < 1e-9 * e[0].abs(), "t = {}: ΔE_aug {}", r.rows[i].0, e[i] - e[i - 1]);
        } else {
            changed += 1;
        }
    }
    assert!(kept > 50 && changed > 3, "kept {kept}, changed {changed}");
}

/// A moving obstacle (a plane rising at speed w, its gap a function of t): the disc's lowest
/// point meets it in the step where 2 − g t²/2 = w t, and the free fall before is untouched.
#[test]
fn a_rising_plane_is_met_when_the_fall_and_the_rise_close_the_gap() {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/problems/rising_plane.wf");
    let r = run(&Options::new(file.to_str().unwrap())).unwrap();
    let (g, w, dt): (f64, f64, f64) = (0.1, 0.5, 0.01);
    let t_star: f64 = (w * w + 4.0 * g).sqrt() / g - w / g;
    let first = r.summary.number("first_contact").expect("the plane is met");
    // Within a few steps after t*: Nitsche's switch turns on at a quadrature point once
    // P_{1,γ}(u) < 0, a little after the gap closes at the lowest node (0.018 here, closing at
    // 0.8 per unit time).
    assert!(first >= t_star - 1e-9 && first <= t_star + 3.0 * dt, "first contact {first}, t* = {t_star}");
    let mean = r.column("uy_mean").unwrap();
    for (i, (t, _)) in r.rows.iter().enumerate().filter(|(_, (t, _))| *t < t_star - dt) {
        assert!((mean[i] + 0.5 * g * t * t).abs() < 1e-10, "t = {t}: {}", mean[i]);
    }
}

/// A rigid cylinder pressed into an elastic block held at its base (examples/problems/
/// indenter.wf: a moving obstacle, each step an equilibrium of the quasi-static scheme beside
/// it): the contact half-width and the peak pressure agree with Hertz's for the measured force
/// within 3 % on the finest mesh; the half-width's error falls under refinement and the peak
/// pressure converges (its successive differences fall), to within the finite block's own
/// departure from the half-space.
#[test]
fn a_cylinder_pressed_into_a_block_follows_hertz() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/problems");
    let runs: Vec<(f64, f64, f64)> = ["indenter_hf020.msh", "indenter_hf010.msh", "indenter_hf005.msh"]
        .iter()
        .map(|mesh| {
            let mut o = Options::new(dir.join("indenter.wf").to_str().unwrap());
            o.mesh = Some(dir.join(mesh));
            let r = run(&o).unwrap();
            let force = r.column("force").unwrap();
            assert!(force.windows(2).all(|w| w[1] > w[0]), "the force grows with the indentation: {force:?}");
            let key = |k: &str| r.summary.number(k).unwrap();
            (key("half_width_error"), key("peak_pressure_error"), *r.column("peak_pressure").unwrap().last().unwrap())
        })
        .collect();
    let (b, p): (Vec<f64>, Vec<f64>) = runs.iter().map(|r| (r.0.abs(), r.1.abs())).unzip();
    assert!(b[2] < 0.03 && p[2] < 0.03, "relative errors against Hertz: half-width {b:?}, peak pressure {p:?}");
    assert!(b[0] > b[1] && b[1] > b[2], "the half-width's error falls: {b:?}");
    let (d1, d2) = ((runs[1].2 - runs[0].2).abs(), (runs[2].2 - runs[1].2).abs());
    assert!(d2 < d1 / 2.0, "the peak pressure converges: differences {d1:e}, {d2:e}");
}

/// A held displacement that moves: the bar pulled at its end by u(1, t) = s t³, free at the
/// other, follows d'Alembert's solution there (u(0, t) = 2 s (t − 1)³ after the wave arrives)
/// at order 2 with every kind of scheme: one stage, an intermediate stage held at its own time
/// (TR-BDF2), the midpoint, and a scheme whose unknown is the acceleration, held through its
/// relation to u' (it runs the same steps as the displacement form to round-off). The held end
/// takes s t³ at every row.
#[test]
fn a_moving_held_displacement_pulls_the_bar_as_d_alembert_says() {
    let here = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/problems");
    let acceleration = here.join("newmark_acceleration.wf").display().to_string();
    let pulled = |scheme: &str, ne: usize| {
        let mut o = Options::new(here.join("pulled_bar.wf").to_str().unwrap());
        o.methods.scheme = scheme.to_string();
        o.chosen.scheme = true;
        o.methods.params.push(Setting { name: "ne".into(), value: ne as f64, origin: "test".into() });
        o.dt = Some(1.0 / ne as f64);
        let r = run(&o).unwrap();
        let held = r.column("held").unwrap();
        for ((t, _), u) in r.rows.iter().zip(&held) {
            assert!((u - 0.01 * t.powi(3)).abs() < 1e-15, "{scheme}: u(1, {t}) = {u}");
        }
        r
    };
    for scheme in ["newmark", "trbdf2", "midpoint", acceleration.as_str()] {
        let e: Vec<f64> =
            [40, 80, 160].iter().map(|&ne| pulled(scheme, ne).summary.number("max_error").unwrap()).collect();
        for w in e.windows(2) {
            let order = (w[0] / w[1]).log2();
            assert!((1.8..2.6).contains(&order), "{scheme}: errors {e:?}, order {order}");
        }
        // u(0, 2.5) = 0.0675: the error is 2e-4 of it on the coarsest mesh.
        assert!(e[0] < 2e-5, "{scheme}: {e:?}");
    }
    let (a, b) = (pulled(&acceleration, 40), pulled("newmark", 40));
    let (ua, ub) = (a.column("u_free").unwrap(), b.column("u_free").unwrap());
    assert!(ua.iter().zip(&ub).all(|(x, y)| (x - y).abs() < 1e-13), "the acceleration form departs from Newmark's");
}

/// `run static`: one equilibrium by the static driver. A block resting on the ground under its
/// weight (held against sliding on one side) is carried by the contact force, ρ g |Ω|, to
/// round-off; the same problem as one step of the quasi-static scheme (no inertia) reaches the
/// same equilibrium.
#[test]
fn a_static_problem_is_one_equilibrium() {
    let here = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/problems");
    let file = here.join("resting_block.wf");
    let r = run(&Options::new(file.to_str().unwrap())).unwrap();
    assert_eq!(r.rows.len(), 1);
    let weight_error = r.summary.number("weight_error").unwrap();
    assert!(weight_error.abs() < 1e-12, "{weight_error:e}");
    assert_eq!(r.summary.get("scheme").and_then(|s| s.as_str()), Some("static"));
    // As a time run of one step with the quasi-static scheme.
    let dir = temp_dir("static");
    let text = std::fs::read_to_string(&file).unwrap().replace("run static", "run dt = 1, t_end = 1");
    std::fs::write(dir.join("resting_block.wf"), text).unwrap();
    let mut o = Options::new(dir.join("resting_block.wf").to_str().unwrap());
    o.methods.scheme =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/problems/quasistatic.wf").display().to_string();
    o.chosen.scheme = true;
    let q = run(&o).unwrap();
    for c in ["force", "penetration"] {
        let (a, b) = (r.column(c).unwrap()[0], *q.column(c).unwrap().last().unwrap());
        assert!((a - b).abs() <= 1e-9 * a.abs(), "{c}: static {a:e}, quasi-static {b:e}");
    }
    // Neither watches an energy: neither reports its growth.
    assert!(r.summary.get("energy_growth").is_none() && q.summary.get("energy_growth").is_none());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `atan2`, `cos`, `sin`, `exp` and `ln` of a problem's params fold to numbers (in its lets,
/// coefs and `set`): the block under gravity inclined by α = atan(0.2) rests on the ground with
/// the normal part of its weight, 2 ρ g cos α = 2/√1.04 (ρ = g = 1; the held side takes the
/// tangential part).
#[test]
fn transcendental_functions_of_a_problem_s_params_fold_to_numbers() {
    let here = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/problems");
    let r = run(&Options::new(here.join("inclined_block.wf").to_str().unwrap())).unwrap();
    let force = *r.column("force").unwrap().last().unwrap();
    let want = 2.0 / 1.04f64.sqrt();
    assert!((force - want).abs() < 1e-9 * want, "normal force {force}, not {want}");
}

/// Regions joined by `+` and cut by `and`, `or`, `not` and `!=`: their facet counts are the
/// rectangle's (4 at the bottom and the top, 2 at each side); `expect ... when` applies where its
/// condition holds, and a param only another law declares makes it not apply.
#[test]
fn regions_join_and_expectations_apply_where_their_condition_holds() {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/problems/joined_regions.wf");
    let file = file.to_str().unwrap();
    let line = signorini::problem::run::check(file).unwrap();
    for region in [
        "Gamma_top (4 facets)",
        "Gamma_sides (4 facets)",
        "Gamma_low_or_left (6 facets)",
        "Gamma_not_top (8 facets)",
        "Gamma_ring (12 facets)",
        "Gamma_C (3 facets)",
    ] {
        assert!(line.contains(region), "{region} in {line}");
    }
    let expectations = |opts: &Options| {
        let s = run(opts).unwrap().summary;
        s.field::<Vec<signorini::problem::summary::Expectation>>("expected").unwrap()
    };
    let here = expectations(&Options::new(file));
    let applies: Vec<bool> = here.iter().map(|x| x.applies).collect();
    assert_eq!(applies, [true, false, false]);
    assert!(here[0].met && !here[1].met && !here[2].met);
    // Under a Coulomb law `F` is declared: the third applies, and is not met.
    let mut coulomb = Options::new(file);
    coulomb.methods.contact = "nitsche_coulomb".into();
    coulomb.chosen.contact = true;
    let there = expectations(&coulomb);
    assert_eq!(there.iter().map(|x| x.applies).collect::<Vec<_>>(), [true, false, true]);
    assert!(there[0].met && !there[2].met);
}

/// The same functions in every place of a problem (lets, `set`, run settings, coefs, initial
/// fields, predicates, columns, keys, expectations, and a problem's own `fn`): on a free fall,
/// which Newmark follows exactly, each expectation is what the functions give.
#[test]
fn the_language_s_functions_serve_every_place_of_a_problem() {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/problems/functions_everywhere.wf");
    let r = run(&Options::new(file.to_str().unwrap())).unwrap();
    assert!((r.rows.last().unwrap().0 - 0.3).abs() < 1e-12, "t_end = min(0.5, max(0.2, 0.3))");
    let expected = r.summary.field::<Vec<signorini::problem::summary::Expectation>>("expected").unwrap();
    assert_eq!(expected.len(), 6);
    for x in &expected {
        assert!(x.met, "{x:?}");
    }
}

/// A problem's `neumann` loads add to the material's `load` (a slot two files provide is their
/// sum): the bar pulled by a traction, or by the same load as a pressure, runs the bits of
/// traction_bar.wf, whose material file integrates the traction itself (and which follows
/// d'Alembert at order 2); a block pressed by a pressure and pulled by a traction passes their
/// resultants, 2 q and s, to the ground and to its held side.
#[test]
fn neumann_loads_add_to_the_material_s_load() {
    let here = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/problems");
    let bar = |file: &str, kind: f64| {
        let mut o = Options::new(here.join(file).to_str().unwrap());
        o.methods.params.push(Setting { name: "ne".into(), value: 80.0, origin: "test".into() });
        if file.starts_with("neumann") {
            o.methods.params.push(Setting { name: "kind".into(), value: kind, origin: "test".into() });
        }
        o.dt = Some(0.5 / 80.0);
        run(&o).unwrap()
    };
    let reference = bar("traction_bar.wf", 0.0);
    for kind in [0.0, 1.0] {
        let r = bar("neumann_bar.wf", kind);
        let (a, b) = (reference.column("u_end").unwrap(), r.column("u_end").unwrap());
        assert_eq!(a.len(), b.len());
        assert!(a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits()), "kind {kind}");
    }
    let block = run(&Options::new(here.join("pressed_block.wf").to_str().unwrap())).unwrap();
    for key in ["pressure_error", "held_error"] {
        let e = block.summary.number(key).unwrap();
        assert!(e.abs() < 1e-10, "{key} = {e}");
    }
}

/// A library problem runs with any law that provides the documented contract: the bar
/// observes `contact_trial`, which a plain penalty law of the user's does not provide; the
/// column is left out, with a note, and the rest of the run is the run (the contact stress
/// against the exact one, the energy).
#[test]
fn a_column_the_law_cannot_measure_is_left_out_with_a_note() {
    let law = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/problems/plain_penalty.wf");
    let mut o = Options::new("bar");
    o.methods.contact = law.to_str().unwrap().into();
    o.chosen.contact = true;
    let r = run(&o).unwrap();
    assert!(!r.columns.iter().any(|c| c == "p1"), "{:?}", r.columns);
    assert!(r.columns.iter().any(|c| c == "lambda") && r.summary.number("err_l2_lambda").is_some());
    let notes: Vec<String> = r.summary.field("notes").unwrap();
    assert!(notes.iter().any(|n| n.contains("p1") && n.contains("contact_trial")), "{notes:?}");
}
