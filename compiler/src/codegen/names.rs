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

/// Whether rustc takes `name` for snake case (`non_snake_case`): no uppercase letter, and no
/// two underscores in a row but at its ends.
pub fn is_snake_case(name: &str) -> bool {
    let inner = name.trim_matches('_');
    !inner.chars().any(char::is_uppercase) && !inner.contains("__")
}

/// `#[allow(non_snake_case)]` before an item that declares one of `names` as the file wrote
/// it (`param E`, `fn P`), else nothing.
pub fn case_allowance<'a>(names: impl IntoIterator<Item = &'a str>) -> &'static str {
    if names.into_iter().all(is_snake_case) { "" } else { "#[allow(non_snake_case)]\n" }
}

/// The identifiers of some Rust text.
pub fn words(text: &str) -> HashSet<&str> {
    text.split(|c: char| !(c.is_ascii_alphanumeric() || c == '_')).filter(|w| !w.is_empty()).collect()
}

/// The names generated Rust binds with `let` (`let x`, `let mut x`, `let (a, b)`).
pub fn locals(text: &str) -> Vec<&str> {
    let mut out = Vec::new();
    for rest in text.split("let ").skip(1) {
        let rest = rest.trim_start_matches("mut ");
        let pattern = match rest.strip_prefix('(') {
            Some(tuple) => tuple.split(')').next().unwrap_or(""),
            None => rest.split(|c: char| !(c.is_ascii_alphanumeric() || c == '_')).next().unwrap_or(""),
        };
        out.extend(pattern.split(',').map(str::trim).filter(|w| !w.is_empty()));
    }
    out
}

/// Allocates unique local names within one generated function.
pub struct Namer {
    taken: HashSet<String>,
    /// Temporaries allocated so far.
    temporaries: usize,
}

impl Namer {
    pub fn new(reserved: &[&str]) -> Self {
        Namer { taken: reserved.iter().map(|s| s.to_string()).collect(), temporaries: 0 }
    }

    /// A name for a subexpression the source did not name: `tmp1`, `tmp2`, ...
    pub fn temporary(&mut self) -> String {
        loop {
            self.temporaries += 1;
            let name = format!("tmp{}", self.temporaries);
            if self.taken.insert(name.clone()) {
                return name;
            }
        }
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
