//! Discovers the form library: every `.wf` file under `forms/` becomes a compiled module
//! (`signorini::forms!`), and `LIBRARY` lists their units. Adding a file and rebuilding is the
//! whole job of adding a scheme or a contact law.

use std::fmt::Write;
use std::path::Path;

fn wf_files(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .map(|entries| {
            entries
                .filter_map(Result::ok)
                .map(|e| e.path())
                .filter(|p| p.extension().is_some_and(|e| e == "wf"))
                .filter_map(|p| p.file_stem().map(|s| s.to_string_lossy().into_owned()))
                .filter(|s| {
                    s.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
                        && !s.starts_with(|c: char| c.is_ascii_digit())
                })
                .collect()
        })
        .unwrap_or_default();
    names.sort();
    names
}

fn main() {
    println!("cargo::rerun-if-changed=forms");
    let forms = wf_files(Path::new("forms"));
    let schemes = wf_files(Path::new("forms/schemes"));
    let mut out = String::new();
    for f in &forms {
        let _ = writeln!(out, "crate::forms!(pub mod {f} = \"forms/{f}.wf\");");
    }
    out.push_str("/// The time schemes of `forms/schemes/`, one module each.\npub mod schemes {\n");
    for s in &schemes {
        let _ = writeln!(out, "crate::forms!(pub mod {s} = \"forms/schemes/{s}.wf\");");
    }
    out.push_str("}\n");
    let units: Vec<String> = forms
        .iter()
        .map(|f| format!("&{f}::UNIT"))
        .chain(schemes.iter().map(|s| format!("&schemes::{s}::UNIT")))
        .collect();
    let _ = writeln!(
        out,
        "/// Every unit of `forms/`: form files first, then schemes, each sorted by name.\npub static LIBRARY: &[&crate::runtime::library::Unit] = &[{}];",
        units.join(", ")
    );
    let texts: Vec<String> = forms
        .iter()
        .map(|f| format!("(\"{f}.wf\", include_str!(concat!(env!(\"CARGO_MANIFEST_DIR\"), \"/forms/{f}.wf\")))"))
        .collect();
    let _ = writeln!(
        out,
        "/// The text of every form file of `forms/`, so that `import elasticity` in a file run by path\n/// finds the library's file wherever the binary runs.\npub static SOURCES: &[(&str, &str)] = &[{}];",
        texts.join(", ")
    );
    let scheme_texts: Vec<String> = schemes
        .iter()
        .map(|s| format!("(\"{s}\", include_str!(concat!(env!(\"CARGO_MANIFEST_DIR\"), \"/forms/schemes/{s}.wf\")))"))
        .collect();
    let _ = writeln!(
        out,
        "/// The text of every scheme file of `forms/schemes/`, by file stem: `verify --scheme` reads\n/// the claims (`claim order = 2`) from it.\npub static SCHEME_SOURCES: &[(&str, &str)] = &[{}];",
        scheme_texts.join(", ")
    );
    let problems = wf_files(Path::new("forms/problems"));
    let problem_texts: Vec<String> = problems
        .iter()
        .map(|s| format!("(\"{s}\", include_str!(concat!(env!(\"CARGO_MANIFEST_DIR\"), \"/forms/problems/{s}.wf\")))"))
        .collect();
    let _ = writeln!(
        out,
        "/// The text of every problem file of `forms/problems/`, by file stem: `run NAME` compiles it at\n/// run time (a problem's expressions are evaluated at points, not generated).\npub static PROBLEM_SOURCES: &[(&str, &str)] = &[{}];",
        problem_texts.join(", ")
    );
    let path = Path::new(&std::env::var("OUT_DIR").expect("cargo sets OUT_DIR")).join("library.rs");
    std::fs::write(&path, out).expect("OUT_DIR is writable");
}
