//! Writes the Rust generated for every `.wf` file of `forms/` and `forms/schemes/` into
//! `OUT_DIR`, as `signorini emit --stage rust` prints it (and the snapshots record it), and
//! `generated.rs`, which includes them all and lists their units; and `fixtures.rs`, the same
//! for the test files of `FIXTURES`.

use std::fmt::Write;
use std::path::{Path, PathBuf};

use signorini_compiler::{FsLoader, Stage, compile, module_name};

fn main() {
    let forms = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../forms");
    println!("cargo::rerun-if-changed={}", forms.display());
    let out = PathBuf::from(std::env::var("OUT_DIR").expect("cargo sets OUT_DIR"));
    let mut files: Vec<PathBuf> = Vec::new();
    for dir in [forms.clone(), forms.join("schemes")] {
        let entries = std::fs::read_dir(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
        files.extend(
            entries.map(|e| e.expect("a readable entry").path()).filter(|p| p.extension().is_some_and(|e| e == "wf")),
        );
    }
    files.sort();
    let mut list = String::new();
    let mut units = Vec::new();
    for f in &files {
        let compiled = compile(f, &FsLoader).unwrap_or_else(|e| panic!("{}:\n{e}", f.display()));
        let code = compiled.print(Stage::Rust, 2).unwrap_or_else(|e| panic!("{}:\n{e}", f.display()));
        let module = module_name(f);
        std::fs::write(out.join(format!("{module}.rs")), code).expect("OUT_DIR is writable");
        let _ = writeln!(list, "include!(concat!(env!(\"OUT_DIR\"), \"/{module}.rs\"));");
        units.push(format!("&{module}::UNIT"));
    }
    let _ = writeln!(
        list,
        "/// The unit of every file, in the order of their paths.\npub static UNITS: &[&::signorini::runtime::library::Unit] = &[{}];",
        units.join(", ")
    );
    std::fs::write(out.join("generated.rs"), list).expect("OUT_DIR is writable");
    // Files outside the library that exercise parts of the language it does not use yet.
    let mut fixtures = String::new();
    for f in FIXTURES {
        let path = forms.join("..").join(f);
        println!("cargo::rerun-if-changed={}", path.display());
        let compiled = compile(&path, &FsLoader).unwrap_or_else(|e| panic!("{}:\n{e}", path.display()));
        let code = compiled.print(Stage::Rust, 2).unwrap_or_else(|e| panic!("{}:\n{e}", path.display()));
        let module = module_name(&path);
        std::fs::write(out.join(format!("fixture_{module}.rs")), code).expect("OUT_DIR is writable");
        let _ = writeln!(fixtures, "include!(concat!(env!(\"OUT_DIR\"), \"/fixture_{module}.rs\"));");
    }
    std::fs::write(out.join("fixtures.rs"), fixtures).expect("OUT_DIR is writable");
}

/// Test files (paths from the repository's root) whose generated Rust is compiled here too.
const FIXTURES: &[&str] = &["tests/problems/transcendental.wf"];
