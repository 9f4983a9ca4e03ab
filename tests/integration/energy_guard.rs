//! The energy guard (docs/language.md, "When a run goes wrong"): on the bar and the disc at their
//! defaults (a frictional law: the disc's first impact and bounce, t ∈ [5.5, 12]), every library
//! scheme × contact law × mass runs without the guard stopping it,
//! except IMEX-HHT, whose explicit contact is only conditionally stable (docs/mathematics.md
//! §5): its energy grows at these steps and the guard must stop it (unless friction takes it). An explicit scheme is
//! refused at set-up where it cannot run (redistributed mass; Δt above its critical step), and a
//! frictional law on the 1D bar (no tangent space).
//! The blow-ups of issue 32 stop with the cause and exit status 1 (tests/bad_inputs has the
//! bar's; the disc's are here).

use signorini::cases::{bar, disc};
use signorini::driver::{Methods, all_schemes, contact_names};
use signorini::error::CaseError;
use signorini::problem::run::Options;
use signorini::simulation::MassChoice;

/// The scheme whose energy the guard must stop at the library's defaults.
const UNSTABLE: &str = "hht_imex";

/// What a run at the defaults may end with: nothing, a refusal at set-up, or (for
/// [`UNSTABLE`]) the guard.
fn judge(problem: &str, scheme: &str, contact: &str, mass: MassChoice, result: Result<f64, CaseError>) -> String {
    let label = format!("{problem} {scheme} {contact} {}", mass.name());
    match result {
        Ok(growth) if scheme != UNSTABLE && growth <= 0.05 => String::new(),
        // Friction takes the energy IMEX-HHT's explicit contact gives the disc.
        Ok(growth) if frictional(contact) && growth <= 0.05 => String::new(),
        Ok(growth) => format!("{label}: ran to the end with energy_growth {growth}"),
        Err(CaseError::BlowUp { .. }) if scheme == UNSTABLE => String::new(),
        Err(CaseError::UnstableStep { .. }) => String::new(),
        Err(CaseError::Option(m)) if m.contains("is explicit") && mass == MassChoice::Redistributed => String::new(),
        // A frictional law on the 1D bar: refused at set-up, at its `tangential`.
        Err(CaseError::NoTangentSpace(_)) if problem == "bar" => String::new(),
        Err(e) => format!("{label}: {e}"),
    }
}

/// Whether a library contact law is frictional: it provides `friction_work`.
fn frictional(contact: &str) -> bool {
    signorini::driver::frictional_contact_names().contains(&contact)
}

fn methods(scheme: &str, contact: &str) -> Methods {
    Methods { scheme: scheme.into(), contact: contact.into(), ..Methods::default() }
}

