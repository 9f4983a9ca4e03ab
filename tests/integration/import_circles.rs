//! No two source files of a crate import each other, directly or around a circle: layers
//! import downwards only (docs/architecture.md). The dependencies are read from the source
//! text: every `crate::a::b` and `super::a` path outside comments and test modules, resolved
//! to the file of the longest module prefix. A path into a module's own ancestors (a child
//! naming its parent's items) is not counted: the parent is the child's namespace.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The crates' source roots, relative to the workspace.
const CRATES: [&str; 6] =
    ["src", "runtime/src", "compiler/src", "compiler/macros/src", "compiler/generated/src", "descriptors/src"];

type Module = Vec<String>;

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<_> = std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().path()).collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
}

/// `a/b.rs` is module `[a, b]`; `a/mod.rs` and `lib.rs`/`main.rs` name their folder.
fn module_of(root: &Path, file: &Path) -> Module {
    let rel = file.strip_prefix(root).unwrap().with_extension("");
    let mut parts: Module = rel.iter().map(|s| s.to_string_lossy().into_owned()).collect();
    if matches!(parts.last().map(String::as_str), Some("lib" | "main" | "mod")) {
        parts.pop();
    }
    parts
}

/// The code of a file without comments, string literals and `#[cfg(test)]` items (tests may
/// use any layer to build their inputs).
fn code(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let b = text.as_bytes();
    let mut i = 0;
    while i < b.len() {
        if text[i..].starts_with("//") {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
        } else if text[i..].starts_with("/*") {
            i += text[i..].find("*/").map_or(b.len() - i, |k| k + 2);
        } else if b[i] == b'"' {
            i += 1;
            while i < b.len() && b[i] != b'"' {
                i += if b[i] == b'\\' { 2 } else { 1 };
            }
            i += 1;
        } else if text[i..].starts_with("#[cfg(test)]") {
            // Skip the attribute and the item after it: up to its closing brace or semicolon.
            i += "#[cfg(test)]".len();
            let mut depth = 0usize;
            while i < b.len() {
                match b[i] {
                    b'{' => depth += 1,
                    b'}' => {
                        depth -= 1;
                        if depth == 0 {
                            i += 1;
                            break;
                        }
                    }
                    b';' if depth == 0 => {
                        i += 1;
                        break;
                    }
                    _ => {}
                }
                i += 1;
            }
        } else {
            let c = text[i..].chars().next().unwrap();
            out.push(c);
            i += c.len_utf8();
        }
    }
    out
}

/// Each `crate::…`, `super::…` or `self::…` path in `code`, as its segments after the keyword
/// resolved against `module` (the file's own module).
fn paths(code: &str, module: &Module) -> Vec<Module> {
    let mut found = Vec::new();
    let ident = |c: char| c.is_alphanumeric() || c == '_';
    let bytes: Vec<char> = code.chars().collect();
    let mut i = 0;
    while i < bytes.len() {
        let start = i;
        while i < bytes.len() && ident(bytes[i]) {
            i += 1;
        }
        if i == start {
            i += 1;
            continue;
        }
        if start > 0 && (ident(bytes[start - 1]) || bytes[start - 1] == ':') {
            continue;
        }
        let word: String = bytes[start..i].iter().collect();
        let mut base = match word.as_str() {
            "crate" => Vec::new(),
            "self" => module.clone(),
            "super" => module[..module.len().saturating_sub(1)].to_vec(),
            _ => continue,
        };
        let mut j = i;
        loop {
            if !(j + 1 < bytes.len() && bytes[j] == ':' && bytes[j + 1] == ':') {
                break;
            }
            j += 2;
            let s = j;
            while j < bytes.len() && ident(bytes[j]) {
                j += 1;
            }
            if s == j {
                break;
            }
            let seg: String = bytes[s..j].iter().collect();
            if seg == "super" {
                base.pop();
            } else {
                base.push(seg);
            }
        }
        found.push(base);
        i = j.max(i);
    }
    found
}

