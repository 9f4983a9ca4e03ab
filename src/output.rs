//! Result files are written whole or not at all: to a temporary name in the same directory,
//! then renamed over the target.

use std::io::Write;
use std::path::Path;

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
