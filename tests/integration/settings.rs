//! forms/library.toml parses, and every scheme, contact law, material, mass matrix and problem it
//! names exists in the library (verify's reference schemes, the cases', the benchmarks' and the
//! report's problems too).

use signorini::driver::{self, Methods};
use signorini::simulation::MassChoice;

#[test]
fn library_settings_name_library_files() {
    let s = signorini::settings::get();
    let schemes = driver::all_schemes();
    let laws = driver::contact_names();
    let known = |scheme: &str, contact: &str| {
        assert!(schemes.contains(&scheme), "unknown scheme `{scheme}`");
        assert!(laws.contains(&contact), "unknown contact law `{contact}`");
    };
    known(&s.defaults.scheme, &s.defaults.contact);
    driver::FilesInUse::resolve(&Methods::default(), &[]).unwrap();
    for (scheme, contact, mass) in s.report.bar.iter().flat_map(|b| b.runs.iter()) {
        known(scheme, contact);
        <MassChoice as clap::ValueEnum>::from_str(mass, true).unwrap_or_else(|e| panic!("mass `{mass}`: {e}"));
    }
    for scheme in &s.verify.references {
        for contact in &s.verify.contacts {
            known(scheme, contact);
        }
    }
    // verify binds the damping slot itself: it must be named.
    assert!(!s.verify.damping_slot.is_empty());
    assert!(laws.contains(&s.bench.disc_friction.as_str()), "unknown contact law `{}`", s.bench.disc_friction);
    let (scheme, mass) = &s.bench.disc_explicit;
    known(scheme, &s.defaults.contact);
    <MassChoice as clap::ValueEnum>::from_str(mass, true).unwrap_or_else(|e| panic!("mass `{mass}`: {e}"));
    let problems = signorini::problem::library_names();
    let named = [&s.cases.bar, &s.cases.disc, &s.bench.disc, &s.bench.sphere, &s.report.hertz_impact];
    for problem in named.into_iter().chain(s.report.hertz.iter().map(|h| &h.problem)) {
        assert!(problems.contains(&problem.as_str()), "unknown problem `{problem}` (known: {problems:?})");
    }
}