/// The circles of one crate: its strongly connected components of more than one file.
fn circles(root: &Path) -> Vec<Vec<String>> {
    let mut files = Vec::new();
    rust_files(root, &mut files);
    let modules: BTreeMap<Module, PathBuf> = files.iter().map(|f| (module_of(root, f), f.clone())).collect();
    let resolve = |p: &Module| (0..=p.len()).rev().map(|n| p[..n].to_vec()).find(|m| modules.contains_key(m));
    let mut edges: BTreeMap<Module, BTreeSet<Module>> = BTreeMap::new();
    for (m, f) in &modules {
        let text = std::fs::read_to_string(f).unwrap();
        let targets = edges.entry(m.clone()).or_default();
        for p in paths(&code(&text), m) {
            if let Some(t) = resolve(&p)
                && !m.starts_with(&t)
            {
                targets.insert(t);
            }
        }
    }
    // Tarjan's strongly connected components.
    struct State<'e> {
        edges: &'e BTreeMap<Module, BTreeSet<Module>>,
        index: BTreeMap<Module, usize>,
        low: BTreeMap<Module, usize>,
        stack: Vec<Module>,
        on: BTreeSet<Module>,
        found: Vec<Vec<Module>>,
    }
    fn visit(s: &mut State, v: &Module) {
        let n = s.index.len();
        s.index.insert(v.clone(), n);
        s.low.insert(v.clone(), n);
        s.stack.push(v.clone());
        s.on.insert(v.clone());
        for w in s.edges.get(v).into_iter().flatten() {
            if !s.index.contains_key(w) {
                visit(s, w);
                let lw = s.low[w];
                let lv = s.low.get_mut(v).unwrap();
                *lv = (*lv).min(lw);
            } else if s.on.contains(w) {
                let iw = s.index[w];
                let lv = s.low.get_mut(v).unwrap();
                *lv = (*lv).min(iw);
            }
        }
        if s.low[v] == s.index[v] {
            let mut comp = Vec::new();
            loop {
                let w = s.stack.pop().unwrap();
                s.on.remove(&w);
                let done = &w == v;
                comp.push(w);
                if done {
                    break;
                }
            }
            if comp.len() > 1 {
                s.found.push(comp);
            }
        }
    }
    let mut s = State {
        edges: &edges,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on: BTreeSet::new(),
        found: Vec::new(),
    };
    for m in modules.keys() {
        if !s.index.contains_key(m) {
            visit(&mut s, m);
        }
    }
    s.found
        .into_iter()
        .map(|comp| {
            let mut names: Vec<String> = comp.iter().map(|m| modules[m].display().to_string()).collect();
            names
                .iter_mut()
                .for_each(|n| *n = n.replace(env!("CARGO_MANIFEST_DIR"), "").trim_start_matches('/').to_string());
            names.sort();
            names
        })
        .collect()
}

#[test]
fn no_source_file_imports_one_that_imports_it_back() {
    let workspace = Path::new(env!("CARGO_MANIFEST_DIR"));
    let found: Vec<String> =
        CRATES.iter().flat_map(|c| circles(&workspace.join(c))).map(|names| names.join(" <-> ")).collect();
    assert!(found.is_empty(), "import circles between files:\n{}", found.join("\n"));
}

/// The reader finds a circle when there is one (so that the test above can fail).
#[test]
fn a_circle_is_found() {
    let dir = std::env::temp_dir().join(format!("signorini-circles-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("a")).unwrap();
    std::fs::write(dir.join("lib.rs"), "mod a;\nmod b;\n").unwrap();
    std::fs::write(dir.join("a/mod.rs"), "// crate::b in a comment does not count\npub mod c;\n").unwrap();
    std::fs::write(dir.join("a/c.rs"), "use crate::b::Thing;\n").unwrap();
    std::fs::write(dir.join("b.rs"), "pub struct Thing;\nfn f() { crate::a::c::g(); }\n").unwrap();
    let found = circles(&dir);
    std::fs::remove_dir_all(&dir).unwrap();
    assert_eq!(found.len(), 1);
    assert!(found[0][0].ends_with("a/c.rs") && found[0][1].ends_with("b.rs"), "{found:?}");
}
