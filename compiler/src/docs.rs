//! Documentation from comments: the comment on a declaration's line (or the `//` lines right
//! above it), the comment block at the top of a file, and `file.wf:line` locations. Comments
//! are the docs of a .wf file, so `signorini list` and the registry read them from here.

use crate::source::{SourceMap, Span};

/// The `// ...` comment after the declaration on its last line, else (if the declaration starts
/// its line) the block of `//` lines directly above it; joined into one paragraph.
pub fn declaration(sources: &SourceMap, span: Span) -> String {
    let text = sources.text(span.file);
    let end = span.end.min(text.len());
    let line_end = text[end..].find('\n').map_or(text.len(), |i| end + i);
    if let Some(i) = text[end..line_end].find("//") {
        return text[end + i + 2..line_end].trim().to_string();
    }
    let begin = span.start.min(text.len());
    let start = text[..begin].rfind('\n').map_or(0, |i| i + 1);
    if !text[start..begin].trim().is_empty() {
        return String::new();
    }
    above(&text[..start])
}

/// The comment block at the top of a file (up to its first blank or non-comment line).
pub fn file(text: &str) -> String {
    let lines: Vec<&str> =
        text.lines().map(str::trim).take_while(|l| l.starts_with("//")).map(|l| l[2..].trim()).collect();
    lines.join(" ")
}

/// The block of `//` lines that ends right before `before` (which ends at a line start).
fn above(before: &str) -> String {
    let mut lines: Vec<&str> =
        before.lines().rev().map(str::trim).take_while(|l| l.starts_with("//")).map(|l| l[2..].trim()).collect();
    lines.reverse();
    lines.join(" ")
}

/// The first sentence of a doc paragraph (without a trailing colon).
pub fn first_sentence(doc: &str) -> &str {
    let s = match doc.find(". ") {
        Some(i) => &doc[..=i],
        None => doc,
    };
    s.trim_end_matches(':')
}

/// A declaration's default and range as written (`0.05 in [0, 1/3]`): its text after `=`.
pub fn written(sources: &SourceMap, span: Span) -> String {
    let text = sources.slice(span);
    text.split_once('=').map_or(text, |(_, rest)| rest).split_whitespace().collect::<Vec<_>>().join(" ")
}

/// `file.wf:line` of a span's start.
pub fn location(sources: &SourceMap, span: Span) -> String {
    let (line, _) = sources.line_col(span.file, span.start);
    format!("{}:{line}", file_name(sources, span))
}

/// `file.wf:line:col` of the region name in form `form`'s first `int(region)`.
pub fn region_site(unit: &crate::check::Unit, form: &str, region: &str) -> String {
    let f = unit.forms.iter().find(|f| f.name == form);
    let i = f.and_then(|f| f.integrals.iter().find(|i| i.region.name == region));
    i.map_or_else(|| "(source unknown)".to_string(), |i| location_col(&unit.sources, i.region.span))
}

/// `file.wf:line:col` of the first `tangential` form `form` takes, through the `fn`s and `let`s
/// it calls: a part across the obstacle normal, which a 1D problem does not have (its runtime
/// binding refuses such a form there, at this site).
pub fn tangential_site(unit: &crate::check::Unit, form: &str) -> Option<String> {
    use crate::check::Global;
    use crate::syntax::ast::{Expr, ExprKind as K};
    fn walk<'a>(unit: &'a crate::check::Unit, e: &'a Expr, seen: &mut Vec<&'a str>) -> Option<Span> {
        let global = |name: &'a str, seen: &mut Vec<&'a str>| match unit.globals.get(name) {
            Some(Global::Fn { body, .. } | Global::Let { value: body, .. }) if !seen.contains(&name) => {
                seen.push(name);
                walk(unit, body, seen)
            }
            _ => None,
        };
        match &e.kind {
            K::Call(f, _) if f.name == "tangential" => Some(e.span),
            K::Call(f, args) => global(&f.name, seen).or_else(|| args.iter().find_map(|a| walk(unit, a, seen))),
            K::Name(n) => global(&n.name, seen),
            K::Number(_) => None,
            K::Neg(a) => walk(unit, a, seen),
            K::Binary(_, a, b) | K::Index(a, b) => walk(unit, a, seen).or_else(|| walk(unit, b, seen)),
            K::Vector(xs) => xs.iter().find_map(|a| walk(unit, a, seen)),
        }
    }
    let f = unit.forms.iter().find(|f| f.name == form)?;
    let mut seen = Vec::new();
    f.integrals.iter().find_map(|i| walk(unit, &i.integrand, &mut seen)).map(|span| location_col(&unit.sources, span))
}

/// `file.wf:line:col` of a span's start.
pub fn location_col(sources: &SourceMap, span: Span) -> String {
    let (line, col) = sources.line_col(span.file, span.start);
    format!("{}:{line}:{col}", file_name(sources, span))
}

fn file_name(sources: &SourceMap, span: Span) -> String {
    crate::source::display_name(sources.path(span.file))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    fn map(text: &str) -> SourceMap {
        let mut m = SourceMap::default();
        m.add(PathBuf::from("/x/a.wf"), text.to_string());
        m
    }

    #[test]
    fn trailing_comment_else_block_above() {
        let text =
            "// File doc\n// more.\n\n// Above one\n// above two\nparam E = 1.0   // Young's modulus\nparam nu = 0.0\n";
        let m = map(text);
        let e = text.find("param E").unwrap();
        let span_e = Span::new(0, e, e + "param E = 1.0".len());
        assert_eq!(declaration(&m, span_e), "Young's modulus");
        let nu = text.find("param nu").unwrap();
        assert_eq!(declaration(&m, Span::new(0, nu, nu + 14)), "");
        let inline = text.find("= 1.0").unwrap();
        assert_eq!(declaration(&m, Span::new(0, inline, inline + 1)), "Young's modulus");
        assert_eq!(file(text), "File doc more.");
        assert_eq!(above(&text[..e]), "Above one above two");
        assert_eq!(location(&m, span_e), "a.wf:6");
        assert_eq!(first_sentence("One. Two."), "One.");
    }
}
