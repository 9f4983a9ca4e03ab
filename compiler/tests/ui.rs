//! Rendered diagnostics of a corpus of bad .wf files (tests/ui/*.wf), as insta snapshots.
//! Every file must produce at least one diagnostic, and together they must exercise every
//! diagnostic code the checker has.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use signorini_compiler::{FsLoader, check_file, render_all};

fn corpus() -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir("tests/ui")
        .expect("tests/ui exists")
        .map(|e| e.expect("readable entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "wf"))
        .collect();
    files.sort();
    files
}

#[test]
fn bad_files_render_their_diagnostics() {
    let files = corpus();
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
                (prog.warnings, r)
            }
        };
        assert!(!diags.is_empty(), "{} produced no diagnostic", path.display());
        codes.extend(diags.iter().map(|d| d.code));
        let name = path.file_stem().unwrap().to_string_lossy().into_owned();
        insta::with_settings!({ snapshot_path => "snapshots/ui", prepend_module_to_snapshot => false, description => source_of(path) }, {
            insta::assert_snapshot!(name, rendered);
        });
    }
    let expected = [
        "E0001", "E0002", "E0101", "E0102", "E0103", "E0104", "E0105", "E0106", "E0201", "E0204", "E0205", "E0206",
        "E0301", "E0303", "E0304", "E0401", "E0402", "E0403", "E0404", "E0405", "E0501", "E0502", "E0601", "E0602",
        "E0603", "E0701", "E0702", "E0802", "E0806", "E0811", "E0813", "E0814", "E0816", "E0817", "W0001",
    ];
    for code in expected {
        assert!(codes.contains(code), "no corpus file exercises {code}");
    }
}

fn source_of(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_default()
}
