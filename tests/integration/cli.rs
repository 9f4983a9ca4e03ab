//! The `signorini` binary: `check` and `emit` on the form library and on a bad file.

use std::process::Command;

fn signorini(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_signorini")).args(args).output().expect("the binary runs");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn check_accepts_the_form_library() {
    let (code, _, err) =
        signorini(&["check", "forms/elasticity.wf", "forms/contact_nitsche.wf", "forms/contact_penalty.wf"]);
    assert_eq!(code, 0, "{err}");
    assert!(err.is_empty(), "{err}");
}

#[test]
fn check_reports_every_error_with_position_and_caret() {
    let (code, _, err) = signorini(&["check", "forms/elasticity.wf", "compiler/tests/ui/syntax_two_broken_items.wf"]);
    assert_eq!(code, 1);
    assert!(err.contains("compiler/tests/ui/syntax_two_broken_items.wf:2:14"), "{err}");
    assert!(err.contains("compiler/tests/ui/syntax_two_broken_items.wf:4:8"), "{err}");
    assert!(err.contains("^ expected"), "{err}");
    assert!(err.contains("3 error(s)"), "{err}");
}

#[test]
fn check_of_a_missing_file_fails_cleanly() {
    let (code, _, err) = signorini(&["check", "forms/no_such_file.wf"]);
    assert_eq!(code, 1);
    assert!(err.contains("cannot read forms/no_such_file.wf"), "{err}");
}

#[test]
fn emit_prints_every_stage() {
    let (code, ast, _) = signorini(&["emit", "forms/contact_nitsche.wf", "--stage", "ast"]);
    assert_eq!(code, 0);
    assert!(ast.contains("form contact(u; v)"), "{ast}");
    let (code, ir, _) = signorini(&["emit", "forms/contact_nitsche.wf", "--stage", "ir", "--dim", "1"]);
    assert_eq!(code, 0);
    assert!(ir.contains("// dimension 1") && ir.contains("H "), "{ir}");
    let (code, rust, _) = signorini(&["emit", "forms/contact_nitsche.wf"]);
    assert_eq!(code, 0);
    assert!(
        rust.contains("pub mod contact_nitsche") && rust.contains("impl<const N: usize> FormKernel<2, N> for Contact")
    );
}

#[test]
fn mesh_info_prints_json_or_the_error() {
    let (code, out, err) = signorini(&["mesh", "info", "runtime/tests/gmsh_good_41.msh"]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["nodes"], 4);
    assert_eq!(v["cells"]["P1 triangle"], 2);
    assert_eq!(v["boundary_facets"], 4);
    assert!((v["measure"].as_f64().unwrap() - 1.0).abs() < 1e-14);
    let (code, _, err) = signorini(&["mesh", "info", "runtime/tests/gmsh_bad/node_out_of_range.msh"]);
    assert_eq!(code, 1);
    assert!(err.contains("node_out_of_range.msh:19: element 3 refers to node 9"), "{err}");
}

