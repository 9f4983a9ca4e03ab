//! docs/tutorial.md works as written: its files (```wf file=NAME blocks) are written to a fresh
//! directory and every `signorini` line of its ```sh blocks runs there and succeeds. Its scheme
//! is the one the example crate (examples/user_scheme) compiles.

use std::path::Path;
use std::process::Command;

const TUTORIAL: &str = include_str!("../../docs/tutorial.md");

/// (info string, body) of every fenced block.
fn blocks(text: &str) -> Vec<(String, String)> {
    let mut out = Vec::new();
    let mut current: Option<(String, String)> = None;
    for line in text.lines() {
        match (&mut current, line.strip_prefix("```")) {
            (None, Some(info)) => current = Some((info.trim().to_string(), String::new())),
            (Some(_), Some(_)) => out.push(current.take().expect("open block")),
            (Some((_, body)), None) => {
                body.push_str(line);
                body.push('\n');
            }
            (None, None) => {}
        }
    }
    out
}

#[test]
fn every_command_of_the_tutorial_runs() {
    let dir = std::env::temp_dir().join(format!("signorini-tutorial-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let blocks = blocks(TUTORIAL);
    let mut files = 0;
    for (info, body) in &blocks {
        if let Some(name) = info.strip_prefix("wf file=") {
            std::fs::write(dir.join(name), body).unwrap();
            files += 1;
        }
    }
    let mut commands = 0;
    for (info, body) in blocks.iter().filter(|(i, _)| i == "sh") {
        for line in body.lines().filter(|l| l.starts_with("signorini ")) {
            let args: Vec<&str> = line.split_whitespace().skip(1).collect();
            let out = Command::new(env!("CARGO_BIN_EXE_signorini")).args(&args).current_dir(&dir).output().unwrap();
            assert!(
                out.status.success(),
                "`{line}` failed ({info}):\n{}{}",
                String::from_utf8_lossy(&out.stdout),
                String::from_utf8_lossy(&out.stderr)
            );
            commands += 1;
        }
    }
    assert!(files >= 3 && commands >= 12, "{files} files, {commands} commands");
    let example = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/user_scheme/wbz.wf");
    assert_eq!(std::fs::read_to_string(dir.join("wbz.wf")).unwrap(), std::fs::read_to_string(example).unwrap());
    let _ = std::fs::remove_dir_all(&dir);
}
