//! Case files: a valid file runs and writes where it says; an unknown key, a key of the other
//! case, a bad name and an out-of-range value fail with the file and the key's line.

use std::process::Command;

fn signorini(args: &[&str]) -> (i32, String) {
    signorini_in(&std::env::temp_dir(), args)
}

/// Runs the binary in `dir`, where a case file without `out` would write `results/`.
fn signorini_in(dir: &std::path::Path, args: &[&str]) -> (i32, String) {
    let out =
        Command::new(env!("CARGO_BIN_EXE_signorini")).args(args).current_dir(dir).output().expect("the binary runs");
    (out.status.code().unwrap_or(-1), String::from_utf8_lossy(&out.stderr).into_owned())
}

fn write(name: &str, text: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("signorini-case-files-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn a_valid_file_runs_and_writes_its_results() {
    let path = write(
        "bar.toml",
        "case = \"bar\"\nscheme = \"trbdf2\"\nmass = \"redistributed\"\nt_end = 1.5\nout = \"bar-out\"\nsolver = \"iterative\"\n",
    );
    let (code, err) = signorini(&["run", path.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    let dir = path.parent().unwrap().join("bar-out");
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!(s["scheme"], "trbdf2");
    assert_eq!(s["mass"], "redistributed");
    assert_eq!(s["steps"], 150);
    assert_eq!(s["solver"], "iterative");
}

/// `[params]` reaches every param of the files in use, qualified by file when asked.
#[test]
fn params_table_sets_scheme_and_form_params() {
    let path = write(
        "params_ok.toml",
        "case = \"bar\"\nscheme = \"hht\"\nt_end = 0.5\nout = \"params-out\"\n[params]\nalpha = 0.2\n[params.contact_nitsche]\ntheta = -1\n",
    );
    let (code, err) = signorini(&["run", path.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path.parent().unwrap().join("params-out/summary.json")).unwrap())
            .unwrap();
    assert_eq!(s["params"]["alpha"]["value"], 0.2);
    assert_eq!(s["params"]["alpha"]["source"], "user");
    assert_eq!(s["params"]["theta"]["value"], -1.0);
    assert_eq!(s["params"]["gamma0"]["source"], "file");
    assert!(s["params"]["gamma0"]["declared"].as_str().unwrap().starts_with("contact_nitsche.wf:"));
}

#[test]
fn mistakes_are_reported_with_their_line() {
    let cases = [
        ("unknown.toml", "case = \"bar\"\nscheme = \"hht\"\nthetta = 1\n", ":3: unknown field `thetta`"),
        (
            "range.toml",
            "case = \"bar\"\n[params]\ntheta = 2\n",
            ":3: param `theta` = 2 is outside its range [-1, 1] (declared at contact_nitsche.wf:",
        ),
        (
            "params.toml",
            "case = \"bar\"\n[params]\ngamma0 = 5\nthetta = 1\n",
            ":4: unknown param `thetta`: the scheme and form files in use declare",
        ),
        (
            "owner.toml",
            "case = \"disc\"\n[params.elasticity]\nnu = 0.5\n",
            ":3: param `nu` = 0.5 is outside its range [0, 0.5) (declared at elasticity.wf:",
        ),
        (
            "other_case.toml",
            "case = \"disc\"\nne = 5\n",
            ":2: unknown field `ne`, expected one of `case`, `scheme`, `contact`, `material`, `forms`, `params`, `mass`, `cell_size`, `dt`, `t_end`, `t_start`, `adaptive`, `dt_min`, `dt_max`, `event_dt`, `out`, `mesh`, `max_step_cuts`, `energy_tolerance`, `allow_unstable_dt`, `solver`, `petsc_options`; nor a param of problem `disc` (its params: h)",
        ),
        (
            "name.toml",
            "case = \"bar\"\nscheme = \"rk4\"\n",
            ":2: `scheme`: invalid option: no scheme `rk4` in the library",
        ),
        ("law.toml", "case = \"bar\"\ncontact = \"nitche\"\n", "did you mean `nitsche`?"),
        ("alpha.toml", "case = \"bar\"\nscheme = \"midpoint\"\n[params]\nalpha = 0.1\n", ":4: unknown param `alpha`"),
        // A param of the scheme or form files has no key of its own: it goes in [params].
        ("removed.toml", "case = \"bar\"\nscheme = \"hht\"\nalpha = 0.1\n", ":3: unknown field `alpha`"),
        ("type.toml", "case = \"disc\"\ndt = \"x\"\n", ":2: invalid type"),
        ("case.toml", "case = \"beam\"\n", ":1: `case`: no problem `beam` in the library"),
        ("solver.toml", "case = \"bar\"\nsolver = \"cholmod\"\n", ":2: `solver`: `cholmod`: expected direct"),
    ];
    // A refused case writes nothing, not even its output directory.
    let cwd = std::env::temp_dir().join(format!("signorini-refused-cases-{}", std::process::id()));
    std::fs::create_dir_all(&cwd).unwrap();
    for (name, text, want) in cases {
        let path = write(name, text);
        let (code, err) = signorini_in(&cwd, &["run", path.to_str().unwrap()]);
        assert_eq!(code, 1, "{name}");
        assert!(err.contains(name) && err.contains(want), "{name}: expected `{want}` in `{err}`");
    }
    assert!(!cwd.join("results").exists(), "a refused case made its output directory");
}

/// A case file names any problem, a library one or a file (relative to the case file), and its
/// `[params]` reach the problem's params as well as the files'.
#[test]
fn a_case_file_runs_a_problem_file_with_its_params() {
    let ring = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/problems/ring.wf");
    let path = write(
        "ring.toml",
        &format!(
            "case = {:?}\nscheme = \"hybrid\"\nt_end = 0.4\nout = \"ring-out\"\n[params]\nomega = 0.05\ngamma0 = 500\n",
            ring.display().to_string()
        ),
    );
    let (code, err) = signorini(&["run", path.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    let dir = path.parent().unwrap().join("ring-out");
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!(s["scheme"], "hybrid");
    assert_eq!(s["steps"], 20);
    assert_eq!(s["params"]["ring.omega"]["value"], 0.05);
    assert_eq!(s["params"]["gamma0"]["value"], 500.0);
    assert!(std::fs::read_to_string(dir.join("series.csv")).unwrap().starts_with("t,energy,energy_aug,ux_cm"));
    // A misspelt problem is refused at the key.
    let bad = write("bad_problem.toml", "case = \"sphre\"\n");
    let (code, err) = signorini(&["run", bad.to_str().unwrap()]);
    assert_eq!(code, 1);
    assert!(err.contains("bad_problem.toml:1: `case`") && err.contains("did you mean `sphere`?"), "{err}");
}

/// Adaptive steps from a case file (issue 56): its keys are the run settings'; a tolerance that
/// is not positive fails with the key's line.
#[test]
fn a_case_file_asks_for_adaptive_steps() {
    let path = write(
        "adaptive.toml",
        "case = \"disc\"\nh = 2\nt_end = 8.5\nadaptive = 1e-3\nevent_dt = 2e-3\nout = \"adaptive-out\"\n",
    );
    let (code, err) = signorini(&["run", path.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    let dir = path.parent().unwrap().join("adaptive-out");
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!(s["adaptive"]["tolerance"], 1e-3);
    assert!(s["adaptive"]["events"].as_u64().unwrap() >= 1, "{}", s["adaptive"]);
    let bad = write("adaptive_bad.toml", "case = \"disc\"\nh = 2\n\nadaptive = -1\n");
    let (code, err) = signorini(&["run", bad.to_str().unwrap()]);
    assert_eq!(code, 1);
    assert!(err.contains("adaptive_bad.toml:4") && err.contains("`adaptive`"), "{err}");
}
