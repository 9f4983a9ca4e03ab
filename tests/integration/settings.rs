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
    for law in &s.bench.disc_friction {
        assert!(laws.contains(&law.as_str()), "unknown contact law `{law}`");
    }
    let table = &s.report.friction_table;
    let pf = signorini::problem::load(&table.problem).expect("the friction table's problem loads");
    for key in &table.keys {
        assert!(pf.problem().summary.iter().any(|d| d.name.name == *key), "{}: no summary key `{key}`", table.problem);
    }
    for f in s.report.friction.iter().filter(|f| !f.contact.is_empty()) {
        assert!(laws.contains(&f.contact.as_str()), "report.friction: unknown contact law `{}`", f.contact);
    }
    let (scheme, mass) = &s.bench.disc_explicit;
    known(scheme, &s.defaults.contact);
    <MassChoice as clap::ValueEnum>::from_str(mass, true).unwrap_or_else(|e| panic!("mass `{mass}`: {e}"));
    let problems = signorini::problem::library_names();
    let named = [
        &s.cases.bar,
        &s.cases.disc,
        &s.bench.disc,
        &s.bench.sphere,
        &s.report.hertz_impact,
        &s.report.friction_table.problem,
    ];
    for problem in named
        .into_iter()
        .chain(s.report.hertz.iter().map(|h| &h.problem))
        .chain(s.report.friction.iter().map(|f| &f.problem))
    {
        assert!(problems.contains(&problem.as_str()), "unknown problem `{problem}` (known: {problems:?})");
    }
}

/// A problem's `set` reaches only the params it names: under every library scheme, every
/// library problem leaves each of the scheme's params at its file's default unless one of its
/// `set`s names it (`rho` is the material's density and generalized-α's ρ∞: the problems say
/// `material.rho`), and each `set` reaches exactly one param when the files declare it.
#[test]
fn a_problem_s_set_reaches_only_the_param_it_names() {
    use signorini::driver::params::Source;
    use signorini::problem::run::{Options, params_in_use};
    for problem in signorini::problem::library_names() {
        let pf = signorini::problem::load(problem).unwrap();
        let sets: Vec<String> = pf.problem().sets.iter().map(|s| s.name.name.clone()).collect();
        for scheme in driver::all_schemes() {
            let mut opts = Options::new(problem);
            opts.methods.scheme = scheme.to_string();
            opts.chosen.scheme = true;
            let params = params_in_use(&opts).unwrap_or_else(|e| panic!("{problem} with {scheme}: {e}"));
            let file = format!("forms/schemes/{scheme}.wf:");
            for (name, p) in params.iter().filter(|(_, p)| p.declared.starts_with(&file)) {
                let bare = name.rsplit('.').next().unwrap();
                let named = sets.iter().any(|s| match s.rsplit_once('.') {
                    Some((owner, n)) => n == bare && (owner == "scheme" || owner == scheme),
                    None => s == bare,
                });
                if named {
                    assert_eq!(p.source, Source::Case, "{problem} with {scheme}: `{name}` is set by the problem");
                } else {
                    assert_eq!(p.source, Source::File, "{problem} with {scheme}: `{name}` = {} was not named", p.value);
                }
            }
            // Each `set` the files in use declare reaches one quantity (files that declare a
            // param of the same name and doc declare one: a finite-strain material's `E` and
            // that of the elasticity its contact law imports): the count of quantities the
            // problem set is at most its count of `set`s.
            let mut reached: Vec<&str> = params
                .iter()
                .filter(|(_, p)| p.source == Source::Case)
                .map(|(name, _)| name.rsplit('.').next().unwrap())
                .collect();
            reached.sort();
            reached.dedup();
            let reached = reached.len();
            assert!(reached <= sets.len(), "{problem} with {scheme}: {reached} params set by {} `set`s", sets.len());
        }
    }
}
