//! The README's commands run as pasted on a fresh clone: every file they name is one the
//! repository ships, and the quick ones (`list`, `check`, `mesh info`, `emit`) succeed.

use std::path::Path;
use std::process::Command;

/// The arguments of each `cargo run --release -- ...` line of the README, its comment cut and
/// its globs (`forms/*.wf`) expanded as a shell would.
fn commands() -> Vec<Vec<String>> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let readme = std::fs::read_to_string(root.join("README.md")).unwrap();
    readme
        .lines()
        .filter_map(|l| l.trim().strip_prefix("cargo run --release -- "))
        .map(|line| {
            let command = line.split(" # ").next().unwrap_or(line);
            command.split_whitespace().flat_map(|word| expand(root, word)).collect()
        })
        .collect()
}

fn expand(root: &Path, word: &str) -> Vec<String> {
    let Some((dir, pattern)) = word.rsplit_once('/').filter(|(_, p)| p.starts_with('*')) else {
        return vec![word.to_string()];
    };
    let ext = pattern.trim_start_matches('*');
    let mut files: Vec<String> = std::fs::read_dir(root.join(dir))
        .unwrap_or_else(|e| panic!("the README's {word}: {e}"))
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(ext))
        .map(|n| format!("{dir}/{n}"))
        .collect();
    files.sort();
    files
}

#[test]
fn every_file_the_readme_names_is_shipped() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let commands = commands();
    assert!(commands.len() > 20, "the README's commands were not found");
    for c in &commands {
        for word in c {
            let input = [".wf", ".msh", ".toml", ".geo"].iter().any(|e| word.ends_with(e));
            if input && !word.starts_with("results/") {
                assert!(
                    root.join(word).is_file(),
                    "`{}` names {word}, which the repository does not ship",
                    c.join(" ")
                );
            }
        }
    }
}

#[test]
fn the_readme_s_quick_commands_succeed() {
    let quick = ["list", "check", "mesh", "emit"];
    let mut ran = 0;
    for c in commands().iter().filter(|c| c.first().is_some_and(|s| quick.contains(&s.as_str()))) {
        let out = Command::new(env!("CARGO_BIN_EXE_signorini"))
            .args(c)
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .output()
            .expect("the binary runs");
        assert!(out.status.success(), "`{}` failed:\n{}", c.join(" "), String::from_utf8_lossy(&out.stderr));
        ran += 1;
    }
    assert!(ran >= 4, "only {ran} quick commands found");
}
