//! No two source files of a crate import each other, directly or around a circle: layers
//! import downwards only (docs/architecture.md). The dependencies are read from the source
//! text: every `crate::a::b` and `super::a` path outside comments and test modules, resolved
//! to the file of the longest module prefix. A path through a `pub use` re-export (`crate::compile`
//! where `lib.rs` says `pub use pipeline::compile`) counts as a path to the file that defines the
//! item, so a facade's re-exports do not hide a circle. A path into a module's own ancestors (a
//! child naming its parent's items) is not counted: the parent is the child's namespace.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The crates' source roots, relative to the workspace.
const CRATES: [&str; 7] = [
    "src",
    "runtime/src",
    "compiler/src",
    "compiler/macros/src",
    "compiler/generated/src",
    "descriptors/src",
    "python/src",
];

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

/// The leaves of a `use` tree (`a::{b, c::{d as e}}`): each full path, and its name in the
/// importing module (the last segment, or the `as` name). Globs name nothing by name.
fn use_leaves(tree: &str) -> Vec<(Vec<String>, String)> {
    fn segments(path: &str) -> Vec<String> {
        path.split("::").map(str::trim).filter(|s| !s.is_empty()).map(String::from).collect()
    }
    fn walk(prefix: &[String], tree: &str, out: &mut Vec<(Vec<String>, String)>) {
        // Split at the top-level commas.
        let (mut depth, mut start, mut items) = (0usize, 0, Vec::new());
        for (i, c) in tree.char_indices() {
            match c {
                '{' => depth += 1,
                '}' => depth = depth.saturating_sub(1),
                ',' if depth == 0 => {
                    items.push(&tree[start..i]);
                    start = i + 1;
                }
                _ => {}
            }
        }
        items.push(&tree[start..]);
        for item in items.into_iter().map(str::trim).filter(|s| !s.is_empty()) {
            if let Some(open) = item.find('{') {
                let inner = item[open + 1..].trim_end().trim_end_matches('}');
                walk(&[prefix, &segments(&item[..open])].concat(), inner, out);
                continue;
            }
            let (path, alias) = match item.split_once(" as ") {
                Some((p, a)) => (p, Some(a.trim())),
                None => (item, None),
            };
            let mut segs = [prefix, &segments(path)].concat();
            // `a::{self}` names the module `a` itself.
            if segs.last().is_some_and(|s| s == "self") {
                segs.pop();
            }
            let Some(last) = segs.last().cloned() else { continue };
            if last == "*" || alias == Some("_") {
                continue;
            }
            out.push((segs, alias.map_or(last, String::from)));
        }
    }
    let mut out = Vec::new();
    walk(&[], tree, &mut out);
    out
}

/// The names `module` re-exports (`pub use …;`, `pub(crate) use …;`), each with the path from
/// the crate root that it stands for. A path that does not start with `crate`, `self` or
/// `super` is relative to the module (or names another crate: the caller drops those).
fn reexports(code: &str, module: &Module) -> Vec<(String, Module)> {
    let ident = |c: char| c.is_alphanumeric() || c == '_';
    let mut found = Vec::new();
    for (at, _) in code.match_indices("pub") {
        if code[..at].chars().next_back().is_some_and(ident) {
            continue;
        }
        let mut tail = &code[at + 3..];
        // An optional restriction: `pub(crate)`, `pub(super)`, `pub(in …)`.
        if tail.starts_with('(') {
            let Some(close) = tail.find(')') else { continue };
            tail = &tail[close + 1..];
        }
        let Some(body) = tail.trim_start().strip_prefix("use") else { continue };
        if !tail.starts_with(char::is_whitespace) || !body.starts_with(char::is_whitespace) {
            continue;
        }
        let Some(end) = body.find(';') else { continue };
        let tree = body[..end].split_whitespace().collect::<Vec<_>>().join(" ");
        for (segs, name) in use_leaves(&tree) {
            let mut base = match segs[0].as_str() {
                "crate" => Vec::new(),
                "self" => module.clone(),
                "super" => module[..module.len().saturating_sub(1)].to_vec(),
                first => [module.as_slice(), &[first.to_string()]].concat(),
            };
            for seg in &segs[1..] {
                if seg == "super" {
                    base.pop();
                } else {
                    base.push(seg.clone());
                }
            }
            found.push((name, base));
        }
    }
    found
}

