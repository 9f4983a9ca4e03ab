//! Rendered diagnostics of a corpus of bad .wf files (tests/ui/*.wf), as insta snapshots.
//! Every file must produce at least one diagnostic, and together they must exercise every code
//! of the catalogue (`diagnostic::CODES`), which must list every code in the compiler's source
//! and match the table in docs/language.md.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use signorini_compiler::diagnostic::{BINDING_CODES, CODES, STAGE_CODES};
use signorini_compiler::{FsLoader, check_file, render_all};

fn files_in(dir: &str, ext: &str) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{dir}: {e}"))
        .map(|e| e.expect("readable entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == ext))
        .collect();
    files.sort();
    files
}

#[test]
fn bad_files_render_their_diagnostics() {
    let files = files_in("tests/ui", "wf");
    assert!(files.len() >= 25, "the corpus has {} files", files.len());
    let mut codes = BTreeSet::new();
    for path in &files {
        let (diags, rendered) = match check_file(path, &FsLoader).expect("corpus files are readable") {
            Err((diags, sources)) => {
                let r = render_all(&diags, &sources);
                (diags, r)
            }
            Ok(prog) => {
                let r = render_all(&prog.warnings, &prog.sources);
                (prog.unit.warnings, r)
            }
        };
        assert!(!diags.is_empty(), "{} produced no diagnostic", path.display());
        codes.extend(diags.iter().map(|d| d.code));
        let name = path.file_stem().unwrap().to_string_lossy().into_owned();
        insta::with_settings!({ snapshot_path => "../snapshots/ui", prepend_module_to_snapshot => false, description => source_of(path) }, {
            insta::assert_snapshot!(name, rendered);
        });
    }
    let missing: Vec<&str> = CODES
        .iter()
        .map(|(c, _)| *c)
        .filter(|c| !codes.contains(c) && !BINDING_CODES.contains(c) && !STAGE_CODES.contains(c))
        .collect();
    assert!(missing.is_empty(), "no corpus file exercises {missing:?}");
}

/// Every `"E0123"`/`"W0123"` literal in the compiler's source is in the catalogue, and every
/// catalogue code is in the source.
#[test]
fn the_catalogue_lists_exactly_the_codes_of_the_source() {
    let mut in_source = BTreeSet::new();
    let mut dirs = vec![PathBuf::from("src")];
    while let Some(dir) = dirs.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let p = entry.unwrap().path();
            if p.is_dir() {
                dirs.push(p);
            } else if p.extension().is_some_and(|e| e == "rs") && !p.ends_with("diagnostic.rs") {
                in_source.extend(code_literals(&std::fs::read_to_string(&p).unwrap()));
            }
        }
    }
    let catalogue: BTreeSet<String> = CODES.iter().map(|(c, _)| c.to_string()).collect();
    assert_eq!(in_source, catalogue);
}

/// The docs name every built-in function of the table: docs/language.md those of every
/// expression, docs/problems.md those of a problem's numbers (`ceil`, `floor`).
#[test]
fn the_docs_name_every_builtin_function() {
    let language = std::fs::read_to_string("../docs/language.md").unwrap();
    let problems = std::fs::read_to_string("../docs/problems.md").unwrap();
    for b in signorini_compiler::check::BUILTINS {
        let docs = if b.numbers_only { &problems } else { &language };
        let named = docs.contains(&format!("`{}`", b.name)) || docs.contains(&format!("`{}(", b.name));
        assert!(named, "the docs do not name `{}` ({})", b.name, b.doc);
    }
}

/// docs/language.md has one table row `| CODE | meaning |` per catalogue entry, and no other
/// code.
#[test]
fn the_language_docs_list_the_catalogue() {
    let docs = std::fs::read_to_string("../docs/language.md").unwrap();
    for (code, meaning) in CODES {
        assert!(docs.contains(&format!("| {code} | {meaning} |")), "docs/language.md lacks `| {code} | {meaning} |`");
    }
    let catalogue: BTreeSet<String> = CODES.iter().map(|(c, _)| c.to_string()).collect();
    let in_docs: BTreeSet<String> = words(&docs).filter(|w| is_code(w)).collect();
    assert_eq!(in_docs, catalogue);
}

fn words(text: &str) -> impl Iterator<Item = String> + '_ {
    text.split(|c: char| !c.is_ascii_alphanumeric()).map(str::to_string)
}

fn is_code(w: &str) -> bool {
    w.len() == 5 && (w.starts_with('E') || w.starts_with('W')) && w[1..].bytes().all(|b| b.is_ascii_digit())
}

fn code_literals(text: &str) -> Vec<String> {
    text.split('"').filter(|w| is_code(w)).map(str::to_string).collect()
}

fn source_of(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_default()
}