#[test]
fn static_block_writes_its_summary() {
    let dir = std::env::temp_dir().join(format!("signorini-cli-{}", std::process::id()));
    let (code, out, err) =
        signorini(&["run", "static_block", "--cells", "4", "--param", "theta=-1", "--out", dir.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("static_block:"), "{out}");
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    for key in ["contact_force", "weight", "max_penetration", "newton_total", "dofs"] {
        assert!(s.get(key).is_some(), "summary.json lacks {key}");
    }
    assert_eq!(s["scheme"], "static");
    let (code, _, err) = signorini(&["run", "static_block", "--cells", "0"]);
    assert_eq!(code, 1);
    assert!(err.contains("param cells of problem `static_block` must be in [1, 256]"), "{err}");
}

/// The Hertz problems write the figures the validation compares, measured and Hertz's, and
/// their plots.
#[test]
fn hertz_cases_write_their_summaries_and_plots() {
    let dir = std::env::temp_dir().join(format!("signorini-cli-hertz-{}", std::process::id()));
    let read = |path: std::path::PathBuf| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
    };
    for (problem, size) in [("hertz_cylinder", "half_width"), ("hertz_ball", "contact_radius")] {
        let out = dir.join(problem);
        let (code, text, err) = signorini(&["run", problem, "--level", "0", "--out", out.to_str().unwrap()]);
        assert_eq!(code, 0, "{err}");
        assert!(text.contains(problem), "{text}");
        let s = read(out.join("summary.json"));
        for key in ["load", "contact_force", "peak_pressure", "hertz_peak_pressure", "profile_l2_error", "h_contact"] {
            assert!(s[key].is_number(), "summary.json lacks {key}");
        }
        assert!(s[size].is_number() && s[format!("hertz_{size}")].is_number(), "{s}");
        assert!(out.join("profile.png").exists());
    }
    let out = dir.join("impact");
    let (code, text, err) = signorini(&["run", "hertz_impact", "--steps", "10", "--out", out.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(text.contains("hertz_impact"), "{text}");
    let s = read(out.join("summary.json"));
    for key in ["contact_duration", "peak_force", "contact_radius"] {
        assert!(s[key].is_number() && s[format!("hertz_{key}")].is_number(), "{key}: {s}");
    }
    for key in ["restitution", "indentation_ratio", "contact_time_over_wave_time"] {
        assert!(s[key].is_number(), "summary.json lacks {key}");
    }
    assert!(out.join("hertz_impact.png").exists() && out.join("series.csv").exists());
    let (code, _, err) = signorini(&["run", "hertz_ball", "--level", "9"]);
    assert_eq!(code, 1);
    assert!(err.contains("param level of problem `hertz_ball` must be in [0, 3]"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bar_writes_series_summary_and_plots() {
    let dir = std::env::temp_dir().join(format!("signorini-bar-{}", std::process::id()));
    let (code, out, err) = signorini(&["run", "bar", "--t-end", "1", "--out", dir.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("bar: newmark"), "{out}");
    let csv = std::fs::read_to_string(dir.join("series.csv")).unwrap();
    assert!(csv.starts_with("t,u_c,v_c,lambda,lambda_half,energy,energy_aug,penetration,newton\n"));
    assert_eq!(csv.lines().count(), 1 + 101);
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    // No contact before t = 1: the relative λ error is undefined, null and explained.
    assert!(s["err_l2_lambda"].is_null(), "{s}");
    assert!(s["notes"][0].as_str().unwrap().contains("err_l2_lambda is undefined on this run"), "{s}");
    assert!(s["err_linf_l2_u"].as_f64().unwrap() < 0.1, "{s}");
    for key in [
        "err_linf_l2_u",
        "energy_aug_drift_final",
        "energy_aug_drift_max",
        "newton_total",
        "newton_max",
        "dofs",
        "steps",
    ] {
        assert!(s.get(key).is_some(), "summary.json lacks {key}");
    }
    let bytes = std::fs::read(dir.join("bar.png")).unwrap();
    assert!(bytes.starts_with(b"\x89PNG"), "bar.png is not a PNG");
    let refused = std::env::temp_dir().join(format!("signorini-refused-{}", std::process::id()));
    let (code, _, err) =
        signorini(&["run", "bar", "--scheme", "midpoint", "--param", "alpha=0.1", "--out", refused.to_str().unwrap()]);
    assert_eq!(code, 1);
    assert!(err.contains("--param alpha=0.1: unknown param `alpha`"), "{err}");
    assert!(!refused.exists(), "a refused run made its --out directory");
    // A rendered diagnostic is its own error line: one prefix.
    let bad = std::env::temp_dir().join(format!("signorini-bad-{}.wf", std::process::id()));
    std::fs::write(&bad, "problem p {\n  bogus\n}\n").unwrap();
    let (code, _, err) = signorini(&["run", bad.to_str().unwrap()]);
    assert_eq!(code, 1);
    assert!(err.starts_with("error[E0001]"), "{err}");
    // A param of the scheme or form files has no option of its own.
    let (code, _, err) = signorini(&["run", "bar", "--scheme", "hht", "--alpha", "0.1"]);
    assert_eq!(code, 2);
    assert!(err.contains("unexpected argument '--alpha'"), "{err}");
}

#[test]
fn report_writes_markdown_with_its_figures() {
    let dir = std::env::temp_dir().join(format!("signorini-report-{}", std::process::id()));
    // Sections 1 and 2; verification and the Δt sweeps have tests of their own (verify.rs, sweep.rs).
    let (code, out, err) = signorini(&["report", "--quick", "--out", dir.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("report.md"), "{out}");
    let md = std::fs::read_to_string(dir.join("report.md")).unwrap();
    assert!(md.contains("## 1. Compressed bar") && md.contains("## 2. Bouncing disc"));
    assert!(!md.contains("## 3."), "--quick skips the verification");
    // Every scheme of the library on the disc, one row each.
    let disc = md.split("## 2. Bouncing disc").nth(1).unwrap();
    let rows = disc.lines().filter(|l| l.starts_with("| ") && !l.starts_with("| scheme")).count();
    assert_eq!(rows, signorini::driver::all_schemes().len(), "{disc}");
    for png in
        ["bar_energies.png", "disc_energies.png", "bar/newmark-nitsche-consistent/bar.png", "disc/hybrid/disc.png"]
    {
        assert!(md.contains(png.split('/').next().unwrap()), "{png} not referenced");
        assert!(std::fs::read(dir.join(png)).unwrap().starts_with(b"\x89PNG"), "{png}");
    }
    markdown_is_a_document(&md, &dir);
}

/// Every table of a Markdown document has a separator line and rows, each row as many cells as
/// its header; every section number is used once; every local link names a file that exists.
fn markdown_is_a_document(md: &str, dir: &std::path::Path) {
    let cells = |line: &str| line.replace("\\|", "").matches('|').count();
    let lines: Vec<&str> = md.lines().collect();
    let mut k = 0;
    while k < lines.len() {
        if !lines[k].starts_with('|') {
            k += 1;
            continue;
        }
        let table: Vec<&str> = lines[k..].iter().take_while(|l| l.starts_with('|')).copied().collect();
        let header = cells(table[0]);
        assert!(table.len() >= 3, "a table without rows at line {}:\n{}", k + 1, table.join("\n"));
        assert!(table[1].starts_with("|---"), "no separator under the header at line {}", k + 1);
        for (i, row) in table.iter().enumerate() {
            assert_eq!(cells(row), header, "line {}: {row}\nunder {}", k + i + 1, table[0]);
        }
        k += table.len();
    }
    let mut numbers: Vec<&str> =
        lines.iter().filter_map(|l| l.strip_prefix("## ")).filter_map(|l| l.split_once(". ")).map(|(n, _)| n).collect();
    let all = numbers.len();
    numbers.dedup();
    assert_eq!(numbers.len(), all, "a section number used twice");
    for link in md.split("](").skip(1).filter_map(|rest| rest.split_once(')')).map(|(l, _)| l) {
        if !link.starts_with("http") {
            assert!(dir.join(link).exists(), "the report links {link}, which it did not write");
        }
    }
}

#[test]
fn bench_disc_times_the_stepper_and_reports_missing_meshes() {
    let (code, _, err) = signorini(&["bench", "disc", "--mesh", "/nonexistent/disc.msh", "--repeats", "1"]);
    assert_eq!(code, 1);
    assert!(err.contains("/nonexistent/disc.msh"), "{err}");
    let mesh = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/meshes/disc_r10_h1_v22.msh");
    let dir = std::env::temp_dir().join(format!("signorini-bench-disc-{}", std::process::id()));
    let (code, _, err) =
        signorini(&["bench", "disc", "--mesh", mesh, "--repeats", "1", "--out", dir.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    let json = std::fs::read_to_string(dir.join("bench_disc.json")).unwrap();
    for key in ["\"dofs\": 3250", "\"steps\": 1000", "\"ms_per_step\"", "\"median_step_ms\""] {
        assert!(json.contains(key), "{key} missing from {json}");
    }
    // The ratios are the timings over the models.
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    let m = &v["meshes"][0];
    let num = |k: &str| m[k].as_f64().unwrap_or_else(|| panic!("{k} missing from {json}"));
    let model = num("model_ms");
    assert!(model > 0.0);
    assert!((num("measured_over_model") - num("ms_per_step") / model).abs() <= 1e-12 * num("measured_over_model"));
    assert!((num("median_over_model") - num("median_step_ms") / model).abs() <= 1e-12 * num("median_over_model"));
    assert!(num("ms_per_step_fastest") <= num("ms_per_step") && num("ms_per_step") <= num("ms_per_step_slowest"));
    // The same bytes at two bandwidths: out of cache (STREAM's) and in cache.
    let cache = num("cache_model_ms");
    assert!((model * num("stream_gb_s") - cache * num("cache_gb_s")).abs() <= 1e-12 * model * num("stream_gb_s"));
    assert!(
        (num("measured_over_cache_model") - num("ms_per_step") / cache).abs() <= 1e-12 * num("ms_per_step") / cache
    );
}

#[test]
fn bench_sphere_runs_each_size_in_its_own_process() {
    let dir = std::env::temp_dir().join(format!("signorini-bench-sphere-{}", std::process::id()));
    // The smallest ball only (14 739 unknowns), with both solvers.
    let (code, out, err) = signorini(&[
        "bench",
        "sphere",
        "--max-dofs",
        "20000",
        "--solvers",
        "direct,iterative",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("14739 dofs, direct") && out.contains("14739 dofs, iterative"), "{out}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("bench_sphere.json")).unwrap()).unwrap();
    let runs = json["runs"].as_array().unwrap();
    assert_eq!(runs.len(), 2);
    for r in runs {
        // 50 steps from t = 6 through the first contact, in a process of its own.
        assert_eq!(r["steps"], 50);
        assert!(r["first_contact"].as_f64().is_some_and(|t| t > 6.3 && t < 6.5), "{r}");
        assert!(r["peak_memory_bytes"].as_u64().is_some_and(|b| b > 1_000_000), "{r}");
    }
    assert!(runs.iter().any(|r| r["solver"] == "iterative" && r["krylov_iterations"].as_u64() > Some(0)));
    // Iterations per solve for the iterative run only: at least one, at most the stall limit.
    for r in runs {
        let per_solve = r["iterations_per_solve"].as_f64();
        match r["solver"].as_str() {
            Some("iterative") => assert!(per_solve.is_some_and(|i| (1.0..250.0).contains(&i)), "{r}"),
            _ => assert!(per_solve.is_none(), "{r}"),
        }
        assert_eq!(r["ranks"], 1);
    }
    assert!(std::fs::read(dir.join("bench_sphere.png")).unwrap().starts_with(b"\x89PNG"));
}

/// SIGINT ends a run after its current step: exit status 130, and the series, the summary
/// (saying it was interrupted) and no temporary file in the output directory. A second run into
/// the same directory writes to a fresh subdirectory; `--force` replaces the first.
#[cfg(unix)]
#[test]
fn an_interrupted_run_leaves_consistent_results_and_runs_never_mix() {
    let dir = std::env::temp_dir().join(format!("signorini-sigint-{}", std::process::id()));
    let child = Command::new(env!("CARGO_BIN_EXE_signorini"))
        .args(["run", "disc", "--t-end", "1000", "--out", dir.to_str().unwrap()])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // Wait until it steps (the marker is written before the computation starts).
    std::thread::sleep(std::time::Duration::from_millis(1500));
    assert!(dir.join(".signorini-output").exists());
    // SAFETY: signalling our own child process.
    unsafe { libc::kill(child.id() as i32, libc::SIGINT) };
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{err}");
    assert!(err.contains("interrupted at t = "), "{err}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    assert!(summary["stopped"].as_str().unwrap().starts_with("interrupted"), "{summary}");
    let rows = std::fs::read_to_string(dir.join("series.csv")).unwrap().lines().count();
    assert!(rows > 2, "{rows} rows");
    let names: Vec<String> =
        std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    assert!(!names.iter().any(|n| n.ends_with(".tmp")), "{names:?}");

    let d = dir.to_str().unwrap();
    let (code, _, err) = signorini(&["run", "bar", "--t-end", "0.1", "--out", d]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("run-2") && dir.join("run-2").join("summary.json").exists(), "{err}");
    let (code, _, err) = signorini(&["run", "bar", "--t-end", "0.1", "--force", "--out", d]);
    assert_eq!(code, 0, "{err}");
    assert!(!dir.join("run-2").exists(), "{err}");
    // Nothing of the disc run is left beside the bar's.
    let series = std::fs::read_to_string(dir.join("series.csv")).unwrap();
    assert!(series.starts_with("t,u_c,"), "{}", series.lines().next().unwrap());
    let summary = std::fs::read_to_string(dir.join("summary.json")).unwrap();
    assert!(summary.contains("\"case\": \"bar\""), "{summary}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// clap's own consistency checks over every subcommand (argument ids must be unique: a global
/// `--force` and a command's `force` field once panicked at parse time).
#[test]
fn the_command_line_definition_is_consistent() {
    use clap::CommandFactory;
    signorini::cli::Cli::command().debug_assert();
    let (code, _, err) = signorini(&["run", "hertz_cylinder", "--level", "0", "--ratio", "0.05"]);
    assert_eq!(code, 0, "{err}");
}

/// A problem's params are options of its run wherever they stand after `run` (`--ne 4`,
/// `--ne=4`, before or after the problem's name), as `--param ne=4`; a run option of its own
/// keeps its meaning.
#[test]
fn a_problems_params_are_options_of_its_run() {
    let dir = std::env::temp_dir().join(format!("signorini-flags-{}", std::process::id()));
    for (k, args) in [
        vec!["run", "bar", "--ne", "4"],
        vec!["run", "--ne", "4", "bar"],
        vec!["run", "--scheme", "hht", "bar", "--ne=4"],
    ]
    .into_iter()
    .enumerate()
    {
        let out = dir.join(k.to_string());
        let mut args = args;
        args.extend(["--t-end", "0.05", "--out", out.to_str().unwrap()]);
        let (code, _, err) = signorini(&args);
        assert_eq!(code, 0, "{args:?}: {err}");
        let s: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
        assert_eq!(s["params"]["bar.ne"]["value"], 4.0, "{args:?}");
        assert_eq!(s["params"]["bar.ne"]["source"], "user", "{args:?}");
        assert_eq!(s["dofs"], 5, "{args:?}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// What a run prints reads back: keys with six significant digits (a value of 1e-17 is not
/// `0.000000`), and an expectation of 0 says its difference and tolerance are absolute;
/// series.csv holds the shortest text of each double, which parses back to the same bits as
/// the summary's.
#[test]
fn a_run_prints_significant_digits_and_says_absolute() {
    let out = std::env::temp_dir().join(format!("signorini-cli-digits-{}", std::process::id()));
    let (code, stdout, err) =
        signorini(&["run", "tests/problems/functions_everywhere.wf", "--out", out.to_str().unwrap(), "--force"]);
    assert_eq!(code, 0, "{err}");
    assert!(stdout.contains("drop_final -0.045,"), "{stdout}");
    assert!(stdout.contains("within 1e-12 absolute): met"), "{stdout}");
    assert!(stdout.contains("within 1e-9 relative): met"), "{stdout}");
    // ln(exp(t)) − t is round-off: shown as such, not as six zeros.
    let log_error = stdout.split("log_error ").nth(1).and_then(|r| r.split(',').next()).unwrap();
    assert!((log_error == "0" || log_error.contains("e-")) && log_error.parse::<f64>().unwrap() < 1e-12, "{stdout}");
    let csv = std::fs::read_to_string(out.join("series.csv")).unwrap();
    let last: Vec<f64> = csv.lines().last().unwrap().split(',').map(|v| v.parse().unwrap()).collect();
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let uy = last[header.iter().position(|h| *h == "uy").unwrap()];
    assert_eq!(uy.to_bits(), summary["drop_final"].as_f64().unwrap().to_bits());
    std::fs::remove_dir_all(&out).unwrap();
}

/// `check` on a problem file ends with one line saying what it bound.
#[test]
fn check_says_what_it_bound() {
    let (code, stdout, err) = signorini(&["check", "forms/problems/disc.wf"]);
    assert_eq!(code, 0, "{err}");
    let line = stdout.lines().last().unwrap();
    for part in ["problem `disc` checked and bound", "1261 nodes", "Gamma_C (30 facets)", "contact_nitsche (contact)"] {
        assert!(line.contains(part), "{part} in {line}");
    }
}

/// `check` on a problem file resolves the names its `expect ... when` lines read, as a run does:
/// a misspelt one is an error at it, not a surprise at the end of a run.
#[test]
fn check_finds_an_unknown_name_in_an_expectation_s_condition() {
    let dir = std::env::temp_dir().join(format!("signorini-check-when-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let disc = std::fs::read_to_string("forms/problems/disc.wf").unwrap();
    let bad =
        disc.replacen("    summary", "    expect first_contact = 6.34 within 0.01 when thetaa == 1\n    summary", 1);
    assert_ne!(bad, disc, "disc.wf has a summary line");
    let path = dir.join("disc_when.wf");
    std::fs::write(&path, bad).unwrap();
    let (code, _, err) = signorini(&["check", path.to_str().unwrap()]);
    assert_ne!(code, 0, "{err}");
    assert!(err.contains("unknown param `thetaa`") && err.contains("did you mean `theta`?"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}