type Aliases = BTreeMap<(Module, String), Module>;

/// The file a path resolves to: its longest module prefix, followed through re-exports (a path
/// `m::x…` where `m` re-exports `x` continues as the path `x` stands for).
fn resolve(modules: &BTreeMap<Module, PathBuf>, aliases: &Aliases, path: &Module) -> Option<Module> {
    let mut p = path.clone();
    // A bound on chains of re-exports (a `pub use` circle would not compile anyway).
    for _ in 0..16 {
        let n = (0..=p.len()).rev().find(|&n| modules.contains_key(&p[..n]))?;
        match p.get(n).and_then(|next| aliases.get(&(p[..n].to_vec(), next.clone()))) {
            Some(target) => p = [target.as_slice(), &p[n + 1..]].concat(),
            None => return Some(p[..n].to_vec()),
        }
    }
    None
}

/// The circles of one crate: its strongly connected components of more than one file.
fn circles(root: &Path) -> Vec<Vec<String>> {
    let mut files = Vec::new();
    rust_files(root, &mut files);
    let modules: BTreeMap<Module, PathBuf> = files.iter().map(|f| (module_of(root, f), f.clone())).collect();
    let codes: BTreeMap<&Module, String> =
        modules.iter().map(|(m, f)| (m, code(&std::fs::read_to_string(f).unwrap()))).collect();
    // A re-export counts when it names another file than the module or its ancestors (`pub use
    // signorini_descriptors as descriptors` names another crate and resolves to the module).
    let aliases: Aliases = codes
        .iter()
        .flat_map(|(m, text)| reexports(text, m).into_iter().map(move |(name, target)| (((*m).clone(), name), target)))
        .filter(|((m, _), target)| resolve(&modules, &Aliases::new(), target).is_some_and(|t| !m.starts_with(&t)))
        .collect();
    let mut edges: BTreeMap<Module, BTreeSet<Module>> = BTreeMap::new();
    for (m, text) in &codes {
        let targets = edges.entry((*m).clone()).or_default();
        for p in paths(text, m) {
            if let Some(t) = resolve(&modules, &aliases, &p)
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

/// A circle through the crate root's re-export (`crate::h` where `lib.rs` says `pub use
/// a::{g as h}`) is found; a re-export of another crate, or a child naming what its parent
/// re-exports, is no edge.
#[test]
fn a_circle_through_a_reexport_is_found() {
    let dir = std::env::temp_dir().join(format!("signorini-circles-reexport-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("c")).unwrap();
    let lib = "mod a;\nmod b;\nmod c;\npub use a::{f, g as h};\npub use other_crate as other;\n";
    std::fs::write(dir.join("lib.rs"), lib).unwrap();
    std::fs::write(dir.join("a.rs"), "use crate::b::Thing;\npub fn f() {}\npub fn g() {}\n").unwrap();
    std::fs::write(dir.join("b.rs"), "pub struct Thing;\nfn k() { crate::h(); crate::other::x(); }\n").unwrap();
    std::fs::write(dir.join("c/mod.rs"), "mod d;\npub(crate) use self::d::E;\n").unwrap();
    std::fs::write(dir.join("c/d.rs"), "pub struct E;\nfn k() -> super::E { super::E }\n").unwrap();
    let found = circles(&dir);
    std::fs::remove_dir_all(&dir).unwrap();
    assert_eq!(found.len(), 1, "{found:?}");
    assert!(found[0][0].ends_with("a.rs") && found[0][1].ends_with("b.rs"), "{found:?}");
}

#[test]
fn use_trees_are_read_to_their_leaves() {
    let leaves = use_leaves("pipeline::{Checked, compile as c, inner::{self, X}}, super::y::*");
    let names: Vec<String> = leaves.iter().map(|(p, n)| format!("{}={n}", p.join("::"))).collect();
    assert_eq!(
        names,
        ["pipeline::Checked=Checked", "pipeline::compile=c", "pipeline::inner=inner", "pipeline::inner::X=X"]
    );
}
