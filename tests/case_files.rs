//! Case files: a valid file runs and writes where it says; an unknown key, a key of the other
//! case, a bad name and an out-of-range value fail with the file and the key's line.

use std::process::Command;

fn signorini(args: &[&str]) -> (i32, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_signorini")).args(args).output().expect("the binary runs");
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
        "case = \"bar\"\nscheme = \"trbdf2\"\nmass = \"redistributed\"\nt_end = 1.5\nout = \"bar-out\"\n",
    );
    let (code, err) = signorini(&["run", path.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    let dir = path.parent().unwrap().join("bar-out");
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!(s["scheme"], "trbdf2");
    assert_eq!(s["mass"], "redistributed");
    assert_eq!(s["steps"], 150);
}

#[test]
fn mistakes_are_reported_with_their_line() {
    let cases = [
        ("unknown.toml", "case = \"bar\"\nscheme = \"hht\"\nthetta = 1\n", ":3: unknown field `thetta`"),
        ("range.toml", "case = \"bar\"\n\ntheta = 2\n", ":3: `theta`: 2 is not in [-1, 1]"),
        ("other_case.toml", "case = \"disc\"\nne = 5\n", ":2: `ne`: not an option of the disc case"),
        ("name.toml", "case = \"bar\"\nscheme = \"rk4\"\n", ":2: `scheme`: `rk4` is not one of"),
        (
            "alpha.toml",
            "case = \"bar\"\nscheme = \"midpoint\"\nalpha = 0.1\n",
            ":3: `alpha`: applies to the HHT schemes",
        ),
        ("type.toml", "case = \"disc\"\ndt = \"x\"\n", ":2: invalid type"),
        ("case.toml", "case = \"beam\"\n", ":1: `case`: `beam` is not a case"),
    ];
    for (name, text, want) in cases {
        let path = write(name, text);
        let (code, err) = signorini(&["run", path.to_str().unwrap()]);
        assert_eq!(code, 1, "{name}");
        assert!(err.contains(name) && err.contains(want), "{name}: expected `{want}` in `{err}`");
    }
}
