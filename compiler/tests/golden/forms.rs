//! Snapshots of every stage for every file of the form library (`forms/`): the AST, the IR in
//! 2D, and the generated Rust (whose first line records its length in lines).

use std::path::{Path, PathBuf};

use signorini_compiler::{FsLoader, Stage, compile};

fn library() -> Vec<PathBuf> {
    let mut files = Vec::new();
    for dir in ["../forms", "../forms/schemes"] {
        let Ok(entries) = std::fs::read_dir(dir) else {
            continue;
        };
        files.extend(
            entries.map(|e| e.expect("readable entry").path()).filter(|p| p.extension().is_some_and(|e| e == "wf")),
        );
    }
    files.sort();
    files
}

fn stem(p: &Path) -> String {
    p.file_stem().unwrap().to_string_lossy().into_owned()
}

#[test]
fn library_compiles_without_warnings() {
    let files = library();
    assert!(files.len() >= 3);
    for f in &files {
        let compiled = compile(f, &FsLoader).unwrap_or_else(|e| panic!("{}:\n{e}", f.display()));
        assert!(compiled.warnings.is_empty(), "{}:\n{}", f.display(), compiled.warnings);
    }
}

#[test]
fn generated_rust_snapshots() {
    for f in library() {
        let compiled = compile(&f, &FsLoader).unwrap();
        let code = compiled.print(Stage::Rust, 2).unwrap();
        insta::with_settings!({ snapshot_path => "../snapshots/rust", prepend_module_to_snapshot => false }, {
            insta::assert_snapshot!(stem(&f), code);
        });
    }
}

#[test]
fn ast_ir_and_scheme_snapshots() {
    for f in library() {
        let compiled = compile(&f, &FsLoader).unwrap();
        let ast_text = compiled.print(Stage::Ast, 2).unwrap();
        let ir_text = compiled.print(Stage::Ir, 2).unwrap();
        let schemes = compiled.print(Stage::Scheme, 2).unwrap();
        insta::with_settings!({ snapshot_path => "../snapshots/stages", prepend_module_to_snapshot => false }, {
            insta::assert_snapshot!(format!("{}.ast", stem(&f)), ast_text);
            insta::assert_snapshot!(format!("{}.ir2d", stem(&f)), ir_text);
            if !compiled.schemes().is_empty() {
                insta::assert_snapshot!(format!("{}.scheme", stem(&f)), schemes);
                // The energy identity, or the located reason there is none.
                let energy = compiled.print(Stage::Energy, 2).unwrap_or_else(|f| f.rendered);
                insta::assert_snapshot!(format!("{}.energy", stem(&f)), energy);
            }
        });
    }
}

/// The library's problems (`forms/problems/`): each checks clean, and its AST as printed (what
/// the binding of a run reads) is a snapshot a reviewer reads.
#[test]
fn library_problems_check_clean_and_print() {
    let Ok(entries) = std::fs::read_dir("../forms/problems") else { panic!("forms/problems is missing") };
    let mut files: Vec<PathBuf> = entries
        .map(|e| e.expect("readable entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "wf"))
        .collect();
    files.sort();
    assert!(!files.is_empty());
    for f in &files {
        let compiled = compile(f, &FsLoader).unwrap_or_else(|e| panic!("{}:\n{e}", f.display()));
        assert!(compiled.warnings.is_empty(), "{}:\n{}", f.display(), compiled.warnings);
        assert!(compiled.program.unit.problems.len() == 1, "{}: one problem per file", f.display());
        let ast = compiled.print(Stage::Ast, 2).unwrap();
        insta::with_settings!({ snapshot_path => "../snapshots/problems", prepend_module_to_snapshot => false }, {
            insta::assert_snapshot!(format!("{}.ast", stem(f)), ast);
        });
    }
}

/// A problem whose pairs have blocks of their own (a law, params): the printed AST keeps each
/// block under its pair.
#[test]
fn pair_blocks_print() {
    let f = PathBuf::from("../tests/problems/stack_on_foundation.wf");
    let compiled = compile(&f, &FsLoader).unwrap_or_else(|e| panic!("{}:\n{e}", f.display()));
    let ast = compiled.print(Stage::Ast, 2).unwrap();
    insta::with_settings!({ snapshot_path => "../snapshots/problems", prepend_module_to_snapshot => false }, {
        insta::assert_snapshot!("stack_on_foundation.ast", ast);
    });
}
