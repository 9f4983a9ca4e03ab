//! Result files are written whole or not at all: to a temporary name in the same directory,
//! then renamed over the target.

use std::io::Write;
use std::path::{Path, PathBuf};

/// The file that marks a directory as one of our runs' outputs (and proves it writable).
pub const MARKER: &str = ".signorini-output";

/// Where a run writes, decided before it computes anything: `dir` itself if it is new or
/// empty; with `force`, `dir` emptied if it holds an earlier run of ours (never a directory we
/// did not write); otherwise the first free `dir/run-N`, so that results of two runs never mix.
/// The directory is created and written to (the marker) here: an unwritable `--out` fails now,
/// not after the computation. Returns the directory and, if it is not `dir`, a note saying so.
pub fn prepare(dir: &Path, force: bool) -> Result<(PathBuf, Option<String>), String> {
    let cannot = |d: &Path, e: std::io::Error| format!("cannot write to {}: {e}", d.display());
    let entries = match std::fs::read_dir(dir) {
        Ok(list) => list.filter_map(Result::ok).map(|e| e.file_name()).filter(|n| n != MARKER).collect::<Vec<_>>(),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Vec::new(),
        Err(e) => return Err(cannot(dir, e)),
    };
    let ours = dir.join(MARKER).is_file();
    let (target, note) = if entries.is_empty() {
        (dir.to_path_buf(), None)
    } else if force && ours {
        std::fs::remove_dir_all(dir).map_err(|e| cannot(dir, e))?;
        (dir.to_path_buf(), None)
    } else if force {
        return Err(format!(
            "{} is not empty and was not written by signorini (no {MARKER}): not removing it; choose another --out",
            dir.display()
        ));
    } else {
        let fresh = (2..).map(|n| dir.join(format!("run-{n}"))).find(|d| !d.exists()).expect("unbounded");
        let note = format!(
            "{} holds {}: writing to {} (--force replaces {})",
            dir.display(),
            if ours { "an earlier run" } else { "other files" },
            fresh.display(),
            if ours { "it" } else { "nothing that signorini did not write" }
        );
        (fresh, Some(note))
    };
    std::fs::create_dir_all(&target).map_err(|e| cannot(&target, e))?;
    write_atomic(&target.join(MARKER), b"written by signorini; `--force` may replace this directory\n")
        .map_err(|e| cannot(&target, e))?;
    Ok((target, note))
}

/// Writes `bytes` to `path` atomically (creating the directory if needed).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let dir = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir)?;
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let tmp = dir.join(format!(".{name}.{}.tmp", std::process::id()));
    let result = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// Serialises `value` as pretty JSON into `path`, atomically. JSON has no NaN or infinity
/// (serde writes them as null): such fields are left out, and a top-level `omitted` list
/// names them, so that a reader never meets a null standing for a number.
pub fn write_json(path: &Path, value: &impl serde::Serialize) -> std::io::Result<()> {
    let mut value = serde_json::to_value(value).map_err(std::io::Error::other)?;
    let mut omitted = Vec::new();
    drop_nulls(&mut value, "", &mut omitted);
    if let (serde_json::Value::Object(map), false) = (&mut value, omitted.is_empty()) {
        let note = format!("undefined in this run (no value, or not a finite number): {}", omitted.join(", "));
        map.insert("omitted".into(), serde_json::Value::String(note));
    }
    let mut text = serde_json::to_string_pretty(&value).map_err(std::io::Error::other)?;
    text.push('\n');
    write_atomic(path, text.as_bytes())
}

/// Removes null members of objects (recursively), collecting their dotted paths.
fn drop_nulls(value: &mut serde_json::Value, path: &str, omitted: &mut Vec<String>) {
    let join = |key: &str| if path.is_empty() { key.to_string() } else { format!("{path}.{key}") };
    match value {
        serde_json::Value::Object(map) => {
            map.retain(|key, v| {
                let keep = !v.is_null();
                if !keep {
                    omitted.push(join(key));
                }
                keep
            });
            for (key, v) in map.iter_mut() {
                drop_nulls(v, &join(key), omitted);
            }
        }
        serde_json::Value::Array(items) => {
            for (i, v) in items.iter_mut().enumerate() {
                drop_nulls(v, &join(&i.to_string()), omitted);
            }
        }
        _ => {}
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_second_run_never_mixes_with_the_first() {
        let root = std::env::temp_dir().join(format!("signorini-prepare-{}", std::process::id()));
        let (first, note) = super::prepare(&root, false).unwrap();
        assert_eq!((first.as_path(), note), (root.as_path(), None));
        std::fs::write(root.join("series.csv"), "t\n").unwrap();
        // Occupied: a fresh subdirectory, said so.
        let (second, note) = super::prepare(&root, false).unwrap();
        assert_eq!(second, root.join("run-2"));
        assert!(note.unwrap().contains("an earlier run"));
        // --force replaces our earlier run entirely.
        let (forced, _) = super::prepare(&root, true).unwrap();
        assert_eq!(forced, root);
        assert!(!root.join("series.csv").exists() && !root.join("run-2").exists());
        // A directory we did not write is never removed.
        let foreign = root.join("foreign");
        std::fs::create_dir_all(&foreign).unwrap();
        std::fs::write(foreign.join("thesis.tex"), "").unwrap();
        assert!(super::prepare(&foreign, true).unwrap_err().contains("not removing"));
        assert!(foreign.join("thesis.tex").exists());
        std::fs::remove_dir_all(&root).unwrap();
    }

    #[test]
    fn an_unwritable_directory_is_an_error_before_any_work() {
        // A path below a regular file cannot be created.
        let file = std::env::temp_dir().join(format!("signorini-plain-{}", std::process::id()));
        std::fs::write(&file, "").unwrap();
        let err = super::prepare(&file.join("out"), false).unwrap_err();
        assert!(err.starts_with("cannot write to"), "{err}");
        std::fs::remove_file(&file).unwrap();
    }

    #[test]
    fn non_finite_numbers_are_left_out_and_named() {
        #[derive(serde::Serialize)]
        struct Inner {
            c: f64,
        }
        #[derive(serde::Serialize)]
        struct S {
            a: f64,
            b: f64,
            inner: Vec<Inner>,
        }
        let dir = std::env::temp_dir().join(format!("signorini-output-{}", std::process::id()));
        let path = dir.join("s.json");
        super::write_json(&path, &S { a: 1.0, b: f64::NAN, inner: vec![Inner { c: 2.0 }, Inner { c: f64::INFINITY }] })
            .unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
        let v: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert_eq!(v["a"], 1.0);
        assert!(v.get("b").is_none(), "{text}");
        assert!(!text.contains("null"), "{text}");
        assert_eq!(v["inner"][0]["c"], 2.0);
        assert_eq!(v["omitted"], "undefined in this run (no value, or not a finite number): b, inner.1.c");
    }
}
