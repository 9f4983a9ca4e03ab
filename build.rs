//! Discovers the form library: every `.wf` file under `forms/` becomes a compiled module
//! (`signorini::forms!`), and `LIBRARY` lists their units. Adding a file and rebuilding is the
//! whole job of adding a scheme or a contact law.

use std::fmt::Write;
use std::path::{Path, PathBuf};

use signorini_compiler::{Compiled, FsLoader, Loader, compile};

/// Reads the file system, with one file bound to one role.
struct Bound<'a> {
    role: &'a str,
    file: PathBuf,
}

impl Loader for Bound<'_> {
    fn load(&self, path: &Path) -> std::io::Result<String> {
        FsLoader.load(path)
    }
    fn role(&self, role: &str) -> Option<PathBuf> {
        (role == self.role).then(|| self.file.clone())
    }
}

/// The bindings compiled in: for each form file that imports a role (`import material =
/// elasticity`), each other form file of the library that does not import the role's default
/// file itself (a law built on `elasticity` is not a stand-in for it) and with which the
/// importing file checks (role, bound file stem, importing file stem). A run that binds such a
/// file (`--material neo_hookean`) runs the law compiled; any other binding (a user's
/// material) compiles it at run time, interpreted.
fn bindings(forms: &[String]) -> Vec<(String, String, String)> {
    let path = |f: &str| PathBuf::from(format!("forms/{f}.wf"));
    let units: Vec<(&String, Compiled)> =
        forms.iter().filter_map(|f| Some((f, compile(&path(f), &FsLoader).ok()?))).collect();
    let imports = |c: &Compiled, stem: &str| c.source_paths().iter().any(|p| p.file_stem().is_some_and(|s| s == stem));
    let mut out = Vec::new();
    for (law, unit) in &units {
        for role in &unit.program.roles {
            for (file, candidate) in &units {
                let stands_in = file != law && **file != role.default && !imports(candidate, &role.default);
                if stands_in && compile(&path(law), &Bound { role: &role.name, file: path(file) }).is_ok() {
                    out.push((role.name.clone(), file.to_string(), law.to_string()));
                }
            }
        }
    }
    out.sort();
    out
}

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
    // The role bindings compiled in, one module per bound file.
    let bound = bindings(&forms);
    out.push_str(
        "/// The library's laws compiled with another of its files bound to a role they import, by\n/// role and bound file: `bound::material_neo_hookean::contact_nitsche_deformed`.\npub mod bound {\n",
    );
    let mut groups: Vec<(&str, &str)> = bound.iter().map(|(r, f, _)| (r.as_str(), f.as_str())).collect();
    groups.dedup();
    for (role, file) in groups {
        let _ = writeln!(out, "pub mod {role}_{file} {{");
        for (_, _, law) in bound.iter().filter(|(r, f, _)| r == role && f == file) {
            let _ = writeln!(out, "crate::forms!(pub mod {law} = \"forms/{law}.wf\", {role} = \"forms/{file}.wf\");");
        }
        out.push_str("}\n");
    }
    out.push_str("}\n");
    let bound_units: Vec<String> =
        bound.iter().map(|(role, file, law)| format!("&bound::{role}_{file}::{law}::UNIT")).collect();
    let _ = writeln!(
        out,
        "/// Every unit of `bound`: a law of the library as compiled for a file bound to its role.\npub static BOUND: &[&crate::runtime::library::Unit] = &[{}];",
        bound_units.join(", ")
    );
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
    let pairs = wf_files(Path::new("forms/pairs"));
    let pair_texts: Vec<String> = pairs
        .iter()
        .map(|s| format!("(\"{s}\", include_str!(concat!(env!(\"CARGO_MANIFEST_DIR\"), \"/forms/pairs/{s}.wf\")))"))
        .collect();
    let _ = writeln!(
        out,
        "/// The text of every contact pair law of `forms/pairs/`, by file stem: interpreted at run time\n/// (a law that reads `opposite` is evaluated at the facing points, not generated).\npub static PAIR_SOURCES: &[(&str, &str)] = &[{}];",
        pair_texts.join(", ")
    );
    let shared = wf_files(Path::new("forms/pairs/shared"));
    let shared_texts: Vec<String> = shared
        .iter()
        .map(|s| {
            format!("(\"{s}.wf\", include_str!(concat!(env!(\"CARGO_MANIFEST_DIR\"), \"/forms/pairs/shared/{s}.wf\")))")
        })
        .collect();
    let _ = writeln!(
        out,
        "/// The text of the files the pair laws import (`forms/pairs/shared/`), by file name, so that\n/// their imports resolve wherever the binary runs.\npub static PAIR_SHARED_SOURCES: &[(&str, &str)] = &[{}];",
        shared_texts.join(", ")
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