#[test]
fn no_library_run_trips_the_guard_but_the_unstable_scheme() {
    let masses = [MassChoice::Consistent, MassChoice::Redistributed, MassChoice::Lumped];
    let mut runs = Vec::new();
    for scheme in all_schemes() {
        for contact in contact_names() {
            for mass in masses {
                runs.push((scheme, contact, mass));
            }
        }
    }
    assert!(runs.iter().any(|r| r.0 == UNSTABLE), "the library has {UNSTABLE}");
    // Two threads: the disc runs take most of the time.
    let failures: Vec<String> = std::thread::scope(|s| {
        let chunks: Vec<_> = runs.chunks(runs.len().div_ceil(2)).collect();
        let handles: Vec<_> = chunks
            .into_iter()
            .map(|chunk| {
                s.spawn(move || {
                    let mut out = Vec::new();
                    for &(scheme, contact, mass) in chunk {
                        let o = Options { methods: methods(scheme, contact), mass, ..bar::options() };
                        out.push(judge("bar", scheme, contact, mass, bar::run(&o).map(|r| r.summary.energy_growth)));
                        // A frictional law from just before the first impact through the bounce:
                        // its runs cost several times a frictionless one's.
                        let times = if frictional(contact) { (Some(5.5), Some(12.0)) } else { (None, None) };
                        let o = Options {
                            methods: methods(scheme, contact),
                            mass,
                            t_start: times.0,
                            t_end: times.1,
                            ..disc::options()
                        };
                        out.push(judge("disc", scheme, contact, mass, disc::run(&o).map(|r| r.summary.energy_growth)));
                    }
                    out
                })
            })
            .collect();
        handles.into_iter().flat_map(|h| h.join().expect("a run panicked")).filter(|f| !f.is_empty()).collect()
    });
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The disc's blow-ups of issue 32: a contact parameter so large that round-off swamps the
/// solve, and IMEX-HHT with the redistributed mass. Each stops with the guard's message, and
/// the series ends at the last good step, below the tolerance.
#[test]
fn the_discs_blow_ups_stop() {
    let stiff = Options { methods: Methods::default().set("gamma0", 1e12), t_end: Some(8.0), ..disc::options() };
    let imex = Options {
        methods: methods(UNSTABLE, "nitsche"),
        mass: MassChoice::Redistributed,
        t_end: Some(20.0),
        ..disc::options()
    };
    for (k, opts) in [stiff, imex].into_iter().enumerate() {
        let dir = std::env::temp_dir().join(format!("signorini-guard-{}-{k}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let opts = Options { out: Some(dir.clone()), ..opts };
        match disc::run(&opts) {
            Err(CaseError::BlowUp { t, energy, bound, scale, tolerance, .. }) => {
                assert!(energy - bound > tolerance * scale, "{t}: {energy} {bound} {scale}");
                assert!(opts.t_end.is_some_and(|end| t < end), "{t}");
            }
            other => panic!("expected the guard to stop the run, got {:?}", other.map(|r| r.summary.energy_growth)),
        }
        let summary = std::fs::read_to_string(dir.join("summary.json")).unwrap();
        assert!(summary.contains("\"stopped\""), "{summary}");
        let growth: f64 =
            serde_json::from_str::<serde_json::Value>(&summary).unwrap()["energy_growth"].as_f64().unwrap();
        assert!(growth <= 0.05, "the written steps passed the guard: {growth}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}

/// The guard measures a step by the scheme's energy identity where it has one: central
/// differences keep Ẽ = E − ¼·½Δt²‖a‖²_M exactly (`emit --stage energy`), so on the plucked bar
/// (no contact, no load) what its steps make is round-off, and a guard at 1e-9 of the scale lets
/// it run, while E itself swings by about (ωΔt)²/4 of itself: measured by E, the same run would
/// show a growth of that size. Newmark at gam = 0.6, beta = 0.3 (proved dissipative there) and
/// TR-BDF2 lose energy and the midpoint rule keeps it: neither makes any.
#[test]
fn the_guard_measures_by_the_scheme_s_identity() {
    let file = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/problems/plucked_bar.wf");
    for (scheme, params) in
        [("central", vec![]), ("newmark", vec![("gam", 0.6), ("beta", 0.3)]), ("trbdf2", vec![]), ("midpoint", vec![])]
    {
        let mut o = Options::new(file.to_str().unwrap());
        o.methods = params.iter().fold(methods(scheme, "penalty"), |m, &(p, v)| m.set(p, v));
        o.methods.guard.energy_tolerance = 1e-9;
        o.chosen.scheme = true;
        let r = signorini::problem::run::run(&o).unwrap_or_else(|e| panic!("{scheme}: {e}"));
        let growth = r.summary.number("energy_growth").unwrap();
        assert!(growth <= 1e-12, "{scheme}: {growth:e}");
        if scheme == "central" {
            let e = r.column("energy").unwrap();
            let swing =
                (e.iter().copied().fold(f64::MIN, f64::max) - e.iter().copied().fold(f64::MAX, f64::min)) / e[0];
            // (πΔt)²/4 with Δt = 0.02: 9.9e-4.
            assert!(swing > 5e-4, "E swings by {swing:e} of itself");
        }
    }
}
