//! Rust identifiers for the user's names: sanitised, never a keyword, never clashing with the
//! kernel's own locals.

use std::collections::HashSet;

const RUST_KEYWORDS: &[&str] = &[
    "as", "break", "const", "continue", "crate", "else", "enum", "extern", "false", "fn", "for", "if", "impl", "in",
    "let", "loop", "match", "mod", "move", "mut", "pub", "ref", "return", "self", "Self", "static", "struct", "super",
    "trait", "true", "type", "unsafe", "use", "where", "while", "async", "await", "dyn", "abstract", "become", "box",
    "do", "final", "macro", "override", "priv", "typeof", "unsized", "virtual", "yield", "try", "gen", "union", "_",
];

/// A valid Rust identifier from a .wf name or a file stem: `u'` → `u_p`, other characters
/// outside `[A-Za-z0-9_]` → `_`, a leading digit gets a `_` before it (`9 bad-name` →
/// `_9_bad_name`), keywords get a trailing `_`.
pub fn ident(name: &str) -> String {
    let mut s: String =
        name.replace('\'', "_p").chars().map(|c| if c.is_ascii_alphanumeric() { c } else { '_' }).collect();
    if s.starts_with(|c: char| c.is_ascii_digit()) {
        s.insert(0, '_');
    }
    if RUST_KEYWORDS.contains(&s.as_str()) || s.is_empty() {
        s.push('_');
    }
    s
}

/// `hybrid_contact` → `HybridContact`.
pub fn camel(name: &str) -> String {
    let mut out = String::new();
    for part in ident(name).split('_').filter(|p| !p.is_empty()) {
        let mut cs = part.chars();
        if let Some(c) = cs.next() {
            out.extend(c.to_uppercase());
            out.push_str(cs.as_str());
        }
    }
    if out.is_empty() || out.starts_with(|c: char| c.is_ascii_digit()) {
        out.insert(0, 'F');
    }
    out
}

/// Allocates unique local names within one generated function.
pub struct Namer {
    taken: HashSet<String>,
}

impl Namer {
    pub fn new(reserved: &[&str]) -> Self {
        Namer { taken: reserved.iter().map(|s| s.to_string()).collect() }
    }

    /// `want` if free, else `want_`, `want_2`, `want_3`, ...
    pub fn fresh(&mut self, want: &str) -> String {
        let base = ident(want);
        if self.taken.insert(base.clone()) {
            return base;
        }
        let under = format!("{base}_");
        if self.taken.insert(under.clone()) {
            return under;
        }
        (2..).map(|k| format!("{base}_{k}")).find(|c| self.taken.insert(c.clone())).expect("an unused name exists")
    }
}

#[cfg(test)]
mod tests {
    use super::ident;

    #[test]
    fn file_stems_become_identifiers() {
        assert_eq!(ident("9 bad-name"), "_9_bad_name");
        assert_eq!(ident("u'"), "u_p");
        assert_eq!(ident("type"), "type_");
        assert_eq!(ident("é"), "__");
        assert_eq!(ident(""), "_");
    }
}
